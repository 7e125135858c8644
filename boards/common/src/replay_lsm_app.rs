//! The QEMU replay firmware with the LSM6DSV320X (`--features replay-lsm6dsv320x`): the
//! stored sprint as that part's FIFO delivers it (`fixtures/sprint_40g_lsm6dsv320x.rs`).
//!
//! The board's timer ticks once per low-g sample period; each tick puts that period's words
//! into the emulated part's FIFO ([`ReplayLsm6dsv320x`], the real driver on top). When the
//! FIFO holds its watermark (the part's INT1), the tick's handler reads the waiting words
//! through the driver and assembles them ([`Assembler`]: each low-g axis at its rail takes the
//! mean of the high-g samples of its period) into the pipeline's samples, which go through
//! the same SPSC queue, main loop, start-up report, stride log and summary as
//! [`crate::replay_app`]'s. The part does not sleep here: the sprint never stands still for
//! 10 s, and the LSM6DSV320X's wake-up is not wired to the sleep policy yet.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::interrupt::{self as irq, Mutex};
use gaitclip::detect::seam::StepDetector;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip::sensor::rate::SampleRate;
use gaitclip_lsm6dsv320x::blocking::Lsm6dsv320x;
use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag};
use gaitclip_lsm6dsv320x::merge::{Assembler, DualRange};
use gaitclip_lsm6dsv320x::mode::Sampling;
use gaitclip_lsm6dsv320x::{self as lsm, Address, HighG, HighGOdr, Odr};
use gaitclip_lsm6dsv320x::{AccelRange, GyroRange, HighGRange};
use heapless::spsc::{Producer, Queue};

use crate::imu_sampler::{Counters, Item};
use crate::live_app::SpinDelay;
use crate::replay_app::{self, fail, wait_for_interrupt, Irq, SampleTimer};
use crate::replay_lsm6dsv320x::{Recorded, ReplayLsm6dsv320x};
use crate::startup::Startup;
use crate::stride_log::{NoSerial, StrideLog};

/// The stored sprint as the LSM6DSV320X's FIFO delivers it.
#[path = "../../../fixtures/sprint_40g_lsm6dsv320x.rs"]
mod lsm_trace;

/// Samples the queue holds between the interrupt and the main loop: 64 = 267 ms at 240 Hz,
/// eight FIFO bursts.
pub const QUEUE_LEN: usize = 64;
/// Words read per FIFO transfer loop: the watermark and a margin.
const BURST_WORDS: usize = 64;

const fn unwrap<T: Copy>(v: Option<T>) -> T {
    match v {
        Some(v) => v,
        None => panic!("the stored trace has an unsupported rate or range"),
    }
}

/// The stored trace's low-g rate (checked at compile time).
pub const RATE: SampleRate = unwrap(SampleRate::from_hz(lsm_trace::RATE_HZ));
const ODR: Odr = unwrap(Odr::from_hz(lsm_trace::RATE_HZ));
const HIGH_G_ODR: HighGOdr = unwrap(HighGOdr::from_hz(lsm_trace::HIGH_G_RATE_HZ));
const ACCEL: AccelRange = unwrap(AccelRange::from_field(lsm_trace::FS_XL));
const HIGH_G: HighGRange = unwrap(HighGRange::from_field(lsm_trace::FS_XL_HG));
const GYRO: GyroRange = unwrap(GyroRange::from_field(lsm_trace::FS_G));
/// The two accelerometers as the firmware merges them.
pub const DUAL: DualRange = DualRange::new(ACCEL, HIGH_G);
/// The part's configuration: the trace's rates and ranges, a watermark of eight periods.
pub const SENSOR: lsm::Config = lsm::Config {
    odr: ODR,
    accel: ACCEL,
    gyro: GYRO,
    high_g: Some(HighG {
        range: HIGH_G,
        odr: HIGH_G_ODR,
    }),
    watermark_words: (8 * lsm_trace::WORDS_PER_SAMPLE) as u8,
};
/// The pipeline's configuration: the merged counts' scale (the high-g channel's) and the
/// gyroscope's, with the firmware's detector.
pub const CONFIG: Config = {
    let mut c = Config::new(RATE, DUAL.scale(), GYRO.scale());
    c.detector = crate::DETECTOR;
    c
};
/// The movement buffer: [`gaitclip::detect::seam::MAX_MOVEMENT_MS`] at the trace's rate.
pub const MOVEMENT_SAMPLES: usize = gaitclip::detect::seam::movement_samples(lsm_trace::RATE_HZ);
/// Low-g sample periods in the stored trace.
pub const TRACE_SAMPLES: u32 = (lsm_trace::FIFO.len()
    / gaitclip_lsm6dsv320x::fifo::WORD_BYTES
    / lsm_trace::WORDS_PER_SAMPLE) as u32;

/// What the interrupt side holds: the driver on the emulated part, the assembler, the queue's
/// producer and the counters.
struct Sampler {
    imu: Lsm6dsv320x<ReplayLsm6dsv320x, Sampling>,
    assembler: Assembler,
    producer: Producer<'static, Item>,
    counters: Counters,
    words: [FifoWord; BURST_WORDS],
    /// Sample periods accounted for: queued as samples, or as gaps (declared or pending).
    periods_out: u32,
    /// Sample periods lost and not yet declared (the queue had no room for the gap).
    pending_gap: u32,
}

impl Sampler {
    /// Reads every waiting word and queues the samples they complete. After an overrun the
    /// FIFO is empty and everything the part's clock counted but the board did not receive
    /// is declared as one gap: nothing is dropped silently.
    fn drain(&mut self) {
        loop {
            let n = match self.imu.read_fifo(&mut self.words) {
                Ok(n) => n,
                Err(lsm::Error::FifoOverflow) => {
                    self.counters.fifo_overflows = self.counters.fifo_overflows.wrapping_add(1);
                    if let Some(s) = self.assembler.flush() {
                        self.queue(s);
                    }
                    let ticked = self.imu.bus_mut().ticked() as u32;
                    self.lose(ticked.saturating_sub(self.periods_out));
                    self.declare_gap();
                    return;
                }
                Err(_) => {
                    // The words stay in the FIFO; the next watermark reads them.
                    self.counters.bus_errors = self.counters.bus_errors.wrapping_add(1);
                    return;
                }
            };
            for k in 0..n {
                if let Some(s) = self.assembler.push(self.words[k]) {
                    self.queue(s);
                }
            }
            if n < BURST_WORDS {
                return;
            }
        }
    }

    /// `n` sample periods lost, to declare as a gap before the next sample.
    fn lose(&mut self, n: u32) {
        self.pending_gap = self.pending_gap.saturating_add(n);
        self.periods_out = self.periods_out.saturating_add(n);
    }

    /// Declares the pending gap, if the queue has room.
    fn declare_gap(&mut self) {
        if self.pending_gap > 0 && self.producer.enqueue(Item::Gap(self.pending_gap)).is_ok() {
            self.counters.lost_samples =
                self.counters.lost_samples.saturating_add(self.pending_gap);
            self.pending_gap = 0;
        }
    }

    /// Queues a sample after any pending gap; without room it becomes part of the gap.
    fn queue(&mut self, s: gaitclip::sensor::sample::RawSample) {
        self.declare_gap();
        if self.pending_gap == 0 && self.producer.enqueue(Item::Sample(s)).is_ok() {
            self.periods_out = self.periods_out.saturating_add(1);
        } else {
            self.counters.overruns = self.counters.overruns.wrapping_add(1);
            self.lose(1);
        }
    }
}

static SAMPLER: Mutex<RefCell<Option<Sampler>>> = Mutex::new(RefCell::new(None));
static TRACE_DONE: AtomicBool = AtomicBool::new(false);

/// Runs the stored sprint through `pipeline` (made from [`CONFIG`]) with the timer `T`
/// ticking at the trace's low-g rate, and exits QEMU.
pub fn run<D: StepDetector, T: SampleTimer>(
    pipeline: &mut Pipeline<D>,
    board: &str,
    cycles_per_us: u32,
) -> ! {
    // Note(unsafe): `run` is the one caller besides the handler (`SampleTimer::steal`).
    let timer = unsafe { T::steal() };
    let part = ReplayLsm6dsv320x::new(
        Address::Sa0Low.bits(),
        lsm_trace::FIFO,
        Recorded {
            odr_field: ODR.field(),
            fs_xl: ACCEL.field(),
            fs_g: GYRO.field(),
            high_g_ctrl: HIGH_G.field() | (HIGH_G_ODR.field() << 3),
            words_per_period: lsm_trace::WORDS_PER_SAMPLE,
        },
    );
    let mut delay = SpinDelay { cycles_per_us };
    let imu = match Lsm6dsv320x::new(part, Address::Sa0Low).init(&mut delay, &SENSOR) {
        Ok(imu) => imu,
        Err(e) => {
            defmt::error!("LSM6DSV320X init failed: {}", defmt::Debug2Format(&e.error));
            fail();
        }
    };
    let mut log = StrideLog::new(RATE);
    log.banner(board, &CONFIG, &mut NoSerial);
    defmt::info!(
        "replaying {=u32} samples of the stored sprint through the emulated LSM6DSV320X's FIFO (low-g + high-g merged)",
        TRACE_SAMPLES
    );
    let Some(queue) = cortex_m::singleton!(: Queue<Item, QUEUE_LEN> = Queue::new()) else {
        fail();
    };
    let (producer, mut consumer) = queue.split();
    irq::free(|cs| {
        *SAMPLER.borrow(cs).borrow_mut() = Some(Sampler {
            imu,
            assembler: Assembler::new(DUAL),
            producer,
            counters: Counters::ZERO,
            words: [FifoWord {
                tag: Tag::Other(0),
                slot: 0,
                data: [0; 3],
            }; BURST_WORDS],
            periods_out: 0,
            pending_gap: 0,
        });
    });
    timer.start_periodic(lsm_trace::RATE_HZ * 1000);
    // Note(unsafe): the handler only touches state behind `Mutex`es and atomics, so
    // unmasking cannot break a critical section.
    unsafe { cortex_m::peripheral::NVIC::unmask(Irq(T::IRQ)) };

    let mut startup = Startup::new(RATE, GYRO.scale());
    let mut samples = 0u32;
    loop {
        while let Some(item) = consumer.dequeue() {
            handle(item, pipeline, &mut startup, &mut log, &mut samples);
        }
        if TRACE_DONE.load(Ordering::Acquire) && !consumer.ready() {
            timer.stop();
            finish(pipeline, &mut log, samples);
        }
        wait_for_interrupt(|| consumer.ready(), &TRACE_DONE);
    }
}

/// One queue item through the pipeline (not inlined, as replay_app's).
#[inline(never)]
fn handle<D: StepDetector>(
    item: Item,
    pipeline: &mut Pipeline<D>,
    startup: &mut Startup,
    log: &mut StrideLog,
    samples: &mut u32,
) {
    let serial = &mut NoSerial;
    let stride = item.feed(pipeline);
    if let Item::Sample(_) = item {
        *samples = samples.wrapping_add(1);
        if let Some(e) = startup.update(pipeline) {
            log.startup(e, serial);
        }
    }
    if let Some(stride) = &stride {
        log.stride(stride, serial);
    }
    if let Item::Gap(n) = item {
        log.gap(n, pipeline.hole_kind(n), serial);
    }
}

/// The end of the trace: [`crate::replay_app`]'s, with the merge's counts before the
/// summary.
#[inline(never)]
fn finish<D: StepDetector>(pipeline: &mut Pipeline<D>, log: &mut StrideLog, samples: u32) -> ! {
    let (counters, merge) = irq::free(|cs| {
        SAMPLER
            .borrow(cs)
            .borrow()
            .as_ref()
            .map_or((Counters::ZERO, (0, 0, 0, 0)), |s| {
                let a = &s.assembler;
                (
                    s.counters,
                    (
                        a.high_g_axes(),
                        a.high_g_missing(),
                        a.unpaired(),
                        a.high_g_dropped(),
                    ),
                )
            })
    });
    replay_app::finish(pipeline, log, samples, &counters, || {
        defmt::println!(
            "merge high_g_axes={=u32} high_g_missing={=u32} unpaired={=u32} high_g_dropped={=u32}",
            merge.0,
            merge.1,
            merge.2,
            merge.3
        );
    })
}

/// The body of the board's `DefaultHandler`: for the timer's interrupt, one low-g period of
/// the emulated part (its words into the FIFO, the FIFO read at its watermark), or, once the
/// trace has been served, the last words and the end of the run.
pub fn on_interrupt<T: SampleTimer>(irqn: i16) {
    if irqn != T::IRQ as i16 {
        return;
    }
    // Note(unsafe): the handler only acknowledges and stops the timer (`steal`).
    let timer = unsafe { T::steal() };
    timer.clear_interrupt();
    let done = irq::free(|cs| {
        let mut cell = SAMPLER.borrow(cs).borrow_mut();
        let Some(s) = cell.as_mut() else {
            return false;
        };
        let part = s.imu.bus_mut();
        if part.remaining() == 0 {
            // Everything served: the last words, and the last period's sample.
            s.drain();
            if let Some(last) = s.assembler.flush() {
                s.queue(last);
            }
            s.declare_gap();
            return true;
        }
        part.tick();
        // INT1: the FIFO at its watermark.
        if part.waiting() >= SENSOR.watermark_words as usize {
            s.drain();
        }
        false
    });
    if done {
        TRACE_DONE.store(true, Ordering::Release);
        timer.stop();
    }
}

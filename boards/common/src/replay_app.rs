//! The firmware of the emulated boards, which differ only in their sample timer.
//!
//! A timer interrupts at the trace's sample rate and stands in for the MPU6050's INT pin:
//! it pulses once per sample of the stored trace. Its handler ([`on_data_ready`]) runs the
//! shared [`ImuSampler`] on the emulated sensor ([`ReplayMpu6050`], the real driver on top),
//! which pushes into an SPSC queue. The main loop ([`run`]) drains the queue through the
//! pipeline, reports start-up, strides and gaps, and sleeps with `wfi` when the queue is
//! empty. When the trace ends it logs a summary and exits QEMU through semihosting with
//! status 0; a panic or HardFault exits with status 1 ([`fail`]).
//!
//! It sleeps as the boards with a real sensor do ([`crate::sleep`]): still for 10 s, the
//! emulated sensor goes to its cycle mode and the timer, standing in for the sensor's own
//! clock now, ticks at the wake rate ([`ReplayMpu6050::wake_tick`]) until the trace moves;
//! then full sampling resumes. The demo walk never stands that long; with the
//! `replay-sleep` feature the sensor holds still for the runs of [`STILL`].

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::interrupt as irq;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use gaitclip::detect::seam::StepDetector;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip::sensor::rate::SampleRate;
use gaitclip_mpu6050::blocking::{Mpu6050, Mpu6050Source};
use gaitclip_mpu6050::{self as mpu6050, Address};
use gaitclip_mpu6050::{AccelRange, GyroRange, SAMPLE_BYTES};
use heapless::spsc::Queue;

use crate::imu_sampler::{ImuSampler, Item, ReadMode};
use crate::live_app::{SampleLink, SpinDelay};
use crate::replay_mpu6050::{ReplayMpu6050, WakeTick};
use crate::sleep::{SleepPolicy, SLEEP};
use crate::startup::Startup;
use crate::stride_log::{NoSerial, StrideLog};
use crate::trace;

/// Samples the queue holds between the interrupt and the main loop: 32 = 160 ms at 200 Hz,
/// more than one stride's processing takes on either core.
pub const QUEUE_LEN: usize = 32;
/// Runs of samples the emulated sensor loses, `(first sample, samples)`: none, or with the
/// `replay-holes` feature the runs of [`crate::replay_holes::LOST`], so that a QEMU run can
/// be compared with the host replay of the same holes (`firmware_qemu`).
#[cfg(not(feature = "replay-holes"))]
pub const LOST: &[(u32, u32)] = &[];
#[cfg(feature = "replay-holes")]
pub use crate::replay_holes::LOST;
/// Runs of periods the emulated sensor holds still: none, or with the `replay-sleep`
/// feature [`crate::replay_still::STILL`].
#[cfg(not(feature = "replay-sleep"))]
pub const STILL: &[(u32, u32)] = &[];
#[cfg(feature = "replay-sleep")]
pub use crate::replay_still::STILL;

/// Samples in the stored trace.
pub const TRACE_SAMPLES: u32 = (trace::REGISTERS.len() / SAMPLE_BYTES) as u32;
/// Samples dropped after a wake-up while the gyro settles.
const SETTLE: u32 = SleepPolicy::settle_samples(RATE, &SLEEP);

const fn unwrap<T: Copy>(v: Option<T>) -> T {
    match v {
        Some(v) => v,
        None => panic!("the stored trace has an unsupported rate or range"),
    }
}

/// The stored trace's sample rate (checked at compile time).
pub const RATE: SampleRate = unwrap(SampleRate::from_millihertz(trace::RATE_MILLIHERTZ));
const ACCEL: AccelRange = unwrap(AccelRange::from_afs_sel(trace::ACCEL_AFS_SEL));
const GYRO: GyroRange = unwrap(GyroRange::from_fs_sel(trace::GYRO_FS_SEL));
/// The pipeline's configuration for the stored trace.
pub const CONFIG: Config = crate::live_settings::mpu6050::config(RATE, ACCEL, GYRO);
/// The movement buffer: [`gaitclip::detect::seam::MAX_MOVEMENT_MS`] at the trace's rate.
pub const MOVEMENT_SAMPLES: usize =
    gaitclip::detect::seam::movement_samples(trace::RATE_MILLIHERTZ.div_ceil(1000));
const SENSOR: mpu6050::Config = crate::live_settings::mpu6050::sensor_config(
    (trace::RATE_MILLIHERTZ / 1000) as u16,
    ACCEL,
    GYRO,
);

/// Sampler, queue producer and pulse count, shared by the timer interrupt and the main loop.
static LINK: SampleLink<Mpu6050Source<ReplayMpu6050>, SpinDelay> = SampleLink::new();
static TRACE_DONE: AtomicBool = AtomicBool::new(false);

/// The board's sample timer.
pub trait SampleTimer: Sized {
    /// Its external interrupt number.
    const IRQ: u16;
    /// The timer, for `main` and for its interrupt handler.
    ///
    /// # Safety
    /// Only [`run`] (once) and [`on_interrupt`] may call it: `run` drives the timer, the
    /// handler only acknowledges and stops it.
    unsafe fn steal() -> Self;
    /// Starts periodic interrupts at `millihertz`.
    fn start_periodic(&self, millihertz: u32);
    /// Stops them.
    fn stop(&self);
    /// Acknowledges the interrupt.
    fn clear_interrupt(&self);
}

/// An external interrupt number of the board, for the NVIC.
#[derive(Clone, Copy)]
pub(crate) struct Irq(pub(crate) u16);

// Note(unsafe): `Irq` is made only of a timer's `SampleTimer::IRQ`, a valid external
// interrupt of its device (both QEMU boards have 32).
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// Runs the trace through `pipeline` (made from [`CONFIG`]; the board keeps it in a static,
/// sized for its RAM) with the timer `T` pulsing at the trace's rate, and exits QEMU.
pub fn run<D: StepDetector, T: SampleTimer>(
    pipeline: &mut Pipeline<D>,
    board: &str,
    cycles_per_us: u32,
) -> ! {
    // Note(unsafe): `run` is the one caller besides the handler (`SampleTimer::steal`).
    let timer = unsafe { T::steal() };
    let imu = Mpu6050::new(
        ReplayMpu6050::with_still(
            Address::Ad0Low.bits(),
            trace::REGISTERS,
            trace::RATE_MILLIHERTZ,
            STILL,
            LOST,
        ),
        Address::Ad0Low,
    );
    let sampler = match ImuSampler::start(
        Mpu6050Source::new(imu, SENSOR),
        SpinDelay { cycles_per_us },
        ReadMode::PerSample,
    ) {
        Ok(s) => s,
        Err((_, _, e)) => {
            defmt::error!("MPU6050 init failed: {}", defmt::Debug2Format(&e));
            fail();
        }
    };
    let mut log = StrideLog::new(RATE);
    log.banner(board, &CONFIG, &mut NoSerial);
    defmt::info!(
        "replaying {=u32} samples of the stored trace through the emulated MPU6050",
        TRACE_SAMPLES
    );

    let Some(queue) = cortex_m::singleton!(: Queue<Item, QUEUE_LEN> = Queue::new()) else {
        fail();
    };
    let (producer, mut consumer) = queue.split();
    LINK.install(sampler, producer);
    timer.start_periodic(trace::RATE_MILLIHERTZ);
    // Note(unsafe): the handler only touches state behind `Mutex`es and atomics, so
    // unmasking cannot break a critical section.
    unsafe { cortex_m::peripheral::NVIC::unmask(Irq(T::IRQ)) };

    let mut startup = Startup::new(RATE, GYRO.scale());
    let mut policy = SleepPolicy::new(RATE, &SLEEP);
    let mut samples = 0u32;
    loop {
        while let Some(item) = consumer.dequeue() {
            handle(
                item,
                pipeline,
                &mut startup,
                &mut policy,
                &mut log,
                &mut samples,
            );
        }
        if TRACE_DONE.load(Ordering::Acquire) && !consumer.ready() {
            timer.stop();
            finish(pipeline, &mut log, samples, &LINK.counters(), || {});
        }
        wait_for_interrupt(|| consumer.ready(), &TRACE_DONE);
    }
}

/// Sleeps until the next interrupt unless an item is `ready` or the trace is `done`.
/// Interrupts are masked while checking, so an item that arrives between the check and `wfi`
/// still wakes the core (WFI wakes on a pending interrupt even with PRIMASK set).
pub(crate) fn wait_for_interrupt(ready: impl Fn() -> bool, done: &AtomicBool) {
    irq::disable();
    if !ready() && !done.load(Ordering::Acquire) {
        cortex_m::asm::wfi();
    }
    // Note(unsafe): re-enables the interrupts disabled just above; no critical section
    // spans this point.
    unsafe { irq::enable() };
}

/// One queue item through the pipeline. Not inlined: its temporaries (strides, features)
/// then live on the stack only while it runs, not for the life of `run`'s frame, which a
/// 16 KiB part cannot spare.
#[inline(never)]
fn handle<D: StepDetector>(
    item: Item,
    pipeline: &mut Pipeline<D>,
    startup: &mut Startup,
    policy: &mut SleepPolicy,
    log: &mut StrideLog,
    samples: &mut u32,
) {
    let serial = &mut NoSerial;
    let stride = item.feed(pipeline);
    match item {
        Item::Sample(_) => {
            *samples = samples.wrapping_add(1);
            if let Some(e) = startup.update(pipeline) {
                log.startup(e, serial);
            }
        }
        Item::Asleep => log.asleep(policy.still_samples(), &SLEEP, serial),
        Item::Gap(_) | Item::Woke(_) => {}
    }
    let at_rest = pipeline.at_rest();
    if let Some(after) = policy.after_item(&item, at_rest, stride.is_some(), *samples, QUEUE_LEN) {
        LINK.request_sleep(after, SLEEP.wake);
    }
    // A stride a gap hands back was closed before it: it comes first.
    if let Some(stride) = &stride {
        log.stride(stride, serial);
    }
    match item {
        Item::Gap(n) => log.gap(n, pipeline.hole_kind(n), serial),
        Item::Woke(n) => log.woke(n, serial),
        _ => {}
    }
}

/// The end of the trace: the strides still held, what `before_summary` prints, the summary
/// with the sampler's `counters`, the stack's high-water mark, and QEMU's exit.
#[inline(never)]
pub(crate) fn finish<D: StepDetector>(
    pipeline: &mut Pipeline<D>,
    log: &mut StrideLog,
    samples: u32,
    counters: &crate::imu_sampler::Counters,
    before_summary: impl FnOnce(),
) -> ! {
    let serial = &mut NoSerial;
    while let Some(stride) = pipeline.finish() {
        log.stride(&stride, serial);
    }
    before_summary();
    log.summary(
        samples,
        counters,
        &pipeline.clipped_samples(),
        (&pipeline.rejected(), &pipeline.between()),
        serial,
    );
    let (used, size) = crate::stack_paint::used_and_size();
    defmt::println!("stack used={=u32} of {=u32} bytes", used, size);
    debug::exit(EXIT_SUCCESS);
    cortex_m::asm::udf()
}

/// The body of the board's `DefaultHandler`: for the timer's interrupt, one data-ready
/// pulse of the emulated sensor (or, while it sleeps, one wake-up of its cycle mode), or,
/// once the trace has been served, the end of the run (the timer stops).
pub fn on_interrupt<T: SampleTimer>(irqn: i16) {
    if irqn == T::IRQ as i16 {
        // Note(unsafe): the handler only acknowledges and stops the timer (`steal`).
        on_timer_interrupt(&unsafe { T::steal() });
    }
}

/// What a timer tick did to the emulated sensor.
enum Tick {
    /// Sampled (or slept on): the timer goes on as it is.
    Same,
    /// The sensor went to sleep: the timer ticks at its wake rate.
    FellAsleep,
    /// It woke on motion: the timer pulses at the sample rate again.
    Woke,
    /// The trace is over.
    Done,
}

fn on_timer_interrupt(timer: &impl SampleTimer) {
    timer.clear_interrupt();
    let tick = LINK.with_sampler(|s, mut push| {
        let asleep = s.asleep();
        let Some(sensor) = s.bus_mut() else {
            return Tick::Done; // not reached: the sampler always holds its sensor
        };
        if asleep {
            return match sensor.wake_tick() {
                WakeTick::Motion => {
                    let slept = sensor.periods_in_cycle();
                    s.on_motion(slept, SETTLE, &mut push);
                    Tick::Woke
                }
                WakeTick::Ended => Tick::Done,
                WakeTick::Still | WakeTick::Awake => Tick::Same,
            };
        }
        if sensor.remaining() == 0 {
            return Tick::Done;
        }
        s.on_data_ready(&mut push);
        if s.asleep() {
            Tick::FellAsleep
        } else {
            Tick::Same
        }
    });
    match tick {
        Some(Tick::Done) => {
            TRACE_DONE.store(true, Ordering::Release);
            timer.stop();
        }
        Some(Tick::FellAsleep) => timer.start_periodic(SLEEP.wake.rate.millihertz()),
        Some(Tick::Woke) => timer.start_periodic(trace::RATE_MILLIHERTZ),
        Some(Tick::Same) | None => {}
    }
}

#[cortex_m_rt::exception]
unsafe fn HardFault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc={=u32:#x}", ef.pc());
    fail();
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    fail();
}

/// Exits QEMU with a failure status.
pub fn fail() -> ! {
    debug::exit(EXIT_FAILURE);
    // Without a debugger attached semihosting returns: stop with a fault instead.
    cortex_m::asm::udf()
}

//! gaitclip on the emulated board: QEMU `mps2-an386` (Cortex-M4F).
//!
//! TIMER0 interrupts at the trace's sample rate; its handler reads the next sample from the
//! MPU6050 through the real driver (the sensor itself is emulated at the bus by
//! [`replay_mpu6050`], replaying a trace from flash) and pushes it into an SPSC queue. The
//! main loop drains the queue through the pipeline, logs one defmt line per stride and sleeps
//! with `wfi` when the queue is empty. A sample that finds the queue full, or a sensor that does
//! not answer after retries and a re-initialisation, is counted and reported to the pipeline
//! as a gap, never dropped silently. When the trace ends it logs a summary and exits QEMU
//! through semihosting with status 0; a panic or HardFault exits with status 1.

#![no_std]
#![no_main]

mod cmsdk_timer;
#[path = "../common/replay_mpu6050.rs"]
mod replay_mpu6050;
#[path = "../common/stride_log.rs"]
mod stride_log;
#[path = "../../fixtures/demo_walk.rs"]
mod trace;

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use cortex_m::interrupt::{self as irq, Mutex};
use cortex_m::peripheral::NVIC;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use defmt_semihosting as _;
use embedded_hal::delay::DelayNs;
use gaitclip::mpu6050::{self, Address, Mpu6050};
use gaitclip::pipeline::{Config, Pipeline};
use gaitclip::rate::SampleRate;
use gaitclip::sample::{AccelRange, GyroRange, RawSample};
use heapless::spsc::{Producer, Queue};

use cmsdk_timer::{CmsdkTimer, TIMER0_BASE, TIMER0_IRQ};
use replay_mpu6050::{ReplayBusError, ReplayMpu6050};
use stride_log::StrideLog;

/// Samples the queue holds between the interrupt and the main loop: 64 = 320 ms at 200 Hz,
/// far more than one stride's processing takes.
const QUEUE_LEN: usize = 64;
/// Bus errors in a row (one read and its retries) after which the sensor is re-initialised.
const REINIT_AFTER_ERRORS: u32 = 3;

type Imu = Mpu6050<ReplayMpu6050>;

/// What the sample interrupt hands to the main loop.
#[derive(Clone, Copy)]
enum Item {
    Sample(RawSample),
    /// This many sample periods were lost (queue full, sensor not answering): the pipeline
    /// drops the stride in progress instead of measuring across the hole.
    Gap(u32),
}

static PRODUCER: Mutex<RefCell<Option<Producer<'static, Item>>>> = Mutex::new(RefCell::new(None));
static IMU: Mutex<RefCell<Option<(Imu, mpu6050::Config)>>> = Mutex::new(RefCell::new(None));
static OVERRUNS: AtomicU32 = AtomicU32::new(0);
/// Sample periods lost and not yet reported to the main loop.
static PENDING_GAP: AtomicU32 = AtomicU32::new(0);
static BUS_ERRORS: AtomicU32 = AtomicU32::new(0);
static TRACE_DONE: AtomicBool = AtomicBool::new(false);

/// TIMER0 as an NVIC interrupt number.
#[derive(Clone, Copy)]
struct Irq(u16);

// Note(unsafe): `number` returns a valid external interrupt number of this device
// (TIMER0 is IRQ 8 on AN386, which has 32 external interrupts).
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// Busy-wait delay for the sensor's reset time; the emulated sensor needs none, a real one
/// 100 ms, and a busy loop is honest about what it costs.
struct SpinDelay;

impl DelayNs for SpinDelay {
    fn delay_ns(&mut self, ns: u32) {
        // 25 MHz core clock: 25 cycles per µs.
        cortex_m::asm::delay(ns / 40);
    }
}

#[entry]
fn main() -> ! {
    let (Some(rate), Some(accel), Some(gyro)) = (
        SampleRate::from_millihertz(trace::RATE_MILLIHERTZ),
        AccelRange::from_afs_sel(trace::ACCEL_AFS_SEL),
        GyroRange::from_fs_sel(trace::GYRO_FS_SEL),
    ) else {
        defmt::error!("the stored trace has an unsupported rate or range");
        fail();
    };
    let mut imu = Mpu6050::new(
        ReplayMpu6050::new(Address::Ad0Low.bits(), trace::REGISTERS),
        Address::Ad0Low,
    );
    let Some(out_rate) = mpu6050::OutputRate::from_hz((trace::RATE_MILLIHERTZ / 1000) as u16)
    else {
        defmt::error!("rate outside the sensor's 100-1000 Hz");
        fail();
    };
    let sensor_config = mpu6050::Config {
        rate: out_rate,
        accel,
        gyro,
    };
    if let Err(e) = imu.init(&mut SpinDelay, &sensor_config) {
        defmt::error!("MPU6050 init failed: {}", defmt::Debug2Format(&e));
        fail();
    }
    defmt::info!(
        "gaitclip on mps2-an386: replaying {=u32} samples at {=u32} mHz",
        (trace::REGISTERS.len() / gaitclip::sample::SAMPLE_BYTES) as u32,
        trace::RATE_MILLIHERTZ
    );

    let Some(queue) = cortex_m::singleton!(: Queue<Item, QUEUE_LEN> = Queue::new()) else {
        fail();
    };
    let (producer, mut consumer) = queue.split();
    irq::free(|cs| {
        PRODUCER.borrow(cs).replace(Some(producer));
        IMU.borrow(cs).replace(Some((imu, sensor_config)));
    });

    // Note(unsafe): TIMER0 is driven only through this value, from here and its handler.
    let timer = unsafe { CmsdkTimer::new(TIMER0_BASE) };
    timer.start_periodic(trace::RATE_MILLIHERTZ);
    // Note(unsafe): the handler only touches state behind `Mutex`es and atomics, so
    // unmasking cannot break a critical section.
    unsafe { NVIC::unmask(Irq(TIMER0_IRQ)) };

    let mut pipeline = Pipeline::new(Config::new(rate, accel, gyro));
    let mut log = StrideLog::new(rate);
    let mut samples = 0u32;
    loop {
        while let Some(item) = consumer.dequeue() {
            match item {
                Item::Sample(s) => {
                    samples = samples.wrapping_add(1);
                    if let Some(stride) = pipeline.process(&s) {
                        log.stride(&stride);
                    }
                }
                Item::Gap(n) => {
                    defmt::warn!(
                        "gap of {=u32} samples: the stride in progress is dropped",
                        n
                    );
                    if let Some(stride) = pipeline.gap(n) {
                        log.stride(&stride);
                    }
                }
            }
        }
        if TRACE_DONE.load(Ordering::Acquire) && !consumer.ready() {
            timer.stop();
            for stride in pipeline.finish().iter().flatten() {
                log.stride(stride);
            }
            log.summary(
                samples,
                OVERRUNS.load(Ordering::Relaxed),
                BUS_ERRORS.load(Ordering::Relaxed),
            );
            debug::exit(EXIT_SUCCESS);
        }
        // Sleep until the next interrupt. Interrupts are masked while checking the queue so
        // a sample that arrives between the check and `wfi` still wakes the core (WFI wakes
        // on a pending interrupt even with PRIMASK set).
        irq::disable();
        if !consumer.ready() && !TRACE_DONE.load(Ordering::Acquire) {
            cortex_m::asm::wfi();
        }
        // Note(unsafe): re-enables the interrupts disabled just above; no critical section
        // spans this point.
        unsafe { irq::enable() };
    }
}

/// Sample clock: one sensor read per tick.
fn on_timer_tick() {
    // Note(unsafe): TIMER0 is only acknowledged here; `main` only starts and stops it.
    let timer = unsafe { CmsdkTimer::new(TIMER0_BASE) };
    timer.clear_interrupt();
    irq::free(|cs| {
        let mut imu = IMU.borrow(cs).borrow_mut();
        let mut producer = PRODUCER.borrow(cs).borrow_mut();
        let (Some((imu, config)), Some(producer)) = (imu.as_mut(), producer.as_mut()) else {
            return;
        };
        let mut failures = 0;
        let item = loop {
            match imu.read_sample() {
                Ok(s) => break Item::Sample(s),
                Err(mpu6050::Error::Bus(ReplayBusError::Exhausted)) => {
                    TRACE_DONE.store(true, Ordering::Release);
                    timer.stop();
                    return;
                }
                Err(_) => {
                    // Counted and retried; after repeated failures the sensor is set up again
                    // and this sample period becomes a gap.
                    BUS_ERRORS.fetch_add(1, Ordering::Relaxed);
                    failures += 1;
                    if failures >= REINIT_AFTER_ERRORS {
                        if imu.init(&mut SpinDelay, config).is_err() {
                            BUS_ERRORS.fetch_add(1, Ordering::Relaxed);
                        }
                        PENDING_GAP.fetch_add(1, Ordering::Relaxed);
                        return;
                    }
                }
            }
        };
        // Report lost periods before the sample that follows them; if the queue has no room
        // for both, this sample is lost too and joins the gap.
        let gap = PENDING_GAP.load(Ordering::Relaxed);
        if gap > 0 {
            if producer.enqueue(Item::Gap(gap)).is_err() {
                OVERRUNS.fetch_add(1, Ordering::Relaxed);
                PENDING_GAP.fetch_add(1, Ordering::Relaxed);
                return;
            }
            PENDING_GAP.store(0, Ordering::Relaxed);
        }
        if producer.enqueue(item).is_err() {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
            PENDING_GAP.fetch_add(1, Ordering::Relaxed);
        }
    });
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == TIMER0_IRQ as i16 {
        on_timer_tick();
    }
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc={=u32:#x}", ef.pc());
    fail();
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    fail();
}

fn fail() -> ! {
    debug::exit(EXIT_FAILURE);
    // Without a debugger attached semihosting returns: stop with a fault instead.
    cortex_m::asm::udf()
}

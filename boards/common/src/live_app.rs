//! The main loop of the boards with a real sensor, and their sensor watchdog.
//!
//! The INT pin's interrupt runs the [`crate::imu_sampler::ImuSampler`] and fills the queue;
//! [`main_loop`] drains it through the pipeline, reports start-up, strides, gaps and a
//! status line every [`STATUS_EVERY_MS`] on defmt and the serial line, and sleeps with
//! `wfi`. A periodic timer drives the [`Watchdog`], which notices a sensor that stopped
//! pulsing (reset, brown-out, loose wire) and has the sampler set it up again.

use core::cell::RefCell;
use core::fmt::Write;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::{self as irq, Mutex};
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use gaitclip::detect::seam::StepDetector;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::Stride;
use gaitclip_imu::source::blocking::ImuSource;
use heapless::spsc::{Consumer, Producer, Queue};

use crate::imu_sampler::{BusRecovery, Counters, ImuSampler, Item, ReadMode};
use crate::serial_line;
use crate::sleep::{SleepPolicy, SleepSettings, WakeFigures};
use crate::startup::Startup;
use crate::stride_log::StrideLog;

/// Interval of the status line.
pub const STATUS_EVERY_MS: u32 = 60_000;

/// Period of the board's watchdog timer.
pub const WATCHDOG_TICK_MS: u32 = 100;
/// Watchdog ticks without a data-ready pulse after which the sensor is declared silent.
pub const SILENT_TICKS: u32 = 3;

/// What the interrupts share with the main loop: the sampler, the queue's producer and the
/// count of data-ready pulses. A board keeps one in a static.
pub struct SampleLink<S: ImuSource, D> {
    sampler: Mutex<RefCell<Option<ImuSampler<S, D>>>>,
    producer: Mutex<RefCell<Option<Producer<'static, Item>>>>,
    /// Data-ready interrupts so far. Written by the INT handler only, with a load and a
    /// store: ARMv6-M has no atomic read-modify-write.
    pulses: AtomicU32,
}

impl<S, D> Default for SampleLink<S, D>
where
    S: ImuSource,
    S::Bus: BusRecovery,
    D: DelayNs,
{
    fn default() -> Self {
        Self::new()
    }
}

impl<S, D> SampleLink<S, D>
where
    S: ImuSource,
    S::Bus: BusRecovery,
    D: DelayNs,
{
    /// An empty link, for a static.
    pub const fn new() -> Self {
        SampleLink {
            sampler: Mutex::new(RefCell::new(None)),
            producer: Mutex::new(RefCell::new(None)),
            pulses: AtomicU32::new(0),
        }
    }

    /// Starts the sensor ([`start_sensor`]), hands the sampler and `queue`'s producer to
    /// the interrupts, and returns the queue's consumer for the main loop.
    pub fn start<const N: usize>(
        &self,
        imu: S,
        delay: D,
        mode: ReadMode,
        queue: &'static mut Queue<Item, N>,
        serial: &mut impl Write,
    ) -> Consumer<'static, Item> {
        let sampler = start_sensor(imu, delay, mode, serial);
        let (producer, consumer) = queue.split();
        self.install(sampler, producer);
        consumer
    }

    /// Hands the started sampler and the queue's producer to the interrupts.
    pub fn install(&self, sampler: ImuSampler<S, D>, producer: Producer<'static, Item>) {
        irq::free(|cs| {
            self.sampler.borrow(cs).replace(Some(sampler));
            self.producer.borrow(cs).replace(Some(producer));
        });
    }

    /// Data-ready pulses so far.
    pub fn pulses(&self) -> u32 {
        self.pulses.load(Ordering::Relaxed)
    }

    /// The fault counters.
    pub fn counters(&self) -> Counters {
        irq::free(|cs| {
            self.sampler
                .borrow(cs)
                .borrow()
                .as_ref()
                .map(|s| s.counters())
                .unwrap_or_default()
        })
    }

    /// The body of the INT pin's interrupt.
    pub fn on_data_ready(&self) {
        self.pulses
            .store(self.pulses().wrapping_add(1), Ordering::Relaxed);
        self.with_sampler(|s, mut push| s.on_data_ready(&mut push));
    }

    /// The body of the INT pin's interrupt on a board that sleeps: data ready while the
    /// sensor samples; motion while it waits in its cycle mode, when `slept()` gives the
    /// sample periods since it went to sleep (the board's low-power clock) and the first
    /// `settle` samples after it are dropped ([`ImuSampler::on_motion`]). Says what changed,
    /// for the board to stop its watchdog timer and note its clock, or start them again.
    pub fn on_int(&self, settle: u32, slept: impl FnOnce() -> u32) -> IntEvent {
        self.with_sampler(|s, mut push| {
            if s.asleep() {
                s.on_motion(slept(), settle, &mut push);
                return IntEvent::Woke;
            }
            self.pulses
                .store(self.pulses().wrapping_add(1), Ordering::Relaxed);
            s.on_data_ready(&mut push);
            if s.asleep() {
                IntEvent::FellAsleep
            } else {
                IntEvent::Sampled
            }
        })
        .unwrap_or(IntEvent::Sampled)
    }

    /// The body of the watchdog timer's interrupt: `periods_per_tick` sample periods
    /// elapse per tick.
    pub fn on_watchdog_tick(&self, watchdog: &mut Watchdog, periods_per_tick: u32) {
        if let Some(lost) = watchdog.tick(self.pulses(), periods_per_tick) {
            self.with_sampler(|s, mut push| s.on_silence(lost, &mut push));
        }
    }

    /// Processes the queue forever, reporting start-up ([`Startup`]), strides, gaps and a
    /// status line (with the sampler's fault counters) every [`STATUS_EVERY_MS`]. When the
    /// foot has been still for `sleep`'s still period, the part waits for motion with its
    /// `wake` settings.
    #[allow(clippy::too_many_arguments)]
    pub fn main_loop<P: StepDetector>(
        &self,
        pipeline: &mut Pipeline<P>,
        config: &Config,
        mut consumer: Consumer<'static, Item>,
        log: &mut StrideLog,
        serial: &mut impl Write,
        sleep: &SleepSettings<S::Wake>,
    ) -> !
    where
        S::Wake: WakeFigures,
    {
        let mut drain = Drain::new(config, consumer.capacity(), sleep);
        loop {
            drain.run(
                pipeline,
                &mut consumer,
                log,
                serial,
                || self.counters(),
                |_| {},
            );
            if let Some(after) = drain.take_sleep_request() {
                self.request_sleep(after, sleep.wake);
            }
            // Interrupts are masked while checking the queue so that a sample arriving between
            // the check and `wfi` still wakes the core (WFI wakes on a pending interrupt even
            // with PRIMASK set).
            irq::disable();
            if !consumer.ready() {
                cortex_m::asm::wfi();
            }
            // Note(unsafe): re-enables the interrupts disabled just above; no critical section
            // spans this point.
            unsafe { irq::enable() };
        }
    }

    /// Runs `f` on the sampler and a push into the queue, in a critical section; `None`
    /// before [`SampleLink::install`].
    pub fn with_sampler<R>(
        &self,
        f: impl FnOnce(&mut ImuSampler<S, D>, &mut dyn FnMut(Item) -> bool) -> R,
    ) -> Option<R> {
        irq::free(|cs| {
            let mut sampler = self.sampler.borrow(cs).borrow_mut();
            let mut producer = self.producer.borrow(cs).borrow_mut();
            match (sampler.as_mut(), producer.as_mut()) {
                (Some(s), Some(p)) => Some(f(s, &mut |item| p.enqueue(item).is_ok())),
                _ => None,
            }
        })
    }

    /// Whether the sensor is in its wait for motion.
    pub fn asleep(&self) -> bool {
        self.with_sampler(|s, _| s.asleep()).unwrap_or(false)
    }

    /// Asks the sampler to sleep after `after` samples in all ([`ImuSampler::request_sleep`]).
    pub fn request_sleep(&self, after: u32, wake: S::Wake) {
        self.with_sampler(|s, _| s.request_sleep(after, wake));
    }
}

/// What an INT interrupt did ([`SampleLink::on_int`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntEvent {
    /// Samples read (or counted), as usual.
    Sampled,
    /// The sensor went to its wait for motion after this read.
    FellAsleep,
    /// The sensor woke on motion and samples again.
    Woke,
}

/// The main loop's work on what the sampler queued: the pipeline, start-up reporting, the
/// stride log, gaps and the periodic status line. A board with a blocking main loop runs it
/// between `wfi`s ([`SampleLink::main_loop`]); the Bluetooth board from its pipeline task.
pub struct Drain<W = gaitclip_mpu6050::MotionWakeConfig> {
    startup: Startup,
    /// When the clip sleeps, and what the log says of it.
    sleep: SleepSettings<W>,
    status_every_samples: u32,
    samples: u32,
    next_status: u32,
    policy: SleepPolicy,
    /// Items the board's queue holds (how far ahead the sampler can have read).
    queue_len: usize,
    /// A sleep the policy asked for, for the board to hand to the sampler.
    sleep_request: Option<u32>,
}

impl<W: WakeFigures + Copy> Drain<W> {
    /// Nothing processed yet, for a pipeline configured by `config` fed from a queue of
    /// `queue_len` items, sleeping as `sleep` says.
    pub fn new(config: &Config, queue_len: usize, sleep: &SleepSettings<W>) -> Self {
        let status_every_samples = config.rate.samples_in_ms(STATUS_EVERY_MS);
        Drain {
            startup: Startup::new(config.rate, config.gyro),
            status_every_samples,
            samples: 0,
            next_status: status_every_samples,
            policy: SleepPolicy::new(config.rate, sleep),
            sleep: *sleep,
            queue_len,
            sleep_request: None,
        }
    }

    /// The sleep the policy asked for since the last call: the sample count to hand to
    /// [`SampleLink::request_sleep`] (or [`ImuSampler::request_sleep`]).
    pub fn take_sleep_request(&mut self) -> Option<u32> {
        self.sleep_request.take()
    }

    /// Samples processed so far.
    pub const fn samples(&self) -> u32 {
        self.samples
    }

    /// Feeds everything queued to the pipeline, logging as it goes; `on_stride` sees every
    /// stride after the log (a gap's held stride first: it was closed before the gap).
    /// `counters` gives the sampler's fault counters for the status line.
    pub fn run<S: StepDetector>(
        &mut self,
        pipeline: &mut Pipeline<S>,
        consumer: &mut Consumer<'_, Item>,
        log: &mut StrideLog,
        serial: &mut impl Write,
        counters: impl Fn() -> Counters,
        mut on_stride: impl FnMut(&Stride),
    ) {
        while let Some(item) = consumer.dequeue() {
            let stride = item.feed(pipeline);
            match item {
                Item::Sample(_) => {
                    self.samples = self.samples.wrapping_add(1);
                    if let Some(e) = self.startup.update(pipeline) {
                        log.startup(e, serial);
                    }
                }
                Item::Asleep => log.asleep(self.policy.still_samples(), &self.sleep, serial),
                Item::Gap(_) | Item::Woke(_) => {}
            }
            let due = self.policy.after_item(
                &item,
                pipeline.at_rest(),
                stride.is_some(),
                self.samples,
                self.queue_len,
            );
            self.sleep_request = due.or(self.sleep_request);
            if let Some(stride) = &stride {
                log.stride(stride, serial);
                on_stride(stride);
            }
            match item {
                Item::Sample(_) if self.samples == self.next_status => {
                    self.next_status = self.next_status.wrapping_add(self.status_every_samples);
                    log.summary(
                        self.samples,
                        &counters(),
                        &pipeline.clipped_samples(),
                        (&pipeline.rejected(), &pipeline.between()),
                        serial,
                    );
                }
                Item::Gap(n) => log.gap(n, pipeline.hole_kind(n), serial),
                Item::Woke(n) => log.woke(n, serial),
                Item::Sample(_) | Item::Asleep => {}
            }
        }
    }
}

/// Starts the sensor, retrying once a second (and saying so on both outputs) while it does
/// not answer: still powering up, or a loose wire.
pub fn start_sensor<S, D>(
    mut imu: S,
    mut delay: D,
    mode: ReadMode,
    serial: &mut impl Write,
) -> ImuSampler<S, D>
where
    S: ImuSource,
    S::Bus: BusRecovery,
    D: DelayNs,
{
    loop {
        match ImuSampler::start(imu, delay, mode) {
            Ok(s) => return s,
            Err((i, d, e)) => {
                report_not_ready(&e, serial);
                (imu, delay) = (i, d);
                delay.delay_ms(1000);
            }
        }
    }
}

/// [`start_sensor`] for the async sampler ([`crate::imu_sampler::asynch`]): the same
/// retries and reports, the waits awaited.
pub async fn start_async_sensor<S, D>(
    mut imu: S,
    mut delay: D,
    mode: ReadMode,
    serial: &mut impl Write,
) -> crate::imu_sampler::asynch::ImuSampler<S, D>
where
    S: gaitclip_imu::source::asynch::ImuSource,
    S::Bus: BusRecovery,
    D: embedded_hal_async::delay::DelayNs,
{
    loop {
        match crate::imu_sampler::asynch::ImuSampler::start(imu, delay, mode).await {
            Ok(s) => return s,
            Err((i, d, e)) => {
                report_not_ready(&e, serial);
                (imu, delay) = (i, d);
                delay.delay_ms(1000).await;
            }
        }
    }
}

/// A failed start, on defmt (with the error) and the serial line.
fn report_not_ready(e: &impl core::fmt::Debug, serial: &mut impl Write) {
    defmt::error!(
        "{=str} not ready ({}): check the wiring; retrying",
        crate::live_settings::NAME,
        defmt::Debug2Format(e)
    );
    let _ = serial_line::comment(
        serial,
        format_args!(
            "{} not ready: check the wiring; retrying",
            crate::live_settings::NAME
        ),
    );
}

/// Finds a sensor that stopped pulsing.
pub struct Watchdog {
    last_pulses: u32,
    quiet_ticks: u32,
}

impl Watchdog {
    /// A watchdog that has seen nothing yet.
    pub const fn new() -> Self {
        Watchdog {
            last_pulses: 0,
            quiet_ticks: 0,
        }
    }

    /// One tick, with the running count of data-ready interrupts. Returns the sample
    /// periods lost when the sensor has been silent for [`SILENT_TICKS`] ticks
    /// (`periods_per_tick` each); the count starts again after that.
    pub fn tick(&mut self, pulses: u32, periods_per_tick: u32) -> Option<u32> {
        if pulses != self.last_pulses {
            self.last_pulses = pulses;
            self.quiet_ticks = 0;
            return None;
        }
        self.quiet_ticks += 1;
        if self.quiet_ticks < SILENT_TICKS {
            return None;
        }
        self.quiet_ticks = 0;
        Some(SILENT_TICKS.saturating_mul(periods_per_tick))
    }
}

impl Default for Watchdog {
    fn default() -> Self {
        Self::new()
    }
}

/// Busy-wait delay (the sensor's 100 ms reset): a busy loop is honest about what it costs.
pub struct SpinDelay {
    /// Core clock, cycles per µs.
    pub cycles_per_us: u32,
}

impl DelayNs for SpinDelay {
    fn delay_ns(&mut self, ns: u32) {
        cortex_m::asm::delay((ns / 1000).saturating_mul(self.cycles_per_us).max(1));
    }
}

/// Clocks a stuck I²C bus free on its SCL pin, taken as a GPIO output: nine clocks let a
/// slave finish the byte it is sending and see a NACK; 5 µs half periods (100 kHz) at
/// `cycles_per_us`.
pub fn clock_bus_free(scl: &mut impl OutputPin, cycles_per_us: u32) {
    for _ in 0..9 {
        let _ = scl.set_low();
        cortex_m::asm::delay(5 * cycles_per_us);
        let _ = scl.set_high();
        cortex_m::asm::delay(5 * cycles_per_us);
    }
}

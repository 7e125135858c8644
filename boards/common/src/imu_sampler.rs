//! The sensor side of every board: what the data-ready interrupt does.
//!
//! Each board calls [`ImuSampler::on_data_ready`] from the interrupt of the MPU6050's INT
//! pin (the emulated boards from a timer standing in for it). The sampler reads the sensor,
//! either one 14-byte burst per data-ready ([`ReadMode::PerSample`]) or the FIFO every few
//! pulses ([`ReadMode::Fifo`], fewer bus transactions and wake-ups of the I2C peripheral),
//! and hands [`Item`]s to the board's queue. Nothing is lost silently:
//!
//! - a failed read is counted and retried at once, [`RETRIES`] times;
//! - a sample period whose read still fails becomes part of a [`Item::Gap`] (per-sample
//!   mode; in FIFO mode the samples wait in the FIFO and the next pulse tries again);
//! - after [`RESTART_AFTER`] failed periods in a row the bus is recovered (the board clocks
//!   SCL, [`BusRecovery`]) and the sensor re-initialised; what it lost meanwhile is a gap;
//! - a FIFO overflow, or a queue with no room, is a gap of the samples it cost;
//! - a sensor that stops pulsing altogether is found by the board's watchdog, which calls
//!   [`ImuSampler::on_silence`];
//! - the periods the sensor spent asleep ([`ImuSampler::request_sleep`], [`crate::sleep`])
//!   and the gyro's settling after it are one [`Item::Woke`], declared like a gap.
//!
//! Board glue, shared: generic over the bus and delay, so the host tests drive it with
//! `embedded-hal-mock`.

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;
use gaitclip::detect::seam::StepDetector;
use gaitclip::mpu6050::blocking::Mpu6050;
use gaitclip::mpu6050::mode::{MotionWake, Sampling, Unconfigured};
use gaitclip::mpu6050::{self, MotionWakeConfig};
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::sample::RawSample;

/// Immediate retries of a failed read.
pub const RETRIES: u32 = 2;
/// Failed sample periods in a row after which the bus is recovered and the sensor set up
/// again.
pub const RESTART_AFTER: u32 = 3;
/// Most samples read from the FIFO in one burst (the sampler's buffer, 14 B each).
pub const FIFO_BURST: usize = 16;

/// What the sample interrupt hands to the main loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// One sample, in order.
    Sample(RawSample),
    /// This many sample periods were lost here: the pipeline reports the stride in progress
    /// as a gap stride (invalid, no length) instead of measuring across the hole.
    Gap(u32),
    /// The sensor went to its low-power wait for motion after the sample before this
    /// ([`ImuSampler::request_sleep`]): nothing follows until [`Item::Woke`].
    Asleep,
    /// The sensor woke on motion and samples again: this many sample periods went
    /// unsampled (asleep, and the gyro's settling after it). The pipeline takes them as a
    /// hole, which restarts detection: a walk that began while the sensor woke is a gap
    /// stride, flagged, not dropped.
    Woke(u32),
}

impl Item {
    /// Hands the item to the pipeline; the stride it lets the pipeline report, if any (a
    /// gap's was closed before the gap).
    pub fn feed<D: StepDetector>(self, pipeline: &mut Pipeline<D>) -> Option<Stride> {
        match self {
            Item::Sample(s) => pipeline.process(&s),
            Item::Gap(n) | Item::Woke(n) => pipeline.gap(n),
            Item::Asleep => None,
        }
    }
}

/// How the sensor is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadMode {
    /// INT latched on data ready; every pulse reads the 14 data registers.
    PerSample,
    /// INT pulses on data ready and is only counted; every `batch` pulses the FIFO is read
    /// in one burst (at most [`FIFO_BURST`] samples).
    Fifo {
        /// Pulses per FIFO read (1..=[`FIFO_BURST`]).
        batch: u8,
    },
}

/// A board's way to free a stuck I2C bus.
pub trait BusRecovery {
    /// Clocks SCL (nine pulses and a STOP) so that a slave holding SDA low lets go;
    /// returns whether the board could do it.
    fn recover_bus(&mut self) -> bool;
}

/// What went wrong so far, for the summary line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Failed bus transactions (every attempt counts).
    pub bus_errors: u32,
    /// Sensor re-initialisations after repeated failures or silence.
    pub restarts: u32,
    /// Bus recoveries (SCL clocked) that the board performed.
    pub recoveries: u32,
    /// FIFO overflows (or misaligned FIFO counts) found.
    pub fifo_overflows: u32,
    /// Watchdog calls: the sensor stopped pulsing.
    pub silences: u32,
    /// Items the queue had no room for.
    pub overruns: u32,
    /// Sample periods reported as gaps.
    pub lost_samples: u32,
    /// Times the sensor went to its low-power wait for motion.
    pub sleeps: u32,
    /// Sample periods spent there (and settling after it), not counted as lost.
    pub slept_periods: u32,
}

impl Counters {
    /// Nothing went wrong yet (for a `static`, where `Default` is not `const`).
    pub const ZERO: Counters = Counters {
        bus_errors: 0,
        restarts: 0,
        recoveries: 0,
        fifo_overflows: 0,
        silences: 0,
        overruns: 0,
        lost_samples: 0,
        sleeps: 0,
        slept_periods: 0,
    };
}

/// The driver in the mode the sampler last brought it to (the driver's modes are types; the
/// sampler switches between them at run time).
enum Sensor<I> {
    Sampling(Mpu6050<I, Sampling>),
    Waiting(Mpu6050<I, MotionWake>),
}

impl<I: I2c> Sensor<I> {
    fn bus_mut(&mut self) -> &mut I {
        match self {
            Sensor::Sampling(d) => d.bus_mut(),
            Sensor::Waiting(d) => d.bus_mut(),
        }
    }

    /// Resets the part into sampling from either mode ([`Mpu6050::init`]); on failure the
    /// driver stays in the mode it was.
    fn init<D: DelayNs>(
        self,
        delay: &mut D,
        config: &mpu6050::Config,
    ) -> (Self, Result<(), mpu6050::Error<I::Error>>) {
        let r = match self {
            Sensor::Sampling(d) => d
                .init(delay, config)
                .map_err(|e| (Sensor::Sampling(e.dev), e.error)),
            Sensor::Waiting(d) => d
                .init(delay, config)
                .map_err(|e| (Sensor::Waiting(e.dev), e.error)),
        };
        match r {
            Ok(d) => (Sensor::Sampling(d), Ok(())),
            Err((s, e)) => (s, Err(e)),
        }
    }
}

/// The sensor, its settings and the fault bookkeeping.
pub struct ImuSampler<I, D> {
    /// Always `Some` between calls: taken only while a mode change moves the driver.
    imu: Option<Sensor<I>>,
    delay: D,
    config: mpu6050::Config,
    mode: ReadMode,
    /// Data-ready pulses whose sample is still in the FIFO (FIFO mode).
    unread: u32,
    /// Sample periods in a row whose read failed.
    failed_periods: u32,
    /// Lost periods not yet handed to the queue.
    pending_gap: u32,
    counters: Counters,
    /// Samples read and handed on so far, not counting those dropped while the gyro
    /// settles (what [`ImuSampler::request_sleep`] counts).
    read: u32,
    /// Go to the low-power wait once this many samples have been read, with these settings.
    sleep_request: Option<(u32, MotionWakeConfig)>,
    /// Samples still to drop after waking while the gyro settles.
    settling: u32,
    /// Periods unsampled since the sensor went to sleep, not yet handed over as
    /// [`Item::Woke`].
    pending_woke: u32,
}

impl<I, D> ImuSampler<I, D>
where
    I: I2c + BusRecovery,
    D: DelayNs,
{
    /// Initialises the sensor for `config` and its interrupt for `mode`. On error the bus
    /// and delay are handed back with it, for the board to report and retry.
    #[allow(clippy::type_complexity)]
    pub fn start(
        imu: Mpu6050<I, Unconfigured>,
        mut delay: D,
        config: mpu6050::Config,
        mode: ReadMode,
    ) -> Result<Self, (Mpu6050<I, Unconfigured>, D, mpu6050::Error<I::Error>)> {
        let mut imu = match imu.init(&mut delay, &config) {
            Ok(imu) => imu,
            Err(e) => return Err((e.dev, delay, e.error)),
        };
        if let Err(e) = enable_interrupt(&mut imu, mode) {
            return Err((imu.into_unconfigured(), delay, e));
        }
        Ok(ImuSampler {
            imu: Some(Sensor::Sampling(imu)),
            delay,
            config,
            mode,
            unread: 0,
            failed_periods: 0,
            pending_gap: 0,
            counters: Counters::default(),
            read: 0,
            sleep_request: None,
            settling: 0,
            pending_woke: 0,
        })
    }

    /// The fault counters.
    pub const fn counters(&self) -> Counters {
        self.counters
    }

    /// Counts an item the queue had no room for: it becomes part of the next gap.
    fn lost(&mut self, periods: u32) {
        self.pending_gap = self.pending_gap.saturating_add(periods);
        self.counters.lost_samples = self.counters.lost_samples.saturating_add(periods);
    }

    /// Hands `item` to `push` (which returns `false` when the queue is full), reporting any
    /// pending gap first; what does not fit joins the gap.
    fn emit(&mut self, push: &mut impl FnMut(Item) -> bool, item: Item) {
        if self.pending_woke > 0 {
            if !push(Item::Woke(self.pending_woke)) {
                self.counters.overruns = self.counters.overruns.saturating_add(1);
                if let Item::Sample(_) = item {
                    // Joins the unsampled periods: the pipeline restarts after them anyway.
                    self.pending_woke = self.pending_woke.saturating_add(1);
                    self.counters.slept_periods = self.counters.slept_periods.saturating_add(1);
                }
                return;
            }
            self.pending_woke = 0;
        }
        if self.pending_gap > 0 {
            if !push(Item::Gap(self.pending_gap)) {
                self.counters.overruns = self.counters.overruns.saturating_add(1);
                if let Item::Sample(_) = item {
                    self.lost(1);
                }
                return;
            }
            self.pending_gap = 0;
        }
        if !push(item) {
            self.counters.overruns = self.counters.overruns.saturating_add(1);
            if let Item::Sample(_) = item {
                self.lost(1);
            }
        }
    }

    /// The data-ready interrupt: reads what is due and hands it to `push`; then, if a sleep
    /// is due ([`ImuSampler::request_sleep`]), sends the sensor to its wait for motion.
    /// Ignored while asleep (the board calls [`ImuSampler::on_motion`] for the INT pin then).
    pub fn on_data_ready(&mut self, push: &mut impl FnMut(Item) -> bool) {
        if self.asleep() {
            return;
        }
        match self.mode {
            ReadMode::PerSample => self.read_one(push),
            ReadMode::Fifo { batch } => {
                self.unread = self.unread.saturating_add(1);
                if self.unread >= batch.max(1) as u32 || self.failed_periods > 0 {
                    self.read_fifo(push);
                }
            }
        }
        if let Some((at, wake)) = self.sleep_request {
            if self.read >= at {
                self.sleep_request = None;
                self.enter_sleep(&wake, push);
            }
        }
    }

    /// Samples read and handed on so far (the main loop's count of samples, plus what is
    /// queued and what the queue had no room for).
    pub const fn samples_read(&self) -> u32 {
        self.read
    }

    /// Whether the sensor is in its low-power wait for motion.
    pub const fn asleep(&self) -> bool {
        matches!(self.imu, Some(Sensor::Waiting(_)))
    }

    /// Sends the sensor to its low-power wait for motion ([`Mpu6050::enter_motion_wake`])
    /// once `after` samples have been handed on in all ([`ImuSampler::samples_read`]). The main
    /// loop decides on what it has processed, while the interrupt may have read a few more:
    /// it asks for a count ahead of anything the queue can hold, so the sleep falls after
    /// the same sample however far behind it ran (the replay's host model relies on it).
    /// Replaces an earlier request.
    pub fn request_sleep(&mut self, after: u32, wake: MotionWakeConfig) {
        self.sleep_request = Some((after, wake));
    }

    fn enter_sleep(&mut self, wake: &MotionWakeConfig, push: &mut impl FnMut(Item) -> bool) {
        for _ in 0..=RETRIES {
            let entered = match self.imu.take() {
                Some(Sensor::Sampling(d)) => match d.enter_motion_wake(wake, self.config.accel) {
                    Ok(d) => {
                        self.imu = Some(Sensor::Waiting(d));
                        true
                    }
                    Err(e) => {
                        self.imu = Some(Sensor::Sampling(e.dev));
                        false
                    }
                },
                other => {
                    self.imu = other;
                    false
                }
            };
            match entered {
                true => {
                    self.unread = 0;
                    self.counters.sleeps = self.counters.sleeps.saturating_add(1);
                    if !push(Item::Asleep) {
                        self.counters.overruns = self.counters.overruns.saturating_add(1);
                    }
                    return;
                }
                false => self.counters.bus_errors = self.counters.bus_errors.saturating_add(1),
            }
        }
        // Half configured: set the sensor up again and stay awake; the main loop asks
        // again after another still period.
        self.restart();
    }

    /// The INT pin rose while asleep: motion. Back to full sampling
    /// ([`Mpu6050::leave_motion_wake`], then the interrupt and FIFO as at start), dropping the first
    /// `settle` samples (the gyro's start-up, datasheet §6.1: 30 ms); `slept` sample periods
    /// passed while asleep (the board's low-power clock). Both become one [`Item::Woke`]
    /// before the first sample kept. On a bus error the sensor is set up again from reset.
    pub fn on_motion(&mut self, slept: u32, settle: u32, push: &mut impl FnMut(Item) -> bool) {
        if !self.asleep() {
            return;
        }
        self.settling = settle;
        self.pending_woke = self.pending_woke.saturating_add(slept);
        self.counters.slept_periods = self.counters.slept_periods.saturating_add(slept);
        let mut resumed = false;
        for _ in 0..=RETRIES {
            if self.resume() {
                resumed = true;
                break;
            }
            self.counters.bus_errors = self.counters.bus_errors.saturating_add(1);
        }
        if !resumed {
            self.restart();
        }
        if self.pending_woke > 0 && self.settling == 0 && push(Item::Woke(self.pending_woke)) {
            self.pending_woke = 0;
        }
    }

    /// Leaves the motion wait (if still in it: a retry after the interrupt's setup failed
    /// is already sampling) and sets the interrupt up again.
    fn resume(&mut self) -> bool {
        match self.imu.take() {
            Some(Sensor::Waiting(d)) => match d.leave_motion_wake(&self.config) {
                Ok(d) => self.imu = Some(Sensor::Sampling(d)),
                Err(e) => {
                    self.imu = Some(Sensor::Waiting(e.dev));
                    return false;
                }
            },
            other => self.imu = other,
        }
        self.enable_interrupt()
    }

    /// Counts a sample read; true if it is kept (not dropped while the gyro settles).
    fn keep(&mut self) -> bool {
        if self.settling > 0 {
            self.settling -= 1;
            self.pending_woke = self.pending_woke.saturating_add(1);
            self.counters.slept_periods = self.counters.slept_periods.saturating_add(1);
            return false;
        }
        self.read = self.read.wrapping_add(1);
        true
    }

    /// The bus, for a board's emulated sensor (its clock in the low-power wait) and tests;
    /// `None` only inside a mode change, which no caller can see.
    pub fn bus_mut(&mut self) -> Option<&mut I> {
        self.imu.as_mut().map(Sensor::bus_mut)
    }

    /// The board's watchdog found no data-ready pulse for `periods` sample periods: the
    /// sensor was reset or lost power. They become a gap and the sensor is set up again.
    pub fn on_silence(&mut self, periods: u32, push: &mut impl FnMut(Item) -> bool) {
        if self.asleep() {
            // Silent by design: the sensor only speaks again on motion.
            return;
        }
        self.counters.silences = self.counters.silences.saturating_add(1);
        let lost = periods.saturating_add(core::mem::take(&mut self.unread));
        self.lost(lost);
        self.restart();
        if self.pending_gap > 0 && push(Item::Gap(self.pending_gap)) {
            self.pending_gap = 0;
        }
    }

    fn read_one(&mut self, push: &mut impl FnMut(Item) -> bool) {
        for _ in 0..=RETRIES {
            let read = match &mut self.imu {
                Some(Sensor::Sampling(d)) => d.read_sample().ok(),
                // Never here while awake; a read that cannot happen fails like a bus error.
                _ => None,
            };
            match read {
                Some(s) => {
                    self.failed_periods = 0;
                    if self.keep() {
                        self.emit(push, Item::Sample(s));
                    }
                    return;
                }
                None => self.counters.bus_errors = self.counters.bus_errors.saturating_add(1),
            }
        }
        // The sample of this period is gone (the registers hold only the newest).
        self.lost(1);
        self.period_failed();
    }

    fn read_fifo(&mut self, push: &mut impl FnMut(Item) -> bool) {
        let mut buf = [RawSample::default(); FIFO_BURST];
        let mut attempts = 0;
        // More than one burst when the reads fell behind; bounded by what was pulsed.
        let mut bursts = self.unread as usize / FIFO_BURST + 1;
        while bursts > 0 {
            let read = match &mut self.imu {
                Some(Sensor::Sampling(d)) => d.read_fifo(&mut buf).map_err(Some),
                _ => Err(None),
            };
            match read {
                Ok(n) => {
                    self.failed_periods = 0;
                    self.unread = self.unread.saturating_sub(n as u32);
                    for s in &buf[..n] {
                        if self.keep() {
                            self.emit(push, Item::Sample(*s));
                        }
                    }
                    if n < FIFO_BURST {
                        // Pulses counted but not in the FIFO: none are waiting any more.
                        self.unread = 0;
                        return;
                    }
                    bursts -= 1;
                }
                Err(Some(mpu6050::Error::FifoOverflow | mpu6050::Error::FifoMisaligned(_))) => {
                    // The FIFO was reset: everything pulsed since the last read is gone.
                    self.counters.fifo_overflows = self.counters.fifo_overflows.saturating_add(1);
                    let lost = core::mem::take(&mut self.unread);
                    self.lost(lost);
                    return;
                }
                Err(_) => {
                    self.counters.bus_errors = self.counters.bus_errors.saturating_add(1);
                    attempts += 1;
                    if attempts > RETRIES {
                        // The samples stay in the FIFO; the next pulse tries again.
                        self.period_failed();
                        return;
                    }
                }
            }
        }
    }

    fn period_failed(&mut self) {
        self.failed_periods = self.failed_periods.saturating_add(1);
        if self.failed_periods >= RESTART_AFTER {
            // Re-initialising resets the FIFO: samples waiting there are lost too.
            let lost = core::mem::take(&mut self.unread);
            self.lost(lost);
            self.restart();
        }
    }

    /// Recovers the bus and sets the sensor up again; on failure the next failed period
    /// tries again.
    fn restart(&mut self) {
        if self.imu.as_mut().is_some_and(|s| s.bus_mut().recover_bus()) {
            self.counters.recoveries = self.counters.recoveries.saturating_add(1);
        }
        if self.setup() {
            self.counters.restarts = self.counters.restarts.saturating_add(1);
            self.failed_periods = 0;
        } else {
            self.counters.bus_errors = self.counters.bus_errors.saturating_add(1);
        }
    }

    /// Resets the sensor into sampling (a reset sensor is awake whatever it was doing) and
    /// sets its interrupt up; whether both worked.
    fn setup(&mut self) -> bool {
        let Some(sensor) = self.imu.take() else {
            return false;
        };
        let (sensor, reset) = sensor.init(&mut self.delay, &self.config);
        self.imu = Some(sensor);
        reset.is_ok() && self.enable_interrupt()
    }

    /// Sets the data-ready interrupt up for the read mode; false if that failed (or the
    /// sensor is not sampling).
    fn enable_interrupt(&mut self) -> bool {
        match &mut self.imu {
            Some(Sensor::Sampling(d)) => enable_interrupt(d, self.mode).is_ok(),
            _ => false,
        }
    }
}

fn enable_interrupt<I: I2c>(
    d: &mut Mpu6050<I, Sampling>,
    mode: ReadMode,
) -> Result<(), mpu6050::Error<I::Error>> {
    match mode {
        ReadMode::PerSample => d.enable_data_ready_interrupt(),
        ReadMode::Fifo { .. } => {
            d.enable_fifo()?;
            d.enable_data_ready_pulse()
        }
    }
}

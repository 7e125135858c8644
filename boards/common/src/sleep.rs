//! Sleeping when still, waking on the first step.
//!
//! A foot pod has no switch: it must cost next to nothing in a cupboard and still catch the
//! first step of a walk. The MPU6050 sampling both sensors draws 3.8 mA (PS-MPU-6000A-00
//! rev 3.4, §6.3), its accelerometer alone cycling at 5 Hz 20 µA; the MCU between
//! interrupts sleeps either way. So, once the clip has been still ([`SleepPolicy`]: the
//! pipeline's rest test true, no stride, for [`SleepSettings::still_ms`]):
//!
//! 1. the main loop asks the sampler to sleep ahead of anything still queued
//!    ([`crate::imu_sampler::ImuSampler::request_sleep`], [`SleepPolicy::sleep_after`]),
//!    and the sampler puts the sensor in its cycle mode with the motion interrupt latched on
//!    INT ([`gaitclip_mpu6050::blocking::Mpu6050::enter_motion_wake`]; the LSM6DSV320X's
//!    low-g accelerometer alone with its wake-up on INT1, whichever part the board has:
//!    [`crate::live_settings`]) and queues [`crate::imu_sampler::Item::Asleep`];
//! 2. the board stops its sample-side timers (the sensor watchdog: a sleeping sensor is
//!    silent by design), says so on its outputs, and the core waits for INT (System ON,
//!    `wfe`/`wfi`), the radio, if any, advertising slowly;
//! 3. INT rises on motion: the sampler brings full sampling back, drops
//!    [`SleepSettings::settle_ms`] of samples while the gyro starts (§6.1: 30 ms), and queues
//!    [`crate::imu_sampler::Item::Woke`] with every period not sampled. The pipeline takes
//!    that as a hole too long to bridge: detection restarts, the rest test and the foot
//!    frame's bias and gravity come from the next rest (the frame is kept if gravity still
//!    agrees, [`gaitclip::detect::foot_frame`]), and the step the wake-up interrupted is reported as a
//!    gap stride (flagged, no length), not dropped; the strides after it are measured.
//!
//! Everything here is plain state, so the host tests (`tests-host/tests/sleep_policy.rs`)
//! and the host model of the sleeping replay firmware use this very code.

use gaitclip::sensor::rate::SampleRate;
use gaitclip_mpu6050::{MotionThreshold, MotionThresholdUnit, MotionWakeConfig, WakeRate};

use crate::imu_sampler::Item;

/// When and how the clip sleeps, `W` the part's wait for motion (the MPU6050's by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SleepSettings<W = MotionWakeConfig> {
    /// Still this long (rest test true, no stride) before sleeping, ms.
    pub still_ms: u32,
    /// The sensor's wait for motion.
    pub wake: W,
    /// Samples dropped after waking while the gyro starts, ms (the MPU6050's datasheet
    /// §6.1, gyroscope start-up time: 30 ms typical).
    pub settle_ms: u32,
}

/// What the log says of a part's wait for motion.
pub trait WakeFigures {
    /// The accelerometer's rate while waiting, mHz.
    fn millihertz(&self) -> u32;
    /// The part's supply current while waiting, µA, where a cited datasheet gives it.
    fn supply_ua(&self) -> Option<u32>;
}

impl WakeFigures for MotionWakeConfig {
    fn millihertz(&self) -> u32 {
        self.rate.millihertz()
    }
    fn supply_ua(&self) -> Option<u32> {
        Some(self.rate.supply_ua())
    }
}

impl WakeFigures for gaitclip_lsm6dsv320x::MotionWakeConfig {
    fn millihertz(&self) -> u32 {
        self.odr.millihertz()
    }
    /// `None`: the LSM6DSV320X datasheet's current table is not among the cited sources.
    fn supply_ua(&self) -> Option<u32> {
        None
    }
}

/// The MOT_THR unit the boards configure for: the product specification's 32 mg per count
/// (rev 3.4, §6.2). If a part follows the 2 mg reading instead, the same count is 16 times
/// more sensitive: the clip wakes more often than it needs to, which costs current but never
/// misses a walk (the other choice would risk sleeping through one).
pub const THRESHOLD_UNIT: MotionThresholdUnit = MotionThresholdUnit::Mg32;

/// Motion that wakes the clip: 96 mg of high-passed acceleration on any axis, three counts
/// of the 32 mg unit. Checked on the real stands of `../shared/datasets` (`gaitclip wake`,
/// docs/energy.md): at 96 mg the clip wakes a median 0.1 s into the walk (90 % within 0.25 s), early
/// (sway) from 4 of the 200 stands the labelled walks hold, and sleeps through the first
/// second of none; 32 mg wakes early from a fifth of them, 160 mg sleeps through some.
pub const WAKE_THRESHOLD_MG: u32 = 96;

const fn threshold(mg: u32) -> MotionThreshold {
    match MotionThreshold::from_mg(mg, THRESHOLD_UNIT) {
        Some(t) => t,
        None => panic!("the wake threshold does not fit MOT_THR"),
    }
}

/// The firmware's settings: still for 10 s, then the accelerometer cycling at 5 Hz (20 µA;
/// 1.25 Hz would save 10 µA but wake up to 0.8 s into a walk, a whole step missed), motion
/// of [`WAKE_THRESHOLD_MG`] for 1 ms, and 30 ms of gyro settling.
pub const SLEEP: SleepSettings = SleepSettings {
    still_ms: 10_000,
    wake: MotionWakeConfig {
        rate: WakeRate::Hz5,
        threshold: threshold(WAKE_THRESHOLD_MG),
        duration_ms: 1,
    },
    settle_ms: 30,
};

/// Counts how long the clip has been still and says when to sleep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SleepPolicy {
    still_needed: u32,
    still: u32,
}

impl SleepPolicy {
    /// A policy for samples at `rate` with `settings`. A still period of 0 never sleeps.
    pub const fn new<W: Copy>(rate: SampleRate, settings: &SleepSettings<W>) -> Self {
        SleepPolicy {
            still_needed: rate.samples_in_ms(settings.still_ms),
            still: 0,
        }
    }

    /// After each sample the pipeline processed: whether it was at rest
    /// ([`gaitclip::pipeline::Pipeline::at_rest`]) and whether it closed a stride. True
    /// when the clip has been still for the still period, and again after every further
    /// still period (a sleep that failed on the bus is retried then).
    pub fn after_sample(&mut self, at_rest: bool, stride: bool) -> bool {
        if !at_rest || stride {
            self.still = 0;
            return false;
        }
        self.still = self.still.saturating_add(1);
        self.still_needed > 0 && self.still % self.still_needed == 0
    }

    /// Samples the clip has been still for.
    pub const fn still_samples(&self) -> u32 {
        self.still
    }

    /// After a hole or a wake-up: stillness counts again from nothing.
    pub fn reset(&mut self) {
        self.still = 0;
    }

    /// The policy's part in the main loop, after `item` went through the pipeline
    /// (`at_rest` its rest test then, `stride` whether it closed one, `processed` the
    /// samples processed so far, `queue_len` the queue's capacity): a sample counts towards
    /// the still period and may make a sleep due, returned as the count for
    /// [`crate::imu_sampler::ImuSampler::request_sleep`]; going to sleep, a hole or a
    /// wake-up starts the count again. A caller that logs the sleep reads
    /// [`SleepPolicy::still_samples`] before handing the [`Item::Asleep`] here.
    pub fn after_item(
        &mut self,
        item: &Item,
        at_rest: bool,
        stride: bool,
        processed: u32,
        queue_len: usize,
    ) -> Option<u32> {
        match item {
            Item::Sample(_) => self
                .after_sample(at_rest, stride)
                .then(|| Self::sleep_after(processed, queue_len)),
            Item::Asleep | Item::Gap(_) | Item::Woke(_) => {
                self.reset();
                None
            }
        }
    }

    /// The sample count, as the sampler counts what it read
    /// ([`crate::imu_sampler::ImuSampler::samples_read`]), after which to sleep, when the
    /// main loop has processed `processed` samples and its queue holds `queue_len` items:
    /// past anything the interrupt can have read ahead, so that the sleep falls after the
    /// same sample however far behind the main loop ran.
    pub const fn sleep_after(processed: u32, queue_len: usize) -> u32 {
        processed.saturating_add(queue_len as u32 + 1)
    }

    /// Samples dropped after a wake-up while the gyro settles, at `rate`.
    pub const fn settle_samples<W: Copy>(rate: SampleRate, settings: &SleepSettings<W>) -> u32 {
        rate.samples_in_ms(settings.settle_ms)
    }
}

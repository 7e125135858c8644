//! The sample rate, a parameter of every stage.

/// Sample rate in millihertz, 25–1000 Hz (204.8 Hz is `SampleRate::from_millihertz(204_800)`).
///
/// Kept in millihertz so that rates such as 204.8 Hz are exact: integration scales with
/// 1/rate², where rounding to whole hertz would cost 0.2 % of every length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleRate(u32);

impl SampleRate {
    /// Slowest supported rate, 25 Hz. Below 100 Hz gait events are coarse (10–40 ms a
    /// sample) and no dataset checks the lengths: the host warns. Below 25 Hz a walking
    /// swing (0.4 s) has fewer than ten samples and a step at the gyro's ±2000 °/s rail
    /// turns the attitude by more than 1.4 rad, where the integration's error grows as the
    /// fifth power of the step ([`crate::fixed::QuatQ30::integrate_half_angle`]): there the
    /// rate truly does not work.
    pub const MIN_MILLIHERTZ: u32 = 25_000;
    /// Fastest supported rate, 1 kHz (the MPU6050's DLPF-on limit).
    pub const MAX_MILLIHERTZ: u32 = 1_000_000;

    /// `None` outside 25–1000 Hz.
    pub const fn from_millihertz(mhz: u32) -> Option<Self> {
        if mhz < Self::MIN_MILLIHERTZ || mhz > Self::MAX_MILLIHERTZ {
            None
        } else {
            Some(SampleRate(mhz))
        }
    }

    /// `None` outside 25–1000 Hz.
    pub const fn from_hz(hz: u32) -> Option<Self> {
        if hz > Self::MAX_MILLIHERTZ / 1000 {
            return None;
        }
        Self::from_millihertz(hz * 1000)
    }

    /// The rate in millihertz.
    pub const fn millihertz(self) -> u32 {
        self.0
    }

    /// Number of whole samples closest to `ms` milliseconds (at least 1 for `ms` > 0).
    pub const fn samples_in_ms(self, ms: u32) -> u32 {
        let n = (self.0 as u64 * ms as u64 + 500_000) / 1_000_000;
        if n == 0 && ms > 0 {
            1
        } else {
            n as u32
        }
    }

    /// Milliseconds spanned by `samples` samples, rounded.
    pub const fn ms_of_samples(self, samples: u32) -> u32 {
        ((samples as u64 * 1_000_000 + self.0 as u64 / 2) / self.0 as u64) as u32
    }
}

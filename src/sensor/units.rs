//! Units the stages compute in, as types: a sensor's scale (counts per g, per °/s) apart
//! from the register values that set it, and the foot-frame acceleration every stage after
//! the foot frame reads. The stages take these, not the MPU6050's range enums
//! ([`AccelScale::of`], [`GyroScale::of`] and [`crate::sensor::sample::RangeScale`] convert),
//! so another sensor needs only its own scale.

use gaitclip_mpu6050::{AccelRange, GyroRange};

/// Foot-frame accelerations are in units of g/`FOOT_LSB_PER_G` whatever the sensor's range:
/// 2048 counts per g, the MPU6050's ±16 g scale, so that ±16 g fits an `i16`.
pub const FOOT_LSB_PER_G: i32 = 2048;

/// An accelerometer's scale: counts per g.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccelScale {
    lsb_per_g: u32,
}

impl AccelScale {
    /// A scale of `lsb_per_g` counts per g (≥ 1).
    pub const fn from_lsb_per_g(lsb_per_g: u32) -> Self {
        AccelScale {
            lsb_per_g: if lsb_per_g == 0 { 1 } else { lsb_per_g },
        }
    }

    /// The scale of an MPU6050 range (its datasheet sensitivity).
    pub const fn of(range: AccelRange) -> Self {
        Self::from_lsb_per_g(range.lsb_per_g())
    }

    /// Counts per g.
    pub const fn lsb_per_g(self) -> u32 {
        self.lsb_per_g
    }
}

/// A gyroscope's scale: counts per °/s, times ten so that the MPU6050's 131 and 16.4 are
/// integers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GyroScale {
    lsb_per_dps_x10: u32,
}

impl GyroScale {
    /// A scale of `lsb_per_dps_x10` / 10 counts per °/s (≥ 1).
    pub const fn from_lsb_per_dps_x10(lsb_per_dps_x10: u32) -> Self {
        GyroScale {
            lsb_per_dps_x10: if lsb_per_dps_x10 == 0 {
                1
            } else {
                lsb_per_dps_x10
            },
        }
    }

    /// The scale of an MPU6050 range (its datasheet sensitivity).
    pub const fn of(range: GyroRange) -> Self {
        Self::from_lsb_per_dps_x10(range.lsb_per_dps_x10())
    }

    /// Counts per (°/s), times ten.
    pub const fn lsb_per_dps_x10(self) -> u32 {
        self.lsb_per_dps_x10
    }

    /// An angular rate in mrad/s as counts of this scale, rounded (exact to ±0.5 count plus
    /// 1 ppm for π; any `mrad_per_s` up to 10⁶, 1 000 rad/s, and scales up to 10⁵).
    pub const fn counts_of_mrad_per_s(self, mrad_per_s: u32) -> u32 {
        // counts = mrad/1000 · (180/π) · lsb10/10, π as 3 141 593 / 10⁶.
        let num = mrad_per_s as u64 * self.lsb_per_dps_x10 as u64 * 180 * 1_000_000;
        let den = 3_141_593u64 * 10_000;
        ((num + den / 2) / den) as u32
    }
}

/// Mean-filtered acceleration in the foot frame, `[forward, left, up − g]`, in g /
/// [`FOOT_LSB_PER_G`] (2048 counts per g, whatever the sensor's range): what the foot frame
/// hands the detectors.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FootAccel(pub [i16; 3]);

impl FootAccel {
    /// `|f| − g` of `[forward, left, up − g]` (g/2048), in g/2048, saturated to `i16`: the
    /// orientation-free magnitude channel of the phase statistics.
    pub fn magnitude_minus_g(self) -> i16 {
        let [forward, left, up] = self.0;
        let up = up as i64 + FOOT_LSB_PER_G as i64;
        let m2 = (forward as i64).pow(2) + (left as i64).pow(2) + up * up;
        let m = crate::fixed::isqrt_u64(m2 as u64) as i64 - FOOT_LSB_PER_G as i64;
        m.clamp(i16::MIN as i64, i16::MAX as i64) as i16
    }

    /// From mg, rounded (half away from zero) and saturated to the ±16 g the unit holds.
    pub const fn from_milli_g(mg: [i32; 3]) -> Self {
        let mut out = [0i16; 3];
        let mut k = 0;
        while k < 3 {
            let c = crate::fixed::div_round_i128(mg[k] as i128 * FOOT_LSB_PER_G as i128, 1000);
            out[k] = if c > i16::MAX as i128 {
                i16::MAX
            } else if c < i16::MIN as i128 {
                i16::MIN
            } else {
                c as i16
            };
            k += 1;
        }
        FootAccel(out)
    }

    /// Forward (sagittal), counts.
    pub const fn forward(self) -> i16 {
        self.0[0]
    }

    /// Up, gravity removed, counts.
    pub const fn up(self) -> i16 {
        self.0[2]
    }
}

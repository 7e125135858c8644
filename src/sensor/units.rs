//! Units the stages compute in, as types: a sensor's scale (counts per g, per °/s) apart
//! from the register values that set it, and the foot-frame acceleration every stage after
//! the foot frame reads. The scales are the sensor seam's records ([`gaitclip_imu`]): each
//! driver says what its configuration's counts are in, and the stages take only that.

pub use gaitclip_imu::{AccelScale, GyroScale};

/// Foot-frame accelerations are in units of g/`FOOT_LSB_PER_G` whatever the sensor's range:
/// 2048 counts per g, the MPU6050's ±16 g scale, so that ±16 g fits an `i16`.
pub const FOOT_LSB_PER_G: i32 = 2048;

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

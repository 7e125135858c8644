//! ZUPT displacement: strapdown integration of one foot movement between two stances.
//!
//! At the end of a stance the foot is at rest, so its velocity is zero (the zero-velocity
//! update) and its specific force is gravity alone: that levels the attitude (roll and
//! pitch; yaw is free because a horizontal distance does not depend on it), gives the gyro
//! bias, and gives the gravity magnitude that calibrates the accelerometer's scale. Over the
//! movement the attitude follows the gyro, the specific force is rotated into the level
//! frame, gravity is removed and the rest is integrated twice. At the next stance the
//! velocity should be zero again; what is left is drift, assumed to have grown linearly over
//! the movement, and removed from the displacement in closed form (no sample buffer).
//!
//! Everything per sample is integer: Q30 quaternion, accelerations in counts·2⁸, velocity and
//! position as `i64` sums. Ranges: movements up to 2³¹ samples do not overflow (velocity
//! < 2²³·n, doubled position < 2²⁴·n²; `i64` holds n = 2²⁰ with margin).

use crate::fixed::{div_round_i128, isqrt_u64, QuatQ30};
use crate::rate::SampleRate;
use crate::rest::RestSums;
use crate::sample::{GyroRange, RawSample};

/// π · 2³².
const PI_Q32: u128 = 13_493_037_705;
/// Standard gravity in µm/s² per g, times 10⁶ (µm/s² · mHz² ↔ m/s² · Hz² bookkeeping).
const G_UM_PER_S2_X1E6: i128 = 9_806_650_000_000;

/// Displacement of the foot over one movement, in the level frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Displacement {
    /// Horizontal distance, µm.
    pub horizontal_um: u64,
    /// Vertical displacement, µm (up positive).
    pub vertical_um: i64,
}

/// Strapdown integrator for one movement.
#[derive(Clone, Debug)]
pub struct ZuptIntegrator {
    /// Gyro counts → Q30 half-angle per sample, scaled by 2¹⁶.
    half_angle_per_count_q46: i64,
    rate: SampleRate,
    attitude: QuatQ30,
    start_attitude: QuatQ30,
    gyro_bias: [i32; 3],
    gravity_q8: i64,
    velocity_q8: [i64; 3],
    position_x2_q8: [i64; 3],
    samples: u32,
}

impl ZuptIntegrator {
    /// An idle integrator for a sample rate and gyro range.
    pub const fn new(rate: SampleRate, gyro: GyroRange) -> Self {
        // rad per count / (2 · rate) · 2⁴⁶ = π·10⁴·2⁴⁶ / (360 · lsb10 · rate_mHz).
        let num = PI_Q32 * (1 << 14) * 10_000;
        let den = 360 * gyro.lsb_per_dps_x10() as u128 * rate.millihertz() as u128;
        ZuptIntegrator {
            half_angle_per_count_q46: ((num + den / 2) / den) as i64,
            rate,
            attitude: QuatQ30::IDENTITY,
            start_attitude: QuatQ30::IDENTITY,
            gyro_bias: [0; 3],
            gravity_q8: 0,
            velocity_q8: [0; 3],
            position_x2_q8: [0; 3],
            samples: 0,
        }
    }

    /// Starts a movement from the rest summed in `rest`. Returns `false` (and stays idle) if
    /// the rest is empty or the accelerometer read zero.
    pub fn start(&mut self, rest: &RestSums) -> bool {
        let (accel_sum, gyro_sum, count) = (rest.accel, rest.gyro, rest.count);
        if count == 0 {
            return false;
        }
        let n = count as i64;
        let mean_q8 = accel_sum.map(|s| (s << 8) / n);
        let Some(level) = QuatQ30::level_from_up(mean_q8) else {
            return false;
        };
        let g2: u64 = mean_q8.iter().map(|&m| (m * m) as u64).sum();
        self.gravity_q8 = isqrt_u64(g2) as i64;
        if self.gravity_q8 == 0 {
            return false;
        }
        self.attitude = level;
        self.start_attitude = level;
        self.gyro_bias = gyro_sum.map(|s| div_round_i128(s as i128, n as i128) as i32);
        self.velocity_q8 = [0; 3];
        self.position_x2_q8 = [0; 3];
        self.samples = 0;
        true
    }

    /// Integrates one sample of the movement.
    pub fn process(&mut self, s: &RawSample) {
        let mut h = [0i32; 3];
        for ((h, &g), &b) in h.iter_mut().zip(s.gyro.iter()).zip(self.gyro_bias.iter()) {
            let w = g as i64 - b as i64;
            *h = ((w * self.half_angle_per_count_q46 + (1 << 15)) >> 16) as i32;
        }
        self.attitude = self.attitude.integrate_half_angle(h);
        let r = self.attitude.matrix();
        for (i, row) in r.iter().enumerate() {
            let a: i64 = row
                .iter()
                .zip(s.accel.iter())
                .map(|(&m, &a)| m as i64 * a as i64)
                .sum();
            let mut a_q8 = (a + (1 << 21)) >> 22;
            if i == 2 {
                a_q8 -= self.gravity_q8;
            }
            let v_prev = self.velocity_q8[i];
            self.velocity_q8[i] = v_prev.saturating_add(a_q8);
            self.position_x2_q8[i] = self.position_x2_q8[i]
                .saturating_add(v_prev)
                .saturating_add(self.velocity_q8[i]);
        }
        self.samples = self.samples.saturating_add(1);
    }

    /// Samples integrated since [`ZuptIntegrator::start`].
    pub const fn samples(&self) -> u32 {
        self.samples
    }

    /// True when the heading changed by more than 45° over the movement: the rotation from
    /// the start attitude to the current one, `q ⊗ q₀*`, is about the vertical for a foot
    /// flat at both ends, and turns by more than 45° when `|z| > tan(22.5°)·|w|`.
    pub fn turned_over_45_deg(&self) -> bool {
        let r = self.attitude * self.start_attitude.conjugate();
        // tan(22.5°) = 0.414 213 56.
        (r.z as i64).abs() * 100_000_000 > (r.w as i64).abs() * 41_421_356
    }

    /// The displacement, with the residual end velocity removed as linear drift.
    pub fn displacement(&self) -> Displacement {
        let n = self.samples as i128;
        let den = 2
            * self.gravity_q8 as i128
            * self.rate.millihertz() as i128
            * self.rate.millihertz() as i128;
        let um = |i: usize| {
            // Trapezoidal position of a velocity error growing linearly to v_N over N samples
            // is v_N·N/2; doubled, v_N·N.
            let p2 = self.position_x2_q8[i] as i128 - self.velocity_q8[i] as i128 * n;
            div_round_i128(p2 * G_UM_PER_S2_X1E6, den)
        };
        let clamp = |v: i128| v.clamp(-(1 << 40), 1 << 40) as i64;
        let (x, y) = (clamp(um(0)), clamp(um(1)));
        Displacement {
            horizontal_um: isqrt_u64((x * x + y * y) as u64),
            vertical_um: clamp(um(2)),
        }
    }
}

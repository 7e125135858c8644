//! ZUPT displacement: strapdown integration of one foot movement between two stances.
//!
//! At the end of a stance the foot is at rest, so its velocity is zero (the zero-velocity
//! update) and its specific force is gravity alone: that levels the attitude (roll and
//! pitch; yaw is free because a horizontal distance does not depend on it), gives the gyro
//! bias, and gives the rest's reading of gravity (below: what it means). Over the
//! movement the attitude follows the gyro, the specific force is rotated into the level
//! frame, gravity is removed and the rest is integrated twice. At the next stance the
//! velocity should be zero again; what is left is drift, assumed to have grown linearly over
//! the movement, and removed from the displacement in closed form (no sample buffer).
//!
//! **What the rest's reading of gravity means.** At rest the accelerometer should read 1 g;
//! what it reads instead is how the sensor errs along gravity, and nothing else: the axes
//! that measure the stride lie across it. That departure is taken for an offset along
//! gravity ([`GravityReading::Offset`], the default): removed from every sample as a vector
//! fixed to the sensor, and the counts turned into metres at the sensor's own scale (counts
//! per g). Taking it for a gain on every axis instead ([`GravityReading::Gain`], lengths in
//! units of the rest's gravity, gaitclip's rule until the bias study) turns an offset along
//! the vertical into an error of every length. Measured (`gaitclip bias`, docs/accuracy.md):
//! `ipol_gait_events`' left-foot sensors read gravity 4.8 % high, the right 1.0 %; read as a
//! gain, the left foot walked 2.67 % (median) less than the right on the same walks; as an
//! offset, 0.47 % less. A 0.5 m/s² offset along gravity made `gaitmap_walk`'s strides 4.7 cm
//! shorter read as a gain, 2.4 cm longer left in, and not at all removed. The departure
//! removed is bounded by [`MAX_GRAVITY_OFFSET_MILLI_G`].
//!
//! Everything per sample is integer: Q30 quaternion, accelerations in counts·2⁸, velocity and
//! position as `i64` sums. Ranges: movements up to 2³¹ samples do not overflow (velocity
//! < 2²³·n, doubled position < 2²⁴·n²; `i64` holds n = 2²⁰ with margin).

use crate::detect::clipping::{ClippedAccel, RailRun};
use crate::detect::rest::RestSums;
use crate::fixed::{atan2_cdeg, div_round_i128, isqrt_u64, QuatQ30};
use crate::record::stride::Stride;
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::{Rails, RawSample};
use crate::sensor::units::{AccelScale, GyroScale};

/// π · 2³².
const PI_Q32: u128 = 13_493_037_705;
/// Standard gravity in µm/s² per g, times 10⁶ (µm/s² · mHz² ↔ m/s² · Hz² bookkeeping).
const G_UM_PER_S2_X1E6: i128 = 9_806_650_000_000;

/// The velocity of a sensor mounted `h` above the foot's rolling contact: at a stance the
/// foot rolls over that contact, so the sensor moves at `ω × (h·up)`, not zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RollingContact {
    /// `π·10·h·rate / (180·lsb10·g)` in Q40: (gyro counts × gravity counts·2⁸) to the
    /// integrator's velocity units.
    factor_q40: i64,
}

impl RollingContact {
    /// For a sensor `height_um` above the contact, at `rate` with gyro range `gyro`.
    /// Range: heights up to 1 m, any supported rate.
    pub const fn new(height_um: u32, rate: SampleRate, gyro: GyroScale) -> Self {
        // v_q8 = ω_counts · (π/180)·(dps/lsb) · h · unit_q8 · rate / g, with ω·(π/180)·dps/lsb
        // in rad/s: π·dps·h_um·rate_mHz / (180·lsb·1e6·1e3·9.80665) per (count · count·2⁸).
        let num = PI_Q32 * gyro.dps() as u128 * height_um as u128 * rate.millihertz() as u128;
        let den = 180 * gyro.lsb() as u128 * 9_806_650_000u128;
        // num / den · 2⁴⁰ = num · 2⁸ / den (num carries 2³²).
        let f = (num << 8) / den;
        RollingContact {
            factor_q40: f as i64,
        }
    }

    /// The sensor's velocity in the level frame of `attitude` for the body rate
    /// `gyro_minus_bias` (counts), in the integrator's units for `unit_q8` (the counts·2⁸
    /// that stand for 1 g, [`ZuptIntegrator::unit_q8`]):
    /// `(q·ω) × (0, 0, h)` = `(ω_y·h, −ω_x·h, 0)`. The level-frame rate is kept in
    /// counts·2⁸ (whole counts would cost up to 2·10⁻⁵ m/s at ±2000 °/s and 4 cm): within
    /// 10⁻⁴ relative and 10 µm/s of the exact velocity (host test). Range: rates up to 2¹⁷
    /// counts, gravity up to 2²³ counts·2⁸.
    pub fn velocity_q8(
        &self,
        attitude: QuatQ30,
        gyro_minus_bias: [i32; 3],
        unit_q8: i64,
    ) -> [i64; 3] {
        let r = attitude.matrix();
        let w = |row: &[i32; 3]| -> i64 {
            let dot: i64 = row
                .iter()
                .zip(gyro_minus_bias.iter())
                .map(|(&m, &g)| m as i64 * g as i64)
                .sum();
            (dot + (1 << 21)) >> 22
        };
        let (wx, wy) = (w(&r[0]), w(&r[1]));
        let scale = |v: i64| -> i64 {
            let p = v as i128 * unit_q8 as i128 * self.factor_q40 as i128;
            ((p + (1 << 47)) >> 48).clamp(i64::MIN as i128, i64::MAX as i128) as i64
        };
        [scale(wy), scale(-wx), 0]
    }
}

/// Points of the vertical trajectory an integrator keeps for the sensor's highest point
/// ([`Displacement::max_lift_um`]): a movement of `n` samples is kept every
/// `2^⌈log₂(n/LIFT_POINTS)⌉` samples, every eighth at 200 Hz for a 0.64–1.28 s stride. At the
/// top the vertical velocity is zero, so a point `k` samples from it is low by only
/// `a·(k·dt)²/2`: up to 2 mm for the ±4 samples of a walking stride at 200 Hz (a ≈ 10 m/s² at
/// the top; 2.0 mm the worst of the demo fixture's strides in `fixed_point.rs`).
pub const LIFT_POINTS: usize = 32;

/// Displacement of the foot over one movement, in the level frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Displacement {
    /// Horizontal distance, µm.
    pub horizontal_um: u64,
    /// Vertical displacement, µm (up positive).
    pub vertical_um: i64,
    /// Highest point of the sensor above where it started, µm (gaitmap's
    /// `max_sensor_lift`), over the kept trajectory points ([`LIFT_POINTS`]) and the end,
    /// de-drifted as the displacement is; 0 if it never rose.
    pub max_lift_um: u32,
    /// Direction of the horizontal displacement in the level frame of the start,
    /// centidegrees counter-clockwise from its x axis, in (−18 000, 18 000] (0 for none):
    /// [`crate::fixed::atan2_cdeg`] of the rounded µm components, within 1 centidegree of
    /// their exact angle.
    pub travel_cdeg: i16,
}

impl Displacement {
    /// The horizontal displacement, µm (saturated): the stride's `zupt_um`.
    pub fn zupt_um(&self) -> u32 {
        self.horizontal_um.min(u32::MAX as u64) as u32
    }

    /// The height gained, mm (rounded, saturated): the stride's `climb_mm`.
    pub fn climb_mm(&self) -> i32 {
        ((self.vertical_um + 500).div_euclid(1000)).clamp(i32::MIN as i64, i32::MAX as i64) as i32
    }

    /// Writes what this trajectory gives into `s`: horizontal displacement, climb, lift
    /// (rounded to mm, saturated) and the heading change `turning_angle_cdeg`.
    pub fn record_on(&self, s: &mut Stride, turning_angle_cdeg: i16) {
        let d = self;
        s.zupt_um = d.zupt_um();
        s.climb_mm = d.climb_mm();
        s.max_sensor_lift_mm = ((d.max_lift_um as u64 + 500) / 1000).min(u16::MAX as u64) as u16;
        s.turning_angle_cdeg = turning_angle_cdeg;
        s.travel_cdeg = d.travel_cdeg;
    }
}

/// What the accelerometer's reading of gravity at rest, where it is not 1 g, is taken to be
/// (the module's essay: *What the rest's reading of gravity means*).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GravityReading {
    /// An offset along gravity, fixed to the sensor: removed from every sample; lengths at
    /// the sensor's scale. The default.
    Offset,
    /// A gain on every axis: lengths in units of the rest's gravity (gaitclip's rule until
    /// the bias study; kept for its comparison).
    Gain,
    /// Neither: lengths at the sensor's scale, the departure left in (the bias study's middle
    /// case).
    Ignored,
}

/// The largest departure of the rest's gravity from 1 g removed as an offset, milli-g: the
/// MPU6050's zero-g tolerance along z is ±80 mg (PS-MPU-6000A-00 rev. 3.4, §6.2); a larger
/// departure is not an offset of a working sensor, and only this much of it is removed.
pub const MAX_GRAVITY_OFFSET_MILLI_G: i64 = 100;

/// Strapdown integrator for one movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ZuptIntegrator {
    /// Gyro counts → Q30 half-angle per sample, scaled by 2¹⁶.
    half_angle_per_count_q46: i64,
    rate: SampleRate,
    /// The sensor's 1 g, counts·2⁸.
    nominal_g_q8: i64,
    reading: GravityReading,
    /// The offset removed from every sample (sensor axes, counts·2⁸; [`GravityReading::Offset`]).
    offset_q8: [i32; 3],
    attitude: QuatQ30,
    start_attitude: QuatQ30,
    gyro_bias: [i32; 3],
    gravity_q8: i64,
    velocity_q8: [i64; 3],
    position_x2_q8: [i64; 3],
    samples: u32,
    /// Samples with a gyro axis at a rail, and for them Σ c and Σ c² (`c`: the sample's
    /// count, 1-based), for [`ZuptIntegrator::displacement_restoring`].
    clipped: u32,
    clipped_c: i64,
    clipped_c2: i64,
    /// Per gyro axis, the rotation lost at its rail.
    rail_runs: [RailRun; 3],
    /// What the accelerometer lost at its rails ([`crate::detect::clipping`]).
    accel: ClippedAccel,
    /// The doubled vertical position every `lift_every` samples (sample `(k + 1)·lift_every`
    /// at `lift[k]`), `lift_len` of them; `lift_countdown` samples to the next.
    lift: [i64; LIFT_POINTS],
    lift_len: u8,
    lift_every: u32,
    lift_countdown: u32,
}

impl ZuptIntegrator {
    /// An idle integrator for a sample rate and the sensor's ranges, the rest's departure
    /// from 1 g read as an offset ([`GravityReading::Offset`]).
    pub const fn new(rate: SampleRate, accel: AccelScale, gyro: GyroScale) -> Self {
        Self::reading(rate, accel, gyro, GravityReading::Offset)
    }

    /// An idle integrator that reads the rest's departure from 1 g as `reading` says.
    pub const fn reading(
        rate: SampleRate,
        accel: AccelScale,
        gyro: GyroScale,
        reading: GravityReading,
    ) -> Self {
        // rad per count / (2 · rate) · 2⁴⁶ = π·dps·10³·2⁴⁶ / (360 · lsb · rate_mHz).
        let num = PI_Q32 * (1 << 14) * 1_000 * gyro.dps() as u128;
        let den = 360 * gyro.lsb() as u128 * rate.millihertz() as u128;
        ZuptIntegrator {
            half_angle_per_count_q46: ((num + den / 2) / den) as i64,
            rate,
            nominal_g_q8: (accel.lsb_per_g() as i64) << 8,
            reading,
            offset_q8: [0; 3],
            attitude: QuatQ30::IDENTITY,
            start_attitude: QuatQ30::IDENTITY,
            gyro_bias: [0; 3],
            gravity_q8: 0,
            velocity_q8: [0; 3],
            position_x2_q8: [0; 3],
            samples: 0,
            clipped: 0,
            clipped_c: 0,
            clipped_c2: 0,
            rail_runs: [RailRun::NEW; 3],
            accel: ClippedAccel::NEW,
            lift: [0; LIFT_POINTS],
            lift_len: 0,
            lift_every: 1,
            lift_countdown: 1,
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
        let gyro_bias = gyro_sum.map(|s| div_round_i128(s as i128, n as i128) as i32);
        // At rest: no velocity to impose.
        let gravity_q8 = self.gravity_q8;
        self.start_at(level, gyro_bias, gravity_q8, [0; 3])
    }

    /// Starts a stride at a stance instant from what is known there: the attitude `level`
    /// (levelled from the stance's gravity), the gyro bias and gravity magnitude of the
    /// last rest (counts; gravity counts·2⁸), and the sensor's velocity there, `v0_q8` (level
    /// frame, the integrator's units: [`ZuptIntegrator::velocity_q8`]). Returns `false` (and
    /// stays idle) for a zero gravity.
    pub fn start_at(
        &mut self,
        level: QuatQ30,
        gyro_bias: [i32; 3],
        gravity_q8: i64,
        v0_q8: [i64; 3],
    ) -> bool {
        if gravity_q8 <= 0 {
            return false;
        }
        self.attitude = level;
        self.start_attitude = level;
        self.gyro_bias = gyro_bias;
        self.gravity_q8 = gravity_q8;
        self.offset_q8 = [0; 3];
        if let GravityReading::Offset = self.reading {
            // The departure from 1 g, bounded, along the level frame's up in sensor axes
            // (the matrix's last row, Q30): |d| ≤ 0.1 g < 2¹⁸ counts·2⁸ at any range.
            let bound = self.nominal_g_q8 * MAX_GRAVITY_OFFSET_MILLI_G / 1000;
            let d = (gravity_q8 - self.nominal_g_q8).clamp(-bound, bound);
            let up = level.matrix()[2];
            self.offset_q8 = up.map(|u| ((d * u as i64 + (1 << 29)) >> 30) as i32);
            self.gravity_q8 = gravity_q8 - d;
        }
        self.velocity_q8 = v0_q8;
        self.position_x2_q8 = [0; 3];
        self.samples = 0;
        self.clipped = 0;
        self.clipped_c = 0;
        self.clipped_c2 = 0;
        self.rail_runs = [RailRun::NEW; 3];
        self.accel = ClippedAccel::NEW;
        self.lift_len = 0;
        self.lift_every = 1;
        self.lift_countdown = 1;
        true
    }

    /// Samples integrated with a gyro axis at a rail.
    pub const fn clipped(&self) -> u32 {
        self.clipped
    }

    /// Samples integrated with an accelerometer axis at a rail.
    pub const fn accel_clipped(&self) -> u32 {
        self.accel.clipped()
    }

    /// The attitude now (sensor to level frame).
    pub const fn attitude(&self) -> QuatQ30 {
        self.attitude
    }

    /// The velocity now, in the level frame, in counts·2⁸ of the accelerometer summed over
    /// samples: `v [m/s] = velocity_q8 · g / (unit_q8 · rate)` ([`ZuptIntegrator::unit_q8`]).
    pub const fn velocity_q8(&self) -> [i64; 3] {
        self.velocity_q8
    }

    /// The gravity magnitude the integrator removes, counts·2⁸ (the rest's, less the offset
    /// removed).
    pub const fn gravity_q8(&self) -> i64 {
        self.gravity_q8
    }

    /// The counts·2⁸ that stand for 1 g when the integral becomes metres: the sensor's scale,
    /// or the rest's gravity read as a gain ([`GravityReading`]).
    pub const fn unit_q8(&self) -> i64 {
        self.unit_q8_for(self.gravity_q8)
    }

    /// [`ZuptIntegrator::unit_q8`] of a stride started with the rest gravity `gravity_q8`
    /// (what the velocity imposed at its start is scaled by).
    pub const fn unit_q8_for(&self, gravity_q8: i64) -> i64 {
        match self.reading {
            GravityReading::Gain => gravity_q8,
            GravityReading::Offset | GravityReading::Ignored => self.nominal_g_q8,
        }
    }

    /// The offset removed from every sample, sensor axes, counts·2⁸.
    pub const fn offset_q8(&self) -> [i32; 3] {
        self.offset_q8
    }

    /// The displacement, with the difference between the end velocity and `v_end_q8` (the
    /// velocity the sensor should have there, [`RollingContact::velocity_q8`]) removed as
    /// linear drift.
    pub fn displacement_to(&self, v_end_q8: [i64; 3]) -> Displacement {
        self.displacement_of(self.drift_to(v_end_q8), self.position_x2_q8)
    }

    /// The velocity less `v_end_q8`: what is left is drift.
    fn drift_to(&self, v_end_q8: [i64; 3]) -> [i64; 3] {
        let mut v = self.velocity_q8;
        for (v, e) in v.iter_mut().zip(v_end_q8) {
            *v = v.saturating_sub(e);
        }
        v
    }

    /// [`ZuptIntegrator::displacement_to`], with what the rails lost put back: the
    /// accelerometer's lost force as velocity steps where it was lost
    /// ([`crate::detect::clipping::ClippedAccel`]), then the gyro's lost tilt.
    ///
    /// **Accelerometer.** Clipped runs of two samples or more are reconstructed from their
    /// shape; single clipped samples take their share of the end-velocity residual (against
    /// `v_end_q8`), projected onto the directions they lost force along and bounded by a
    /// rail's worth each.
    ///
    /// **Gyro.** A rate beyond the rail loses rotation while it is clipped, and the lost
    /// rotation tilts the level frame from then on, which leaks gravity into the horizontal
    /// acceleration. At the end stance the accelerometer's gravity `end_gravity_q8` (sensor
    /// axes, counts·2⁸, a stance mean) seen through the integrated attitude shows the tilt
    /// `h`; it is spread evenly over the clipped samples (a step `h/K` at each of the `K`),
    /// but never more of it than the rails can have lost: `|h|` is capped at the rotation
    /// [`RailRun`] reconstructs above the rails, so the tilt that gyro noise and bias leave on
    /// every stride is not blamed on a few clipped samples. After linear dedrift a tilt step
    /// `s` at sample `c` of `N` leaves the doubled position off by `−s·g·(N − c)·c`, which is
    /// put back in closed form: `+g·h·(N·Σc − Σc²)/K`. Measured on traces converted to ±500
    /// and ±250 °/s: `gaitclip zupt-sweep`.
    ///
    /// Without clipped samples this is `displacement_to`. `restore_accel` false leaves the
    /// accelerometer's loss in (what the clipping sweep compares against).
    // Not inlined: its temporaries (the restored sums, `i128` arrays) then take stack only
    // while it runs, not under the phase split of the stride's close (the M0's stack).
    #[inline(never)]
    pub fn displacement_restoring(
        &self,
        v_end_q8: [i64; 3],
        end_gravity_q8: [i64; 3],
        rails: &Rails,
        restore_accel: bool,
    ) -> Displacement {
        let (mut velocity, mut position) = (self.velocity_q8, self.position_x2_q8);
        if restore_accel && self.accel.clipped() > 0 {
            (velocity, position) = self.accel.restore(
                self.velocity_q8,
                self.position_x2_q8,
                self.samples,
                &rails.accel,
                v_end_q8,
            );
        }
        let mut drift = velocity;
        for (v, e) in drift.iter_mut().zip(v_end_q8) {
            *v = v.saturating_sub(e);
        }
        if self.clipped > 0 {
            self.restore_tilt(&mut position, end_gravity_q8, &rails.gyro);
        }
        self.displacement_of(drift, position)
    }

    /// The gyro part of [`ZuptIntegrator::displacement_restoring`]: the lost tilt's effect
    /// on the doubled position.
    fn restore_tilt(
        &self,
        position: &mut [i64; 3],
        end_gravity_q8: [i64; 3],
        rails: &[crate::sensor::sample::AxisRails; 3],
    ) {
        let r = self.attitude.matrix();
        let level: [i128; 3] = r.map(|row| {
            row.iter()
                .zip(end_gravity_q8.iter())
                .map(|(&m, &g)| m as i128 * g as i128)
                .sum::<i128>()
                >> 30
        });
        let norm2: i128 = level.iter().map(|v| v * v).sum();
        let norm = isqrt_u64(norm2.clamp(0, u64::MAX as i128) as u64) as i128;
        let lxy2 = level[0] * level[0] + level[1] * level[1];
        let lxy = isqrt_u64(lxy2.clamp(0, u64::MAX as i128) as u64) as i128;
        if norm == 0 || lxy == 0 {
            return;
        }
        // The rotation lost above the rails, rad Q30: counts·samples × rad per count·sample.
        let lost_area: i128 = self
            .rail_runs
            .iter()
            .zip(rails.iter())
            .map(|(r, &rails)| r.lost_counts_samples(rails) as i128)
            .sum();
        let lost_q30 = (lost_area * 2 * self.half_angle_per_count_q46 as i128) >> 16;
        // h per axis, rad Q30: the measured tilt, or the lost rotation along it if smaller.
        let capped = lxy << 30 > lost_q30.saturating_mul(norm);
        let n = self.samples as i128;
        let w = n * self.clipped_c as i128 - self.clipped_c2 as i128;
        let k_count = self.clipped as i128;
        for (p, &l) in position.iter_mut().zip(level.iter()).take(2) {
            let h_q30 = if capped {
                div_round_i128(l * lost_q30, lxy)
            } else {
                div_round_i128(l << 30, norm)
            };
            // g·h·w/K: gravity 2²⁰ × h 2³¹ × w < 2⁴⁸ (movements up to 2¹⁶ samples) < 2¹⁰⁰.
            let fix = div_round_i128(
                (self.gravity_q8 as i128 * h_q30).saturating_mul(w),
                k_count << 30,
            );
            *p = (*p as i128 + fix).clamp(i64::MIN as i128, i64::MAX as i128) as i64;
        }
    }

    /// Integrates one sample of the movement, clipped where `rails` say.
    pub fn process(&mut self, s: &RawSample, rails: &Rails) {
        let mut h = [0i32; 3];
        for ((h, &g), &b) in h.iter_mut().zip(s.gyro.iter()).zip(self.gyro_bias.iter()) {
            let w = g as i64 - b as i64;
            *h = ((w * self.half_angle_per_count_q46 + (1 << 15)) >> 16) as i32;
        }
        self.attitude = self.attitude.integrate_half_angle(h);
        let r = self.attitude.matrix();
        // The sample less the offset, counts·2⁸: |·| < 2²³ + 2¹⁹ < 2²⁴ (an i32, so that the
        // products below stay 32 × 32 bits), × Q30 < 2⁵⁴, three of them < 2⁵⁶.
        let f_q8: [i32; 3] = [0, 1, 2].map(|k| ((s.accel[k] as i32) << 8) - self.offset_q8[k]);
        for (i, row) in r.iter().enumerate() {
            let a: i64 = row
                .iter()
                .zip(f_q8.iter())
                .map(|(&m, &f)| m as i64 * f as i64)
                .sum();
            let mut a_q8 = (a + (1 << 29)) >> 30;
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
        self.keep_lift_point();
        self.accel.process(self.samples, &s.accel, &rails.accel, &r);
        for ((run, &g), &rails) in self
            .rail_runs
            .iter_mut()
            .zip(s.gyro.iter())
            .zip(rails.gyro.iter())
        {
            run.process(g, rails);
        }
        if rails.gyro_clipped(s) {
            // Σc < 2³², Σc² < 2⁴⁸ for movements up to 2¹⁶ samples.
            let c = self.samples as i64;
            self.clipped = self.clipped.saturating_add(1);
            self.clipped_c = self.clipped_c.saturating_add(c);
            self.clipped_c2 = self.clipped_c2.saturating_add(c.saturating_mul(c));
        }
    }

    /// Keeps the vertical position every `lift_every` samples; when the points are full,
    /// every other one is dropped and the spacing doubles.
    fn keep_lift_point(&mut self) {
        self.lift_countdown -= 1;
        if self.lift_countdown > 0 {
            return;
        }
        if self.lift_len as usize == LIFT_POINTS {
            // Keep samples 2·every, 4·every, …: points 1, 3, 5, …
            for k in 0..LIFT_POINTS / 2 {
                self.lift[k] = self.lift[2 * k + 1];
            }
            self.lift_len = (LIFT_POINTS / 2) as u8;
            self.lift_every = self.lift_every.saturating_mul(2);
            // This sample is an odd multiple of the old spacing: the next point is one new
            // spacing on from the last kept one, half of it from here.
            self.lift_countdown = self.lift_every / 2;
            return;
        }
        self.lift[self.lift_len as usize] = self.position_x2_q8[2];
        self.lift_len += 1;
        self.lift_countdown = self.lift_every;
    }

    /// The heading change over the movement, centidegrees, counter-clockwise seen from
    /// above positive (gaitmap's `turning_angle`): the direction the sensor's x axis turned
    /// to in the level plane under the rotation from the start attitude to now, `q ⊗ q₀*`.
    /// Within 1 centidegree of the exact angle of that rotation (host test).
    pub fn heading_change_cdeg(&self) -> i16 {
        let r = (self.attitude * self.start_attitude.conjugate()).matrix();
        atan2_cdeg(r[0][0] as i64, r[1][0] as i64) as i16
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
        self.displacement_of(self.velocity_q8, self.position_x2_q8)
    }

    /// The displacement for an end velocity error `drift` (removed as growing linearly over
    /// the movement) and a doubled position `position_x2` (the integrator's units).
    fn displacement_of(&self, drift: [i64; 3], position_x2: [i64; 3]) -> Displacement {
        let n = self.samples as i128;
        let den = 2
            * self.unit_q8() as i128
            * self.rate.millihertz() as i128
            * self.rate.millihertz() as i128;
        let um = |i: usize| {
            // Trapezoidal position of a velocity error growing linearly to v_N over N samples
            // is v_N·N/2; doubled, v_N·N.
            let p2 = position_x2[i] as i128 - drift[i] as i128 * n;
            div_round_i128(p2 * G_UM_PER_S2_X1E6, den)
        };
        let clamp = |v: i128| v.clamp(-(1 << 40), 1 << 40) as i64;
        // Horizontally ±2³¹ µm (2 km, far beyond any stride): the sum of squares then fits
        // a u64 (≤ 2⁶³) whatever a hostile input integrated to.
        let horizontal = |v: i128| v.clamp(-(1 << 31), 1 << 31).unsigned_abs() as u64;
        let (dx, dy) = (um(0), um(1));
        let (x, y) = (horizontal(dx), horizontal(dy));
        // Within ±2³¹ µm as above: far inside atan2_cdeg's range, and its result inside i16.
        let travel = atan2_cdeg(
            dx.clamp(-(1 << 31), 1 << 31) as i64,
            dy.clamp(-(1 << 31), 1 << 31) as i64,
        );
        // The highest doubled height, de-drifted: a velocity error growing linearly to v_N
        // leaves v_N·c²/N on the doubled position at sample c; compared as ·N.
        let drift_z = drift[2] as i128;
        let mut top_n: i128 = 0;
        let mut c: i128 = 0;
        for &p2 in self.lift.iter().take(self.lift_len as usize) {
            c += self.lift_every as i128;
            top_n = top_n.max(p2 as i128 * n - drift_z * c * c);
        }
        top_n = top_n.max((position_x2[2] as i128 - drift_z * n) * n);
        let top_um = if n > 0 {
            div_round_i128(div_round_i128(top_n, n) * G_UM_PER_S2_X1E6, den)
        } else {
            0
        };
        Displacement {
            horizontal_um: isqrt_u64(x * x + y * y),
            vertical_um: clamp(um(2)),
            max_lift_um: top_um.clamp(0, u32::MAX as i128) as u32,
            travel_cdeg: travel.clamp(-18_000, 18_000) as i16,
        }
    }
}

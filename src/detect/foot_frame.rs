//! The foot frame, found from the data: which way is up, which way is forward.
//!
//! A clip is mounted however its user mounts it, but Huang's stance test and phase splitter
//! read the *vertical* and *sagittal* (forward) acceleration of the foot. The estimator works
//! them out from two facts of walking:
//!
//! - **At rest the accelerometer reads gravity alone.** The mean specific force of each rest
//!   period (found by the orientation-free [`crate::detect::rest`] test) is the up axis.
//! - **In a step the foot pitches about its medio-lateral axis.** The angular rate of a
//!   movement is dominated by that axis: the principal eigenvector of `Σ ω ωᵀ` over the
//!   movement, projected on the horizontal plane. Its sign comes from the order of the
//!   rotations: the foot first rolls onto its toes (toe down) and pitches toe up through the
//!   swing, so the first moment `Σ (k − k̄) ω` points along *minus* the left axis when the
//!   rotation is measured about *left* (toe-down is a positive rotation about left when x is
//!   forward and z up).
//!
//! Forward is then `left × up`. Estimates are smoothed over rest periods and strides, and
//! re-started when a rest period's gravity direction is more than [`REMOUNT_DEG`] away from
//! the current up (the clip was moved on the shoe).
//!
//! The once-per-movement 3×3 work is `f32` with `nalgebra` (Jacobi eigen-decomposition);
//! IEEE arithmetic and `libm` make it bit-identical on every target. The per-sample rotation
//! ([`FootFrame::apply`]) is integer.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::detect::rest::RestSums;
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::RawSample;
use crate::sensor::units::{AccelScale, FootAccel, GyroScale, FOOT_LSB_PER_G};

/// A rest period whose gravity direction is further than this from the current up axis
/// means the clip was moved: the frame starts again.
pub const REMOUNT_DEG: u32 = 25;
/// Movements used to learn the medio-lateral axis: longer than this (a step, not a wobble)…
pub const AXIS_MIN_MOVEMENT_MS: u32 = 250;
/// …and shorter than this (walking, not fiddling with the shoe).
pub const AXIS_MAX_MOVEMENT_MS: u32 = 2500;
/// The very first frame is set once the first rest has lasted this long, so that the stance
/// detector is running before the first step (later rests update it when they end).
pub const FIRST_FRAME_AFTER_MS: u32 = 100;
/// The cycle detector's calibration (gyro bias, gravity: [`FootFrameEstimator::still_calibration`])
/// comes from blocks this long inside rests: the stillest, not the whole rest, because the
/// rest detector's rests take in a settling foot or a slow shift of weight (a steady 3 °/s
/// over a 1.6 s "rest" in one `pyshoe_vicon` trial, 0.2 rad/s of wobble at the start of an
/// `ipol_gait_events` one), whose mean is no bias.
pub const STILL_BLOCK_MS: u32 = 250;
/// A block whose angular rate spreads by less than this (all axes together) is standing
/// still: 0.05 rad/s (3 °/s); a walking stance's rolling foot spreads by 0.1–0.3 rad/s. The
/// latest such block calibrates; until one comes, the steadiest block so far (or the
/// steadiest rest shorter than a block).
pub const STILL_GYRO_STD_MRADPS: u32 = 50;
/// …and whose gravity turns slower than this between its halves: 0.02 rad/s (1.1 °/s). A
/// steady slow rotation (a foot rolling onto its toes, a shift of weight) has no spread, but
/// turns gravity; its mean rate is no bias. (Accelerometer noise turns the halves' means of a
/// 250 ms block at 100 Hz by ≈ 0.001 rad, a third of this rate's 0.0025 rad.)
pub const STILL_TILT_MRADPS: u32 = 20;
/// cos(REMOUNT_DEG).
const COS_REMOUNT: f32 = 0.906_307_8;
/// Weight of a new rest period in the smoothed up axis and gravity.
const UP_SMOOTHING: f32 = 0.125;
/// Weight kept by the medio-lateral axis sum at each new movement.
const AXIS_MEMORY: f32 = 0.875;

/// The angular rate `omega` (counts, bias removed) about the unit axis `axis` (Q14),
/// counts, saturated to ±32 767: `|axis| = 2¹⁴` and `|ω| < 2¹⁶` keep each product under
/// 2³¹ and the sum in an `i64`; within 1 count of the exact projection.
pub fn sagittal_rate(axis: &[i32; 3], omega: &[i32; 3]) -> i16 {
    let dot: i64 = axis
        .iter()
        .zip(omega.iter())
        .map(|(&l, &w)| l as i64 * w as i64)
        .sum();
    ((dot + (1 << 13)) >> 14).clamp(-32_767, 32_767) as i16
}

/// Rotation from sensor counts into the foot frame, Q14 with the range scaling folded in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FootFrame {
    /// Rows: forward, left, up; each `unit · 2¹⁴ · FOOT_LSB_PER_G / lsb_per_g`.
    rows: [[i32; 3]; 3],
    /// Gravity in foot units (g/2048), as measured at rest.
    gravity: i32,
    /// The forward axis was learnt from movements (not a placeholder perpendicular to up).
    heading_known: bool,
    /// The steps' rotation axis, unit Q14 in sensor axes, once learnt.
    pitch: Option<[i32; 3]>,
    /// The horizontal axes a step turns the foot about, unit Q14 in sensor axes: the steps'
    /// pitch axis laid level (left, or a placeholder level axis before any step taught it),
    /// and the axis across it (forward: a sideways step rolls the foot about it).
    level_axes_q14: [[i32; 3]; 2],
}

impl FootFrame {
    /// Specific force `accel` (counts) in the foot frame, gravity removed from the vertical:
    /// `[forward, left, up − g]` in g/2048, saturated to ±32 767 (±16 g).
    ///
    /// Error: the Q14 matrix is within 2⁻¹⁵ per entry of the `f32` rotation, so the result
    /// is within 1 unit (0.5 mg) plus rounding of the exact rotation for any `i16` input.
    pub fn apply(&self, accel: [i16; 3]) -> FootAccel {
        let mut out = [0i16; 3];
        for (k, (o, row)) in out.iter_mut().zip(self.rows.iter()).enumerate() {
            // |row| ≤ 2¹⁴·√(Σ) per axis and |a| ≤ 2¹⁵: each product < 2²⁹, the sum < 2³¹.
            let dot: i64 = row
                .iter()
                .zip(accel.iter())
                .map(|(&r, &a)| r as i64 * a as i64)
                .sum();
            let mut v = (dot + (1 << 13)) >> 14;
            if k == 2 {
                v -= self.gravity as i64;
            }
            *o = v.clamp(-32_767, 32_767) as i16;
        }
        FootAccel(out)
    }

    /// The rotation as rows of `f32` unit vectors (forward, left, up), for logs and tests.
    pub fn axes(&self, accel: AccelScale) -> [[f32; 3]; 3] {
        let scale = (1u32 << 14) as f32 * FOOT_LSB_PER_G as f32 / accel.lsb_per_g() as f32;
        self.rows.map(|r| r.map(|v| v as f32 / scale))
    }

    /// The up axis as a row of the rotation (sensor axes, Q14 with the range scaling): the
    /// foot's standing up, for a direction test.
    pub const fn up_row(&self) -> [i32; 3] {
        self.rows[2]
    }

    /// The axis the foot pitches about in its steps as a unit row in sensor axes, Q14, any
    /// sign ([`FootFrameEstimator`]: the steps' principal rotation axis, not projected on the
    /// horizontal); `None` before a step has been learnt from.
    pub const fn pitch_axis_q14(&self) -> Option<[i32; 3]> {
        self.pitch
    }

    /// The angular rate `omega` (counts, bias removed) about the two level axes a step turns
    /// the foot about: the pitch axis laid level, and the axis across it (forward), counts,
    /// saturated to ±32 767; within 1 count of the exact projection plus the axes' Q14
    /// rounding (2⁻¹⁴ relative). Before a step has taught the pitch axis, the first axis is a
    /// placeholder level axis: the pair still spans the horizontal plane.
    pub fn level_rates(&self, omega: &[i32; 3]) -> [i32; 2] {
        self.level_axes_q14
            .map(|axis| sagittal_rate(&axis, omega) as i32)
    }

    /// Gravity measured at rest, in g/2048.
    pub const fn gravity(&self) -> i32 {
        self.gravity
    }

    /// Whether the forward axis has been learnt from movements yet.
    pub const fn heading_known(&self) -> bool {
        self.heading_known
    }
}

/// The block of a rest the cycle detector is calibrated from.
#[derive(Clone, Copy, Debug)]
struct StillBlock {
    gyro_bias: [i32; 3],
    gravity_counts: i32,
    /// Its angular rate's variance, counts² (all axes).
    gyro_variance: u64,
    /// A whole block within [`STILL_GYRO_STD_MRADPS`].
    qualified: bool,
}

/// Learns the foot frame from rest periods and movements.
#[derive(Clone, Debug)]
pub struct FootFrameEstimator {
    accel: AccelScale,
    axis_min: u32,
    axis_max: u32,
    first_after: u32,
    /// Samples of [`STILL_BLOCK_MS`].
    block_len: u32,
    /// [`STILL_GYRO_STD_MRADPS`]² in counts².
    still_variance: u64,
    frame: Option<FootFrame>,
    /// The calibration block ([`STILL_BLOCK_MS`]).
    still: Option<StillBlock>,
    /// The block of the rest in progress, and its first half's force sums.
    block: RestSums,
    block_half: [i64; 3],
    up: [f32; 3],
    gravity_counts: f32,
    left_sum: [f32; 3],
    /// The steps' principal rotation axes, summed as `left_sum` is but not projected on the
    /// horizontal, each signed to agree with the sum so far (the rate's events take their
    /// sign from each movement, [`crate::detect::gyro_events`]).
    pitch_sum: [f32; 3],
    heading_known: bool,
    was_rest: bool,
    rest: RestSums,
    gyro_bias: [i32; 3],
    /// Σ ω ωᵀ over the movement: xx, yy, zz, xy, xz, yz (counts²).
    cov: [i64; 6],
    sum_w: [i64; 3],
    moment: [i64; 3],
    move_n: u32,
    /// Samples were lost in the movement (or its current chunk): nothing is learnt from it.
    gapped: bool,
    /// The movement has gone on past [`AXIS_MAX_MOVEMENT_MS`]: its chunks teach the pitch
    /// axis, not the heading.
    chunked: bool,
}

impl FootFrameEstimator {
    /// An estimator that knows nothing yet.
    pub const fn new(rate: SampleRate, accel: AccelScale, gyro: GyroScale) -> Self {
        let still_std = gyro.counts_of_mrad_per_s(STILL_GYRO_STD_MRADPS) as u64;
        FootFrameEstimator {
            accel,
            axis_min: rate.samples_in_ms(AXIS_MIN_MOVEMENT_MS),
            axis_max: rate.samples_in_ms(AXIS_MAX_MOVEMENT_MS),
            first_after: rate.samples_in_ms(FIRST_FRAME_AFTER_MS),
            block_len: rate.samples_in_ms(STILL_BLOCK_MS),
            still_variance: still_std * still_std,
            frame: None,
            still: None,
            block: RestSums::new(),
            block_half: [0; 3],
            up: [0.0; 3],
            gravity_counts: 0.0,
            left_sum: [0.0; 3],
            pitch_sum: [0.0; 3],
            heading_known: false,
            was_rest: false,
            rest: RestSums::new(),
            gyro_bias: [0; 3],
            cov: [0; 6],
            sum_w: [0; 3],
            moment: [0; 3],
            move_n: 0,
            gapped: false,
            chunked: false,
        }
    }

    /// The current frame; `None` until the first rest period has ended.
    pub const fn frame(&self) -> Option<FootFrame> {
        self.frame
    }

    /// Gyroscope bias and gravity magnitude, counts, from the latest still block of a rest
    /// ([`STILL_BLOCK_MS`], [`STILL_GYRO_STD_MRADPS`]; until there is one, the steadiest so
    /// far): standing still, not a walking stance. `None` before the first block or rest.
    pub const fn still_calibration(&self) -> Option<([i32; 3], i32)> {
        match self.still {
            Some(s) => Some((s.gyro_bias, s.gravity_counts)),
            None => None,
        }
    }

    /// Whether gravity kept its direction over the block `b` (its halves within
    /// [`STILL_TILT_MRADPS`] × half the block).
    fn block_level(&self, b: &RestSums) -> bool {
        let first = Vector3::from(self.block_half.map(|v| v as f32));
        let second = Vector3::from([0, 1, 2].map(|k| (b.accel[k] - self.block_half[k]) as f32));
        let (n1, n2) = (first.norm(), second.norm());
        if n1 <= 0.0 || n2 <= 0.0 {
            return false;
        }
        let sin = first.cross(&second).norm() / (n1 * n2);
        let max = STILL_TILT_MRADPS as f32 * 1e-3 * STILL_BLOCK_MS as f32 * 0.5e-3;
        sin <= max
    }

    /// Offers the block for calibration and starts the next.
    fn end_block(&mut self) {
        let b = core::mem::replace(&mut self.block, RestSums::new());
        if b.count == 0 {
            return;
        }
        let variance = b.gyro_variance();
        let qualified =
            b.count >= self.block_len && variance <= self.still_variance && self.block_level(&b);
        let n = b.count as i64;
        let mean = |v: i64| (v + n / 2).div_euclid(n);
        let a = b.accel.map(|v| mean(v) as f32);
        let g = libm_round(Vector3::from(a).norm());
        if g <= 0 {
            return;
        }
        let new = StillBlock {
            gyro_bias: b.gyro.map(|v| mean(v) as i32),
            gravity_counts: g,
            gyro_variance: variance,
            qualified,
        };
        self.still = match self.still {
            None => Some(new),
            // Until a still block comes, the steadiest whole block (a rest shorter than a
            // block serves only as the first calibration).
            Some(s) if !s.qualified => {
                let steadier = b.count >= self.block_len && variance < s.gyro_variance;
                Some(if qualified || steadier { new } else { s })
            }
            // Still blocks are averaged in slowly: the bias drifts with temperature over
            // minutes, while one block can hold a slow turn about gravity that neither
            // the spread nor the tilt shows (a foot pivoting on the spot).
            Some(s) if qualified => Some(StillBlock {
                gyro_bias: [0, 1, 2].map(|k| blend(s.gyro_bias[k], new.gyro_bias[k])),
                gravity_counts: blend(s.gravity_counts, new.gravity_counts),
                ..s
            }),
            keep => keep,
        };
    }

    /// Gyroscope bias, counts: the mean angular rate of the last rest period (zero before
    /// the first). The movement axis is learnt from the rates minus this bias.
    pub const fn gyro_bias(&self) -> [i32; 3] {
        self.gyro_bias
    }

    /// Feeds one raw sample and the rest decision about it.
    pub fn process(&mut self, s: &RawSample, rest: bool) {
        match (self.was_rest, rest) {
            (false, true) => {
                self.end_movement();
                self.rest = RestSums::new();
                self.accumulate_rest(s);
            }
            (true, true) => self.accumulate_rest(s),
            (true, false) => {
                self.end_block();
                self.end_rest();
                self.cov = [0; 6];
                self.sum_w = [0; 3];
                self.moment = [0; 3];
                self.move_n = 0;
                self.gapped = false;
                self.chunked = false;
                self.accumulate_movement(s);
            }
            (false, false) => self.accumulate_movement(s),
        }
        self.was_rest = rest;
    }

    /// Samples were lost. A movement in progress has a hole, so its axis and the sign of its
    /// first moment mean nothing: it is not learnt from (marked full, as a movement too long
    /// to learn from is). A rest in progress goes on: its samples are gravity either side.
    pub fn gap(&mut self) {
        if !self.was_rest {
            self.gapped = true;
        }
    }

    fn accumulate_rest(&mut self, s: &RawSample) {
        self.rest.add(s);
        self.block.add(s);
        if self.block.count == self.block_len / 2 {
            self.block_half = self.block.accel;
        }
        if self.block.count >= self.block_len {
            self.end_block();
        }
        if self.frame.is_none() && self.rest.count == self.first_after {
            self.end_rest();
        }
    }

    fn accumulate_movement(&mut self, s: &RawSample) {
        if self.move_n >= self.axis_max {
            // A movement with no rest in it for this long (running, pedalling) teaches the
            // steps' rotation axis (not the heading: a chunk of a run has no first step to
            // tell the sign by), and the next chunk starts.
            if !self.gapped {
                self.learn_pitch_axis();
            }
            self.cov = [0; 6];
            self.sum_w = [0; 3];
            self.moment = [0; 3];
            self.move_n = 0;
            self.gapped = false;
            self.chunked = true;
        }
        let w = [0, 1, 2].map(|i| s.gyro[i] as i64 - self.gyro_bias[i] as i64);
        // |w| < 2¹⁷, products < 2³⁴, sums over ≤ 25 000 samples < 2⁴⁹.
        let products = [
            w[0] * w[0],
            w[1] * w[1],
            w[2] * w[2],
            w[0] * w[1],
            w[0] * w[2],
            w[1] * w[2],
        ];
        for (c, p) in self.cov.iter_mut().zip(products) {
            *c += p;
        }
        let k = self.move_n as i64;
        for ((s, m), &w) in self
            .sum_w
            .iter_mut()
            .zip(self.moment.iter_mut())
            .zip(w.iter())
        {
            *s += w;
            *m += w * k;
        }
        self.move_n += 1;
    }

    fn end_rest(&mut self) {
        if self.rest.count == 0 {
            return;
        }
        let n = self.rest.count as f32;
        let mean = self.rest.accel.map(|v| v as f32 / n);
        self.gyro_bias = [0, 1, 2].map(|i| {
            let n = self.rest.count as i64;
            ((self.rest.gyro[i] + n / 2).div_euclid(n)) as i32
        });
        let m = Vector3::from(mean);
        let g = m.norm();
        if g.is_nan() || g <= 0.0 {
            return;
        }
        let u = m / g;
        let up = Vector3::from(self.up);
        if self.frame.is_none() || u.dot(&up) < COS_REMOUNT {
            self.up = u.into();
            self.gravity_counts = g;
            self.left_sum = [0.0; 3];
            self.pitch_sum = [0.0; 3];
            self.heading_known = false;
        } else {
            let blended = up * (1.0 - UP_SMOOTHING) + u * UP_SMOOTHING;
            self.up = blended.normalize().into();
            self.gravity_counts = self.gravity_counts * (1.0 - UP_SMOOTHING) + g * UP_SMOOTHING;
        }
        self.rebuild();
    }

    /// The principal rotation axis of the movement's rates so far (sensor axes, unit, any
    /// sign), if it is mostly horizontal (a step's pitch, not a turn on the spot).
    fn movement_axis(&self) -> Option<Vector3<f32>> {
        let c = self.cov.map(|v| v as f32);
        let cov = Matrix3::new(c[0], c[3], c[4], c[3], c[1], c[5], c[4], c[5], c[2]);
        let eig = SymmetricEigen::new(cov);
        let mut best = 0;
        for i in 1..3 {
            if eig.eigenvalues[i] > eig.eigenvalues[best] {
                best = i;
            }
        }
        let axis: Vector3<f32> = eig.eigenvectors.column(best).into();
        let up = Vector3::from(self.up);
        let horizontal = axis - up * axis.dot(&up);
        // A rotation mostly about the vertical is a turn on the spot, not a step.
        (horizontal.norm() >= 0.7).then_some(axis)
    }

    /// Adds `axis` (any sign) to the smoothed pitch axis.
    fn add_pitch(&mut self, axis: Vector3<f32>) {
        let pitch = Vector3::from(self.pitch_sum);
        let along = if axis.dot(&pitch) < 0.0 { -1.0 } else { 1.0 };
        self.pitch_sum = (pitch * AXIS_MEMORY + axis * along).into();
    }

    /// A chunk of a movement without rest ([`AXIS_MAX_MOVEMENT_MS`] of running or pedalling):
    /// its rotation axis is the steps' pitch axis; the heading is not learnt from it.
    fn learn_pitch_axis(&mut self) {
        if self.frame.is_none() {
            return;
        }
        if let Some(axis) = self.movement_axis() {
            self.add_pitch(axis);
            self.rebuild();
        }
    }

    fn end_movement(&mut self) {
        if self.frame.is_none() || self.move_n < self.axis_min || self.gapped || self.chunked {
            return;
        }
        let Some(axis) = self.movement_axis() else {
            return;
        };
        let up = Vector3::from(self.up);
        let horizontal = axis - up * axis.dot(&up);
        let n = self.move_n as f32;
        let centred =
            [0, 1, 2].map(|i| self.moment[i] as f32 - self.sum_w[i] as f32 * (n - 1.0) * 0.5);
        let sign = if horizontal.dot(&Vector3::from(centred)) < 0.0 {
            1.0
        } else {
            -1.0
        };
        let left = horizontal.normalize() * sign;
        let sum = Vector3::from(self.left_sum) * AXIS_MEMORY + left;
        self.left_sum = sum.into();
        self.add_pitch(axis);
        self.heading_known = true;
        self.rebuild();
    }

    fn rebuild(&mut self) {
        let up = Vector3::from(self.up);
        let mut left = Vector3::from(self.left_sum);
        left -= up * left.dot(&up);
        if left.norm() < 1e-3 {
            // No heading yet: any horizontal axis, from the sensor axis least aligned with up.
            let mut k = 0;
            for i in 1..3 {
                if self.up[i].abs() < self.up[k].abs() {
                    k = i;
                }
            }
            let mut e = Vector3::zeros();
            e[k] = 1.0;
            left = e - up * e.dot(&up);
        }
        let left = left.normalize();
        let forward = left.cross(&up);
        let scale = (1u32 << 14) as f32 * FOOT_LSB_PER_G as f32 / self.accel.lsb_per_g() as f32;
        let row = |v: Vector3<f32>| [0, 1, 2].map(|i| libm_round(v[i] * scale));
        let gravity =
            libm_round(self.gravity_counts * FOOT_LSB_PER_G as f32 / self.accel.lsb_per_g() as f32);
        let pitch = Vector3::from(self.pitch_sum);
        let pitch = (pitch.norm() > 1e-3).then(|| {
            let unit = pitch.normalize();
            [0, 1, 2].map(|i| libm_round(unit[i] * (1u32 << 14) as f32))
        });
        self.frame = Some(FootFrame {
            rows: [row(forward), row(left), row(up)],
            gravity,
            heading_known: self.heading_known,
            pitch,
            level_axes_q14: {
                // The pitch axis where it is known (a run teaches it before the heading),
                // else the left axis.
                let p = Vector3::from(self.pitch_sum);
                let p = p - up * p.dot(&up);
                let pitch_level = if p.norm() > 1e-3 { p.normalize() } else { left };
                let across = pitch_level.cross(&up);
                let q14 =
                    |v: Vector3<f32>| [0, 1, 2].map(|i| libm_round(v[i] * (1u32 << 14) as f32));
                [q14(pitch_level), q14(across)]
            },
        });
    }
}

/// Round to nearest, for values well inside `i32` (matrix entries and gravity).
/// One still block's weight in the calibration, 1/2^[`STILL_BLEND_SHIFT`]: the bias settles
/// over ≈ 8 blocks (2 s of standing) and one pivot moves it by an eighth.
const STILL_BLEND_SHIFT: u32 = 3;

/// `old + (new − old) / 2^STILL_BLEND_SHIFT`, rounded to nearest.
fn blend(old: i32, new: i32) -> i32 {
    let d = new as i64 - old as i64;
    let half = 1i64 << (STILL_BLEND_SHIFT - 1);
    (old as i64 + ((d + half) >> STILL_BLEND_SHIFT)) as i32
}

fn libm_round(v: f32) -> i32 {
    if v >= 0.0 {
        (v + 0.5) as i32
    } else {
        (v - 0.5) as i32
    }
}

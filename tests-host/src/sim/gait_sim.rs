//! Gait simulator: foot trajectories → what an MPU6050 clipped to the shoe would read.
//!
//! Each stride is a stance (foot flat, at rest) followed by a movement from heel-off to the
//! next foot-flat. Over the movement, with τ ∈ [0, 1] its normalised time:
//!
//! - horizontal position follows the minimum-jerk profile `L·(10τ³ − 15τ⁴ + 6τ⁵)` along the
//!   heading (zero velocity and acceleration at both ends, as a foot leaving and landing);
//! - foot clearance is `H·sin⁴(πτ)`;
//! - pitch is `−P·sin(2πτ)·sin²(πτ)`: toe down after push-off, toe up before heel strike;
//! - heading turns by the stride's turn angle with the same minimum-jerk profile;
//! - the heel-strike impact is a damped 35 Hz oscillation of `IMPACT_G` g along the foot's
//!   vertical axis starting at heel-strike.
//!
//! Gait events are defined on τ: toe-off at [`TOE_OFF_TAU`], heel-strike at
//! [`HEEL_STRIKE_TAU`]; foot-flat is τ = 1. The ground-truth stride length is `L`.
//!
//! The foot frame is x forward, y left, z up. The sensor sits at the foot origin, rotated by
//! the scenario's mounting rotation. Specific force `f = a − g` and body rate are computed by
//! central differences (h = 10 µs) of the analytic trajectory, rotated into the sensor frame,
//! given white noise and a constant bias per axis (seeded ChaCha8), and quantised to counts
//! with saturation as the sensor would.

use std::f64::consts::PI;

use gaitclip::sensor::sample::RawSample;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;

use crate::io::trace::{ImuSample, Ranges, G_MPS2};

/// τ of toe-off within the movement.
pub const TOE_OFF_TAU: f64 = 0.15;
/// τ of heel-strike within the movement.
pub const HEEL_STRIKE_TAU: f64 = 0.88;
/// Peak of the heel-strike impact, g.
pub const IMPACT_G: f64 = 3.0;
/// Foot clearance, m.
pub const CLEARANCE_M: f64 = 0.12;
/// Peak pitch, rad (≈ 40°).
pub const PITCH_RAD: f64 = 0.7;
/// Accelerometer white noise, m/s² per sample (MPU6050: 400 µg/√Hz over ~100 Hz).
pub const ACC_NOISE_MPS2: f64 = 0.04;
/// Gyro white noise, rad/s per sample (0.005 °/s/√Hz over ~100 Hz ≈ 0.05 °/s, doubled).
pub const GYR_NOISE_RADPS: f64 = 0.002;
/// Largest accelerometer bias, m/s² (uniform in ±).
pub const ACC_BIAS_MAX_MPS2: f64 = 0.1;
/// Largest gyro bias, rad/s (uniform in ±; 1 °/s).
pub const GYR_BIAS_MAX_RADPS: f64 = 0.017;

/// How hard the foot moves over a movement: a walk's figures, or a sprint's. Every term is a
/// displacement or an attitude of the foot (the dip, the snap), so the specific force and
/// body rate that the central differences take from them integrate back to the stride
/// itself; only the walk's heel-strike oscillation ([`IMPACT_G`]) is added to the
/// acceleration alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vigour {
    /// Peak of the heel-strike oscillation added to the acceleration, g.
    pub impact_g: f64,
    /// Foot clearance, m.
    pub clearance_m: f64,
    /// Peak pitch, rad.
    pub pitch_rad: f64,
    /// Touch-down: the foot's origin dips by this much and comes back, m, as
    /// `−d·sin⁴(πu/D)` over [`Vigour::dip_s`] from heel-strike: a specific force of
    /// `4·d·(π/D)²` upward at its middle.
    pub dip_m: f64,
    /// The dip's duration `D`, s.
    pub dip_s: f64,
    /// Toe-off: the foot plantar-flexes by this much more and comes back, rad, as
    /// `−A·sin²(πu/S)` over [`Vigour::snap_s`] from toe-off: a pitch rate of `±A·π/S`.
    pub snap_rad: f64,
    /// The snap's duration `S`, s.
    pub snap_s: f64,
}

impl Vigour {
    /// A walk: the figures the committed fixtures were made with.
    pub const WALK: Vigour = Vigour {
        impact_g: IMPACT_G,
        clearance_m: CLEARANCE_M,
        pitch_rad: PITCH_RAD,
        dip_m: 0.0,
        dip_s: 0.0,
        snap_rad: 0.0,
        snap_s: 0.0,
    };
}

/// One piece of a scenario.
#[derive(Clone, Debug, Serialize)]
pub enum Segment {
    /// Stand still for this many seconds.
    Stand(f64),
    /// Strides of the same kind.
    Walk {
        /// Number of strides.
        strides: u32,
        /// Length of each, m.
        length_m: f64,
        /// Stance duration, s.
        stance_s: f64,
        /// Movement (heel-off to foot-flat) duration, s.
        movement_s: f64,
        /// Heading change over each stride, degrees (left positive).
        turn_deg: f64,
        /// Flag written to the ground truth (`""`, `"turn"`, `"last"` …).
        flag: &'static str,
    },
}

/// A scenario: what the walker does and how the clip is mounted.
#[derive(Clone, Debug, Serialize)]
pub struct Scenario {
    /// Name, also the fixture's file stem.
    pub name: &'static str,
    /// What it exercises.
    pub description: &'static str,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Mounting as roll, pitch, yaw (degrees, applied z·y·x): sensor → foot.
    pub mounting_deg: [f64; 3],
    /// RNG seed for noise and biases.
    pub seed: u64,
    /// The walk.
    pub segments: Vec<Segment>,
    /// How hard the foot moves (not written to the fixtures' descriptions).
    #[serde(skip)]
    pub vigour: Vigour,
}

/// Ground truth of one stride, indices into the generated samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthStride {
    /// Stride number.
    pub stride: u32,
    /// Foot-flat starting the stride (start of its stance).
    pub start_idx: u32,
    /// Heel-off.
    pub heel_off_idx: u32,
    /// Toe-off.
    pub toe_off_idx: u32,
    /// Heel-strike.
    pub heel_strike_idx: u32,
    /// Foot-flat ending the stride.
    pub end_idx: u32,
    /// Horizontal distance, m.
    pub length_m: f64,
    /// Heading change, degrees.
    pub turn_deg: f64,
    /// `""` for a clean straight stride, else why not.
    pub flag: &'static str,
}

/// The simulator's output.
#[derive(Clone, Debug)]
pub struct Simulated {
    /// Samples in physical units (after noise, bias and quantisation).
    pub samples: Vec<ImuSample>,
    /// The same samples as sensor counts.
    pub counts: Vec<RawSample>,
    /// Ground truth.
    pub truth: Vec<TruthStride>,
}

/// One planned movement in absolute time.
struct Movement {
    t0: f64,
    dur: f64,
    from: [f64; 2],
    length: f64,
    heading0: f64,
    turn: f64,
}

impl Movement {
    fn tau(&self, t: f64) -> f64 {
        ((t - self.t0) / self.dur).clamp(0.0, 1.0)
    }
}

fn min_jerk(tau: f64) -> f64 {
    tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
}

/// Foot pose at time `t`: position (m) and Euler (pitch, yaw) in rad; roll is zero.
fn pose(moves: &[Movement], rest: ([f64; 2], f64), v: &Vigour, t: f64) -> ([f64; 3], f64, f64) {
    // The last movement that started at or before t (movements are sorted by time).
    let m = moves.iter().take_while(|m| m.t0 <= t).last();
    let Some(m) = m else {
        return ([rest.0[0], rest.0[1], 0.0], 0.0, rest.1);
    };
    let tau = m.tau(t);
    let s = min_jerk(tau);
    let dir = m.heading0 + m.turn * 0.5; // straight chord between the two stances
    let x = m.from[0] + m.length * s * dir.cos();
    let y = m.from[1] + m.length * s * dir.sin();
    let sp = (PI * tau).sin();
    let mut z = v.clearance_m * sp.powi(4) * if m.length > 0.3 { 1.0 } else { m.length / 0.3 };
    let mut pitch = -v.pitch_rad * (2.0 * PI * tau).sin() * sp * sp * (m.length / 1.4).min(1.2);
    let within = |from_tau: f64, dur: f64| {
        let u = (t - (m.t0 + from_tau * m.dur)) / dur;
        (dur > 0.0 && (0.0..=1.0).contains(&u)).then_some(u)
    };
    if let Some(u) = within(HEEL_STRIKE_TAU, v.dip_s) {
        z -= v.dip_m * (PI * u).sin().powi(4);
    }
    if let Some(u) = within(TOE_OFF_TAU, v.snap_s) {
        pitch -= v.snap_rad * (PI * u).sin().powi(2);
    }
    let yaw = m.heading0 + m.turn * s;
    ([x, y, z], pitch, yaw)
}

type Mat = [[f64; 3]; 3];

fn rot_x(a: f64) -> Mat {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}
fn rot_y(a: f64) -> Mat {
    let (s, c) = a.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
fn rot_z(a: f64) -> Mat {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}
fn mat_mul(a: &Mat, b: &Mat) -> Mat {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}
fn transpose(a: &Mat) -> Mat {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[j][i];
        }
    }
    r
}
fn mat_vec(a: &Mat, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// Rotation matrix for roll, pitch, yaw in degrees, `Rz(yaw)·Ry(pitch)·Rx(roll)`.
pub fn rotation_from_deg(rpy: [f64; 3]) -> Mat {
    let r = rpy.map(f64::to_radians);
    mat_mul(&rot_z(r[2]), &mat_mul(&rot_y(r[1]), &rot_x(r[0])))
}

/// A scenario's foot and sensor in continuous time: what the sensor feels at any instant,
/// before it is sampled and quantised.
pub struct Trajectory {
    moves: Vec<Movement>,
    /// (stance start time, movement index, flag, turn °) per stride.
    plan: Vec<(f64, usize, &'static str, f64)>,
    vigour: Vigour,
    /// Sensor → foot.
    mount_t: Mat,
    acc_bias: [f64; 3],
    gyr_bias: [f64; 3],
    acc_noise: Normal<f64>,
    gyr_noise: Normal<f64>,
    /// The scenario's length, s.
    pub duration_s: f64,
}

impl Trajectory {
    /// Plans `sc`'s movements and draws the sensor's biases from `rng`.
    pub fn new(sc: &Scenario, rng: &mut ChaCha8Rng) -> Trajectory {
        let mut moves = Vec::new();
        let mut plan = Vec::new();
        let (mut t, mut pos, mut heading) = (0.0f64, [0.0f64; 2], 0.0f64);
        let mut last_stance_start = 0.0;
        for seg in &sc.segments {
            match *seg {
                Segment::Stand(d) => t += d,
                Segment::Walk {
                    strides,
                    length_m,
                    stance_s,
                    movement_s,
                    turn_deg,
                    flag,
                } => {
                    for _ in 0..strides {
                        t += stance_s;
                        let turn = turn_deg.to_radians();
                        let m = Movement {
                            t0: t,
                            dur: movement_s,
                            from: pos,
                            length: length_m,
                            heading0: heading,
                            turn,
                        };
                        let dir = heading + turn * 0.5;
                        pos = [pos[0] + length_m * dir.cos(), pos[1] + length_m * dir.sin()];
                        heading += turn;
                        plan.push((last_stance_start, moves.len(), flag, turn_deg));
                        moves.push(m);
                        t += movement_s;
                        last_stance_start = t;
                    }
                }
            }
        }
        let acc_bias: [f64; 3] =
            [0; 3].map(|_| rng.random_range(-ACC_BIAS_MAX_MPS2..ACC_BIAS_MAX_MPS2));
        let gyr_bias: [f64; 3] =
            [0; 3].map(|_| rng.random_range(-GYR_BIAS_MAX_RADPS..GYR_BIAS_MAX_RADPS));
        Trajectory {
            moves,
            plan,
            vigour: sc.vigour,
            mount_t: transpose(&rotation_from_deg(sc.mounting_deg)),
            acc_bias,
            gyr_bias,
            acc_noise: Normal::new(0.0, ACC_NOISE_MPS2).expect("valid sigma"),
            gyr_noise: Normal::new(0.0, GYR_NOISE_RADPS).expect("valid sigma"),
            duration_s: t,
        }
    }

    fn pose(&self, t: f64) -> ([f64; 3], f64, f64) {
        pose(&self.moves, ([0.0, 0.0], 0.0), &self.vigour, t)
    }

    /// Foot → nav.
    fn foot_rot(&self, t: f64) -> Mat {
        let (_, pitch, yaw) = self.pose(t);
        mat_mul(&rot_z(yaw), &rot_y(pitch))
    }

    /// What the sensor feels at `t` (specific force, m/s², and body rate, rad/s, in its own
    /// frame), without bias or noise.
    pub fn exact(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        let h = 1e-5;
        let p = |t| self.pose(t).0;
        let (pm, p0, pp) = (p(t - h), p(t), p(t + h));
        let mut acc_n = [0, 1, 2].map(|k| (pp[k] - 2.0 * p0[k] + pm[k]) / (h * h));
        // Heel-strike impact along the foot's vertical.
        let r_nf = self.foot_rot(t);
        for m in &self.moves {
            let t_hs = m.t0 + HEEL_STRIKE_TAU * m.dur;
            let u = t - t_hs;
            if (0.0..0.08).contains(&u) && m.length > 0.3 {
                let a = self.vigour.impact_g
                    * G_MPS2
                    * (-u / 0.012).exp()
                    * (2.0 * PI * 35.0 * u).sin();
                let v = mat_vec(&r_nf, [0.0, 0.0, a]);
                for k in 0..3 {
                    acc_n[k] += v[k];
                }
            }
        }
        acc_n[2] += G_MPS2; // specific force: the ground pushes up at rest
                            // Body rate from the rotation's derivative: [ω]× = Rᵀ·dR/dt.
        let (rm, rp) = (self.foot_rot(t - h), self.foot_rot(t + h));
        let mut dr = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                dr[a][b] = (rp[a][b] - rm[a][b]) / (2.0 * h);
            }
        }
        let w = mat_mul(&transpose(&r_nf), &dr);
        let omega_f = [w[2][1], w[0][2], w[1][0]];
        let r_sn = mat_mul(&self.mount_t, &transpose(&r_nf)); // nav → sensor
        (mat_vec(&r_sn, acc_n), mat_vec(&self.mount_t, omega_f))
    }

    /// What the sensor reads at `t` before quantisation: [`Trajectory::exact`] with its
    /// biases and white noise drawn from `rng`.
    pub fn sample(&self, t: f64, rng: &mut ChaCha8Rng) -> ImuSample {
        let (f_s, w_s) = self.exact(t);
        ImuSample {
            t_s: t,
            acc_mps2: [0, 1, 2].map(|k| f_s[k] + self.acc_bias[k] + self.acc_noise.sample(rng)),
            gyr_radps: [0, 1, 2].map(|k| w_s[k] + self.gyr_bias[k] + self.gyr_noise.sample(rng)),
        }
    }

    /// The ground truth, the events as sample indices at `rate_hz`.
    pub fn truth(&self, rate_hz: f64) -> Vec<TruthStride> {
        let idx = |t: f64| (t * rate_hz).round() as u32;
        self.plan
            .iter()
            .enumerate()
            .map(|(k, &(stance_start, mi, flag, turn_deg))| {
                let m = &self.moves[mi];
                TruthStride {
                    stride: k as u32,
                    start_idx: idx(stance_start),
                    heel_off_idx: idx(m.t0),
                    toe_off_idx: idx(m.t0 + TOE_OFF_TAU * m.dur),
                    heel_strike_idx: idx(m.t0 + HEEL_STRIKE_TAU * m.dur),
                    end_idx: idx(m.t0 + m.dur),
                    length_m: m.length,
                    turn_deg,
                    flag,
                }
            })
            .collect()
    }
}

/// Runs a scenario.
pub fn simulate(sc: &Scenario, ranges: Ranges) -> Simulated {
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let tr = Trajectory::new(sc, &mut rng);
    let n = (tr.duration_s * sc.rate_hz).floor() as usize + 1;
    let mut samples = Vec::with_capacity(n);
    let mut counts = Vec::with_capacity(n);
    let dt = 1.0 / sc.rate_hz;
    for i in 0..n {
        let t = i as f64 * dt;
        let phys = tr.sample(t, &mut rng);
        let c = ranges.to_counts(&phys);
        // What the file holds is what the sensor reported: the quantised value.
        let q = ranges.to_physical(round6(t), &c);
        samples.push(ImuSample {
            t_s: q.t_s,
            acc_mps2: q.acc_mps2.map(round6),
            gyr_radps: q.gyr_radps.map(round6),
        });
        counts.push(c);
    }
    Simulated {
        samples,
        counts,
        truth: tr.truth(sc.rate_hz),
    }
}

/// Rounds to 6 decimals: the files carry 1e−6 m/s² and rad/s, far below one count
/// (4.8e−3 m/s², 1.1e−3 rad/s at the default ranges), so counts survive the round trip.
fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

fn walk(strides: u32, length_m: f64, stride_s: f64, turn_deg: f64, flag: &'static str) -> Segment {
    // Stance takes 40 % of a walking stride.
    Segment::Walk {
        strides,
        length_m,
        stance_s: stride_s * 0.4,
        movement_s: stride_s * 0.6,
        turn_deg,
        flag,
    }
}

/// The scenarios committed under `fixtures/`.
pub fn scenarios() -> Vec<Scenario> {
    vec![
        Scenario {
            name: "demo_walk",
            description: "200 Hz, clip on the outside of the right shoe: stand, walk at three speeds with a 180° turn over two strides, stand mid-walk, a final half-stride, stand",
            rate_hz: 200.0,
            mounting_deg: [85.0, -15.0, 100.0],
            seed: 1,
            vigour: Vigour::WALK,
            segments: vec![
                Segment::Stand(2.0),
                walk(1, 0.8, 1.2, 0.0, "first"),
                walk(7, 1.35, 1.1, 0.0, ""),
                walk(2, 0.7, 1.3, 90.0, "turn"),
                walk(6, 1.55, 1.0, 0.0, ""),
                Segment::Stand(1.5),
                walk(1, 0.8, 1.2, 0.0, "first"),
                walk(5, 1.0, 1.3, 0.0, ""),
                walk(1, 0.65, 1.0, 0.0, "last"),
                Segment::Stand(2.0),
            ],
        },
        Scenario {
            name: "upside_down_100hz",
            description: "100 Hz, clip mounted upside down under the laces: walk, turn on the spot, walk back",
            rate_hz: 100.0,
            mounting_deg: [180.0, 10.0, -30.0],
            seed: 2,
            vigour: Vigour::WALK,
            segments: vec![
                Segment::Stand(1.5),
                walk(1, 0.75, 1.2, 0.0, "first"),
                walk(6, 1.3, 1.1, 0.0, ""),
                walk(3, 0.1, 0.9, 60.0, "turn"),
                walk(6, 1.2, 1.15, 0.0, ""),
                walk(1, 0.6, 1.0, 0.0, "last"),
                Segment::Stand(1.5),
            ],
        },
        Scenario {
            name: "fast_500hz",
            description: "500 Hz, clip on the heel counter: brisk walk with a gentle curve",
            rate_hz: 500.0,
            mounting_deg: [-90.0, 0.0, 180.0],
            seed: 3,
            vigour: Vigour::WALK,
            segments: vec![
                Segment::Stand(1.0),
                walk(1, 0.9, 1.0, 0.0, "first"),
                walk(4, 1.6, 0.95, 10.0, ""),
                walk(1, 0.7, 0.9, 0.0, "last"),
                Segment::Stand(1.0),
            ],
        },
    ]
}

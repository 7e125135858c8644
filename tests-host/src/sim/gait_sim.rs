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
fn pose(moves: &[Movement], rest: ([f64; 2], f64), t: f64) -> ([f64; 3], f64, f64) {
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
    let z = CLEARANCE_M * sp.powi(4) * if m.length > 0.3 { 1.0 } else { m.length / 0.3 };
    let pitch = -PITCH_RAD * (2.0 * PI * tau).sin() * sp * sp * (m.length / 1.4).min(1.2);
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

/// Runs a scenario.
pub fn simulate(sc: &Scenario, ranges: Ranges) -> Simulated {
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let dt = 1.0 / sc.rate_hz;
    // Plan the movements.
    let mut moves = Vec::new();
    let mut plan = Vec::new(); // (stance start time, movement index, flag)
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
    let total = t;
    let n = (total * sc.rate_hz).floor() as usize + 1;
    let mount = rotation_from_deg(sc.mounting_deg); // sensor → foot
    let mount_t = transpose(&mount);
    let acc_noise = Normal::new(0.0, ACC_NOISE_MPS2).expect("valid sigma");
    let gyr_noise = Normal::new(0.0, GYR_NOISE_RADPS).expect("valid sigma");
    let acc_bias: [f64; 3] =
        [0; 3].map(|_| rng.random_range(-ACC_BIAS_MAX_MPS2..ACC_BIAS_MAX_MPS2));
    let gyr_bias: [f64; 3] =
        [0; 3].map(|_| rng.random_range(-GYR_BIAS_MAX_RADPS..GYR_BIAS_MAX_RADPS));
    let rest = ([0.0, 0.0], 0.0);
    let foot_rot = |t: f64| {
        let (_, pitch, yaw) = pose(&moves, rest, t);
        mat_mul(&rot_z(yaw), &rot_y(pitch)) // foot → nav
    };
    let h = 1e-5;
    let mut samples = Vec::with_capacity(n);
    let mut counts = Vec::with_capacity(n);
    for i in 0..n {
        let t = i as f64 * dt;
        let p = |t| pose(&moves, rest, t).0;
        let (pm, p0, pp) = (p(t - h), p(t), p(t + h));
        let mut acc_n = [0, 1, 2].map(|k| (pp[k] - 2.0 * p0[k] + pm[k]) / (h * h));
        // Heel-strike impact along the foot's vertical.
        let r_nf = foot_rot(t);
        for m in &moves {
            let t_hs = m.t0 + HEEL_STRIKE_TAU * m.dur;
            let u = t - t_hs;
            if (0.0..0.08).contains(&u) && m.length > 0.3 {
                let a = IMPACT_G * G_MPS2 * (-u / 0.012).exp() * (2.0 * PI * 35.0 * u).sin();
                let v = mat_vec(&r_nf, [0.0, 0.0, a]);
                for k in 0..3 {
                    acc_n[k] += v[k];
                }
            }
        }
        acc_n[2] += G_MPS2; // specific force: the ground pushes up at rest
                            // Body rate from the rotation's derivative: [ω]× = Rᵀ·dR/dt.
        let (rm, rp) = (foot_rot(t - h), foot_rot(t + h));
        let mut dr = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                dr[a][b] = (rp[a][b] - rm[a][b]) / (2.0 * h);
            }
        }
        let w = mat_mul(&transpose(&r_nf), &dr);
        let omega_f = [w[2][1], w[0][2], w[1][0]];
        let r_sn = mat_mul(&mount_t, &transpose(&r_nf)); // nav → sensor
        let f_s = mat_vec(&r_sn, acc_n);
        let w_s = mat_vec(&mount_t, omega_f);
        let phys = ImuSample {
            t_s: t,
            acc_mps2: [0, 1, 2].map(|k| f_s[k] + acc_bias[k] + acc_noise.sample(&mut rng)),
            gyr_radps: [0, 1, 2].map(|k| w_s[k] + gyr_bias[k] + gyr_noise.sample(&mut rng)),
        };
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
    let idx = |t: f64| (t * sc.rate_hz).round() as u32;
    let truth = plan
        .iter()
        .enumerate()
        .map(|(k, &(stance_start, mi, flag, turn_deg))| {
            let m = &moves[mi];
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
        .collect();
    Simulated {
        samples,
        counts,
        truth,
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

//! `gaitclip sprint`: what a sensor's range buys, on a simulated sprint whose true peaks
//! pass both of the MPU6050's rails.
//!
//! A sprint stride cannot be measured unclipped on the MPU6050, and no shared recording has
//! a sprint unclipped (`esangeni_course`'s VN-200 sits at ±16 g and ±2 000 °/s in every
//! sprint stride). So the sprint is simulated ([`crate::sim::gait_sim`]) with peaks from the
//! literature: touch-down at 40 g and at 70 g (a sprinting foot meets the ground at up to
//! 70 g, Bailey & Harle 2014), and a toe-off pitch rate beyond 2 000 °/s. Every term of the
//! sprint's motion is a displacement or an attitude of the foot (touch-down is a dip of the
//! foot's origin, toe-off a plantar-flexion snap: [`Vigour`]), so what the sensor feels
//! integrates back to the stride's true length, and the only errors left are the sensor's
//! and the core's.
//!
//! The same motion, with the same biases and noise (the MPU6050's figures), is then
//! recorded as each part would record it, and replayed through the core as the firmware runs
//! it:
//!
//! - the **MPU6050** at 200 Hz, ±16 g and ±2 000 °/s: both saturate; the core puts back what
//!   the accelerometer's rail took (its default) and, as a control, leaves it in;
//! - the **LSM6DSV320X**'s low-g accelerometer alone at 240 Hz (±16 g, the same rail) with
//!   its ±4 000 °/s gyroscope: what the gyroscope's range alone buys;
//! - the **LSM6DSV320X** as the firmware reads it: its FIFO's words (low-g and gyroscope at
//!   240 Hz, the high-g channel at ±128 g and 960 Hz) through
//!   [`gaitclip_lsm6dsv320x::merge::Assembler`], which takes each axis at the low-g rail
//!   from the mean of the high-g samples of its period.

use std::path::Path;

use anyhow::{bail, Result};
use gaitclip::pipeline::config::Config;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::{Rails, RawSample};
use gaitclip::sensor::units::{AccelScale, GyroScale};
use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag};
use gaitclip_lsm6dsv320x::merge::{Assembler, DualRange};
use gaitclip_lsm6dsv320x::{AccelRange as StAccel, GyroRange as StGyro, HighGRange};
use gaitclip_mpu6050::{AccelRange, GyroRange};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::eval::markdown::{cm_cell, Column, ErrorStats, Table};
use crate::io::trace::{quantize, G_MPS2};
use crate::replay::core_strides;
use crate::sim::gait_sim::{Scenario, Trajectory};
use crate::sim::sprint::lsm_fifo;
pub use crate::sim::sprint::{
    scenarios, sprint_vigour, SPRINT_LENGTH_M, SPRINT_MOVEMENT_S, SPRINT_STANCE_S,
};

/// How a part records the motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recording {
    /// MPU6050, ±16 g, ±2 000 °/s; `restore` the accelerometer's rails in the core.
    Mpu6050 {
        /// [`Config::restore_accel`].
        restore: bool,
        /// Its rate: 200 Hz (1 kHz / 5), or 240 Hz, which it cannot run at but the
        /// LSM6DSV320X does: the rate's share of the difference.
        rate_hz: u32,
    },
    /// LSM6DSV320X, low-g ±16 g only, ±4 000 °/s, 240 Hz.
    LowGOnly,
    /// LSM6DSV320X, low-g ±16 g merged with high-g ±128 g at 960 Hz, ±4 000 °/s, 240 Hz.
    Merged,
}

impl Recording {
    /// Every recording, in the table's order.
    pub const ALL: [Recording; 5] = [
        Recording::Mpu6050 {
            restore: true,
            rate_hz: 200,
        },
        Recording::Mpu6050 {
            restore: false,
            rate_hz: 200,
        },
        Recording::Mpu6050 {
            restore: true,
            rate_hz: 240,
        },
        Recording::LowGOnly,
        Recording::Merged,
    ];

    /// The table's label.
    pub fn label(self) -> &'static str {
        match self {
            Recording::Mpu6050 {
                restore: true,
                rate_hz: 200,
            } => "MPU6050 ±16 g, ±2 000 °/s, 200 Hz; rails put back (default)",
            Recording::Mpu6050 { restore: false, .. } => {
                "MPU6050 ±16 g, ±2 000 °/s, 200 Hz; rails left in"
            }
            Recording::Mpu6050 { .. } => {
                "MPU6050's ranges at 240 Hz (a rate it cannot run at: the rate's share)"
            }
            Recording::LowGOnly => "LSM6DSV320X low-g ±16 g only, ±4 000 °/s, 240 Hz",
            Recording::Merged => "LSM6DSV320X low-g + high-g ±128 g (960 Hz), ±4 000 °/s, 240 Hz",
        }
    }

    /// The rate the core runs at, Hz.
    pub fn rate_hz(self) -> u32 {
        match self {
            Recording::Mpu6050 { rate_hz, .. } => rate_hz,
            Recording::LowGOnly | Recording::Merged => 240,
        }
    }

    fn scales(self) -> (AccelScale, GyroScale) {
        match self {
            Recording::Mpu6050 { .. } => (AccelRange::G16.scale(), GyroRange::Dps2000.scale()),
            Recording::LowGOnly => (StAccel::G16.scale(), StGyro::Dps4000.scale()),
            Recording::Merged => (self.dual().scale(), StGyro::Dps4000.scale()),
        }
    }

    fn dual(self) -> DualRange {
        DualRange::new(StAccel::G16, HighGRange::G128)
    }

    /// The core's configuration for this recording.
    pub fn config(self) -> Result<Config> {
        let Some(rate) = SampleRate::from_hz(self.rate_hz()) else {
            bail!("{} Hz is not a rate the core takes", self.rate_hz());
        };
        let (a, g) = self.scales();
        let mut c = Config::new(rate, a, g);
        c.restore_accel = !matches!(self, Recording::Mpu6050 { restore: false, .. });
        Ok(c)
    }
}

/// Counts of `v` at `counts_per_unit`, rounded and saturated as a part reports them.
fn counts(v: [f64; 3], counts_per_unit: f64) -> [i16; 3] {
    v.map(|x| quantize(x * counts_per_unit))
}

fn accel_counts_per_mps2(s: AccelScale) -> f64 {
    s.lsb_per_g() as f64 / G_MPS2
}

fn gyro_counts_per_radps(s: GyroScale) -> f64 {
    s.lsb_per_dps() * 180.0 / std::f64::consts::PI
}

/// What a part delivered: the samples the core takes, and how many of them sat at a rail.
#[derive(Clone, Debug, Default)]
pub struct Recorded {
    /// The samples, at the recording's rate.
    pub samples: Vec<RawSample>,
    /// Samples with an accelerometer axis at a rail (for the merge: the low-g channel's,
    /// before the merge).
    pub accel_railed: usize,
    /// Samples with a gyroscope axis at a rail.
    pub gyro_railed: usize,
    /// Merged axes the high-g channel gave.
    pub high_g_axes: u32,
}

/// Records `sc` as `rec` would: the trajectory sampled at the part's instants, with the
/// scenario's biases and noise (seeded by the scenario), quantised and saturated at the
/// part's scales.
pub fn record(sc: &Scenario, rec: Recording) -> Recorded {
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let tr = Trajectory::new(sc, &mut rng);
    let rate = rec.rate_hz() as f64;
    let n = (tr.duration_s * rate).floor() as usize + 1;
    let (a_scale, g_scale) = rec.scales();
    let g_k = gyro_counts_per_radps(g_scale);
    let mut out = Recorded::default();
    let low_rails = Rails::FULL_SCALE;
    match rec {
        Recording::Mpu6050 { .. } | Recording::LowGOnly => {
            let a_k = accel_counts_per_mps2(a_scale);
            for i in 0..n {
                let s = tr.sample(i as f64 / rate, &mut rng);
                let c = RawSample {
                    accel: counts(s.acc_mps2, a_k),
                    gyro: counts(s.gyr_radps, g_k),
                    temp: 0,
                };
                out.accel_railed += low_rails.accel_clipped(&c) as usize;
                out.gyro_railed += low_rails.gyro_clipped(&c) as usize;
                out.samples.push(c);
            }
        }
        Recording::Merged => {
            let dual = rec.dual();
            let mut asm = Assembler::new(dual);
            let railed = |v: [i16; 3]| v.iter().any(|&c| (c as i32).abs() >= dual.rail_counts());
            for w in lsm_fifo(sc) {
                // Each word round-trips through its 7 bytes, as the FIFO delivers it.
                let w = FifoWord::from_bytes(&w.to_bytes());
                match w.tag {
                    Tag::Accel => out.accel_railed += railed(w.data) as usize,
                    Tag::Gyro => {
                        let s = RawSample {
                            accel: [0; 3],
                            gyro: w.data,
                            temp: 0,
                        };
                        out.gyro_railed += low_rails.gyro_clipped(&s) as usize;
                    }
                    _ => {}
                }
                out.samples.extend(asm.push(w));
            }
            out.samples.extend(asm.flush());
            out.high_g_axes = asm.high_g_axes();
        }
    }
    out
}

/// The true peaks of a scenario's motion (no bias, no noise), on a 0.1 ms grid: specific
/// force, g, and body rate, °/s.
pub fn true_peaks(sc: &Scenario) -> (f64, f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let tr = Trajectory::new(sc, &mut rng);
    let n = (tr.duration_s * 10_000.0) as usize;
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (0..n).fold((0.0f64, 0.0f64), |(f, w), i| {
        let (fs, ws) = tr.exact(i as f64 / 10_000.0);
        (f.max(norm(fs) / G_MPS2), w.max(norm(ws).to_degrees()))
    })
}

/// One recording of one sprint, scored.
#[derive(Clone, Debug)]
pub struct Scored {
    /// The recording.
    pub recording: Recording,
    /// What the part delivered.
    pub recorded: Recorded,
    /// Strides the core reported.
    pub strides: Vec<Stride>,
    /// Strides of the truth.
    pub truth_strides: usize,
    /// Sprint strides (the twelve at full speed) found, each length error, m.
    pub sprint_errors_m: Vec<f64>,
    /// Their climbs, m (the truth: 0).
    pub sprint_climbs_m: Vec<f64>,
    /// Reported distance − true distance, m.
    pub distance_error_m: f64,
    /// True distance, m.
    pub distance_m: f64,
}

/// Records `sc` as `rec` would and replays it through the core.
pub fn score(sc: &Scenario, rec: Recording) -> Result<Scored> {
    let recorded = record(sc, rec);
    let config = rec.config()?;
    let strides = core_strides(&recorded.samples, config);
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let tr = Trajectory::new(sc, &mut rng);
    let rate = rec.rate_hz() as f64;
    let truth = tr.truth(rate);
    // A reported stride is a true one if it ends in the stance that ends the true one (the
    // core ends a stride at its stance instant, inside that stance), give or take 40 ms.
    let tolerance = (0.04 * rate).round() as i64;
    let mut sprint_errors_m = Vec::new();
    let mut sprint_climbs_m = Vec::new();
    for (k, t) in truth.iter().enumerate() {
        let stance_end = truth.get(k + 1).map_or(i64::MAX, |n| n.heel_off_idx as i64);
        let Some(s) = strides.iter().find(|s| {
            let e = s.events.end as i64;
            e >= t.end_idx as i64 - tolerance && e <= stance_end.saturating_add(tolerance)
        }) else {
            continue;
        };
        if t.flag.is_empty() {
            sprint_errors_m.push(s.length_mm as f64 / 1000.0 - t.length_m);
            sprint_climbs_m.push(s.climb_mm as f64 / 1000.0);
        }
    }
    let distance_m: f64 = truth.iter().map(|t| t.length_m).sum();
    let reported: f64 = strides.iter().map(|s| s.length_mm as f64 / 1000.0).sum();
    Ok(Scored {
        recording: rec,
        recorded,
        truth_strides: truth.len(),
        strides,
        sprint_errors_m,
        sprint_climbs_m,
        distance_error_m: reported - distance_m,
        distance_m,
    })
}

/// The sprint table, Markdown (`_datasets`: none needed; the signature of the docs'
/// generators).
pub fn report(_datasets: &Path) -> Result<String> {
    let mut t = Table::new([
        Column::from("sprint"),
        Column::from("recorded as"),
        Column::right("samples at a rail: accel / gyro"),
        Column::right("strides found / true"),
        Column::right("sprint strides: RMSE / bias cm (n)"),
        Column::right("their climb RMSE cm"),
        Column::right("distance error"),
    ]);
    for sc in scenarios() {
        let (f_g, w_dps) = true_peaks(&sc);
        let name = format!("{} (true peaks {f_g:.0} g, {w_dps:.0} °/s)", sc.name);
        for rec in Recording::ALL {
            let s = score(&sc, rec)?;
            t.row([
                name.clone(),
                rec.label().to_string(),
                format!("{} / {}", s.recorded.accel_railed, s.recorded.gyro_railed),
                format!("{} / {}", s.strides.len(), s.truth_strides),
                cm_cell(&s.sprint_errors_m),
                format!("{:.1}", 100.0 * ErrorStats::of(&s.sprint_climbs_m).rmse),
                format!(
                    "{:+.2} m of {:.1} m ({:+.1} %)",
                    s.distance_error_m,
                    s.distance_m,
                    100.0 * s.distance_error_m / s.distance_m
                ),
            ]);
        }
    }
    Ok(t.render())
}

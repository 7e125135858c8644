//! `gaitclip clipping`: what a clipped accelerometer costs a stride, and what putting its loss
//! back ([`gaitclip::detect::clipping`]) recovers, measured on real recordings clipped on purpose.
//!
//! `gaitmap_walk` and `pyshoe_vicon` are replayed as recorded (±16 g: their sensors barely
//! reach it) and again clipped: converted at the MPU6050's ±8 g and ±4 g ranges (the counts
//! saturate), and as a part given as ±8 g that clips at 7 g: clamped there in physical units
//! but converted at ±16 g, so that the rails sit inside the counts and must be learnt from the
//! data ([`crate::io::rails`]). Each
//! stride of a clipped replay that starts and ends at the same stance instants as a stride of
//! the unclipped replay (clipping moved the others' instants: counted apart; what a moved
//! instant takes from one stride it gives the next) has its ZUPT length compared with that
//! stride's: with the
//! loss left in (`Config::restore_accel` false) and put back, and against what the estimate
//! from the strides before it ([`gaitclip::length::estimate`]) would have said: on every row putting
//! the loss back is far nearer, so a clipped stride is always measured, never estimated. By
//! how many samples clipped and where in the
//! stride (push-off: heel-off to toe-off; swing; heel strike: heel-strike to the stance
//! instant that ends the stride).
//!
//! **A sprint's rails, on running strides that did not reach them.** At a sprint both
//! sensors of a foot pod sit at their rails at once (±16 g at touch-down and push-off,
//! ±2 000 °/s around toe-off); what that takes from a stride cannot be measured on the sprint
//! itself, which has no unclipped self. The running strides of the 800 Hz recordings
//! (`esangeni_run`, and `esangeni_course`'s jog and run) peak at 10–15 g and 1 000–1 400 °/s:
//! converted at ±8 g, at ±1 000 °/s and at both, they meet their rails where a sprint meets
//! its own, and each is compared with itself as recorded ([`SPRINT_CLIPPINGS`], strides
//! clipped by the conversion and not as recorded), length and climb.

use anyhow::Result;
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::sample::{Rails, RawSample};
use gaitclip_mpu6050::{AccelRange, GyroRange};

use crate::eval::markdown::{cm_cell, median_p95_beside, Table};
use crate::io::datasets;
use crate::io::trace::{Ranges, Trace, G_MPS2};
use crate::{io::csv_trace, replay};

/// One way of clipping a recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clipping {
    /// Row label.
    pub label: &'static str,
    /// The ranges the recording is converted at (their counts saturate).
    pub ranges: Ranges,
    /// A clamp in physical units before the conversion, g, of a part given as ±8 g (its
    /// rails then learnt).
    pub clamp_g: Option<f64>,
}

/// The clippings of the tables (the last: a part given as ±8 g, clipping below it at 7 g, its
/// rails inside the ±16 g counts, so that they must be learnt).
pub const CLIPPINGS: [Clipping; 3] = [
    Clipping {
        label: "±8 g (MPU6050 range)",
        ranges: Ranges {
            accel: AccelRange::G8,
            gyro: GyroRange::Dps2000,
        },
        clamp_g: None,
    },
    Clipping {
        label: "±4 g (MPU6050 range)",
        ranges: Ranges {
            accel: AccelRange::G4,
            gyro: GyroRange::Dps2000,
        },
        clamp_g: None,
    },
    Clipping {
        label: "a ±8 g part clipping at 7 g (rails learnt)",
        ranges: Ranges {
            accel: AccelRange::G16,
            gyro: GyroRange::Dps2000,
        },
        clamp_g: Some(7.0),
    },
];

/// A sprint's two rails met at once, on the 800 Hz running strides (see the module): the
/// accelerometer at the MPU6050's ±8 g, the gyro at its ±1 000 °/s, and both.
pub const SPRINT_CLIPPINGS: [Clipping; 3] = [
    Clipping {
        label: "accelerometer at ±8 g",
        ranges: Ranges {
            accel: AccelRange::G8,
            gyro: GyroRange::Dps2000,
        },
        clamp_g: None,
    },
    Clipping {
        label: "gyro at ±1 000 °/s",
        ranges: Ranges {
            accel: AccelRange::G16,
            gyro: GyroRange::Dps1000,
        },
        clamp_g: None,
    },
    Clipping {
        label: "both (±8 g, ±1 000 °/s)",
        ranges: Ranges {
            accel: AccelRange::G8,
            gyro: GyroRange::Dps1000,
        },
        clamp_g: None,
    },
];

/// The recordings [`SPRINT_CLIPPINGS`] run on.
pub const SPRINT_DATASETS: [&str; 2] = ["esangeni_run", "esangeni_course"];

/// Which clipped strides a sweep compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clipped {
    /// Those with the accelerometer at a rail (what [`gaitclip::detect::clipping`] puts
    /// back).
    Accel,
    /// Those with either sensor at a rail that were not clipped as recorded.
    Newly,
}

/// Where in its stride a clipped sample lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Position {
    /// Before heel-off (the stance the stride starts in).
    Stance,
    /// Heel-off to toe-off.
    PushOff,
    /// Toe-off to heel-strike.
    Swing,
    /// Heel-strike to the end.
    HeelStrike,
}

/// One clipped stride against its unclipped self.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClippedStride {
    /// Samples of the stride with an accelerometer axis at a rail.
    pub clipped_samples: u32,
    /// Where most of them lie.
    pub position: Position,
    /// ZUPT length with the loss left in, minus the unclipped stride's, m.
    pub left_m: f64,
    /// ZUPT length with the loss put back, minus the unclipped stride's, m.
    pub restored_m: f64,
    /// What the estimate from the strides before it would have said, minus the unclipped
    /// stride's reported length, m.
    pub estimate_m: Option<f64>,
    /// Its climb with the loss put back, and the unclipped stride's, m.
    pub climb_m: (f64, f64),
}

/// The clipped strides of one dataset under one clipping, and how many strides there were.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepResult {
    /// Strides of the clipped replay with the instants of an unclipped one.
    pub matched: usize,
    /// Clipped strides whose instants clipping moved.
    pub moved: usize,
    /// Clipped samples in the recordings.
    pub clipped_samples: usize,
    /// The clipped strides.
    pub strides: Vec<ClippedStride>,
}

fn clamp_trace(t: &Trace, g: f64) -> Trace {
    let lim = g * G_MPS2;
    let mut out = t.clone();
    out.given.acc_g = Some(8.0);
    for s in &mut out.samples {
        for a in &mut s.acc_mps2 {
            *a = a.clamp(-lim, lim);
        }
    }
    out
}

/// The stride of `refs` (a replay of the same recording, unclipped) between the same two
/// instants as `s`.
pub fn same_instants<'a>(s: &Stride, refs: &'a [Stride]) -> Option<&'a Stride> {
    refs.iter()
        .find(|r| r.events.start == s.events.start && r.events.end == s.events.end)
}

fn position(s: &Stride, at: &[u32]) -> Position {
    let mut n = [0usize; 4];
    for &i in at {
        let p = if i < s.events.heel_off {
            0
        } else if i < s.events.toe_off {
            1
        } else if i < s.events.heel_strike {
            2
        } else {
            3
        };
        n[p] += 1;
    }
    let k = (0..4).max_by_key(|&k| n[k]).unwrap_or(3);
    [
        Position::Stance,
        Position::PushOff,
        Position::Swing,
        Position::HeelStrike,
    ][k]
}

/// One dataset under one clipping: the strides with the accelerometer at a rail.
pub fn sweep(dataset: &datasets::Dataset, clipping: &Clipping) -> Result<SweepResult> {
    sweep_of(dataset, clipping, Clipped::Accel)
}

/// One dataset under one clipping, the strides `which` says.
pub fn sweep_of(
    dataset: &datasets::Dataset,
    clipping: &Clipping,
    which: Clipped,
) -> Result<SweepResult> {
    let mut out = SweepResult::default();
    for trial in &dataset.trials {
        let t = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        let unclipped = replay::prepare(&t, Ranges::default())?;
        let refs = unclipped.strides(unclipped.config(Ranges::default()));
        let ct = match clipping.clamp_g {
            Some(g) => clamp_trace(&t, g),
            None => t.clone(),
        };
        let p = replay::prepare(&ct, clipping.ranges)?;
        let config = p.config(clipping.ranges);
        let restored = p.strides(config);
        let left = p.strides(gaitclip::pipeline::config::Config {
            restore_accel: false,
            ..config
        });
        let rails: Rails = config.rails;
        let clipped_at: Vec<u32> = p
            .counts
            .iter()
            .enumerate()
            .filter(|(_, s)| match which {
                Clipped::Accel => rails.accel_clipped(s),
                Clipped::Newly => rails.accel_clipped(s) || rails.gyro_clipped(s),
            })
            .map(|(i, _)| p.clock.number_of_row(i))
            .collect();
        out.clipped_samples += clipped_at.len();
        let mut estimator = gaitclip::length::estimate::LengthEstimator::new();
        for (s, l) in restored.iter().zip(&left) {
            let est = estimator.estimate_mm();
            estimator.process(&mut s.clone());
            let clipped = |x: &Stride, f: u16| x.flags.has(f);
            let counted = match which {
                Clipped::Accel => clipped(s, StrideFlags::ACCEL_CLIPPED),
                Clipped::Newly => {
                    clipped(s, StrideFlags::ACCEL_CLIPPED | StrideFlags::GYRO_CLIPPED)
                }
            };
            if !counted || s.flags.has(StrideFlags::GAP) {
                out.matched += 1;
                continue;
            }
            let Some(r) = same_instants(s, &refs) else {
                out.moved += 1;
                continue;
            };
            // Clipped as recorded: no unclipped self to compare with.
            if which == Clipped::Newly
                && clipped(r, StrideFlags::ACCEL_CLIPPED | StrideFlags::GYRO_CLIPPED)
            {
                out.matched += 1;
                continue;
            }
            out.matched += 1;
            let at: Vec<u32> = clipped_at
                .iter()
                .copied()
                .filter(|&i| i > s.events.start && i <= s.events.end)
                .collect();
            let m = |x: &Stride| x.zupt_um as f64 / 1e6;
            out.strides.push(ClippedStride {
                clipped_samples: at.len() as u32,
                position: position(s, &at),
                left_m: m(l) - m(r),
                restored_m: m(s) - m(r),
                estimate_m: est.map(|e| (e as f64 - r.length_mm as f64) / 1000.0),
                climb_m: (s.climb_mm as f64 / 1000.0, r.climb_mm as f64 / 1000.0),
            });
        }
    }
    Ok(out)
}

/// The clipped samples of `counts` at `rails`, for tests.
pub fn clipped_samples(counts: &[RawSample], rails: &Rails) -> usize {
    counts.iter().filter(|s| rails.accel_clipped(s)).count()
}

/// The two tables, Markdown, for the datasets under `root`.
pub fn report(root: &std::path::Path) -> Result<String> {
    let sets: Vec<datasets::Dataset> = ["gaitmap_walk", "pyshoe_vicon"]
        .iter()
        .map(|n| datasets::load(&root.join(n)))
        .collect::<Result<_>>()?;
    let mut summary = Table::new([
        "clipping",
        "dataset",
        "clipped samples",
        "clipped strides (of strides)",
        "instants moved",
        "loss left in",
        "loss put back",
        "estimate instead",
    ]);
    let mut by = Table::new([
        "clipping",
        "dataset",
        "1 sample",
        "2–3",
        "4–9",
        "≥ 10",
        "at push-off",
        "in the swing",
        "at heel strike",
    ]);
    for c in &CLIPPINGS {
        for d in &sets {
            let r = sweep(d, c)?;
            let pick = |f: &dyn Fn(&ClippedStride) -> Option<f64>| -> Vec<f64> {
                r.strides.iter().filter_map(f).collect()
            };
            summary.row([
                c.label.to_string(),
                d.name.clone(),
                r.clipped_samples.to_string(),
                format!("{} ({})", r.strides.len(), r.matched + r.moved),
                r.moved.to_string(),
                cm_cell(&pick(&|s| Some(s.left_m))),
                cm_cell(&pick(&|s| Some(s.restored_m))),
                cm_cell(&pick(&|s| s.estimate_m)),
            ]);
            let n = |lo: u32, hi: u32| {
                cm_cell(&pick(&|s| {
                    (s.clipped_samples >= lo && s.clipped_samples <= hi).then_some(s.restored_m)
                }))
            };
            let at = |p: Position| cm_cell(&pick(&|s| (s.position == p).then_some(s.restored_m)));

            by.row([
                c.label.to_string(),
                d.name.clone(),
                n(1, 1),
                n(2, 3),
                n(4, 9),
                n(10, u32::MAX),
                at(Position::PushOff),
                at(Position::Swing),
                at(Position::HeelStrike),
            ]);
        }
    }
    Ok(format!(
        "Clipped strides against their unclipped selves (ZUPT length; RMSE / bias cm (strides)):\n\n{}\n\
         The loss put back, by clipped samples in the stride and where most of them lie (RMSE / bias cm (strides)):\n\n{}\n\
         A sprint's rails on the 800 Hz running strides that did not reach them (strides the conversion clipped, against themselves as recorded; ZUPT length RMSE / bias cm (strides); |climb| m):\n\n{}",
        summary.render(),
        by.render(),
        sprint_table(root)?.render()
    ))
}

/// The table of [`SPRINT_CLIPPINGS`] on [`SPRINT_DATASETS`].
pub fn sprint_table(root: &std::path::Path) -> Result<Table> {
    let mut t = Table::new([
        "clipping",
        "dataset",
        "clipped strides (of strides)",
        "instants moved",
        "accelerometer's loss left in",
        "loss put back",
        "estimate instead",
        "|climb| median / p95: clipped (as recorded)",
        "climb over 0.3 m: clipped (as recorded)",
    ]);
    for c in &SPRINT_CLIPPINGS {
        for name in SPRINT_DATASETS {
            let d = datasets::load(&root.join(name))?;
            let r = sweep_of(&d, c, Clipped::Newly)?;
            let pick = |f: &dyn Fn(&ClippedStride) -> Option<f64>| -> Vec<f64> {
                r.strides.iter().filter_map(f).collect()
            };
            let climb = |k: usize| -> Vec<f64> {
                r.strides
                    .iter()
                    .map(|s| [s.climb_m.0, s.climb_m.1][k].abs())
                    .collect()
            };
            let (clipped, recorded) = (climb(0), climb(1));
            let over = |v: &[f64]| v.iter().filter(|&&x| x > 0.3).count();
            t.row([
                c.label.to_string(),
                d.name.clone(),
                format!("{} ({})", r.strides.len(), r.matched + r.moved),
                r.moved.to_string(),
                cm_cell(&pick(&|s| Some(s.left_m))),
                cm_cell(&pick(&|s| Some(s.restored_m))),
                cm_cell(&pick(&|s| s.estimate_m)),
                median_p95_beside(&clipped, &recorded, ""),
                format!("{} ({})", over(&clipped), over(&recorded)),
            ]);
        }
    }
    Ok(t)
}

//! `gaitclip constraints`: what the constraints a stride offers beyond its two zero-velocity
//! instants would do to its length, measured on strides whose length is known.
//!
//! The core removes a stride's zero-velocity residual as a drift grown linearly over the
//! movement. A sprint stride on a level floor then climbs up to a metre, which a level floor
//! does not allow, and its rest at the end reads gravity a few degrees off the attitude the
//! gyro integrated to. Both are constraints the core does not use. Each row here applies one
//! to the `f64` twin's integration of the same strides ([`cycle_ref::Integration`]) and scores
//! the length against the references that measure it (`pyshoe_vicon`'s Vicon, `gaitmap_walk`'s
//! strides) and the courses against their geometry (`esangeni_course`):
//!
//! - **the residual as a step at the heel strike**: the velocity error appeared at once at the
//!   touch-down (de Ruiter et al. 2022's artefact), not gradually;
//! - **a level landing**: the linear drift and that step mixed, the mix kept between the two,
//!   so that the stride climbs nothing (everywhere, or only where it climbs over 0.15 m,
//!   issue 45's bound for a level floor); the same mix then moves the horizontal displacement;
//! - **gravity at the end**: the horizontal part of the end rest's gravity, turned by the
//!   integrated attitude, taken for a tilt error grown uniformly over the movement (a gyro
//!   bias), whose leaked gravity is removed in closed form (−leak·T²/12 after the linear
//!   dedrift); strides with a clipped gyro keep the core's rail correction instead;
//! - **the walker's estimate** ([`LengthEstimator`], the mean of the last two measured
//!   strides) where the integration is physically inconsistent, a foot at rest still moving
//!   over 2 m/s by it (issue 45's proposal): on every stride, or only on those at a rail;
//! - **a hidden rail**: where the accelerometer came within 10 % of its rail and the foot
//!   stands at over 2 m/s, the residual taken for what an impact beyond the rail took at the
//!   sample the sensor saw largest (a sensor that filters after it clips shows no flat run).
//!
//! A second table asks the sensors' clocks: the core's finish with the attitude integrated
//! from the gyro read one or two samples early or late against the accelerometer.
//!
//! Strides at a rail are scored twice more, where something measures them: `pyshoe_vicon`
//! converted at ±4 g against the Vicon, and `esangeni_course` converted at a sprint's two
//! rails against themselves as recorded (the clipping table's rows).
//!
//! The twin skips strides it cannot re-measure (bridged, without a contiguous stride before
//! them); in a course's total those keep the core's length in every row.

use std::path::Path;

use anyhow::Result;
use gaitclip::length::estimate::LengthEstimator;
use gaitclip::record::stride::StrideFlags;
use nalgebra::{Vector2, Vector3};

use crate::eval::clip_sweep::same_instants;
use crate::eval::course;
use crate::eval::length_eval::SPEED_BINS;
use crate::eval::markdown::{cm_cell, Table};
use crate::eval::matching::{self, Detected, Scored};
use crate::eval::stats::{median, quantile};
use crate::io::datasets;
use crate::io::trace::Ranges;
use crate::reference::cycle_ref::{self, CoreRun, Integration, Skipped};
use crate::{io::csv_trace, replay};
use gaitclip_mpu6050::{AccelRange, GyroRange};

/// A stride climbing more than this on a level floor is beyond issue 45's bound, m.
const LEVEL_CLIMB_M: f64 = 0.15;

/// One way to finish a stride's integration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Finish {
    Linear,
    StepAtHeelStrike,
    LevelLanding,
    LevelLandingOverBound,
    EndGravity,
    EstimateOverResidual,
    EstimateOverResidualClipped,
    StepNearRail,
}

const FINISHES: [(Finish, &str); 8] = [
    (
        Finish::Linear,
        "the core: the residual as a drift grown linearly",
    ),
    (
        Finish::StepAtHeelStrike,
        "the residual as a step at the heel strike",
    ),
    (
        Finish::LevelLanding,
        "a level landing: linear and step mixed to climb nothing",
    ),
    (
        Finish::LevelLandingOverBound,
        "a level landing where the stride climbs over 0.15 m",
    ),
    (
        Finish::EndGravity,
        "gravity at the end: its tilt grown uniformly, leak removed",
    ),
    (
        Finish::EstimateOverResidual,
        "the walker's estimate where the residual exceeds 2 m/s",
    ),
    (
        Finish::EstimateOverResidualClipped,
        "the same, on strides at a rail only",
    ),
    (
        Finish::StepNearRail,
        "a step at the impact, where the accelerometer neared its rail and the foot stands at over 2 m/s",
    ),
];

/// `pyshoe_vicon` converted at the MPU6050's ±4 g: its walking and running strides at a rail
/// (the clipping table's row), scored against the Vicon.
const PYSHOE_RAILS: Ranges = Ranges {
    accel: AccelRange::G4,
    gyro: GyroRange::Dps2000,
};

/// A sprint's two rails on running strides that stayed inside ±16 g and ±2 000 °/s (the
/// clipping table's last row): the MPU6050's ±8 g and ±1 000 °/s.
const SPRINT_RAILS: Ranges = Ranges {
    accel: AccelRange::G8,
    gyro: GyroRange::Dps1000,
};

/// A foot at rest still moving this fast by the integration, m/s: beyond 99 % of
/// `pyshoe_vicon`'s strides (p99 2.2 m/s), where issue 45 would take the estimate instead.
const INCONSISTENT_RESIDUAL_M_S: f64 = 2.0;

/// An accelerometer reading this near its axis's rail (its share of the rail) counts as
/// near it: within 10 %.
const NEAR_RAIL: f64 = 0.9;

/// What a finish works from: the twin's integration of a stride, its heel strike (samples
/// from the start) and the core's estimate for it from the strides before
/// ([`LengthEstimator`]), m.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Measured {
    integration: Integration,
    heel_strike: f64,
    estimate_m: Option<f64>,
    /// A sensor sat at a rail in the stride.
    at_rail: bool,
}

impl Finish {
    /// The length and climb of `m`, m.
    fn length_and_climb(self, m: &Measured) -> (f64, f64) {
        let d = self.displacement(&m.integration, m.heel_strike);
        let inconsistent = m.integration.residual.norm() > INCONSISTENT_RESIDUAL_M_S;
        match (self, m.estimate_m) {
            (Finish::EstimateOverResidual, Some(e)) if inconsistent => (e, d.z),
            (Finish::EstimateOverResidualClipped, Some(e)) if inconsistent && m.at_rail => (e, d.z),
            _ => (d.xy().norm(), d.z),
        }
    }

    /// The displacement, m, of `x` (heel strike `hs` samples from the start).
    fn displacement(self, x: &Integration, hs: f64) -> Vector3<f64> {
        let linear = x.linear();
        match self {
            Finish::Linear | Finish::EstimateOverResidual | Finish::EstimateOverResidualClipped => {
                linear
            }
            Finish::StepAtHeelStrike => x.step_at(hs),
            Finish::LevelLanding => level(x, hs),
            Finish::LevelLandingOverBound if linear.z.abs() > LEVEL_CLIMB_M => level(x, hs),
            Finish::LevelLandingOverBound => linear,
            Finish::StepNearRail
                if x.of_rail >= NEAR_RAIL && x.residual.norm() > INCONSISTENT_RESIDUAL_M_S =>
            {
                x.step_at(x.impact)
            }
            Finish::StepNearRail => linear,
            Finish::EndGravity if x.gyro_clipped => linear,
            Finish::EndGravity => {
                // A tilt e·t/T leaks a·t/T; twice integrated it moves the foot a·T²/6, of
                // which the linear dedrift (of the residual a·T/2) takes a·T²/4 back.
                let t = x.samples * x.dt;
                let moved: Vector2<f64> = x.end_leak * (-t * t / 12.0);
                linear - Vector3::new(moved.x, moved.y, 0.0)
            }
        }
    }
}

/// The mix of the linear drift and the step at `hs` under which `x` climbs nothing, the mix
/// kept between the two.
fn level(x: &Integration, hs: f64) -> Vector3<f64> {
    let (linear, step) = (x.linear(), x.step_at(hs));
    let d = step.z - linear.z;
    let a = if d.abs() > 1e-12 {
        (step.z / d).clamp(0.0, 1.0)
    } else {
        1.0
    };
    linear * a + step * (1.0 - a)
}

/// A matched stride: its reference length and speed, and what the finishes work from.
struct Known {
    speed_m_s: f64,
    length_m: f64,
    measured: Measured,
}

/// Per stride of `run`, in order, what the finishes work from (`Err`: the twin skips it).
fn measured(run: &CoreRun, gyro_shift: i32) -> Vec<Result<Measured, Skipped>> {
    let mut estimator = LengthEstimator::new();
    run.strides
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let estimate_m = estimator.estimate_mm().map(|mm| mm as f64 / 1e3);
            estimator.process(&mut s.clone());
            cycle_ref::integration_shifted(run, k, gyro_shift).map(|integration| Measured {
                integration,
                heel_strike: s.events.heel_strike.saturating_sub(s.events.start) as f64,
                estimate_m,
                at_rail: s
                    .flags
                    .has(StrideFlags::ACCEL_CLIPPED | StrideFlags::GYRO_CLIPPED),
            })
        })
        .collect()
}

/// Every clean matched stride of the dataset in `dir`, converted at `ranges`, with a
/// reference length that the twin re-measures (`at_rail`: only those with a sensor at a
/// rail).
fn known(dir: &Path, ranges: Ranges, at_rail: bool, gyro_shift: i32) -> Result<Vec<Known>> {
    let d = datasets::load(dir)?;
    let mut out = Vec::new();
    for trial in &d.trials {
        let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
        let p = replay::prepare(&t, ranges)?;
        let run = cycle_ref::run(&p.counts, &p.clock.holes, p.config(ranges));
        let det: Vec<Detected> = run.strides.iter().map(Detected::from).collect();
        let refs = trial.references_in_numbers(&p.clock);
        let measured = measured(&run, gyro_shift);
        for (i, c) in matching::classify(trial, &p.clock, &det, &refs)
            .iter()
            .enumerate()
        {
            let Scored::Found(j) = *c else { continue };
            let (s, r) = (&run.strides[i], &refs[j]);
            if !s.flags.valid() || s.flags.has(StrideFlags::FROM_REST | StrideFlags::TO_REST) {
                continue;
            }
            let (Some(length_m), Ok(measured)) = (r.length_m, measured[i]) else {
                continue;
            };
            if at_rail && !measured.at_rail {
                continue;
            }
            out.push(Known {
                speed_m_s: length_m / ((r.end - r.start) as f64 * p.clock.period_s),
                length_m,
                measured,
            });
        }
    }
    Ok(out)
}

/// The strides of the dataset in `dir` that converting it at `ranges` put at a rail, with
/// the length the core measures of them as recorded (none of their samples at a rail) for
/// reference: the rails' loss and nothing else.
fn against_unclipped(dir: &Path, ranges: Ranges, gyro_shift: i32) -> Result<Vec<Known>> {
    let d = datasets::load(dir)?;
    let clip = StrideFlags::ACCEL_CLIPPED | StrideFlags::GYRO_CLIPPED;
    let mut out = Vec::new();
    for trial in &d.trials {
        let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
        let recorded = replay::prepare(&t, Ranges::default())?;
        let refs = recorded.strides(recorded.config(Ranges::default()));
        let p = replay::prepare(&t, ranges)?;
        let run = cycle_ref::run(&p.counts, &p.clock.holes, p.config(ranges));
        for (s, m) in run.strides.iter().zip(measured(&run, gyro_shift)) {
            let Ok(measured) = m else { continue };
            if !measured.at_rail || s.flags.has(StrideFlags::GAP) {
                continue;
            }
            let Some(r) = same_instants(s, &refs) else {
                continue;
            };
            if r.flags.has(clip) || !r.flags.valid() {
                continue;
            }
            let length_m = r.zupt_um as f64 / 1e6;
            out.push(Known {
                speed_m_s: length_m / ((r.events.end - r.events.start) as f64 * p.clock.period_s),
                length_m,
                measured,
            });
        }
    }
    Ok(out)
}

/// A course: its length, and per stride what the finishes work from (or, where the twin
/// skips it, the core's length, m).
struct CourseRun {
    course_m: f64,
    strides: Vec<Result<Measured, f64>>,
}

fn course_runs(dir: &Path, gyro_shift: i32) -> Result<Vec<CourseRun>> {
    let ranges = Ranges::default();
    Ok(course::prepared(dir)?
        .into_iter()
        .map(|(truth, p)| {
            let run = cycle_ref::run(&p.counts, &p.clock.holes, p.config(ranges));
            let strides = run
                .strides
                .iter()
                .zip(measured(&run, gyro_shift))
                .filter(|(s, _)| s.zupt_um > 0)
                .map(|(s, m)| m.map_err(|_| s.zupt_um as f64 / 1e6))
                .collect();
            CourseRun {
                course_m: truth.course_m,
                strides,
            }
        })
        .collect())
}

/// Everything the tables score, integrated with the gyro read `gyro_shift` samples late.
struct Sets {
    pyshoe: Vec<Known>,
    gaitmap: Vec<Known>,
    pyshoe_4g: Vec<Known>,
    course_rails: Vec<Known>,
    courses: Vec<CourseRun>,
}

impl Sets {
    fn of(root: &Path, gyro_shift: i32) -> Result<Self> {
        let course = root.join("esangeni_course");
        Ok(Sets {
            pyshoe: known(
                &root.join("pyshoe_vicon"),
                Ranges::default(),
                false,
                gyro_shift,
            )?,
            gaitmap: known(
                &root.join("gaitmap_walk"),
                Ranges::default(),
                false,
                gyro_shift,
            )?,
            pyshoe_4g: known(&root.join("pyshoe_vicon"), PYSHOE_RAILS, true, gyro_shift)?,
            course_rails: against_unclipped(&course, SPRINT_RAILS, gyro_shift)?,
            courses: course_runs(&course, gyro_shift)?,
        })
    }

    /// The table's header, its first column named `first`.
    fn header(first: &str) -> Vec<String> {
        let mut header = vec![first.to_string()];
        for (lo, hi) in SPEED_BINS {
            header.push(if hi.is_finite() {
                format!("`pyshoe_vicon` {lo}–{hi} m/s")
            } else {
                format!("`pyshoe_vicon` > {lo} m/s")
            });
        }
        header.push("`gaitmap_walk`".into());
        header.push("`pyshoe_vicon` at ±4 g: strides at a rail".into());
        header.push("`esangeni_course` at ±8 g, ±1 000 °/s: strides newly at a rail, against themselves as recorded".into());
        header.push("`esangeni_course` |total error| median / worst".into());
        header.push("courses' |climb| p95 / max m".into());
        header
    }

    /// The row of `finish`, named `name`.
    fn row(&self, finish: Finish, name: &str) -> Vec<String> {
        let errors = |k: &[Known], (lo, hi): (f64, f64)| -> Vec<f64> {
            k.iter()
                .filter(|x| x.speed_m_s >= lo && x.speed_m_s < hi)
                .map(|x| finish.length_and_climb(&x.measured).0 - x.length_m)
                .collect()
        };
        let mut row = vec![name.to_string()];
        for bin in SPEED_BINS {
            row.push(cm_cell(&errors(&self.pyshoe, bin)));
        }
        let every = (0.0, f64::INFINITY);
        row.push(cm_cell(&errors(&self.gaitmap, every)));
        row.push(cm_cell(&errors(&self.pyshoe_4g, every)));
        row.push(cm_cell(&errors(&self.course_rails, every)));
        let mut totals = Vec::new();
        let mut climbs = Vec::new();
        for c in &self.courses {
            let mut total = 0.0;
            for s in &c.strides {
                match s {
                    Ok(m) => {
                        let (length, climb) = finish.length_and_climb(m);
                        total += length;
                        climbs.push(climb.abs());
                    }
                    Err(core_m) => total += core_m,
                }
            }
            totals.push((100.0 * (total - c.course_m) / c.course_m).abs());
        }
        row.push(format!(
            "{:.1} / {:.1} %",
            median(&totals),
            totals.iter().copied().fold(0.0, f64::max)
        ));
        row.push(format!(
            "{:.2} / {:.2}",
            quantile(&climbs, 0.95),
            climbs.iter().copied().fold(0.0, f64::max)
        ));
        row
    }
}

/// The gyro read this many samples late (negative: early) against the accelerometer, for the
/// clock's table.
const GYRO_SHIFTS: [i32; 5] = [-2, -1, 0, 1, 2];

/// The tables, Markdown.
pub fn report(root: &Path) -> Result<String> {
    let sets = Sets::of(root, 0)?;
    let mut t = Table::new(Sets::header("finish"));
    for (finish, name) in FINISHES {
        t.row(sets.row(finish, name));
    }
    let leak = |k: &[Known]| {
        median(
            &k.iter()
                .map(|x| x.measured.integration.end_leak.norm())
                .collect::<Vec<_>>(),
        )
    };
    let residual = |k: &[Known]| {
        median(
            &k.iter()
                .map(|x| x.measured.integration.residual.norm())
                .collect::<Vec<_>>(),
        )
    };
    let mut clock = Table::new(Sets::header("gyro against the accelerometer"));
    let mut residuals = Vec::new();
    for shift in GYRO_SHIFTS {
        // As recorded is the first table's integration: not replayed again.
        let other;
        let shifted = if shift == 0 {
            &sets
        } else {
            other = Sets::of(root, shift)?;
            &other
        };
        let samples = |d: i32| match d.abs() {
            1 => "1 sample".to_string(),
            n => format!("{n} samples"),
        };
        let name = match shift {
            0 => "as recorded (the core)".to_string(),
            d if d < 0 => format!("{} early", samples(d)),
            d => format!("{} late", samples(d)),
        };
        residuals.push(format!(
            "{name}: {:.2} / {:.2}",
            residual(&shifted.pyshoe),
            residual(&shifted.gaitmap)
        ));
        clock.row(shifted.row(Finish::Linear, &name));
    }
    Ok(format!(
        "The same strides finished eight ways, the `f64` twin's integration of the core's own \
         strides (clean matched strides, against the reference's length: RMSE / bias cm (strides); \
         the courses' total against their geometry, the twin's strides only for |climb|). The \
         gravity the end's rest leaks through the integrated attitude: median {:.2} m/s² on \
         `pyshoe_vicon`'s strides, {:.2} m/s² on `gaitmap_walk`'s.\n\n{}\n\
         The sensors' clocks: the core's finish with the gyro read a sample or two early or late \
         against the accelerometer (the median |residual|, m/s, `pyshoe_vicon` / `gaitmap_walk`: \
         {}):\n\n{}",
        leak(&sets.pyshoe),
        leak(&sets.gaitmap),
        t.render(),
        residuals.join("; "),
        clock.render()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An integration of `n` samples at `dt` whose only error is the acceleration `a(c)`
    /// (m/s², level frame) integrated as the twin does (trapezoidal position).
    fn integrated(n: usize, dt: f64, a: impl Fn(f64) -> Vector3<f64>) -> Integration {
        let (mut v, mut p) = (Vector3::zeros(), Vector3::zeros());
        for c in 1..=n {
            let v_prev = v;
            v += a(c as f64) * dt;
            p += (v_prev + v) * (dt / 2.0);
        }
        Integration {
            displacement: p,
            residual: v,
            rail_tilt: Vector2::zeros(),
            gyro_clipped: false,
            end_leak: Vector2::zeros(),
            impact: n as f64,
            of_rail: 0.0,
            samples: n as f64,
            dt,
        }
    }

    #[test]
    fn a_uniformly_grown_tilt_is_removed_by_its_end_leak() {
        // A tilt grown linearly to 3° at the end of a 0.7 s movement at 200 Hz leaks gravity
        // along x: 1.5 cm of displacement the linear dedrift leaves in.
        let (n, dt) = (140, 0.005);
        let leak = 9.80665 * 3f64.to_radians().sin();
        let mut x = integrated(n, dt, |c| Vector3::new(leak * c / n as f64, 0.0, 0.0));
        x.end_leak = Vector2::new(leak, 0.0);
        let left_in = x.linear().x;
        assert!(left_in.abs() > 0.01, "{left_in}");
        let finished = Finish::EndGravity.displacement(&x, 0.0);
        assert!(
            finished.x.abs() < 1e-4 * left_in.abs().max(1.0),
            "{finished}"
        );
    }

    #[test]
    fn a_level_landing_climbs_nothing_within_the_mix_and_the_rest_follows_it() {
        // A velocity error of 0.4 m/s up and 0.2 m/s forward appearing at sample 100 of 140:
        // the linear dedrift leaves a climb; the step at 100 removes it exactly.
        let (n, dt, at) = (140, 0.005, 100.0);
        let x = integrated(n, dt, |c| {
            if c == at {
                Vector3::new(0.2, 0.0, 0.4) / dt
            } else {
                Vector3::zeros()
            }
        });
        assert!(x.linear().z.abs() > 0.05);
        let l = level(&x, at);
        assert!(l.z.abs() < 1e-9, "{l}");
        assert!(l.x.abs() < 1e-9, "{l}");
        // Where no mix levels it, the mix stops at the end nearer level.
        let y = Integration {
            displacement: x.displacement + Vector3::new(0.0, 0.0, 1.0),
            ..x
        };
        assert!(y.linear().z < y.step_at(at).z);
        assert_eq!(level(&y, at), y.linear());
        // Over the bound only.
        let small = Integration {
            residual: Vector3::new(0.0, 0.0, 0.01),
            ..x
        };
        let hs = at;
        assert_eq!(
            Finish::LevelLandingOverBound.displacement(&small, hs),
            small.linear()
        );
    }
}

//! `gaitclip course`: walk-jog-run-sprint courses scored against their geometry, whole and by
//! part (`esangeni_course`: forward, then backward, then sideways, with each part's length in
//! `trials.csv`).
//!
//! A course has no per-stride truth, only the lengths walked, so the strides are split into
//! the course's parts by the direction the foot points, from the core's own heading change per
//! stride (`turning_angle_deg`, the ZUPT integration's): a stride that turns the foot by at
//! least [`TURN_DEG`] is a **turning step** (a pivot at a stand; it walks no part of the
//! course's geometry and is reported apart), and a stride whose heading, summed from the
//! start, lies more than [`TURN_DEG`] from the median heading of the part so far starts the
//! next part. The first part is the forward one (slow walk to sprint), the second the
//! backward one (the walker turns round), every later one sideways (the walker turns a
//! quarter, and round again between left and right). [`TURN_DEG`] is the step check's turn on
//! the spot ([`gaitclip::detect::step_check::TURN_STEP_MIN_DEG`]), not fitted to a course.
//!
//! Also per course: the strides by gait class, |climb| per stride (the courses are level, so
//! any climb is integration error: its median, p95, max and the strides over
//! [`CLIMB_CHECK_M`]) and the strides flagged.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Deserialize;

use crate::eval::markdown::{Column, Table};
use crate::eval::stats::{median, quantile};
use crate::io::datasets;
use crate::io::trace::Ranges;
use crate::replay::{self, StrideReport};
use crate::{io::csv_trace, replay::Summary};

/// A change of direction, degrees: a turning step, or the start of the next part.
pub const TURN_DEG: f64 = gaitclip::detect::step_check::TURN_STEP_MIN_DEG as f64;
/// |climb| over this on a level course is reported (issue 45's check), m.
pub const CLIMB_CHECK_M: f64 = 0.3;

/// A course's row of `trials.csv`: the lengths walked, m.
#[derive(Clone, Debug, Deserialize)]
pub struct CourseTruth {
    /// The recording's name (`<trial>.csv`).
    pub trial: String,
    /// The whole course.
    pub course_m: f64,
    /// Slow walk to sprint.
    pub forward_m: f64,
    /// Walked backward.
    pub backward_m: f64,
    /// Walked sideways.
    pub sideways_m: f64,
}

/// The parts a course's strides fall in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Part {
    /// The first straight part.
    Forward,
    /// The second.
    Backward,
    /// Every later one.
    Sideways,
    /// A stride that turned the foot by [`TURN_DEG`] or more.
    Turning,
}

/// Each stride's part, from its heading change (degrees, counter-clockwise), in order.
pub fn split(turning_deg: &[f64]) -> Vec<Part> {
    let mut heading = 0.0;
    let mut part = 0usize;
    let mut in_part: Vec<f64> = Vec::new();
    turning_deg
        .iter()
        .map(|&turn| {
            heading += turn;
            if turn.abs() >= TURN_DEG {
                return Part::Turning;
            }
            if !in_part.is_empty() && (heading - median(&in_part)).abs() > TURN_DEG {
                part += 1;
                in_part.clear();
            }
            in_part.push(heading);
            match part {
                0 => Part::Forward,
                1 => Part::Backward,
                _ => Part::Sideways,
            }
        })
        .collect()
}

/// One course replayed: its strides and summary.
pub struct Course {
    /// Its geometry.
    pub truth: CourseTruth,
    /// Every stride, as `gaitclip replay` reports it.
    pub strides: Vec<StrideReport>,
    /// The replay's summary.
    pub summary: Summary,
}

/// Every course of the folder `dir` (`trials.csv` with the lengths, `meta.json`, one CSV
/// per trial), replayed with the shipped configuration.
pub fn courses(dir: &Path) -> Result<Vec<Course>> {
    let d = datasets::load(dir)?;
    let truths_csv = dir.join("trials.csv");
    let mut reader = csv::Reader::from_path(&truths_csv)
        .with_context(|| format!("reading {}", truths_csv.display()))?;
    let ranges = Ranges::default();
    let mut out = Vec::new();
    for row in reader.deserialize::<CourseTruth>() {
        let truth = row.with_context(|| format!("a row of {}", truths_csv.display()))?;
        let csv = dir.join(format!("{}.csv", truth.trial));
        let t = csv_trace::read(&csv, Some(d.rate_hz))?;
        let p = replay::prepare(&t, ranges)?;
        let config = p.config(ranges);
        let (strides, summary) = p.run(config);
        let strides = strides
            .into_iter()
            .map(|(s, _)| replay::report(s, config, &|n| p.clock.t_s(n)))
            .collect();
        out.push(Course {
            truth,
            strides,
            summary,
        });
    }
    Ok(out)
}

fn against(measured: f64, truth: f64) -> String {
    format!(
        "{measured:.2} / {truth:.2} ({:+.1} %)",
        100.0 * (measured - truth) / truth
    )
}

/// The table of `esangeni_course` under the datasets folder `root`.
pub fn report(root: &Path) -> Result<String> {
    let courses = courses(&root.join("esangeni_course"))?;
    let mut t = Table::new([
        Column::from("course"),
        Column::right("total m / course (error)"),
        Column::right("forward"),
        Column::right("backward"),
        Column::right("sideways"),
        Column::right("turning steps (m)"),
        Column::right("strides: walking / running / stairs / unknown"),
        Column::right("|climb| median / p95 / max m"),
        Column::right("over 0.3 m"),
        Column::right("flagged"),
    ]);
    let mut totals = Vec::new();
    for c in &courses {
        let parts = split(
            &c.strides
                .iter()
                .map(|s| s.turning_angle_deg)
                .collect::<Vec<_>>(),
        );
        let mut by_part: BTreeMap<Part, (usize, f64)> = BTreeMap::new();
        for (s, p) in c.strides.iter().zip(&parts) {
            let e = by_part.entry(*p).or_default();
            e.0 += 1;
            e.1 += s.length_m;
        }
        let part = |p: Part| by_part.get(&p).copied().unwrap_or_default();
        let gait = |g: &[&str]| c.strides.iter().filter(|s| g.contains(&s.gait)).count();
        let climbs: Vec<f64> = c.strides.iter().map(|s| s.climb_m.abs()).collect();
        let mut flags: BTreeMap<&str, usize> = BTreeMap::new();
        for f in c.strides.iter().flat_map(|s| s.flags.iter()) {
            *flags.entry(f).or_default() += 1;
        }
        let flagged = c.strides.iter().filter(|s| !s.flags.is_empty()).count();
        totals.push(100.0 * (c.summary.distance_m - c.truth.course_m) / c.truth.course_m);
        t.row([
            c.truth.trial.clone(),
            against(c.summary.distance_m, c.truth.course_m),
            format!(
                "{} ({})",
                against(part(Part::Forward).1, c.truth.forward_m),
                part(Part::Forward).0
            ),
            format!(
                "{} ({})",
                against(part(Part::Backward).1, c.truth.backward_m),
                part(Part::Backward).0
            ),
            format!(
                "{} ({})",
                against(part(Part::Sideways).1, c.truth.sideways_m),
                part(Part::Sideways).0
            ),
            format!("{} ({:.2})", part(Part::Turning).0, part(Part::Turning).1),
            format!(
                "{} / {} / {} / {}",
                gait(&["walking"]),
                gait(&["running"]),
                gait(&["stairs_up", "stairs_down"]),
                gait(&["unknown"])
            ),
            format!(
                "{:.3} / {:.3} / {:.3}",
                median(&climbs),
                quantile(&climbs, 0.95),
                climbs.iter().copied().fold(0.0, f64::max)
            ),
            climbs
                .iter()
                .filter(|&&c| c > CLIMB_CHECK_M)
                .count()
                .to_string(),
            if flagged == 0 {
                "0".into()
            } else {
                format!(
                    "{flagged}: {}",
                    flags
                        .iter()
                        .map(|(f, n)| format!("{f} {n}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            },
        ]);
    }
    let abs: Vec<f64> = totals.iter().map(|e| e.abs()).collect();
    Ok(format!(
        "`esangeni_course`, each course's reported distance (the foot pod's total: every stride with a length) against its geometry, and the parts split by the foot's heading (forward, then backward, then sideways; turning steps apart), m / m (error), (strides):\n\n{}\n|total error|: median {:.1} %, worst {:.1} % over {} courses.\n",
        t.render(),
        median(&abs),
        abs.iter().copied().fold(0.0, f64::max),
        abs.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_follow_the_heading_and_turning_steps_stand_apart() {
        // Forward with a little drift, a 180° turn in two pivots, backward, a quarter turn,
        // sideways, a half turn, sideways the other way.
        let turns = [
            2.0, -3.0, 5.0, 4.0, 20.0, -18.0, // forward (a 20° wobble is no new part)
            90.0, 85.0, // pivots
            3.0, -2.0, 1.0, // backward
            25.0, 25.0, 25.0, 20.0, // a turn spread over small steps: a new part
            -1.0, 2.0, // sideways
            170.0, 1.0, -2.0, // sideways again
        ];
        use Part::*;
        assert_eq!(
            split(&turns),
            vec![
                Forward, Forward, Forward, Forward, Forward, Forward, Turning, Turning, Backward,
                Backward, Backward, Backward, Sideways, Sideways, Sideways, Sideways, Sideways,
                Turning, Sideways, Sideways
            ]
        );
    }
}

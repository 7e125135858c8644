//! `gaitclip course`: walk-jog-run-sprint courses scored against their geometry, whole and by
//! part (`esangeni_course`: forward, then backward, then sideways, with each part's length in
//! `trials.csv`).
//!
//! A course has no per-stride truth, only the lengths walked, so the strides are split into
//! the course's parts by which way each one travelled against the foot: the core's
//! `travel_deg` (the direction of the stride's displacement from the sensor's x axis laid
//! level at its start, fixed to the foot by the mounting: a backward stride reads 180° from a
//! forward one, a sideways one 90°). The course's forward direction is the circular median
//! over its strides of at least [`MEDIAN_MIN_M`] (most of a course is walked forward); a
//! stride within [`FORWARD_MAX_DEG`] of it goes forward, beyond [`BACKWARD_MIN_DEG`] backward,
//! between them sideways. The parts follow one another (forward, backward, sideways): the
//! backward part starts at the first of [`PART_RUN`] strides in a row that go backward, the
//! sideways part at the first of as many that go sideways, and every stride belongs to the
//! part it falls in by time (a stride split in two whose halves point elsewhere stays in its
//! part). Turning steps (the foot turned by [`TURN_DEG`] or more) are counted in their part
//! and listed apart as well. The bounds halve the angles between the three directions; none
//! is fitted to a course. Until 2026-12-07 the split followed the heading summed from the
//! strides' turning angles and left turning steps out of every part: that put the sidesteps
//! after a turn outside the sideways part (−7 to −65 % where this split finds −15 to +1 %).
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
use crate::replay::{self, RejectedReport, StrideReport};
use crate::{io::csv_trace, replay::Summary};

/// A turning step turns the foot by this much or more, degrees (the step check's turn on
/// the spot).
pub const TURN_DEG: f64 = gaitclip::detect::step_check::TURN_STEP_MIN_DEG as f64;
/// A stride within this of the course's forward direction travels forward, degrees.
pub const FORWARD_MAX_DEG: f64 = 45.0;
/// A stride this far or further from it travels backward, degrees.
pub const BACKWARD_MIN_DEG: f64 = 135.0;
/// Strides this long or longer set the forward direction, m (a turning pivot's few
/// centimetres point anywhere).
pub const MEDIAN_MIN_M: f64 = 0.3;
/// Strides in a row that start the next part.
pub const PART_RUN: usize = 3;
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
}

/// Which way a stride went against the course's forward direction `forward_deg`.
pub fn direction(travel_deg: f64, forward_deg: f64) -> Part {
    let off = (travel_deg - forward_deg + 540.0).rem_euclid(360.0) - 180.0;
    if off.abs() < FORWARD_MAX_DEG {
        Part::Forward
    } else if off.abs() >= BACKWARD_MIN_DEG {
        Part::Backward
    } else {
        Part::Sideways
    }
}

/// The circular median of `angles_deg`: the one of them nearest to all the others (the least
/// sum of arc distances), which the larger group of directions decides; 0 for none.
pub fn circular_median(angles_deg: &[f64]) -> f64 {
    let arc = |a: f64, b: f64| ((a - b + 540.0).rem_euclid(360.0) - 180.0).abs();
    angles_deg
        .iter()
        .map(|&a| (angles_deg.iter().map(|&b| arc(a, b)).sum::<f64>(), a))
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map_or(0.0, |(_, a)| a)
}

/// Each stride's part, in order, from its direction of travel (`travel_deg`) and length
/// (`length_m`): see the module.
pub fn split(travel_deg: &[f64], length_m: &[f64]) -> Vec<Part> {
    let long: Vec<f64> = travel_deg
        .iter()
        .zip(length_m)
        .filter(|(_, &l)| l >= MEDIAN_MIN_M)
        .map(|(&a, _)| a)
        .collect();
    let forward = circular_median(&long);
    let dirs: Vec<Part> = travel_deg.iter().map(|&a| direction(a, forward)).collect();
    // The first of PART_RUN strides in a row going `want`, from `from` on.
    let run_start = |from: usize, want: Part| {
        (from..dirs.len()).find(|&i| {
            i + PART_RUN <= dirs.len() && dirs[i..i + PART_RUN].iter().all(|&d| d == want)
        })
    };
    let n = dirs.len();
    let backward = run_start(0, Part::Backward).unwrap_or(n);
    let sideways = run_start(backward.min(n), Part::Sideways).unwrap_or(n);
    (0..n)
        .map(|i| {
            if i < backward {
                Part::Forward
            } else if i < sideways {
                Part::Backward
            } else {
                Part::Sideways
            }
        })
        .collect()
}

/// Movements the step check refused in pairs cut where the foot never rested: the first with
/// a rest before it only, the second, straight after it, with a rest after it only. Each such
/// pair is one movement of the foot cut at a zero-velocity instant that the rest test does not
/// confirm (a stride split in two, and both halves refused): their count, and the distance
/// the halves' own integrations moved the foot, m (the sum of both halves, an upper bound).
pub fn split_refused(movements: &[RejectedReport]) -> (usize, f64) {
    movements
        .windows(2)
        .filter(|w| {
            let (a, b) = (&w[0], &w[1]);
            a.end_s == b.start_s && a.rest_before && !a.rest_after && !b.rest_before && b.rest_after
        })
        .fold((0, 0.0), |(n, m), w| {
            (n + 1, m + w[0].horizontal_m + w[1].horizontal_m)
        })
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
/// per trial), its recording prepared for the core at the default ranges.
pub fn prepared(dir: &Path) -> Result<Vec<(CourseTruth, replay::Prepared)>> {
    let d = datasets::load(dir)?;
    let truths_csv = dir.join("trials.csv");
    let mut reader = csv::Reader::from_path(&truths_csv)
        .with_context(|| format!("reading {}", truths_csv.display()))?;
    let mut out = Vec::new();
    for row in reader.deserialize::<CourseTruth>() {
        let truth = row.with_context(|| format!("a row of {}", truths_csv.display()))?;
        let t = csv_trace::read(&dir.join(format!("{}.csv", truth.trial)), Some(d.rate_hz))?;
        let p = replay::prepare(&t, Ranges::default())?;
        out.push((truth, p));
    }
    Ok(out)
}

/// Every course of the folder `dir` ([`prepared`]), replayed with the shipped configuration.
pub fn courses(dir: &Path) -> Result<Vec<Course>> {
    let ranges = Ranges::default();
    Ok(prepared(dir)?
        .into_iter()
        .map(|(truth, p)| {
            let config = p.config(ranges);
            let (strides, summary) = p.run(config);
            let strides = strides
                .into_iter()
                .map(|(s, _)| replay::report(s, config, &|n| p.clock.t_s(n)))
                .collect();
            Course {
                truth,
                strides,
                summary,
            }
        })
        .collect())
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
        Column::right("of which turning steps (m)"),
        Column::right("strides: walking / running / stairs / unknown"),
        Column::right("|climb| median / p95 / max m"),
        Column::right("over 0.3 m"),
        Column::right("flagged"),
        Column::right("refused halves of one movement (m)"),
    ]);
    let mut totals = Vec::new();
    for c in &courses {
        let parts = split(
            &c.strides.iter().map(|s| s.travel_deg).collect::<Vec<_>>(),
            &c.strides.iter().map(|s| s.length_m).collect::<Vec<_>>(),
        );
        let turning: Vec<&StrideReport> = c
            .strides
            .iter()
            .filter(|s| s.turning_angle_deg.abs() >= TURN_DEG)
            .collect();
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
        let (split, split_m) = split_refused(&c.summary.rejected_movements);
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
            format!(
                "{} ({:.2})",
                turning.len(),
                turning.iter().map(|s| s.length_m).sum::<f64>()
            ),
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
            format!("{split} ({split_m:.2})"),
        ]);
    }
    let abs: Vec<f64> = totals.iter().map(|e| e.abs()).collect();
    Ok(format!(
        "`esangeni_course`, each course's reported distance (the foot pod's total: every stride with a length) against its geometry, and the parts split by each stride's direction of travel against the foot (forward, then backward, then sideways; turning steps in their part and listed apart), m / m (error), (strides). The last column: movements the step check refused in pairs cut where the foot never rested (the first with a rest before it only, the second, straight after, with a rest after it only), one movement of the foot split at a zero-velocity instant the rest test does not confirm; both halves count nowhere, and the metres are what their own integrations moved the foot:\n\n{}\n|total error|: median {:.1} %, worst {:.1} % over {} courses.\n",
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
    fn refused_halves_are_pairs_cut_where_the_foot_never_rested() {
        let m = |start_s: f64, end_s: f64, rest: (bool, bool), horizontal_m: f64| RejectedReport {
            start_s,
            end_s,
            movement_s: (start_s, end_s),
            reason: "no_rest",
            swing_deg: 30,
            swing_peak_rad_s: 3.0,
            rest_before: rest.0,
            rest_after: rest.1,
            horizontal_m,
            climb_m: 0.0,
            lift_m: 0.0,
        };
        let (t, f) = (true, false);
        let movements = [
            m(1.0, 2.0, (t, f), 0.5),
            m(2.0, 3.0, (f, t), 0.25), // the pair: 0.75 m
            m(3.0, 4.0, (t, f), 1.0),
            m(4.5, 5.0, (f, t), 1.0), // not straight after: a moment between
            m(5.0, 6.0, (t, t), 1.0), // rested at the cut
            m(6.0, 7.0, (f, f), 1.0), // pedalling: no rest either side
            m(7.0, 8.0, (f, t), 1.0),
        ];
        assert_eq!(split_refused(&movements), (1, 0.75));
        assert_eq!(split_refused(&movements[..1]), (0, 0.0));
    }

    #[test]
    fn parts_follow_the_direction_of_travel_in_runs() {
        // Forward (mounted 100° off the sensor's x), with a split stride whose halves point
        // back; a turnaround; backward; a quarter turn; sideways one way, then the other.
        let f = 100.0;
        #[rustfmt::skip]
        let travel = [
            f + 3.0, f - 5.0, f + 2.0, f - 180.0, f + 170.0, f + 1.0, f - 2.0, f + 4.0, f - 1.0,
            f + 2.0, f + 0.0, f - 3.0, // forward, most of a course, one stride split in two
            f + 60.0, // the turnaround's pivot: in its part
            f + 178.0, f - 175.0, f + 180.0, f + 172.0, // backward
            f + 95.0, f + 88.0, f + 92.0, // sideways
            f - 90.0, f - 85.0, // sideways the other way
        ];
        let lengths = [1.2; 22];
        use Part::*;
        let parts = split(&travel, &lengths);
        assert_eq!(
            parts,
            vec![
                Forward, Forward, Forward, Forward, Forward, Forward, Forward, Forward, Forward,
                Forward, Forward, Forward, Forward, Backward, Backward, Backward, Backward,
                Sideways, Sideways, Sideways, Sideways, Sideways
            ]
        );
        assert_eq!(circular_median(&[350.0, 10.0, 5.0, -5.0, 170.0]), 5.0);
        assert_eq!(direction(f + 200.0, f), Backward);
        assert_eq!(direction(f - 50.0, f), Sideways);
        assert_eq!(direction(f + 40.0, f), Forward);
    }
}

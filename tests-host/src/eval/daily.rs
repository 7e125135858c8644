//! `gaitclip daily`: what the core counts while its wearer lives a day, on recordings of
//! daily life labelled by activity (`hugadb_daily`: walking, stairs, running, sitting,
//! standing, elevators, bicycling, a car ride as a passenger).
//!
//! A shoe clip is worn all day, so a stride counted where nobody walks is a wrong cadence
//! and a wrong distance from the first day of a study. Each foot stream is replayed through
//! the core as recorded (its own clock, its own rails), and every stride the core reports is
//! put under the activity labelled at the middle of its movement (heel-off to heel-strike:
//! the foot in the air); the core's rejected movements likewise, by reason; and the time the
//! core says the wearer spent between strides (still, or moving without walking) against
//! the labels.
//!
//! The labels are the experimenter's key presses, good to about 0.5–1 s at their boundaries:
//! a stride of the last step before standing can fall under `standing`. The counts are per
//! foot (a walker makes about 55 strides a minute per foot); nothing here judges a length
//! (the accelerometer rails at ±2 g in walking).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::eval::markdown::{Column, Table};
use crate::io::csv_trace;
use crate::io::trace::Ranges;
use crate::replay::{self, StrideReport, Summary};

/// The activities, in the order of the tables: the ones a stride belongs to first.
pub const ACTIVITIES: [&str; 12] = [
    "walking",
    "running",
    "stairs_up",
    "stairs_down",
    "standing",
    "sitting",
    "sitting_down",
    "standing_up",
    "elevator_up",
    "elevator_down",
    "sitting_in_car",
    "bicycling",
];

/// Activities where people step: a stride within [`BOUNDARY_S`] of one of these is not
/// judged false.
pub const STEPPING: [&str; 4] = ["walking", "running", "stairs_up", "stairs_down"];

/// How far from a stepping activity's segment a stride counts as false where nobody walks,
/// s: the labels' boundaries are good to 0.5–1 s (the dataset's meta.json), so the last step
/// before standing falls under `standing` as often as not.
pub const BOUNDARY_S: f64 = 1.0;

/// Activities where nobody takes a step: every stride there is a false one.
pub const NOT_WALKING: [&str; 6] = [
    "standing",
    "sitting",
    "elevator_up",
    "elevator_down",
    "sitting_in_car",
    "bicycling",
];

/// One labelled segment, s in the stream's clock.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// Start, s.
    pub from_s: f64,
    /// End, s.
    pub to_s: f64,
    /// The activity.
    pub activity: String,
}

/// One foot stream of a recording, with its labels.
#[derive(Clone, Debug)]
pub struct Stream {
    /// `<rec>/<foot>`.
    pub name: String,
    /// The CSV.
    pub csv: PathBuf,
    /// The recording's labelled segments.
    pub labels: Vec<Segment>,
}

/// The activity labelled at `t_s`, if any.
pub fn activity_at(labels: &[Segment], t_s: f64) -> Option<&str> {
    labels
        .iter()
        .find(|s| s.from_s <= t_s && t_s < s.to_s)
        .map(|s| s.activity.as_str())
}

/// Every foot stream of the dataset folder `dir` (its `trials.csv` lists them).
pub fn streams(dir: &Path) -> Result<Vec<Stream>> {
    let list = dir.join("trials.csv");
    let mut r = csv::Reader::from_path(&list).with_context(|| list.display().to_string())?;
    let mut out = Vec::new();
    let mut labels_of: BTreeMap<String, Vec<Segment>> = BTreeMap::new();
    for row in r.deserialize::<BTreeMap<String, String>>() {
        let row = row.with_context(|| list.display().to_string())?;
        let get = |k: &str| {
            row.get(k)
                .cloned()
                .with_context(|| format!("{}: no column `{k}`", list.display()))
        };
        let (rec, foot) = (get("rec")?, get("foot")?);
        if !labels_of.contains_key(&rec) {
            labels_of.insert(rec.clone(), labels(&dir.join(&rec).join("labels.csv"))?);
        }
        out.push(Stream {
            name: format!("{rec}/{foot}"),
            csv: dir.join(&rec).join(format!("{foot}_foot.csv")),
            labels: labels_of[&rec].clone(),
        });
    }
    Ok(out)
}

fn labels(path: &Path) -> Result<Vec<Segment>> {
    let mut r = csv::Reader::from_path(path).with_context(|| path.display().to_string())?;
    let mut out = Vec::new();
    for (line, row) in r.deserialize::<BTreeMap<String, String>>().enumerate() {
        let row = row.with_context(|| path.display().to_string())?;
        let num = |k: &str| -> Result<f64> {
            let v = row
                .get(k)
                .with_context(|| format!("{}: no column `{k}`", path.display()))?;
            v.trim().parse().with_context(|| {
                format!(
                    "{}:{}: `{k}` = {v:?} is not a number",
                    path.display(),
                    line + 2
                )
            })
        };
        out.push(Segment {
            from_s: num("t_start_s")?,
            to_s: num("t_end_s")?,
            activity: row
                .get("activity")
                .with_context(|| format!("{}: no column `activity`", path.display()))?
                .clone(),
        });
    }
    Ok(out)
}

/// One stream replayed.
#[derive(Clone, Debug)]
pub struct Replayed {
    /// The stream.
    pub stream: Stream,
    /// Its strides and summary, or why it could not be replayed.
    pub result: std::result::Result<(Vec<StrideReport>, Summary), String>,
}

/// Every stream of `dir` through the core, side by side on the machine's cores.
pub fn replay_all(dir: &Path) -> Result<Vec<Replayed>> {
    let streams = streams(dir)?;
    let results = crate::eval::docs::run_side_by_side(&streams, |s| {
        let r = csv_trace::read(&s.csv, None)
            .map_err(anyhow::Error::from)
            .and_then(|t| {
                Ok(replay::replay_summarised(
                    &t,
                    Ranges::default(),
                    gaitclip::pipeline::detectors::Detector::Cycle,
                    gaitclip::pipeline::config::DEFAULT_MODEL,
                    false,
                )?)
            });
        Ok(Replayed {
            stream: s.clone(),
            result: r.map_err(|e| format!("{e:#}")),
        })
    });
    results.into_iter().collect()
}

/// Where a stride's foot was in the air: the middle of its movement, s.
pub fn movement_middle_s(s: &StrideReport) -> f64 {
    (s.heel_off_s + s.heel_strike_s) / 2.0
}

/// Foot-minutes and strides per activity over `runs`.
#[derive(Clone, Debug, Default)]
pub struct ByActivity {
    /// Minutes labelled, summed over the streams replayed.
    pub minutes: BTreeMap<String, f64>,
    /// Strides reported.
    pub strides: BTreeMap<String, usize>,
    /// Of them, where nobody walks: the ones further than [`BOUNDARY_S`] from a stepping
    /// segment.
    pub false_strides: BTreeMap<String, usize>,
    /// Streams replayed, and those refused (with why).
    pub replayed: usize,
    /// Streams the core refused, with why.
    pub refused: Vec<(String, String)>,
}

/// Whether stride `s` lies within [`BOUNDARY_S`] of a segment labelled as stepping.
fn near_stepping(labels: &[Segment], s: &StrideReport) -> bool {
    labels.iter().any(|seg| {
        STEPPING.contains(&seg.activity.as_str())
            && seg.from_s - BOUNDARY_S < s.end_s
            && s.start_s < seg.to_s + BOUNDARY_S
    })
}

/// The activity stride `s` is a false one under (nobody walks there, and no stepping
/// segment lies within [`BOUNDARY_S`]), if it is one.
fn false_under<'a>(labels: &'a [Segment], s: &StrideReport) -> Option<&'a str> {
    let a = activity_at(labels, movement_middle_s(s))?;
    (NOT_WALKING.contains(&a) && !near_stepping(labels, s)).then_some(a)
}

/// Tallies `runs` by activity.
pub fn by_activity(runs: &[Replayed]) -> ByActivity {
    let mut b = ByActivity::default();
    for r in runs {
        let (strides, _) = match &r.result {
            Ok(x) => x,
            Err(e) => {
                b.refused.push((r.stream.name.clone(), e.clone()));
                continue;
            }
        };
        b.replayed += 1;
        for seg in &r.stream.labels {
            *b.minutes.entry(seg.activity.clone()).or_default() += (seg.to_s - seg.from_s) / 60.0;
        }
        for s in strides {
            if let Some(a) = activity_at(&r.stream.labels, movement_middle_s(s)) {
                *b.strides.entry(a.to_string()).or_default() += 1;
            }
            if let Some(a) = false_under(&r.stream.labels, s) {
                *b.false_strides.entry(a.to_string()).or_default() += 1;
            }
        }
    }
    b
}

/// False strides per 10 foot-minutes where nobody walks, over `b`.
pub fn false_per_10_minutes(b: &ByActivity) -> f64 {
    let (n, m) = NOT_WALKING.iter().fold((0usize, 0.0), |(n, m), a| {
        (
            n + b.false_strides.get(*a).copied().unwrap_or(0),
            m + b.minutes.get(*a).copied().unwrap_or(0.0),
        )
    });
    if m > 0.0 {
        10.0 * n as f64 / m
    } else {
        0.0
    }
}

/// The Markdown report of `dir` (`gaitclip daily`).
pub fn report(dir: &Path) -> Result<String> {
    let runs = replay_all(dir)?;
    let b = by_activity(&runs);
    let mut out = String::new();
    out.push_str(&format!(
        "{} foot streams replayed of {}",
        b.replayed,
        runs.len()
    ));
    if b.refused.is_empty() {
        out.push_str(".\n\n");
    } else {
        out.push_str("; refused:\n\n");
        for (name, why) in &b.refused {
            out.push_str(&format!("- `{name}`: {why}\n"));
        }
        out.push('\n');
    }
    out.push_str("Strides the core reports, by the activity labelled at the middle of each stride's movement (per foot):\n\n");
    let mut t = Table::new(vec![
        Column::from("activity"),
        Column::right("foot-minutes"),
        Column::right("strides"),
        Column::right("per minute"),
        Column::right(format!("false (over {BOUNDARY_S} s from stepping)")),
    ]);
    for a in ACTIVITIES {
        let m = b.minutes.get(a).copied().unwrap_or(0.0);
        if m <= 0.0 {
            continue;
        }
        let n = b.strides.get(a).copied().unwrap_or(0);
        let name = if NOT_WALKING.contains(&a) {
            format!("{a} (nobody walks)")
        } else {
            a.to_string()
        };
        t.row(vec![
            name,
            format!("{m:.1}"),
            n.to_string(),
            format!("{:.1}", n as f64 / m),
            if NOT_WALKING.contains(&a) {
                b.false_strides.get(a).copied().unwrap_or(0).to_string()
            } else {
                String::new()
            },
        ]);
    }
    out.push_str(&t.render());
    out.push_str(&format!(
        "\nWhere nobody walks: {:.2} false strides per 10 foot-minutes.\n",
        false_per_10_minutes(&b)
    ));
    out.push_str(&false_strides_table(&runs));
    out.push_str("\nMovements the step check refused, by the activity labelled at their middle (they count nowhere: no stride, no distance):\n\n");
    let mut t = Table::new(
        std::iter::once(Column::from("activity")).chain(
            gaitclip::detect::step_check::Rejection::ALL
                .iter()
                .map(|r| Column::right(format!("`{}`", r.name()))),
        ),
    );
    let refused = refused_by_activity(&runs);
    for a in ACTIVITIES {
        let Some(n) = refused.get(a) else { continue };
        t.row(std::iter::once(a.to_string()).chain(n.iter().map(|v| v.to_string())));
    }
    out.push_str(&t.render());
    out.push_str("\nWhat the core says the wearer did, by labelled activity (% of the labelled time: in strides by the stride's own class, and between strides at rest or moving without a step):\n\n");
    let mut t = Table::new(vec![
        Column::from("activity"),
        Column::right("minutes"),
        Column::right("walking"),
        Column::right("running"),
        Column::right("stairs up"),
        Column::right("stairs down"),
        Column::right("still"),
        Column::right("moving, not walking"),
    ]);
    let time = time_by_activity(&runs);
    for a in ACTIVITIES {
        let Some(v) = time.get(a) else { continue };
        let total: f64 = v.iter().sum();
        if total <= 0.0 {
            continue;
        }
        let mut row = vec![a.to_string(), format!("{:.1}", total / 60.0)];
        row.extend(v.iter().map(|x| format!("{:.0} %", 100.0 * x / total)));
        t.row(row);
    }
    out.push_str(&t.render());
    Ok(out)
}

/// How close a stride of the other foot must be for the two to be one stepping moment, s:
/// half a walking stride either side.
pub const OTHER_FOOT_S: f64 = 1.5;

/// The false strides one by one, with what the stride looked like and whether the other foot
/// stepped at the same moment (a wearer turning round in an elevator steps with both feet:
/// steps, whatever the label).
fn false_strides_table(runs: &[Replayed]) -> String {
    let mut t = Table::new(vec![
        Column::from("stream"),
        Column::from("activity"),
        Column::right("at, s"),
        Column::right("swing, °"),
        Column::right("moved, m"),
        Column::right("lift, m"),
        Column::right("turn, °"),
        Column::right("still / moving before, s"),
        Column::from("other foot"),
    ]);
    let mut n = 0;
    for r in runs {
        let Ok((strides, _)) = &r.result else {
            continue;
        };
        let rec = r.stream.name.split('/').next().unwrap_or_default();
        let other: Vec<f64> = runs
            .iter()
            .filter(|o| {
                o.stream.name != r.stream.name && o.stream.name.starts_with(&format!("{rec}/"))
            })
            .filter_map(|o| o.result.as_ref().ok())
            .flat_map(|(ss, _)| ss.iter().map(movement_middle_s))
            .collect();
        for s in strides {
            let Some(a) = false_under(&r.stream.labels, s) else {
                continue;
            };
            let at = movement_middle_s(s);
            n += 1;
            let stepped = other.iter().any(|o| (o - at).abs() <= OTHER_FOOT_S);
            t.row(vec![
                format!("`{}`", r.stream.name),
                a.to_string(),
                format!("{at:.1}"),
                s.swing_deg.to_string(),
                format!("{:.2}", s.zupt_m),
                format!("{:.2}", s.max_sensor_lift_m),
                format!("{:+.0}", s.turning_angle_deg),
                format!("{:.1} / {:.1}", s.still_before_s, s.moving_before_s),
                if stepped { "stepped" } else { "–" }.to_string(),
            ]);
        }
    }
    if n == 0 {
        return String::new();
    }
    format!(
        "\nThe false strides one by one (other foot: a stride of the other foot within {OTHER_FOOT_S} s):\n\n{}",
        t.render()
    )
}

/// Refused movements of every stream, by labelled activity, counted by reason.
fn refused_by_activity(runs: &[Replayed]) -> BTreeMap<String, [u32; 4]> {
    let mut out: BTreeMap<String, [u32; 4]> = BTreeMap::new();
    for r in runs {
        let Ok((_, summary)) = &r.result else {
            continue;
        };
        for m in &summary.rejected_movements {
            let Some(a) = activity_at(&r.stream.labels, (m.start_s + m.end_s) / 2.0) else {
                continue;
            };
            let k = gaitclip::detect::step_check::Rejection::ALL
                .iter()
                .position(|x| x.name() == m.reason)
                .unwrap_or(0);
            out.entry(a.to_string()).or_default()[k] += 1;
        }
    }
    out
}

/// Seconds of each labelled activity the core spent, per stream and summed: in strides
/// (walking — unknown strides, one not a whole cycle, count as walking —, running, stairs up,
/// stairs down) and between them (still, moving), in that order.
fn time_by_activity(runs: &[Replayed]) -> BTreeMap<String, [f64; 6]> {
    let mut out: BTreeMap<String, [f64; 6]> = BTreeMap::new();
    for r in runs {
        let Ok((strides, summary)) = &r.result else {
            continue;
        };
        let labels = &r.stream.labels;
        let mut spans: Vec<(f64, f64, usize, f64)> = Vec::new();
        let mut last_end = labels.first().map_or(0.0, |s| s.from_s);
        let (mut still, mut moving) = (0.0, 0.0);
        for s in strides {
            let between = s.still_before_s + s.moving_before_s;
            if between > 0.0 && s.start_s > last_end {
                spans.push((last_end, s.start_s, 4, s.still_before_s / between));
            }
            still += s.still_before_s;
            moving += s.moving_before_s;
            let k = match s.gait {
                "running" => 1,
                "stairs_up" => 2,
                "stairs_down" => 3,
                _ => 0,
            };
            spans.push((s.start_s, s.end_s, k, 1.0));
            last_end = last_end.max(s.end_s);
        }
        // After the last stride: what the summary holds beyond the strides' own.
        let (tail_still, tail_moving) = (
            summary.still_min * 60.0 - still,
            summary.moving_min * 60.0 - moving,
        );
        let end = labels.last().map_or(last_end, |s| s.to_s);
        if tail_still + tail_moving > 0.0 && end > last_end {
            spans.push((
                last_end,
                end,
                4,
                (tail_still / (tail_still + tail_moving)).clamp(0.0, 1.0),
            ));
        }
        for seg in labels {
            let v = out.entry(seg.activity.clone()).or_default();
            for &(a, b, k, still_share) in &spans {
                let o = (b.min(seg.to_s) - a.max(seg.from_s)).max(0.0);
                if k == 4 {
                    v[4] += o * still_share;
                    v[5] += o * (1.0 - still_share);
                } else {
                    v[k] += o;
                }
            }
        }
    }
    out
}

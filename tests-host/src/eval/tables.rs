//! The Markdown tables of `gaitclip eval`: detection, events and phases per dataset, the
//! recordings as read, and the detectors side by side.

use std::fmt::Write as _;

use anyhow::{Context, Result};

use crate::io::csv_trace;
use crate::io::trace::Ranges;

use crate::eval::markdown::{Column, Table};
use crate::eval::matching::{mean, ratio, PhaseTally, Tally};
use crate::eval::scoring::DatasetResult;
use crate::eval::stats::{abs_quantile, median};
use crate::io::datasets::Dataset;

fn fmt3(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else {
        format!("{v:.3}")
    }
}

fn fmt_ms(v: &[f64]) -> String {
    if v.is_empty() {
        "–".into()
    } else {
        format!(
            "{:.0} / {:.0} ({:+.0})",
            abs_quantile(v, 0.5),
            abs_quantile(v, 0.95),
            median(v)
        )
    }
}

/// The columns [`detection_cells`] fills.
const DETECTION_COLUMNS: [&str; 8] = [
    "found",
    "extra",
    "missed",
    "not scored",
    "unbordered movements",
    "precision",
    "recall",
    "F1",
];

/// The cells `found | extra | missed | not scored | unbordered | precision | recall | F1`
/// of a tally.
fn detection_cells(t: &Tally) -> [String; 8] {
    [
        t.tp.to_string(),
        t.fp.to_string(),
        t.fn_.to_string(),
        t.unscored.to_string(),
        t.unbordered.to_string(),
        fmt3(t.precision()),
        fmt3(t.recall()),
        fmt3(t.f1()),
    ]
}

fn phase_cell(p: &PhaseTally) -> String {
    if p.labelled {
        format!("{} / {}", fmt3(p.f_score()), fmt3(p.mean_iou()))
    } else {
        "–".into()
    }
}

/// The Markdown table: one row per dataset and an overall row; with rotations, one more
/// table of the rotated runs pooled and the largest change of any rotation.
pub fn table(results: &[DatasetResult]) -> String {
    let header = || {
        let mut h: Vec<&str> = vec!["dataset", "trials", "clean strides"];
        h.extend(DETECTION_COLUMNS);
        h.extend([
            "toe-off |error| ms: median / p95 (signed median)",
            "heel-strike |error| ms: median / p95 (signed median)",
            "swing F / IoU",
            "contact F / IoU",
            "stance F1",
            "zero-velocity instants in a Vicon stance",
        ]);
        Table::new(h)
    };
    let row = |t: &mut Table, name: &str, y: &Tally| {
        let mut r = vec![name.to_string(), y.trials.to_string(), y.clean.to_string()];
        r.extend(detection_cells(y));
        r.extend([
            fmt_ms(&y.toe_off_ms),
            fmt_ms(&y.heel_strike_ms),
            phase_cell(&y.swing),
            phase_cell(&y.contact),
            y.stance_f1().map_or("–".into(), fmt3),
            y.instants.map_or("–".into(), |(i, n)| {
                format!("{i} / {n} ({:.1} %)", 100.0 * ratio(i as f64, n as f64))
            }),
        ]);
        t.row(r);
    };
    let mut t = header();
    let mut overall = Tally::default();
    for r in results {
        row(&mut t, &r.name, &r.tally);
        overall.add(&r.tally);
    }
    if results.len() > 1 {
        row(&mut t, "**overall**", &overall);
    }
    let mut s = t.render();
    let n = results.first().map_or(0, |r| r.rotated.len());
    if n > 0 {
        let _ = writeln!(s, "\nAfter {n} random rotations of every trace (pooled):\n");
        let mut t = header();
        let mut overall = Tally::default();
        for r in results {
            let mut pooled = Tally::default();
            for x in &r.rotated {
                pooled.add(x);
            }
            row(&mut t, &r.name, &pooled);
            overall.add(&pooled);
        }
        if results.len() > 1 {
            row(&mut t, "**overall**", &overall);
        }
        s.push_str(&t.render());
        let _ = writeln!(
            s,
            "\nLargest change of any single rotation from the unrotated figures:\n"
        );
        let mut t = Table::new([
            "dataset",
            "F1",
            "toe-off median ms",
            "heel-strike median ms",
            "swing IoU",
            "stance F1",
        ]);
        for r in results {
            let y = &r.tally;
            let d = |f: &dyn Fn(&Tally) -> f64| {
                r.rotated
                    .iter()
                    .map(|x| (f(x) - f(y)).abs())
                    .filter(|v| !v.is_nan())
                    .fold(0.0f64, f64::max)
            };
            t.row([
                r.name.clone(),
                format!("{:.3}", d(&|x| x.f1())),
                format!("{:.1}", d(&|x| abs_quantile(&x.toe_off_ms, 0.5))),
                format!("{:.1}", d(&|x| abs_quantile(&x.heel_strike_ms, 0.5))),
                format!("{:.3}", d(&|x| x.swing.mean_iou())),
                if y.stance.is_some() {
                    format!("{:.3}", d(&|x| x.stance_f1().unwrap_or(f64::NAN)))
                } else {
                    "–".into()
                },
            ]);
        }
        s.push_str(&t.render());
    }
    s
}

/// What each folder holds and what its truth scores ([`crate::io::datasets::Truth`]).
pub fn truth_table(dirs: &[std::path::PathBuf], datasets: &[Dataset]) -> String {
    let mut table = Table::new([
        Column::from("dataset"),
        Column::right("recordings"),
        Column::right("reference strides or steps"),
        Column::from("truth: what it scores"),
    ]);
    for (dir, d) in dirs.iter().zip(datasets) {
        table.row([
            d.name.clone(),
            d.trials.len().to_string(),
            d.trials
                .iter()
                .map(|t| t.references.len())
                .sum::<usize>()
                .to_string(),
            crate::io::datasets::truth_of(dir).scores().to_string(),
        ]);
    }
    table.render()
}

/// What the recordings' stamps and holes cost, per dataset: the replay's summaries
/// ([`crate::replay::Summary`]) of every trial added up.
pub fn data_table(datasets: &[Dataset]) -> Result<String> {
    let mut table = Table::new([
        Column::from("dataset"),
        Column::right("trials"),
        Column::right("samples read"),
        Column::right("repeated samples dropped"),
        Column::right("trials with holes"),
        Column::from("holes (samples lost)"),
        Column::from("bridged holes (samples)"),
        Column::from("gap holes: filled / restart (samples)"),
        Column::right("strides"),
        Column::right("bridged strides"),
        Column::right("gap strides"),
        Column::from("trials re-timed (stamps off the clock)"),
        Column::from(CLIMB_COLUMN),
    ]);
    for d in datasets {
        let mut t = crate::replay::Summary::default();
        let (mut holed, mut retimed) = (0, 0);
        let mut climbs = Vec::new();
        for trial in &d.trials {
            let trace = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
            let p = crate::replay::prepare(&trace, Ranges::default())
                .with_context(|| format!("{}", trial.csv.display()))?;
            let (strides, one) = p.run(p.config(Ranges::default()));
            climbs.extend(
                strides
                    .iter()
                    .map(|(s, _)| s.climb_mm.unsigned_abs() as f64 / 1000.0),
            );
            holed += (one.holes > 0) as usize;
            retimed += (one.retimed_stamps > 0) as usize;
            t.add(&one);
        }
        table.row([
            d.name.clone(),
            d.trials.len().to_string(),
            t.samples_read.to_string(),
            t.repeated_dropped.to_string(),
            holed.to_string(),
            format!("{} ({})", t.holes, t.lost_samples),
            format!("{} ({})", t.bridged, t.bridged_samples),
            format!(
                "{} / {} ({})",
                t.gaps_filled,
                t.gaps - t.gaps_filled,
                t.gap_samples
            ),
            t.strides.to_string(),
            t.bridged_strides.to_string(),
            t.gap_strides.to_string(),
            format!("{retimed} ({})", t.retimed_stamps),
            climb_cell(&climbs),
        ]);
    }
    Ok(table.render())
}

/// The climb check's column: a stride's height gained is integration error on the level and
/// a riser or two on stairs, so its spread says how physical the strides are.
const CLIMB_COLUMN: &str = "|climb| per stride, m: median / p95 / max (strides over 0.3 m)";

fn climb_cell(climbs_m: &[f64]) -> String {
    if climbs_m.is_empty() {
        return "–".into();
    }
    format!(
        "{:.3} / {:.3} / {:.3} ({})",
        crate::eval::stats::median(climbs_m),
        crate::eval::stats::quantile(climbs_m, 0.95),
        climbs_m.iter().copied().fold(0.0, f64::max),
        climbs_m
            .iter()
            .filter(|&&c| c > crate::eval::course::CLIMB_CHECK_M)
            .count()
    )
}

/// Step detection side by side: one row per dataset and detector (the `Tally` of each, as
/// recorded), with Lu's eq. 13 step-count error as the mean over trials and pooled.
pub fn detectors_table(rows: &[(&str, &str, &Tally)]) -> String {
    let mut h: Vec<&str> = vec!["dataset", "detector", "strides (all / clean)", "detected"];
    h.extend(DETECTION_COLUMNS);
    h.extend([
        "count error (eq. 13): mean of trials / pooled",
        "too long (merged)",
    ]);
    let mut table = Table::new(h);
    for (dataset, detector, t) in rows {
        let pct = |v: f64| {
            if v.is_nan() {
                "–".to_string()
            } else {
                format!("{:.1} %", 100.0 * v)
            }
        };
        let mut r = vec![
            dataset.to_string(),
            detector.to_string(),
            format!("{} / {}", t.references, t.clean),
            t.detected.to_string(),
        ];
        r.extend(detection_cells(t));
        r.push(format!(
            "{} / {}",
            pct(mean(&t.count_errors)),
            pct(t.pooled_count_error())
        ));
        r.push(t.too_long.to_string());
        table.row(r);
    }
    table.render()
}

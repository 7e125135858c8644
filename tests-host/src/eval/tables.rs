//! The Markdown tables of `gaitclip eval`: detection, events and phases per dataset, the
//! recordings as read, and the detectors side by side.

use std::fmt::Write as _;

use anyhow::{Context, Result};

use crate::io::csv_trace;
use crate::io::trace::Ranges;

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

/// The cells `found | extra | missed | not scored | unbordered | precision | recall | F1`
/// of a tally.
fn detection_cells(t: &Tally) -> String {
    format!(
        "{} | {} | {} | {} | {} | {} | {} | {}",
        t.tp,
        t.fp,
        t.fn_,
        t.unscored,
        t.unbordered,
        fmt3(t.precision()),
        fmt3(t.recall()),
        fmt3(t.f1())
    )
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
    let mut s = String::new();
    let header = "| dataset | trials | clean strides | found | extra | missed | not scored | unbordered movements | precision | recall | F1 | toe-off \\|error\\| ms: median / p95 (signed median) | heel-strike \\|error\\| ms: median / p95 (signed median) | swing F / IoU | contact F / IoU | stance F1 | zero-velocity instants in a Vicon stance |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let row = |s: &mut String, name: &str, t: &Tally| {
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            t.trials,
            t.clean,
            detection_cells(t),
            fmt_ms(&t.toe_off_ms),
            fmt_ms(&t.heel_strike_ms),
            phase_cell(&t.swing),
            phase_cell(&t.contact),
            t.stance_f1().map_or("–".into(), fmt3),
            t.instants.map_or("–".into(), |(i, n)| format!(
                "{i} / {n} ({:.1} %)",
                100.0 * ratio(i as f64, n as f64)
            )),
        );
    };
    s.push_str(header);
    let mut overall = Tally::default();
    for r in results {
        row(&mut s, &r.name, &r.tally);
        overall.add(&r.tally);
    }
    if results.len() > 1 {
        row(&mut s, "**overall**", &overall);
    }
    let n = results.first().map_or(0, |r| r.rotated.len());
    if n > 0 {
        let _ = writeln!(s, "\nAfter {n} random rotations of every trace (pooled):\n");
        s.push_str(header);
        let mut overall = Tally::default();
        for r in results {
            let mut pooled = Tally::default();
            for t in &r.rotated {
                pooled.add(t);
            }
            row(&mut s, &r.name, &pooled);
            overall.add(&pooled);
        }
        if results.len() > 1 {
            row(&mut s, "**overall**", &overall);
        }
        let _ = writeln!(
            s,
            "\nLargest change of any single rotation from the unrotated figures:\n\n| dataset | F1 | toe-off median ms | heel-strike median ms | swing IoU | stance F1 |\n|---|---|---|---|---|---|"
        );
        for r in results {
            let t = &r.tally;
            let d = |f: &dyn Fn(&Tally) -> f64| {
                r.rotated
                    .iter()
                    .map(|x| (f(x) - f(t)).abs())
                    .filter(|v| !v.is_nan())
                    .fold(0.0f64, f64::max)
            };
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.1} | {:.1} | {:.3} | {} |",
                r.name,
                d(&|x| x.f1()),
                d(&|x| abs_quantile(&x.toe_off_ms, 0.5)),
                d(&|x| abs_quantile(&x.heel_strike_ms, 0.5)),
                d(&|x| x.swing.mean_iou()),
                if t.stance.is_some() {
                    format!("{:.3}", d(&|x| x.stance_f1().unwrap_or(f64::NAN)))
                } else {
                    "–".into()
                },
            );
        }
    }
    s
}

/// What the recordings' stamps and holes cost, per dataset: the replay's summaries
/// ([`crate::replay::Summary`]) of every trial added up.
pub fn data_table(datasets: &[Dataset]) -> Result<String> {
    let mut s = String::from(
        "| dataset | trials | samples read | repeated samples dropped | trials with holes | holes (samples lost) | bridged holes (samples) | gap holes: filled / restart (samples) | strides | bridged strides | gap strides | trials re-timed (stamps off the clock) |\n|---|---:|---:|---:|---:|---|---|---|---:|---:|---:|---|\n",
    );
    for d in datasets {
        let mut t = crate::replay::Summary::default();
        let (mut holed, mut retimed) = (0, 0);
        for trial in &d.trials {
            let trace = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
            let p = crate::replay::prepare(&trace, Ranges::default())
                .with_context(|| format!("{}", trial.csv.display()))?;
            let (_, one) = p.run(p.config(Ranges::default()));
            holed += (one.holes > 0) as usize;
            retimed += (one.retimed_stamps > 0) as usize;
            t.add(&one);
        }
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {holed} | {} ({}) | {} ({}) | {} / {} ({}) | {} | {} | {} | {retimed} ({}) |",
            d.name,
            d.trials.len(),
            t.samples_read,
            t.repeated_dropped,
            t.holes,
            t.lost_samples,
            t.bridged,
            t.bridged_samples,
            t.gaps_filled,
            t.gaps - t.gaps_filled,
            t.gap_samples,
            t.strides,
            t.bridged_strides,
            t.gap_strides,
            t.retimed_stamps,
        );
    }
    Ok(s)
}

/// Step detection side by side: one row per dataset and detector (the `Tally` of each, as
/// recorded), with Lu's eq. 13 step-count error as the mean over trials and pooled.
pub fn detectors_table(rows: &[(&str, &str, &Tally)]) -> String {
    let mut s = String::from(
        "| dataset | detector | strides (all / clean) | detected | found | extra | missed | not scored | unbordered movements | precision | recall | F1 | count error (eq. 13): mean of trials / pooled | too long (merged) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (dataset, detector, t) in rows {
        let pct = |v: f64| {
            if v.is_nan() {
                "–".to_string()
            } else {
                format!("{:.1} %", 100.0 * v)
            }
        };
        let _ = writeln!(
            s,
            "| {dataset} | {detector} | {} / {} | {} | {} | {} / {} | {} |",
            t.references,
            t.clean,
            t.detected,
            detection_cells(t),
            pct(mean(&t.count_errors)),
            pct(t.pooled_count_error()),
            t.too_long,
        );
    }
    s
}

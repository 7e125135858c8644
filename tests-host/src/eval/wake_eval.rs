//! Does the clip's wake-up rule catch real walks, and does it keep still through real stands?
//! (`gaitclip wake`, `tests/sleep_policy.rs`.)
//!
//! On every recording of the datasets, the pipeline's rest test marks where the wearer
//! stood still. For every stand of at least [`MIN_STAND_S`] that a movement ends, the sensor
//! is put to sleep as the firmware would at the stand's start (its cycle mode waking every
//! wake period on its own clock, [`gaitclip_board::replay_mpu6050::motion_between`] at the
//! firmware's threshold) and the first wake-up is compared with the movement's start (the
//! first sample the rest test calls moving):
//!
//! * **woke early**: a wake-up more than [`EARLY_S`] before the movement, inside the stand:
//!   sway, a shuffle of the foot (the firmware then sleeps again after its still period);
//! * **latency**: how far into the movement the first wake-up came, the part of the first
//!   step the firmware does not sample;
//! * **slept through**: no wake-up within [`MISSED_S`] of the movement's start: a walk whose
//!   first stride would be lost entirely.

use std::path::Path;

use anyhow::{Context, Result};
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip_board::replay_mpu6050::{mg_to_counts, motion_between, REPLAY_MOTION_UNIT};
use gaitclip_board::sleep::SLEEP;

use crate::eval::markdown::{Column, Table};
use crate::io::datasets;
use crate::io::trace::Ranges;

/// Stands shorter than this are not looked at (a walking stance lasts under 1 s).
pub const MIN_STAND_S: f64 = 2.0;
/// A wake-up this long before the movement counts as early.
pub const EARLY_S: f64 = 0.5;
/// No wake-up this long into the movement: slept through the first stride.
pub const MISSED_S: f64 = 1.0;
/// A stand counts when the pipeline's first stride after it starts within this long of the
/// movement (a walk follows, not a shuffle before the recording ends).
pub const WALK_WITHIN_S: f64 = 2.0;

/// What the wake rule did at the stands of one dataset.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WakeResult {
    /// Dataset name.
    pub dataset: String,
    /// The wake threshold, mg.
    pub threshold_mg: u32,
    /// Stands a walk ends.
    pub stands: usize,
    /// Stands with a wake-up more than [`EARLY_S`] before the movement.
    pub woke_early: usize,
    /// Of the others, latency from the movement's start to the wake-up, s (negative: up
    /// to [`EARLY_S`] before it).
    pub latencies_s: Vec<f64>,
    /// Movements with no wake-up within [`MISSED_S`].
    pub slept_through: usize,
}

/// The wake rule at every stand of the dataset in `dir`, at the firmware's threshold.
pub fn evaluate(dir: &Path) -> Result<WakeResult> {
    evaluate_at(dir, SLEEP.wake.threshold.mg(REPLAY_MOTION_UNIT))
}

/// [`evaluate`] with a threshold of `threshold_mg`.
pub fn evaluate_at(dir: &Path, threshold_mg: u32) -> Result<WakeResult> {
    let ds = datasets::load(dir)?;
    let mut out = WakeResult {
        dataset: ds.name.clone(),
        threshold_mg,
        ..WakeResult::default()
    };
    let ranges = Ranges::default();
    let threshold = mg_to_counts(threshold_mg, ranges.accel.afs_sel());
    for trial in &ds.trials {
        let trace = crate::io::csv_trace::read(&trial.csv, Some(ds.rate_hz))
            .with_context(|| trial.csv.display().to_string())?;
        let rate = trace.sample_rate().context("trace rate")?;
        let counts: Vec<_> = trace.samples.iter().map(ranges.converter()).collect();
        let mut p = Pipeline::new(Config::new(rate, ranges.accel.scale(), ranges.gyro.scale()));
        let mut stride_starts = Vec::new();
        let mut rest: Vec<bool> = Vec::with_capacity(counts.len());
        for s in &counts {
            stride_starts.extend(p.process(s).map(|st| st.events.start as usize));
            rest.push(p.at_rest());
        }
        stride_starts.extend(std::iter::from_fn(|| p.finish()).map(|st| st.events.start as usize));
        let hz = ds.rate_hz;
        let period =
            ((hz / (f64::from(SLEEP.wake.rate.millihertz()) / 1000.0)).round() as usize).max(1);
        let mut k = 0;
        while k < rest.len() {
            if !rest[k] {
                k += 1;
                continue;
            }
            let start = k;
            while k < rest.len() && rest[k] {
                k += 1;
            }
            let moved = k;
            if moved >= rest.len() || ((moved - start) as f64) < MIN_STAND_S * hz {
                continue;
            }
            // Inside the labelled walk (its first stand included), where the dataset says:
            // not the shuffling after a recording's walk has ended.
            let t_moved = trace.samples[moved].t_s;
            let (from_s, to_s) = trial
                .span_s
                .unwrap_or((trial.span.0 as f64 / hz, trial.span.1 as f64 / hz));
            if t_moved < from_s - WALK_WITHIN_S || t_moved > to_s {
                continue;
            }
            // A walk, not a shuffle at the end: a stride leaves this stand.
            let near =
                |i: usize| i + hz as usize >= moved && i <= moved + (WALK_WITHIN_S * hz) as usize;
            if !stride_starts.iter().any(|&i| near(i)) {
                continue;
            }
            out.stands += 1;
            // Asleep from the stand's start; wake-ups on the sensor's own grid.
            let mut t = start.div_ceil(period) * period + period;
            let woke = loop {
                if t >= counts.len() {
                    break None;
                }
                if motion_between(counts[t - period].accel, counts[t].accel, threshold) {
                    break Some(t);
                }
                t += period;
            };
            let latency = woke.map(|t| (t as f64 - moved as f64) / hz);
            match latency {
                Some(l) if l < -EARLY_S => out.woke_early += 1,
                Some(l) if l <= MISSED_S => out.latencies_s.push(l),
                _ => out.slept_through += 1,
            }
        }
    }
    Ok(out)
}

/// [`evaluate`] on each dataset of `root` with stands, at the firmware's threshold and,
/// for comparison, at the other counts of the 32 mg unit; a Markdown table. Returns the
/// firmware threshold's results too.
pub fn report(root: &Path) -> Result<(Vec<WakeResult>, String)> {
    let firmware = SLEEP.wake.threshold.mg(REPLAY_MOTION_UNIT);
    let mut results = Vec::new();
    let mut rows = Vec::new();
    for name in ["pyshoe_vicon", "ipol_gait_events"] {
        for mg in [32, 64, 96, 128, 160] {
            let r = evaluate_at(&root.join(name), mg)?;
            if mg == firmware {
                results.push(r.clone());
            }
            rows.push(r);
        }
    }
    let mut table = Table::new([
        Column::from("dataset"),
        Column::right("threshold, mg"),
        Column::right(format!("stands ≥ {MIN_STAND_S} s ended by a walk")),
        Column::right(format!("woke > {EARLY_S} s early")),
        Column::right("latency median, ms"),
        Column::right("latency 90th pct, ms"),
        Column::right(format!("slept through the first {MISSED_S} s")),
    ]);
    for r in &rows {
        let mut l = r.latencies_s.clone();
        l.sort_by(f64::total_cmp);
        let q = |f: f64| {
            l.get(((l.len() as f64 - 1.0) * f).round() as usize)
                .map_or(f64::NAN, |v| v * 1000.0)
        };
        let mark = if r.threshold_mg == firmware {
            " (firmware)"
        } else {
            ""
        };
        table.row([
            r.dataset.to_string(),
            format!("{}{mark}", r.threshold_mg),
            r.stands.to_string(),
            r.woke_early.to_string(),
            format!("{:.0}", q(0.5)),
            format!("{:.0}", q(0.9)),
            r.slept_through.to_string(),
        ]);
    }
    let o = table.render();
    Ok((results, o))
}

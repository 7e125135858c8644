//! `gaitclip gait`: the per-stride gait parameters ([`gaitclip::gait`]) against the references
//! that have them.
//!
//! Strides are the core's (the default configuration, as the firmware runs), matched to the
//! reference strides as `gaitclip eval` matches them ([`crate::eval::matching`]); only clean matched
//! strides are compared.
//!
//! - **Times** (`gaitmap_walk`, `ipol_gait_events`): the reference stride time is heel-strike
//!   to heel-strike (`ic − pre_ic`, gaitmap's definition), swing `ic − tc`, stance
//!   `tc − pre_ic`; ours are the stride's own (`end − start`, `heel_strike − toe_off`, their
//!   difference). Cadence from each stride time (120 / s), stance as % of each.
//! - **Velocity and lift** (`pyshoe_vicon`): over the detected stride's own interval, the
//!   Vicon foot marker's horizontal displacement per stride time, and its highest point above
//!   where it started; ours are `gait_velocity` and `max_sensor_lift`. The marker is not the
//!   sensor: on a foot pitching 30–40° in the swing, a few cm between them move the top by
//!   some mm either way.
//! - **Turning** (`gaitmap_walk`, `ipol_gait_events`): every walk has one U-turn, so the
//!   heading changes of a trial's strides add up to ±180°; a clean straight stride turns by 0.
//! - **Walking or running** (`pyshoe_vicon`, which labels no gait): by the Vicon speed (over
//!   2.5 m/s runs, under 1.5 m/s walks), and by the Vicon stride's cadence (its duration, end of
//!   stance to end of stance): under [`WALKING_UNDER_SPM`] walks, over [`RUNNING_OVER_SPM`]
//!   runs. The cadence tells what the speed cannot in a 3 × 3 m room: the `2017-11-27` trials
//!   jog at 1.1–1.5 m/s with 140–160 steps/min, where the `2017-11-22` walks at the same
//!   speeds take 100–120.
//!
//! Errors are ours minus the reference, by pace: `gaitmap_walk` and `ipol_gait_events` are
//! walks at the subjects' own speed; `pyshoe_vicon` strides are binned by their Vicon speed.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use anyhow::Result;
use gaitclip::record::gait::Gait;
use gaitclip::record::stride::Stride;

use crate::eval::markdown::{Column, Table};
use crate::eval::matching::{classify, Detected, Scored};
use crate::eval::stats::{abs_quantile, median};
use crate::io::csv_trace;
use crate::io::datasets::{Dataset, Trial};
use crate::io::trace::Ranges;
use crate::replay;

/// Vicon speed above which a `pyshoe_vicon` stride is a run, m/s (the bound).
pub const RUNNING_OVER_M_S: f64 = 2.5;
/// Vicon speed under which a `pyshoe_vicon` stride is a walk, m/s.
pub const WALKING_UNDER_M_S: f64 = 1.5;
/// Cadence of the Vicon stride under which a `pyshoe_vicon` stride is a walk, steps/min, and
/// over which it is a run (the dataset's walks take 100–120, its jogs 140–160).
pub const WALKING_UNDER_SPM: f64 = 125.0;
/// See [`WALKING_UNDER_SPM`].
pub const RUNNING_OVER_SPM: f64 = 140.0;

/// One compared parameter of one stride.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// gaitmap's name of the parameter.
    pub parameter: &'static str,
    /// Its unit in the table.
    pub unit: &'static str,
    /// Dataset.
    pub dataset: String,
    /// Pace bin.
    pub pace: &'static str,
    /// Ours.
    pub ours: f64,
    /// The reference.
    pub reference: f64,
}

/// What a dataset's strides gave.
#[derive(Clone, Debug, Default)]
pub struct GaitResult {
    /// Every comparison.
    pub comparisons: Vec<Comparison>,
    /// Per trial (`gaitmap_walk`, `ipol_gait_events`): |Σ turning angle| of the strides in the
    /// labelled span, degrees (reference 180).
    pub trial_turns: Vec<(String, f64)>,
    /// `pyshoe_vicon`: (Vicon class, our status) counts, the class `walking` (< 1.5 m/s) or
    /// `running` (> 2.5 m/s).
    pub status: BTreeMap<(&'static str, &'static str), usize>,
    /// `pyshoe_vicon`: (Vicon cadence class, our status) counts, the class `walking` (under
    /// [`WALKING_UNDER_SPM`]), `running` (over [`RUNNING_OVER_SPM`]) or `between`.
    pub status_by_cadence: BTreeMap<(&'static str, &'static str), usize>,
    /// Matched strides left out of the time comparisons: the core marks them not one gait
    /// cycle ([`Gait::Unknown`]: from or into a rest, across a gap).
    pub not_a_cycle: usize,
}

/// The pace bin of a Vicon speed.
fn pace_of(speed_m_s: f64) -> &'static str {
    if speed_m_s > RUNNING_OVER_M_S {
        "running (> 2.5 m/s)"
    } else if speed_m_s < WALKING_UNDER_M_S {
        "walking (< 1.5 m/s)"
    } else {
        "fast (1.5–2.5 m/s)"
    }
}

/// Runs the core on every trial of `dataset` and compares its gait parameters.
pub fn evaluate(dataset: &Dataset) -> Result<GaitResult> {
    let mut out = GaitResult::default();
    for trial in &dataset.trials {
        let trace = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        let ranges = Ranges::default();
        let prepared = replay::prepare(&trace, ranges)?;
        let strides = prepared.strides(prepared.config(ranges));
        compare_trial(dataset, trial, &prepared.clock, &strides, &mut out);
    }
    Ok(out)
}

fn compare_trial(
    dataset: &Dataset,
    trial: &Trial,
    clock: &crate::io::clock::SampleClock,
    strides: &[Stride],
    out: &mut GaitResult,
) {
    let span = trial.span_in_numbers(clock);
    let in_span: Vec<&Stride> = strides
        .iter()
        .filter(|s| s.events.heel_off < span.1 && s.events.foot_flat > span.0)
        .collect();
    let det: Vec<Detected> = in_span.iter().map(|s| Detected::from(*s)).collect();
    let refs = trial.references_in_numbers(clock);
    let scored = classify(trial, clock, &det, &refs);
    let ms = |samples: f64| samples * 1000.0 * clock.period_s;
    let mut push = |parameter, unit, pace, ours: f64, reference: f64| {
        out.comparisons.push(Comparison {
            parameter,
            unit,
            dataset: dataset.name.clone(),
            pace,
            ours,
            reference,
        })
    };
    if dataset.name != "pyshoe_vicon" {
        let turn: f64 = in_span
            .iter()
            .map(|s| s.turning_angle_cdeg as f64 / 100.0)
            .sum();
        out.trial_turns.push((trial.name.clone(), turn.abs()));
    }
    for (s, sc) in in_span.iter().zip(&scored) {
        let Scored::Found(j) = *sc else { continue };
        let r = &refs[j];
        let g = &s.gait;
        if let (Some(phs), Some(to), Some(hs)) = (r.prev_heel_strike, r.toe_off, r.heel_strike) {
            let pace = "walking (own speed)";
            let stride_ref = ms(hs as f64 - phs as f64);
            let swing_ref = ms(hs as f64 - to as f64);
            let stance_ref = ms(to as f64 - phs as f64);
            if stride_ref <= 0.0 {
                continue;
            }
            // A stride from or into a rest (or across a gap) is not one cycle, and says so.
            if g.gait == Gait::Unknown {
                out.not_a_cycle += 1;
                continue;
            }
            push(
                "stride_time",
                "ms",
                pace,
                g.stride_time_ms as f64,
                stride_ref,
            );
            push(
                "stance_time",
                "ms",
                pace,
                g.stance_time_ms as f64,
                stance_ref,
            );
            push("swing_time", "ms", pace, g.swing_time_ms as f64, swing_ref);
            push(
                "stance_time %",
                "% of cycle",
                pace,
                g.stance_permille as f64 / 10.0,
                100.0 * stance_ref / stride_ref,
            );
            push(
                "cadence",
                "steps/min",
                pace,
                g.cadence_spm as f64,
                120_000.0 / stride_ref,
            );
            if !s.flags.has(gaitclip::record::stride::StrideFlags::TURN) {
                push(
                    "turning_angle (straight)",
                    "°",
                    pace,
                    s.turning_angle_cdeg as f64 / 100.0,
                    0.0,
                );
            }
        }
        if let Some(pos) = &trial.positions {
            let (r0, r1) = (
                clock.row_of_number(s.events.start) as usize,
                clock.row_of_number(s.events.end) as usize,
            );
            if r1 >= pos.len() || r1 <= r0 {
                continue;
            }
            let span = &pos[r0..=r1];
            if span.iter().flatten().any(|v| v.is_nan()) {
                continue;
            }
            let (a, b) = (pos[r0], pos[r1]);
            let t_s = (s.events.end - s.events.start) as f64 * clock.period_s;
            let speed = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt() / t_s;
            let top = span.iter().map(|p| p[2]).fold(f64::MIN, f64::max) - a[2];
            let pace = pace_of(speed);
            push(
                "gait_velocity",
                "m/s",
                pace,
                g.gait_velocity_mm_s as f64 / 1000.0,
                speed,
            );
            push(
                "max_sensor_lift",
                "mm",
                pace,
                s.max_sensor_lift_mm as f64,
                top * 1000.0,
            );
            let class = if speed > RUNNING_OVER_M_S {
                "running"
            } else if speed < WALKING_UNDER_M_S {
                "walking"
            } else {
                "fast"
            };
            *out.status.entry((class, g.gait.name())).or_default() += 1;
            let cycle_s = r.end.saturating_sub(r.start) as f64 * clock.period_s;
            if cycle_s > 0.0 {
                let cadence = 120.0 / cycle_s;
                let class = if cadence < WALKING_UNDER_SPM {
                    "walking"
                } else if cadence > RUNNING_OVER_SPM {
                    "running"
                } else {
                    "between"
                };
                *out.status_by_cadence
                    .entry((class, g.gait.name()))
                    .or_default() += 1;
            }
            push(
                "stance_time %",
                "% of cycle",
                pace,
                g.stance_permille as f64 / 10.0,
                f64::NAN,
            );
        }
    }
}

/// The Markdown tables of `results` (one per dataset): per parameter, dataset and pace, the
/// strides compared, the median reference, the bias (median of ours − reference) and the
/// median and 95th percentile of |ours − reference|; then the U-turns and the gait status.
pub fn table(results: &[(String, GaitResult)]) -> String {
    /// One row: the unit, the errors, the references and our values.
    type Row<'a> = (&'a str, Vec<f64>, Vec<f64>, Vec<f64>);
    let mut groups: BTreeMap<(usize, &str, &str, &str), Row> = BTreeMap::new();
    let order = |p: &str| {
        [
            "stride_time",
            "stance_time",
            "swing_time",
            "stance_time %",
            "cadence",
            "gait_velocity",
            "max_sensor_lift",
            "turning_angle (straight)",
        ]
        .iter()
        .position(|&q| q == p)
        .unwrap_or(99)
    };
    for (_, r) in results {
        for c in &r.comparisons {
            let e = groups
                .entry((order(c.parameter), c.parameter, &c.dataset, c.pace))
                .or_insert((c.unit, vec![], vec![], vec![]));
            e.3.push(c.ours);
            if c.reference.is_nan() {
                continue;
            }
            e.1.push(c.ours - c.reference);
            e.2.push(c.reference);
        }
    }
    let mut t = Table::new([
        Column::from("parameter"),
        Column::from("dataset"),
        Column::from("pace"),
        Column::right("strides"),
        Column::right("reference (median)"),
        Column::right("ours (median)"),
        Column::right("bias"),
        Column::right("median |error|"),
        Column::right("p95 |error|"),
    ]);
    for ((_, p, d, pace), (unit, err, refs, ours)) in &groups {
        let head = [format!("{p} ({unit})"), d.to_string(), pace.to_string()];
        if err.is_empty() {
            let mut r = head.to_vec();
            r.extend([ours.len().to_string(), "—".into()]);
            r.push(format!("{:.1}", median(ours)));
            r.extend(["—".to_string(), "—".into(), "—".into()]);
            t.row(r);
            continue;
        }
        let f = |v: f64| {
            if *unit == "m/s" {
                format!("{v:.3}")
            } else {
                format!("{v:.1}")
            }
        };
        let mut r = head.to_vec();
        r.extend([
            err.len().to_string(),
            f(median(refs)),
            f(median(ours)),
            f(median(err)),
            f(abs_quantile(err, 0.5)),
            f(abs_quantile(err, 0.95)),
        ]);
        t.row(r);
    }
    let mut s = t.render();
    let skipped: usize = results.iter().map(|r| r.1.not_a_cycle).sum();
    let _ = writeln!(
        s,
        "\nTimes over strides the core reports as one gait cycle: {skipped} matched strides it marks `unknown` (from or into a rest, across a gap) are left out.\n"
    );
    let mut t = Table::new([
        Column::from("U-turn: |Σ turning_angle| of a trial's strides"),
        Column::right("trials"),
        Column::right("median"),
        Column::right("median |error| vs 180°"),
        Column::right("p95 |error|"),
    ]);
    for (name, r) in results {
        if r.trial_turns.is_empty() {
            continue;
        }
        let turns: Vec<f64> = r.trial_turns.iter().map(|t| t.1).collect();
        let err: Vec<f64> = turns.iter().map(|t| t - 180.0).collect();
        t.row([
            name.to_string(),
            turns.len().to_string(),
            format!("{:.1}°", median(&turns)),
            format!("{:.1}°", abs_quantile(&err, 0.5)),
            format!("{:.1}°", abs_quantile(&err, 0.95)),
        ]);
    }
    s.push_str(&t.render());
    for (name, r) in results {
        if r.status.is_empty() {
            continue;
        }
        s.push('\n');
        s.push_str(&status_table(
            &format!("{name}: Vicon speed"),
            &r.status,
            [
                ("walking", "< 1.5 m/s".into()),
                ("fast", "1.5–2.5 m/s".into()),
                ("running", "> 2.5 m/s".into()),
            ],
        ));
        s.push('\n');
        s.push_str(&status_table(
            &format!("{name}: Vicon cadence"),
            &r.status_by_cadence,
            [
                ("walking", format!("< {WALKING_UNDER_SPM} steps/min")),
                (
                    "between",
                    format!("{WALKING_UNDER_SPM}–{RUNNING_OVER_SPM} steps/min"),
                ),
                ("running", format!("> {RUNNING_OVER_SPM} steps/min")),
            ],
        ));
    }
    s
}

/// One walking-or-running table: per reference class (its label), how many strides the core
/// called walking, running or unknown, and the share it got right (`walking` and `running`
/// classes; the middle one has no reference).
fn status_table(
    title: &str,
    status: &BTreeMap<(&'static str, &'static str), usize>,
    classes: [(&str, String); 3],
) -> String {
    let mut t = Table::new([
        Column::from(title),
        Column::right("strides"),
        Column::right("walking"),
        Column::right("running"),
        Column::right("unknown"),
        Column::right("correct"),
    ]);
    for (class, bound) in classes {
        let n = |g: Gait| status.get(&(class, g.name())).copied().unwrap_or(0);
        let (w, ru, u) = (n(Gait::Walking), n(Gait::Running), n(Gait::Unknown));
        let total = w + ru + u;
        let share = |k: usize| format!("{:.1} %", 100.0 * k as f64 / total.max(1) as f64);
        let correct = match class {
            "walking" => share(w),
            "running" => share(ru),
            _ => "(no reference)".to_string(),
        };
        t.row([
            format!("{bound} ({class})"),
            total.to_string(),
            w.to_string(),
            ru.to_string(),
            u.to_string(),
            correct,
        ]);
    }
    t.render()
}

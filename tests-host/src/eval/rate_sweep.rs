//! `gaitclip rates`: the same recordings at lower rates, so that what the rate does to the
//! strides is measured rather than assumed.
//!
//! Each recording is replayed at its own rate and decimated by 2, 4 and 8
//! ([`crate::io::resample`]: anti-aliased, as a slower sensor would record it): `esangeni_run`
//! from 800 Hz to 400, 200 and 100 Hz, `gaitmap_walk` and `pyshoe_vicon` from ≈ 200 Hz to
//! 100, 50 and 25 Hz (the slowest rate the core takes). Every stride of a decimated replay is matched to the stride of the
//! full-rate replay it overlaps most in time (at least half of both), and their lengths and
//! events compared.
//!
//! **Why the core runs at the recording's rate, not resampled to the firmware's.** The core
//! sizes what it keeps by time (the movement buffer holds
//! [`gaitclip::detect::seam::MAX_MOVEMENT_MS`] at any rate, the windows are set in milliseconds), so
//! a 400–1000 Hz recording replays without a `too_long` stride, and a clipped run keeps its
//! shape, which the rail reconstruction needs ([`gaitclip::detect::clipping`]): a filter before a
//! resampler would smear a rail into unclipped samples below it. The table is the check that
//! the rate-independence holds.

use anyhow::Result;

use crate::eval::markdown::{cm_cell, Table};
use crate::eval::stats::median;
use crate::io::csv_trace;
use crate::io::datasets;
use crate::io::resample::decimate;
use crate::io::trace::{Ranges, Trace};
use crate::replay::{self, StrideReport};

/// One recording at one rate against itself at its own rate.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RateResult {
    /// Rate, Hz.
    pub rate_hz: f64,
    /// Strides, and those with a length.
    pub strides: usize,
    /// Summed length (what the foot pod shows), m.
    pub distance_m: f64,
    /// Length differences of matched strides against the full rate, m.
    pub length_m: Vec<f64>,
    /// Toe-off and heel-strike differences, ms.
    pub toe_off_ms: Vec<f64>,
    /// Heel-strike differences, ms.
    pub heel_strike_ms: Vec<f64>,
    /// Strides of the full rate that no decimated stride matched.
    pub unmatched: usize,
}

fn overlap(a: &StrideReport, b: &StrideReport) -> f64 {
    (a.end_s.min(b.end_s) - a.start_s.max(b.start_s)).max(0.0)
}

/// `strides` against `full`, the same recording's strides at its own rate.
pub fn compare(
    rate_hz: f64,
    strides: &[StrideReport],
    full: &[StrideReport],
    distance_m: f64,
) -> RateResult {
    let mut r = RateResult {
        rate_hz,
        strides: strides.len(),
        distance_m,
        ..RateResult::default()
    };
    let mut used = vec![false; full.len()];
    for s in strides {
        let best = full
            .iter()
            .enumerate()
            .map(|(i, f)| (overlap(s, f), i))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        let Some((o, i)) = best else { continue };
        let f = &full[i];
        if 2.0 * o < (s.end_s - s.start_s) || 2.0 * o < (f.end_s - f.start_s) {
            continue;
        }
        used[i] = true;
        r.length_m.push(s.length_m - f.length_m);
        r.toe_off_ms.push((s.toe_off_s - f.toe_off_s) * 1e3);
        r.heel_strike_ms
            .push((s.heel_strike_s - f.heel_strike_s) * 1e3);
    }
    r.unmatched = used.iter().filter(|u| !**u).count();
    r
}

/// One recording at its own rate and decimated by each of `factors`.
pub fn sweep(t: &Trace, factors: &[usize]) -> Result<Vec<RateResult>> {
    let ranges = Ranges::default();
    let run = |t: &Trace| -> Result<(Vec<StrideReport>, f64)> {
        let (s, summary) = replay::replay_summarised(
            t,
            ranges,
            gaitclip::pipeline::detectors::Detector::Cycle,
            gaitclip::pipeline::config::DEFAULT_MODEL,
            false,
        )?;
        Ok((s, summary.distance_m))
    };
    let (full, full_distance) = run(t)?;
    let mut out = vec![compare(t.rate_hz, &full, &full, full_distance)];
    for &k in factors {
        let d = decimate(t, k);
        let (s, distance) = run(&d)?;
        out.push(compare(d.rate_hz, &s, &full, distance));
    }
    Ok(out)
}

/// The table, Markdown, for the datasets under `root`.
pub fn report(root: &std::path::Path) -> Result<String> {
    let mut table = Table::new([
        "recording",
        "rate",
        "strides",
        "distance",
        "length vs full rate: RMSE / bias cm (strides)",
        "largest |difference|",
        "full-rate strides unmatched",
        "toe-off / heel-strike, median difference",
    ]);
    let mut sets: Vec<(String, Vec<Trace>, Vec<usize>)> = Vec::new();
    for (name, factors) in [
        ("esangeni_run", vec![2, 4, 8]),
        ("gaitmap_walk", vec![2, 4, 8]),
        ("pyshoe_vicon", vec![2, 4, 8]),
    ] {
        let d = datasets::load(&root.join(name))?;
        let traces = d
            .trials
            .iter()
            .map(|tr| csv_trace::read(&tr.csv, Some(d.rate_hz)).map_err(anyhow::Error::from))
            .collect::<Result<Vec<_>>>()?;
        sets.push((name.to_string(), traces, factors));
    }
    for (name, traces, factors) in &sets {
        let mut pooled: Vec<RateResult> = Vec::new();
        for t in traces {
            let r = sweep(t, factors)?;
            if pooled.is_empty() {
                pooled = r;
            } else {
                for (p, x) in pooled.iter_mut().zip(r) {
                    p.strides += x.strides;
                    p.distance_m += x.distance_m;
                    p.length_m.extend(x.length_m);
                    p.toe_off_ms.extend(x.toe_off_ms);
                    p.heel_strike_ms.extend(x.heel_strike_ms);
                    p.unmatched += x.unmatched;
                }
            }
        }
        for r in &pooled {
            let worst = r.length_m.iter().fold(0f64, |m, x| m.max(x.abs()));
            table.row([
                format!(
                    "{name} ({} trial{})",
                    traces.len(),
                    if traces.len() > 1 { "s" } else { "" }
                ),
                format!("{:.1} Hz", r.rate_hz),
                r.strides.to_string(),
                format!("{:.2} m", r.distance_m),
                cm_cell(&r.length_m),
                format!("{:.1} cm", worst * 100.0),
                r.unmatched.to_string(),
                if r.toe_off_ms.is_empty() {
                    "–".into()
                } else {
                    format!(
                        "{:+.1} / {:+.1} ms",
                        median(&r.toe_off_ms),
                        median(&r.heel_strike_ms)
                    )
                },
            ]);
        }
    }
    Ok(format!(
        "Each recording at its own rate and decimated (anti-aliased) to lower ones; strides matched in time to the full-rate replay:\n\n{}",
        table.render()
    ))
}

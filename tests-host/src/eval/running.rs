//! `gaitclip running`: what happens at the stance instant as the pace rises, measured against
//! the Vicon foot marker of `pyshoe_vicon`, so that a short running stride is explained by its
//! mechanics rather than corrected by a gain.
//!
//! For every clean stride matched to a reference (as `gaitclip zupt-sweep` scores them), by the
//! reference's speed:
//!
//! - the **ZUPT error** (our ZUPT length − the Vicon stride);
//! - the **Vicon foot speed at our stance instant** (the marker's 3-D speed over ±10 ms): is
//!   the instant a zero-velocity instant at all;
//! - the **rolling-contact speed the integrator imposes there**, `|ω|·h` with the shipped
//!   sensor height `h`, and the gyro's `|ω|` at the instant;
//! - the **Vicon stance** the instant lies in (the marker-speed stance label): its length,
//!   and how often the instant lies outside any;
//! - our **duty factor** (stance share of the cycle) and the share of strides called running.

use anyhow::Result;
use gaitclip::record::gait::Gait;
use gaitclip::record::stride::StrideFlags;

use crate::eval::course::{circular_median, direction, Part, MEDIAN_MIN_M};
use crate::eval::length_eval::SPEED_BINS;
use crate::eval::markdown::{cm_cell, median_p95_beside, Table};
use crate::eval::matching::{self, Detected, Scored};
use crate::eval::stats::median;
use crate::io::datasets;
use crate::io::trace::Ranges;
use crate::{io::csv_trace, replay};

/// One matched stride at its stance instant (the stride's start).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instant {
    /// Reference speed, m/s.
    pub speed_m_s: f64,
    /// ZUPT length − reference, m.
    pub zupt_error_m: f64,
    /// The Vicon marker's speed at the instant, m/s.
    pub marker_m_s: f64,
    /// The gyro's |ω| at the instant, rad/s.
    pub omega_rad_s: f64,
    /// The Vicon stance holding the instant, ms (`None`: outside any).
    pub vicon_stance_ms: Option<f64>,
    /// Our stance share of the cycle, %.
    pub stance_pct: f64,
    /// Called running.
    pub running: bool,
    /// Our stride's climb, m.
    pub climb_m: f64,
    /// The Vicon marker's height change over the stride (its end instant's row less its
    /// start's), m: the floor is level, so about zero.
    pub vicon_climb_m: f64,
    /// Which way it travelled against the trial's forward direction
    /// ([`crate::eval::course::direction`]).
    pub direction: Part,
    /// The Vicon's length, m.
    pub length_m: f64,
}

/// The instants of every clean matched stride of `pyshoe_vicon`.
pub fn instants(root: &std::path::Path) -> Result<Vec<Instant>> {
    let d = datasets::load(&root.join("pyshoe_vicon"))?;
    let ranges = Ranges::default();
    let mut out = Vec::new();
    for trial in &d.trials {
        let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
        let p = replay::prepare(&t, ranges)?;
        let strides = p.strides(p.config(ranges));
        let det: Vec<Detected> = strides.iter().map(Detected::from).collect();
        let refs = trial.references_in_numbers(&p.clock);
        let scored = matching::classify(trial, &p.clock, &det, &refs);
        let (Some(pos), Some(stance)) = (&trial.positions, &trial.stance) else {
            continue;
        };
        let dt = p.clock.period_s;
        // The trial's forward direction: where most of its strides travel (a trial walks
        // forward mostly; its backward and sideways strides read 180° and 90° from it).
        let forward = circular_median(
            &strides
                .iter()
                .filter(|s| s.zupt_um >= (MEDIAN_MIN_M * 1e6) as u32)
                .map(|s| s.travel_cdeg as f64 / 100.0)
                .collect::<Vec<_>>(),
        );
        let per_radps = ranges.gyro_counts_per_radps();
        for (i, c) in scored.iter().enumerate() {
            let Scored::Found(j) = *c else { continue };
            let (s, r) = (&strides[i], &refs[j]);
            if !s.flags.valid() || s.flags.has(StrideFlags::FROM_REST | StrideFlags::TO_REST) {
                continue;
            }
            let Some(len) = r.length_m else { continue };
            let speed = len / ((r.end - r.start) as f64 * dt);
            let row = p.clock.row_of_number(s.events.start) as usize;
            if row < 2 || row + 2 >= pos.len() || row >= p.counts.len() {
                continue;
            }
            let (a, b) = (pos[row - 2], pos[row + 2]);
            if a.iter().chain(&b).any(|v| v.is_nan()) {
                continue;
            }
            let marker = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2))
                .sqrt()
                / (4.0 * dt);
            let end_row = p.clock.row_of_number(s.events.end) as usize;
            let vicon_climb_m = match pos.get(end_row) {
                Some(e) if !e[2].is_nan() && !pos[row][2].is_nan() => e[2] - pos[row][2],
                _ => f64::NAN,
            };
            let g = p.counts[row].gyro;
            let omega = (g.iter().map(|&v| (v as f64).powi(2)).sum::<f64>()).sqrt() / per_radps;
            let vicon_stance_ms = stance.get(row).copied().unwrap_or(false).then(|| {
                let lo = (0..=row).rev().take_while(|&k| stance[k]).count();
                let hi = (row..stance.len()).take_while(|&k| stance[k]).count();
                (lo + hi - 1) as f64 * dt * 1e3
            });
            out.push(Instant {
                speed_m_s: speed,
                zupt_error_m: s.zupt_um as f64 / 1e6 - len,
                marker_m_s: marker,
                omega_rad_s: omega,
                vicon_stance_ms,
                stance_pct: s.gait.stance_permille as f64 / 10.0,
                running: s.gait.gait == Gait::Running,
                climb_m: s.climb_mm as f64 / 1000.0,
                vicon_climb_m,
                direction: direction(s.travel_cdeg as f64 / 100.0, forward),
                length_m: len,
            });
        }
    }
    Ok(out)
}

/// The table, Markdown.
pub fn report(root: &std::path::Path) -> Result<String> {
    let all = instants(root)?;
    let h = gaitclip::detect::cycle::SENSOR_HEIGHT_UM as f64 / 1e6;
    let mut t = Table::new([
        "Vicon speed",
        "strides",
        "ZUPT RMSE / bias cm",
        "marker speed at our instant (median)",
        "|ω| there / imposed |ω|·h (median)",
        "instant in a Vicon stance",
        "that stance (median)",
        "our stance % (median)",
        "called running",
        "|climb| median / p95 (Vicon's)",
    ]);
    for (lo, hi) in SPEED_BINS {
        let b: Vec<&Instant> = all
            .iter()
            .filter(|x| x.speed_m_s >= lo && x.speed_m_s < hi)
            .collect();
        if b.is_empty() {
            continue;
        }
        let col = |f: &dyn Fn(&Instant) -> f64| -> Vec<f64> { b.iter().map(|x| f(x)).collect() };
        let in_stance: Vec<f64> = b.iter().filter_map(|x| x.vicon_stance_ms).collect();
        let label = if hi.is_infinite() {
            format!("> {lo} m/s")
        } else {
            format!("{lo}–{hi} m/s")
        };
        t.row([
            label,
            b.len().to_string(),
            cm_cell(&col(&|x| x.zupt_error_m)),
            format!("{:.2} m/s", median(&col(&|x| x.marker_m_s))),
            format!(
                "{:.2} rad/s / {:.2} m/s",
                median(&col(&|x| x.omega_rad_s)),
                median(&col(&|x| x.omega_rad_s * h))
            ),
            format!("{} of {}", in_stance.len(), b.len()),
            if in_stance.is_empty() {
                "–".into()
            } else {
                format!("{:.0} ms", median(&in_stance))
            },
            format!("{:.1} %", median(&col(&|x| x.stance_pct))),
            format!(
                "{} ({:.0} %)",
                b.iter().filter(|x| x.running).count(),
                100.0 * b.iter().filter(|x| x.running).count() as f64 / b.len() as f64
            ),
            climb_cell(&b),
        ]);
    }
    // A climb on the level floor is an error of the integration: what it says of the length.
    let mut c = Table::new([
        "our |climb|",
        "strides",
        "ZUPT RMSE / bias cm",
        "median |error| cm",
        "Vicon's |climb| median / max",
    ]);
    for (lo, hi) in CLIMB_BINS {
        let b: Vec<&Instant> = all
            .iter()
            .filter(|x| x.climb_m.abs() >= lo && x.climb_m.abs() < hi)
            .collect();
        if b.is_empty() {
            continue;
        }
        let vicon: Vec<f64> = b
            .iter()
            .map(|x| x.vicon_climb_m.abs())
            .filter(|v| v.is_finite())
            .collect();
        let errors: Vec<f64> = b.iter().map(|x| x.zupt_error_m).collect();
        c.row([
            crate::eval::length_eval::bin_label((lo, hi), "m"),
            b.len().to_string(),
            cm_cell(&errors),
            format!(
                "{:.1}",
                100.0 * median(&errors.iter().map(|e| e.abs()).collect::<Vec<_>>())
            ),
            format!(
                "{:.3} / {:.3} m",
                median(&vicon),
                vicon.iter().copied().fold(0.0, f64::max)
            ),
        ]);
    }
    // Backward and sideways strides: the trial's forward direction from its own strides.
    let mut d = Table::new([
        "direction of travel against the foot",
        "strides",
        "ZUPT RMSE / bias cm",
        "their sum against the Vicon's",
    ]);
    for (part, name) in [
        (Part::Forward, "forward (within 45°)"),
        (Part::Sideways, "sideways (45–135°)"),
        (Part::Backward, "backward (beyond 135°)"),
    ] {
        let b: Vec<&Instant> = all.iter().filter(|x| x.direction == part).collect();
        let errors: Vec<f64> = b.iter().map(|x| x.zupt_error_m).collect();
        let truth: f64 = b.iter().map(|x| x.length_m).sum();
        d.row([
            name.to_string(),
            b.len().to_string(),
            cm_cell(&errors),
            if truth > 0.0 {
                format!("{:+.1} %", 100.0 * errors.iter().sum::<f64>() / truth)
            } else {
                "–".into()
            },
        ]);
    }
    Ok(format!(
        "`pyshoe_vicon`, clean matched strides by the Vicon stride's speed; the instant is the stance instant our stride starts at:\n\n{}\n\
         The same strides by the climb our integration gives them (the Vicon marker's own climb beside it), against the Vicon's length:\n\n{}\n\
         The same strides by which way they travelled against the foot (`travel_deg` against the circular median of the trial's strides):\n\n{}",
        t.render(),
        c.render(),
        d.render()
    ))
}

/// Bins of |climb| for the second table, m.
pub const CLIMB_BINS: [(f64, f64); 4] = [(0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, f64::INFINITY)];

/// `median / p95 (Vicon's median / p95)` of |climb|, m.
fn climb_cell(b: &[&Instant]) -> String {
    let ours: Vec<f64> = b.iter().map(|x| x.climb_m.abs()).collect();
    let vicon: Vec<f64> = b
        .iter()
        .map(|x| x.vicon_climb_m.abs())
        .filter(|v| v.is_finite())
        .collect();
    median_p95_beside(&ours, &vicon, " m")
}

//! `gaitclip events`: when the core's toe-off and heel-strike fall against the references,
//! beside the same events defined on the foot's sagittal angular rate in `f64` on the host,
//! to show which definition each reference follows.
//!
//! The core's events are the sagittal rate's ([`gaitclip::detect::gyro_events`]: the push-off
//! peak, the zero crossing that ends the swing), or Huang et al. 2022's phase boundaries
//! ([`gaitclip::detect::phases`]) where the rate gives none. The candidates here are read from
//! the gyro alone inside each matched stride's movement (heel-off − 50 ms to foot-flat +
//! 150 ms), independently of the core's:
//!
//! - **sagittal rate**: the gyro projected on its principal axis over the trial's moving
//!   samples (|ω| above a third of its 95th percentile; the foot rotates mostly about its
//!   medio-lateral axis, whatever the mounting), signed so that the swing's forward rotation is
//!   negative: the push-off (heel rising) and the foot-slap after contact are then positive
//!   peaks, either side of the swing's negative one.
//! - `push-off peak`: the largest rate before the swing minimum (the foot's plantar-flexion
//!   is fastest as the toe leaves the ground).
//! - `zero crossing` (toe-off): the last + → − crossing before the swing minimum, Rampp et
//!   al. 2014's terminal contact as gaitmap's `RamppEventDetection` finds it (`_detect_tc`:
//!   the first sign change after the pre-swing extreme).
//! - `zero crossing` (heel-strike): the first − → + crossing after the swing minimum: the
//!   swing rotation stops when the heel meets the ground.
//! - `foot-slap peak`: the largest rate after that, the foot rotating flat onto the ground.
//!
//! Errors are the event minus the reference (positive: late), ms, over the clean strides
//! `gaitclip eval` matches ([`crate::eval::matching`]); a stride whose window holds a hole, or
//! whose rate lacks the crossing, gives no candidate and is counted apart.

use std::path::Path;

use anyhow::Result;
use gaitclip::record::stride::Stride;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::eval::markdown::{Column, Table};
use crate::eval::matching::{classify, Detected, Scored};
use crate::eval::stats::{abs_quantile, median};
use crate::io::clock::SampleClock;
use crate::io::csv_trace;
use crate::io::datasets::{self, Dataset};
use crate::io::trace::Ranges;
use crate::replay;

/// The datasets with annotated toe-offs and heel-strikes.
pub const EVENT_DATASETS: [&str; 2] = ["gaitmap_walk", "ipol_gait_events"];

/// The window around a stride's movement the candidates are searched in, s: before its
/// heel-off and after its foot-flat.
const WINDOW_S: (f64, f64) = (0.05, 0.15);

/// One matched stride's events, ms from the reference (positive: late); `None` where the
/// definition found none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventErrors {
    /// The core's toe-off.
    pub toe_off_core: f64,
    /// Sagittal rate's push-off peak.
    pub toe_off_peak: Option<f64>,
    /// Its + → − zero crossing before the swing.
    pub toe_off_crossing: Option<f64>,
    /// The core's heel-strike.
    pub heel_strike_core: f64,
    /// Its − → + zero crossing after the swing.
    pub heel_strike_crossing: Option<f64>,
    /// Its foot-slap peak.
    pub heel_strike_peak: Option<f64>,
}

/// What one dataset gave.
#[derive(Clone, Debug, Default)]
pub struct DatasetEvents {
    /// Folder name.
    pub name: String,
    /// One row per clean matched stride with both reference events.
    pub strides: Vec<EventErrors>,
    /// Of those, strides whose window held a hole (no gyro candidates).
    pub holed: usize,
}

/// The principal rotation axis of `gyro` (counts), over the samples whose |ω| is above a
/// third of its 95th percentile.
fn sagittal_axis(gyro: &[[f64; 3]]) -> Vector3<f64> {
    let mut mags: Vec<f64> = gyro
        .iter()
        .map(|g| (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt())
        .collect();
    mags.sort_by(f64::total_cmp);
    let floor = mags
        .get(((mags.len() as f64) * 0.95) as usize)
        .copied()
        .unwrap_or(0.0)
        / 3.0;
    let mut c = Matrix3::zeros();
    for g in gyro {
        let v = Vector3::new(g[0], g[1], g[2]);
        if v.norm() > floor {
            c += v * v.transpose();
        }
    }
    let e = SymmetricEigen::new(c);
    let k = e.eigenvalues.imax();
    e.eigenvectors.column(k).into_owned()
}

/// Fills runs of at most `max` missing values that have a value on both sides by a straight
/// line between them.
fn bridge_short_holes(v: &mut [Option<f64>], max: usize) {
    let mut k = 0;
    while k < v.len() {
        if v[k].is_some() {
            k += 1;
            continue;
        }
        let start = k;
        while k < v.len() && v[k].is_none() {
            k += 1;
        }
        let len = k - start;
        if start == 0 || k == v.len() || len > max {
            continue;
        }
        if let (Some(a), Some(b)) = (v[start - 1], v[k]) {
            for (i, x) in v[start..k].iter_mut().enumerate() {
                let f = (i + 1) as f64 / (len + 1) as f64;
                *x = Some(a + (b - a) * f);
            }
        }
    }
}

/// Fractional sample number where `s` crosses zero between `k` and `k + 1`.
fn crossing(s: &[f64], k: usize) -> f64 {
    k as f64 + s[k] / (s[k] - s[k + 1])
}

/// The candidates of one stride, sample numbers: (push-off peak, toe-off crossing,
/// heel-strike crossing, foot-slap peak); `None` when the window holds a hole.
fn candidates(
    rate: &[Option<f64>],
    stride: &Stride,
    period_s: f64,
) -> Option<(f64, Option<f64>, Option<f64>, f64)> {
    let before = (WINDOW_S.0 / period_s).round() as u32;
    let after = (WINDOW_S.1 / period_s).round() as u32;
    let a = stride.events.heel_off.saturating_sub(before) as usize;
    let b = ((stride.events.foot_flat + after) as usize).min(rate.len());
    if b < a + 5 {
        return None;
    }
    let s: Vec<f64> = rate[a..b].iter().copied().collect::<Option<_>>()?;
    let argmax = |v: &[f64]| {
        v.iter()
            .enumerate()
            .max_by(|x, y| x.1.total_cmp(y.1))
            .map_or(0, |m| m.0)
    };
    let swing = s
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .map_or(0, |m| m.0);
    let push = argmax(&s[..=swing]);
    let slap = swing + argmax(&s[swing..]);
    let to = (push..swing)
        .rev()
        .find(|&k| s[k] >= 0.0 && s[k + 1] < 0.0)
        .map(|k| crossing(&s, k));
    let hs = (swing..s.len() - 1)
        .find(|&k| s[k] < 0.0 && s[k + 1] >= 0.0)
        .map(|k| crossing(&s, k));
    let at = |x: f64| a as f64 + x;
    Some((at(push as f64), to.map(at), hs.map(at), at(slap as f64)))
}

/// Runs the core on every trial of `dataset` and times its events and the candidates.
pub fn evaluate(dataset: &Dataset) -> Result<DatasetEvents> {
    let mut out = DatasetEvents {
        name: dataset.name.clone(),
        ..DatasetEvents::default()
    };
    for trial in &dataset.trials {
        let trace = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        let ranges = Ranges::default();
        let prepared = replay::prepare(&trace, ranges)?;
        let clock: &SampleClock = &prepared.clock;
        let strides = prepared.strides(prepared.config(ranges));
        // The gyro in sample numbers of the sensor clock (None in the holes).
        let last = prepared.counts.len().saturating_sub(1);
        let n = clock.number_of_row(last) as usize + 1;
        let mut gyro: Vec<Option<[f64; 3]>> = vec![None; n];
        for (row, c) in prepared.counts.iter().enumerate() {
            let k = clock.number_of_row(row) as usize;
            if let Some(g) = gyro.get_mut(k) {
                *g = Some(c.gyro.map(f64::from));
            }
        }
        let present: Vec<[f64; 3]> = gyro.iter().flatten().copied().collect();
        let axis = sagittal_axis(&present);
        let mut rate: Vec<Option<f64>> = gyro
            .iter()
            .map(|g| g.map(|g| g[0] * axis[0] + g[1] * axis[1] + g[2] * axis[2]))
            .collect();
        // Holes of up to three samples are bridged by a straight line, as the core bridges
        // short holes; longer ones stay holes.
        bridge_short_holes(&mut rate, 3);
        // Swing negative: the median rate between the core's toe-offs and heel-strikes.
        let swing: Vec<f64> = strides
            .iter()
            .flat_map(|s| {
                let (a, b) = (s.events.toe_off as usize, s.events.heel_strike as usize);
                rate.get(a..b.min(rate.len()))
                    .unwrap_or(&[])
                    .iter()
                    .flatten()
                    .copied()
                    .collect::<Vec<_>>()
            })
            .collect();
        if median(&swing) > 0.0 {
            for r in rate.iter_mut().flatten() {
                *r = -*r;
            }
        }

        let span = trial.span_in_numbers(clock);
        let in_span: Vec<&Stride> = strides
            .iter()
            .filter(|s| s.events.heel_off < span.1 && s.events.foot_flat > span.0)
            .collect();
        let det: Vec<Detected> = in_span.iter().map(|s| Detected::from(*s)).collect();
        let refs = trial.references_in_numbers(clock);
        let ms = |samples: f64| samples * 1000.0 * clock.period_s;
        for (s, sc) in in_span.iter().zip(classify(trial, clock, &det, &refs)) {
            let Scored::Found(j) = sc else { continue };
            let (Some(to), Some(hs)) = (refs[j].toe_off, refs[j].heel_strike) else {
                continue;
            };
            let (to, hs) = (to as f64, hs as f64);
            let mut e = EventErrors {
                toe_off_core: ms(s.events.toe_off as f64 - to),
                heel_strike_core: ms(s.events.heel_strike as f64 - hs),
                ..EventErrors::default()
            };
            match candidates(&rate, s, clock.period_s) {
                Some((push, to_x, hs_x, slap)) => {
                    e.toe_off_peak = Some(ms(push - to));
                    e.toe_off_crossing = to_x.map(|x| ms(x - to));
                    e.heel_strike_crossing = hs_x.map(|x| ms(x - hs));
                    e.heel_strike_peak = Some(ms(slap - hs));
                }
                None => out.holed += 1,
            }
            out.strides.push(e);
        }
    }
    Ok(out)
}

/// The signed median, |error| median and p95 of `e`, ms.
pub fn summary(e: &[f64]) -> (f64, f64, f64) {
    let abs: Vec<f64> = e.iter().map(|x| x.abs()).collect();
    (median(e), median(&abs), abs_quantile(e, 0.95))
}

/// The table, Markdown, over [`EVENT_DATASETS`] under `root`.
pub fn report(root: &Path) -> Result<String> {
    let mut t = Table::new([
        Column::from("dataset"),
        Column::from("event"),
        Column::from("definition"),
        Column::right("strides"),
        Column::right("signed median, ms"),
        Column::right("|error| median, ms"),
        Column::right("|error| p95, ms"),
    ]);
    for name in EVENT_DATASETS {
        let d = evaluate(&datasets::load(&root.join(name))?)?;
        type Pick = fn(&EventErrors) -> Option<f64>;
        let rows: [(&str, &str, Pick); 6] = [
            (
                "toe-off",
                "core (the sagittal rate; Huang's pair where it has none)",
                |e| Some(e.toe_off_core),
            ),
            ("toe-off", "sagittal rate: push-off peak", |e| {
                e.toe_off_peak
            }),
            ("toe-off", "sagittal rate: zero crossing (Rampp)", |e| {
                e.toe_off_crossing
            }),
            (
                "heel-strike",
                "core (the sagittal rate; Huang's pair where it has none)",
                |e| Some(e.heel_strike_core),
            ),
            ("heel-strike", "sagittal rate: zero crossing", |e| {
                e.heel_strike_crossing
            }),
            ("heel-strike", "sagittal rate: foot-slap peak", |e| {
                e.heel_strike_peak
            }),
        ];
        for (event, definition, pick) in rows {
            let e: Vec<f64> = d.strides.iter().filter_map(pick).collect();
            let (signed, abs, p95) = summary(&e);
            t.row([
                d.name.clone(),
                event.to_string(),
                definition.to_string(),
                e.len().to_string(),
                format!("{signed:+.0}"),
                format!("{abs:.0}"),
                format!("{p95:.0}"),
            ]);
        }
    }
    Ok(t.render())
}

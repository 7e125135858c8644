//! `gaitclip holes`: what a hole of lost samples costs a bridged stride, by hole length, so
//! that the bridge limit ([`gaitclip::pipeline::config::BRIDGE_MAX_MS`]) is chosen by measurement.
//!
//! **Method.** Each trial of `gaitmap_walk` and `pyshoe_vicon` is replayed uncut. Its
//! *walking strides* are the core's valid strides matched to a clean reference stride, not
//! the first or last of a walk nor a turn, slower than [`WALKING_MAX_MPS`] (reference length
//! over the stride's duration). Into them, holes of 1 to [`MAX_HOLE`] samples are cut:
//!
//! - **single**: one hole; **cluster**: [`CLUSTER`] holes of that length, [`CLUSTER_SPACING`]
//!   samples apart, as the wireless link of `ipol_gait_events` drops packets;
//! - **stance**: centred on the middle of the stance before the stride's heel-off;
//!   **swing**: centred on the middle of its swing (toe-off to heel-strike).
//!
//! Every other walking stride gets a hole in one replay and the rest in a second, so that no
//! stride's neighbour is cut. The cut trace is replayed with every hole bridged (the limit
//! set to [`gaitclip::pipeline::config::FILL_MAX_MS`]), and each cut stride is compared with the same
//! stride uncut: |length difference| of the default model and of the ZUPT displacement, and
//! |toe-off| and |heel-strike| differences. A cut stride that is no longer found (or is
//! split) counts as lost. The same sweep runs again on the recordings decimated to half
//! their rate (every other sample, ≈ 100 Hz, as `ipol_gait_events` records), to tell
//! whether what matters is the hole's samples or its milliseconds.
//!
//! **Choice.** The limit is the longest hole, in milliseconds, such that at both rates every
//! hole up to it keeps the mean |length difference| of every pattern and place within
//! [`MEAN_LENGTH_BOUND_M`].

use crate::eval::stats::quantile;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use gaitclip::pipeline::config::{Config, FILL_MAX_MS};
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::sample::RawSample;

use crate::eval::markdown::{Column, Table};
use crate::eval::matching::{self, Detected};
use crate::io::clock::Gap;
use crate::io::datasets;
use crate::io::trace::{Ranges, Trace};
use crate::{io::csv_trace, replay};

/// Longest hole cut, samples.
pub const MAX_HOLE: u32 = 16;
/// Holes per cluster.
pub const CLUSTER: u32 = 3;
/// Measured samples between the holes of a cluster.
pub const CLUSTER_SPACING: u32 = 5;
/// Walking strides are slower than this (running and jogging are not what a lost packet
/// of a walk does).
pub const WALKING_MAX_MPS: f64 = 2.0;
/// The bound the limit keeps: mean |length difference| per pattern and place, m.
pub const MEAN_LENGTH_BOUND_M: f64 = 0.01;
/// The datasets with per-stride references.
pub const DATASETS: [&str; 2] = ["gaitmap_walk", "pyshoe_vicon"];

/// One hole pattern.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pattern {
    /// Samples per hole.
    pub len: u32,
    /// A cluster of [`CLUSTER`] holes, or one.
    pub cluster: bool,
    /// In the swing, or in the stance before heel-off.
    pub swing: bool,
}

/// What the holes of one pattern cost.
#[derive(Clone, Debug, Default)]
pub struct Cost {
    /// |length difference| of each cut stride, default model, m.
    pub length_m: Vec<f64>,
    /// |ZUPT displacement difference|, m.
    pub zupt_m: Vec<f64>,
    /// |toe-off difference|, ms.
    pub toe_off_ms: Vec<f64>,
    /// |heel-strike difference|, ms.
    pub heel_strike_ms: Vec<f64>,
    /// |heel-off difference| and |foot-flat difference| (the stance edges), ms.
    pub edges_ms: Vec<f64>,
    /// Cut strides no longer found (or split).
    pub lost: usize,
    /// Cut strides that became invalid.
    pub invalid: usize,
}

impl Cost {
    fn add(&mut self, o: Cost) {
        self.length_m.extend(o.length_m);
        self.zupt_m.extend(o.zupt_m);
        self.toe_off_ms.extend(o.toe_off_ms);
        self.heel_strike_ms.extend(o.heel_strike_ms);
        self.edges_ms.extend(o.edges_ms);
        self.lost += o.lost;
        self.invalid += o.invalid;
    }

    /// Mean |length difference|, m.
    pub fn mean_length_m(&self) -> f64 {
        mean(&self.length_m)
    }
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// One trial ready for cutting: counts, rate, its walking strides uncut.
pub struct Walk {
    /// Dataset/trial.
    pub name: String,
    /// The counts, one per sample (no hole).
    pub counts: Vec<RawSample>,
    /// Configuration (every hole up to [`FILL_MAX_MS`] bridged).
    pub config: Config,
    /// Uncut strides.
    pub strides: Vec<Stride>,
    /// Indices into `strides` of the walking strides.
    pub walking: Vec<usize>,
    /// Sample period, ms.
    pub period_ms: f64,
}

/// The trials of `DATASETS` under `root`, at their own rate (`decimate` 1) or every
/// `decimate`-th sample.
pub fn walks(root: &Path, decimate: usize) -> Result<Vec<Walk>> {
    let mut out = Vec::new();
    for name in DATASETS {
        let d = datasets::load(&root.join(name))?;
        for trial in &d.trials {
            let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
            out.push(walk(&d.name, trial, &t, decimate)?);
        }
    }
    Ok(out)
}

fn walk(dataset: &str, trial: &datasets::Trial, t: &Trace, decimate: usize) -> Result<Walk> {
    let ranges = Ranges::default();
    let prepared =
        replay::prepare(t, ranges).with_context(|| format!("{}", trial.csv.display()))?;
    anyhow::ensure!(
        prepared.clock.holes.is_empty(),
        "{}: the sweep needs a recording without holes",
        trial.csv.display()
    );
    let references = trial.references_in_numbers(&prepared.clock);
    // Decimated: every `decimate`-th sample at the rate divided by it; references follow.
    let counts: Vec<RawSample> = prepared.counts.iter().step_by(decimate).copied().collect();
    let mhz = prepared.rate.millihertz() / decimate as u32;
    let rate = gaitclip::sensor::rate::SampleRate::from_millihertz(mhz)
        .with_context(|| format!("{}: rate {mhz} mHz", trial.csv.display()))?;
    let mut config = Config::new(rate, ranges.accel.scale(), ranges.gyro.scale());
    config.bridge_max_ms = FILL_MAX_MS;
    let strides = replay::core_strides(&counts, config);
    let scaled: Vec<datasets::Reference> = references
        .iter()
        .map(|r| datasets::Reference {
            start: r.start / decimate as u32,
            end: r.end / decimate as u32,
            ..*r
        })
        .collect();
    let det: Vec<Detected> = strides.iter().map(Detected::from).collect();
    let period_ms = 1e6 / mhz as f64;
    let mut walking = Vec::new();
    for (i, j) in matching::match_strides(&det, &scaled) {
        let (s, r) = (&strides[i], &scaled[j]);
        let informational = StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::TURN;
        let Some(len) = r.length_m else { continue };
        let secs = (s.events.end - s.events.start) as f64 * period_ms / 1e3;
        if !r.flagged
            && s.flags.valid()
            && !s.flags.has(informational)
            && len / secs < WALKING_MAX_MPS
        {
            walking.push(i);
        }
    }
    walking.sort_unstable();
    Ok(Walk {
        name: format!("{dataset}/{}", trial.name),
        counts,
        config,
        strides,
        walking,
        period_ms,
    })
}

/// The first sample of each hole of `p` in `s`.
fn holes_in(s: &Stride, p: Pattern) -> Vec<u32> {
    let at = if p.swing {
        (s.events.toe_off + s.events.heel_strike) / 2
    } else {
        (s.events.start + s.events.heel_off) / 2
    };
    let n = if p.cluster { CLUSTER } else { 1 };
    // Centred on the middle of the phase.
    let span = n * p.len + (n - 1) * CLUSTER_SPACING;
    let first = at.saturating_sub(span / 2);
    (0..n)
        .map(|k| first + k * (p.len + CLUSTER_SPACING))
        .collect()
}

/// What pattern `p` costs the walking strides of `w`.
pub fn cost(w: &Walk, p: Pattern) -> Cost {
    let mut total = Cost::default();
    for parity in 0..2 {
        let (cut, got) = cut_replay(w, p, parity);
        for &i in &cut {
            total.add(compare(&w.strides[i], &got, w.period_ms));
        }
    }
    total
}

/// Every other walking stride of `w` (`parity` 0 or 1) cut by pattern `p`, and the strides of
/// the cut replay (with `w.config`): the indices of the cut strides into `w.strides`, and
/// what the core reported.
pub fn cut_replay(w: &Walk, p: Pattern, parity: usize) -> (Vec<usize>, Vec<Stride>) {
    let cut: Vec<usize> = w
        .walking
        .iter()
        .copied()
        .enumerate()
        .filter(|(k, _)| k % 2 == parity)
        .map(|(_, i)| i)
        .collect();
    let mut lost_at: Vec<u32> = cut
        .iter()
        .flat_map(|&i| holes_in(&w.strides[i], p))
        .collect();
    lost_at.sort_unstable();
    // Rows kept and the gaps before them, in the core's numbering (which counts the
    // lost samples, so it is the uncut trace's).
    let mut counts = Vec::with_capacity(w.counts.len());
    let mut gaps = Vec::new();
    let mut next = lost_at.iter().peekable();
    let mut n = 0u32;
    while (n as usize) < w.counts.len() {
        if next.next_if(|&&a| a == n).is_some() {
            let missing = p.len.min(w.counts.len() as u32 - n);
            gaps.push(Gap {
                before: counts.len(),
                missing,
            });
            n += missing;
            continue;
        }
        counts.push(w.counts[n as usize]);
        n += 1;
    }
    (cut, replay::core_strides_gapped(&counts, &gaps, w.config))
}

/// The stride of `got` overlapping `want`'s movement most, if it overlaps at least half of
/// the longer of the two (else the stride was lost: missed or split).
pub fn matching_stride<'a>(want: &Stride, got: &'a [Stride]) -> Option<&'a Stride> {
    let m = got
        .iter()
        .map(|g| {
            let ov = want
                .events
                .end
                .min(g.events.end)
                .saturating_sub(want.events.heel_off.max(g.events.heel_off));
            (ov, g)
        })
        .max_by_key(|x| x.0);
    match m {
        Some((ov, g))
            if 2 * ov
                >= (want.events.end - want.events.heel_off)
                    .max(g.events.end.saturating_sub(g.events.heel_off)) =>
        {
            Some(g)
        }
        _ => None,
    }
}

/// One cut stride against the cut replay's strides.
fn compare(want: &Stride, got: &[Stride], period_ms: f64) -> Cost {
    let mut c = Cost::default();
    match matching_stride(want, got) {
        Some(g) => {
            if !g.flags.valid() {
                c.invalid += 1;
                return c;
            }
            c.length_m
                .push(g.length_mm.abs_diff(want.length_mm) as f64 / 1e3);
            c.zupt_m.push(g.zupt_um.abs_diff(want.zupt_um) as f64 / 1e6);
            c.toe_off_ms
                .push(g.events.toe_off.abs_diff(want.events.toe_off) as f64 * period_ms);
            c.heel_strike_ms
                .push(g.events.heel_strike.abs_diff(want.events.heel_strike) as f64 * period_ms);
            c.edges_ms
                .push(g.events.heel_off.abs_diff(want.events.heel_off) as f64 * period_ms);
            c.edges_ms
                .push(g.events.end.abs_diff(want.events.end) as f64 * period_ms);
        }
        None => c.lost += 1,
    }
    c
}

/// Every pattern of hole length `len`.
pub fn patterns(len: u32) -> [Pattern; 4] {
    [(false, false), (false, true), (true, false), (true, true)].map(|(cluster, swing)| Pattern {
        len,
        cluster,
        swing,
    })
}

/// The costs of every pattern of every length up to `max_len` over `walks`.
pub fn sweep(walks: &[Walk], max_len: u32) -> Vec<(Pattern, Cost)> {
    let mut out = Vec::new();
    for len in 1..=max_len {
        for p in patterns(len) {
            let mut c = Cost::default();
            for w in walks {
                c.add(cost(w, p));
            }
            out.push((p, c));
        }
    }
    out
}

/// The longest hole, ms, that keeps every pattern of every hole up to it within
/// [`MEAN_LENGTH_BOUND_M`], over sweeps at periods `period_ms` each.
pub fn limit_ms(sweeps: &[(f64, Vec<(Pattern, Cost)>)]) -> f64 {
    let mut limit = f64::INFINITY;
    for (period_ms, sweep) in sweeps {
        let mut ok_up_to = 0.0;
        for len in 1..=MAX_HOLE {
            let cells: Vec<&Cost> = sweep
                .iter()
                .filter(|(p, _)| p.len == len)
                .map(|(_, c)| c)
                .collect();
            if cells.is_empty() {
                break;
            }
            if cells
                .iter()
                .all(|c| c.mean_length_m() <= MEAN_LENGTH_BOUND_M)
            {
                ok_up_to = len as f64 * period_ms;
            } else {
                break;
            }
        }
        limit = limit.min(ok_up_to);
    }
    limit
}

/// The Markdown table of one sweep.
pub fn table(title: &str, period_ms: f64, sweep: &[(Pattern, Cost)]) -> String {
    let mut table = Table::new([
        Column::right("hole (samples)"),
        Column::right("hole (ms)"),
        Column::right("strides cut per pattern"),
        Column::from(
            "mean |Δ length| mm: single stance / single swing / cluster stance / cluster swing",
        ),
        Column::right("p95 |Δ length| mm, worst pattern"),
        Column::right("mean |Δ ZUPT| mm, worst pattern"),
        Column::from("|Δ toe-off| / |Δ heel-strike| ms, swing holes, median / p95"),
        Column::right("|Δ heel-off|, |Δ foot-flat| ms, p95, worst pattern"),
        Column::right("lost (missed or split) / invalid"),
    ]);
    let lens: Vec<u32> = {
        let mut l: Vec<u32> = sweep.iter().map(|(p, _)| p.len).collect();
        l.dedup();
        l
    };
    for len in lens {
        let cells: Vec<&Cost> = sweep
            .iter()
            .filter(|(p, _)| p.len == len)
            .map(|(_, c)| c)
            .collect();
        let swing: Vec<&Cost> = sweep
            .iter()
            .filter(|(p, _)| p.len == len && p.swing)
            .map(|(_, c)| c)
            .collect();
        let cut = cells
            .iter()
            .map(|c| c.length_m.len() + c.lost + c.invalid)
            .max()
            .unwrap_or(0);
        let means: Vec<String> = cells
            .iter()
            .map(|c| format!("{:.1}", c.mean_length_m() * 1e3))
            .collect();
        let p95 = cells
            .iter()
            .map(|c| quantile(&c.length_m, 0.95))
            .fold(0.0f64, f64::max);
        let zupt = cells.iter().map(|c| mean(&c.zupt_m)).fold(0.0f64, f64::max);
        let to: Vec<f64> = swing
            .iter()
            .flat_map(|c| c.toe_off_ms.iter().copied())
            .collect();
        let hs: Vec<f64> = swing
            .iter()
            .flat_map(|c| c.heel_strike_ms.iter().copied())
            .collect();
        let lost: usize = cells.iter().map(|c| c.lost).sum();
        let invalid: usize = cells.iter().map(|c| c.invalid).sum();
        let edges = cells
            .iter()
            .map(|c| quantile(&c.edges_ms, 0.95))
            .fold(0.0f64, f64::max);
        table.row([
            len.to_string(),
            format!("{:.0}", len as f64 * period_ms),
            cut.to_string(),
            means.join(" / "),
            format!("{:.1}", p95 * 1e3),
            format!("{:.1}", zupt * 1e3),
            format!(
                "{:.0} / {:.0}, {:.0} / {:.0}",
                quantile(&to, 0.5),
                quantile(&to, 0.95),
                quantile(&hs, 0.5),
                quantile(&hs, 0.95)
            ),
            format!("{edges:.0}"),
            format!("{lost} / {invalid}"),
        ]);
    }
    format!("{title}\n\n{}", table.render())
}

/// The whole report: both rates' tables and the limit they give.
pub fn report(root: &Path) -> Result<String> {
    let native = walks(root, 1)?;
    let half = walks(root, 2)?;
    let period = |w: &[Walk]| w.iter().map(|w| w.period_ms).sum::<f64>() / w.len() as f64;
    let (pn, ph) = (period(&native), period(&half));
    let sn = sweep(&native, MAX_HOLE);
    let sh = sweep(&half, MAX_HOLE / 2);
    let walking: usize = native.iter().map(|w| w.walking.len()).sum();
    let limit = limit_ms(&[(pn, sn.clone()), (ph, sh.clone())]);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{walking} walking strides of {} trials ({}); every hole bridged; differences against the uncut replay.\n",
        native.len(),
        DATASETS.join(", ")
    );
    s += &table(
        &format!("At the recordings' own rate (mean period {pn:.2} ms):"),
        pn,
        &sn,
    );
    s += "\n";
    s += &table(
        &format!("Decimated to half the rate (every other sample, mean period {ph:.2} ms):"),
        ph,
        &sh,
    );
    let _ = writeln!(
        s,
        "\nLongest hole keeping every pattern's mean |Δ length| ≤ {:.0} cm at both rates: {limit:.1} ms.",
        MEAN_LENGTH_BOUND_M * 100.0
    );
    Ok(s)
}

//! `gaitclip bias`: what moves the ZUPT stride's bias from one set-up to another, and the
//! bias by dataset × mounting × pace before and after the change it led to.
//!
//! **The question.** On walks it was never tuned on (another IMU, other walkers and shoes) the
//! ZUPT stride came out 1.3 cm long per stride, on the datasets here within 0.5 cm. A set-up
//! constant is the suspect: the lever arm `h` of the rolling contact (80 mm), or something
//! else a set-up changes. This module measures each candidate's effect instead of assuming it:
//!
//! - **the sensitivity table**: the bias change when one thing changes: `h` at 0, 40 and
//!   120 mm, the sample clock off by 0.5 %, an accelerometer gain 1 % off, an offset of
//!   0.5 m/s² along gravity, and the unit a count is turned into metres with
//!   ([`gaitclip::detect::zupt::GravityReading`]);
//! - **the lever arm from the strides**: the least-squares `h` that makes each stride's end
//!   velocity residual agree with the rolling contact at both instants (what a recursive
//!   estimator on the pod would converge to), pooled per dataset and per trial after 10, 20
//!   and all of its strides, beside the `h` that would zero each dataset's bias;
//! - **what the sensors read for gravity at rest**, per dataset and foot;
//! - **the bias by set-up**, before (lengths in the rest's gravity, the old unit) and after
//!   (the sensor's own scale), with 95 % bootstrap intervals; the walked distance per
//!   recording; and for `ipol_gait_events`, which has no per-stride lengths, each foot's
//!   distance and the difference between the two feet of the same walk.
//!
//! Strides are scored as `gaitclip eval` scores the `zupt` model: the cycle detector's
//! valid strides matched to clean reference strides (unscored spans, and references holding
//! a movement the Vicon labels show unbordered, left out), error = ZUPT length − reference.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use gaitclip::detect::zupt::GravityReading;
use gaitclip::length::models::Model;
use gaitclip::pipeline::config::Config;
use gaitclip::record::stride::StrideFlags;
use gaitclip::sensor::rate::SampleRate;
use rand::{Rng, SeedableRng};

use crate::eval::length_eval::SPEED_BINS;
use crate::eval::markdown::{Column, Table};
use crate::eval::matching::{self, Detected, Scored};
use crate::eval::scoring;
use crate::eval::stats::{median, quantile};
use crate::io::datasets::{self, Dataset, Trial};
use crate::io::trace::{ImuSample, Ranges, Trace};
use crate::reference::cycle_ref;
use crate::{io::csv_trace, replay};

/// One clean matched stride: the reference stride's speed (m/s), the ZUPT error (m) and
/// whether the gyro clipped in it.
#[derive(Clone, Copy, Debug)]
pub struct StrideError {
    /// Reference length over the reference stride's duration, m/s.
    pub speed_mps: f64,
    /// ZUPT length − reference length, m.
    pub error_m: f64,
    /// The stride's gyro reached a rail.
    pub gyro_clipped: bool,
}

/// One trial replayed with one configuration.
#[derive(Clone, Debug)]
pub struct TrialRun {
    /// Its clean matched strides.
    pub strides: Vec<StrideError>,
    /// Summed length of the strides whose movement's middle lies in the trial's span (every
    /// stride that counts distance: measured or estimated), m.
    pub walked_m: f64,
}

/// A change to the configuration.
pub type Setup<'a> = &'a dyn Fn(&mut Config);

/// Replays `trace` (trial `trial`) with the default configuration changed by `setup` and
/// scores its ZUPT strides.
pub fn run_trial(trial: &Trial, trace: &Trace, ranges: Ranges, setup: Setup) -> Result<TrialRun> {
    let p = replay::prepare(trace, ranges).with_context(|| format!("{}", trial.csv.display()))?;
    let mut c = p.config(ranges);
    c.model = Model::Zupt;
    setup(&mut c);
    let strides = p.strides(c);
    let det: Vec<Detected> = strides.iter().map(Detected::from).collect();
    let refs = trial.references_in_numbers(&p.clock);
    let rate = p.clock.rate_hz();
    let scored = matching::classify(trial, &p.clock, &det, &refs);
    // As training scores: a reference holding a movement its borders leave out measured two
    // movements, and no stride is compared with it.
    let holds_two = |r: &datasets::Reference| {
        det.iter().zip(&scored).any(|(d, c)| {
            *c == Scored::Unbordered
                && 2 * (d.events.foot_flat.min(r.end))
                    .saturating_sub(d.events.heel_off.max(r.start))
                    >= d.events.foot_flat - d.events.heel_off
        })
    };
    let mut out = Vec::new();
    for (i, c) in scored.iter().enumerate() {
        let Scored::Found(j) = *c else { continue };
        let (s, r) = (&strides[i], &refs[j]);
        if !s.flags.valid() || holds_two(r) {
            continue;
        }
        let Some(len) = r.length_m else { continue };
        out.push(StrideError {
            speed_mps: len / ((r.end - r.start) as f64 / rate),
            error_m: s.zupt_um as f64 / 1e6 - len,
            gyro_clipped: s.flags.has(StrideFlags::GYRO_CLIPPED),
        });
    }
    let span = trial.span_in_numbers(&p.clock);
    let walked_m = strides
        .iter()
        .filter(|s| {
            let mid = s.events.heel_off / 2 + s.events.end / 2;
            mid >= span.0 && mid < span.1
        })
        .filter(|s| s.flags.counts_distance())
        .map(|s| s.length_mm as f64 / 1e3)
        .sum();
    Ok(TrialRun {
        strides: out,
        walked_m,
    })
}

/// The mean specific force magnitude where the foot is still (|ω| under 0.05 rad/s for a
/// quarter second either side), m/s²: what the sensor reads for gravity. NaN if never still.
pub fn rest_gravity_mps2(trace: &Trace) -> f64 {
    let s = &trace.samples;
    let half = ((trace.rate_hz * 0.125).round() as usize).max(1);
    let w: Vec<f64> = s.iter().map(|x| norm(x.gyr_radps)).collect();
    let (mut sum, mut n) = (0.0, 0usize);
    for i in half..s.len().saturating_sub(half) {
        if w[i - half..=i + half].iter().all(|&v| v < 0.05) {
            sum += norm(s[i].acc_mps2);
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The unit vector of the sensor axes along which it reads gravity at rest.
fn rest_up(trace: &Trace) -> [f64; 3] {
    let s = &trace.samples;
    let mut m = [0.0; 3];
    for x in s.iter().filter(|x| norm(x.gyr_radps) < 0.05) {
        for (m, a) in m.iter_mut().zip(x.acc_mps2) {
            *m += a;
        }
    }
    let n = norm(m);
    if n > 0.0 {
        m.map(|v| v / n)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// The trace as a clip turned 180° about the vertical would have recorded it (the rotation
/// `2·u·uᵀ − I` about the axis `u` that reads gravity at rest).
pub fn turned_180(trace: &Trace) -> Trace {
    let u = rest_up(trace);
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = 2.0 * u[i] * u[j] - if i == j { 1.0 } else { 0.0 };
        }
    }
    Trace {
        samples: scoring::rotate(&trace.samples, &r),
        ..trace.clone()
    }
}

/// The trace with its accelerometer changed by `f` (gain, offset), as another sensor would
/// have read it.
fn with_accel(trace: &Trace, f: impl Fn([f64; 3]) -> [f64; 3]) -> Trace {
    Trace {
        samples: trace
            .samples
            .iter()
            .map(|s| ImuSample {
                acc_mps2: f(s.acc_mps2),
                ..*s
            })
            .collect(),
        ..trace.clone()
    }
}

/// Mean and a 95 % percentile bootstrap interval of `stat` over `v` (2 000 resamples, a fixed
/// seed: the table is the same on every run).
fn bootstrap(v: &[f64], stat: impl Fn(&[f64]) -> f64) -> (f64, f64, f64) {
    let x = stat(v);
    if v.len() < 2 {
        return (x, f64::NAN, f64::NAN);
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
    let mut buf = vec![0.0; v.len()];
    let mut stats: Vec<f64> = (0..2000)
        .map(|_| {
            for b in buf.iter_mut() {
                *b = v[rng.random_range(0..v.len())];
            }
            stat(&buf)
        })
        .collect();
    stats.sort_by(f64::total_cmp);
    (x, quantile(&stats, 0.025), quantile(&stats, 0.975))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn rmse(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// `±x.x [lo, hi]` in cm.
fn ci_cell((x, lo, hi): (f64, f64, f64), signed: bool) -> String {
    if lo.is_nan() {
        return if signed {
            format!("{:+.1}", x * 100.0)
        } else {
            format!("{:.1}", x * 100.0)
        };
    }
    if signed {
        format!("{:+.1} [{:+.1}, {:+.1}]", x * 100.0, lo * 100.0, hi * 100.0)
    } else {
        format!("{:.1} [{:.1}, {:.1}]", x * 100.0, lo * 100.0, hi * 100.0)
    }
}

fn bin_name(bin: (f64, f64)) -> String {
    crate::eval::length_eval::bin_label(bin, "m/s")
}

/// A dataset's trials with their traces read once.
pub struct Loaded {
    /// The dataset.
    pub dataset: Dataset,
    /// Its trials' traces, in its trials' order.
    pub traces: Vec<Trace>,
}

/// Reads dataset `name` of the datasets folder `root`.
pub fn load(root: &Path, name: &str) -> Result<Loaded> {
    let dataset = datasets::load(&root.join(name))?;
    let traces = dataset
        .trials
        .iter()
        .map(|t| csv_trace::read(&t.csv, Some(dataset.rate_hz)).map_err(anyhow::Error::from))
        .collect::<Result<_>>()?;
    Ok(Loaded { dataset, traces })
}

impl Loaded {
    /// Every trial's run with `setup`, each trace first changed by `change`.
    pub fn runs(&self, change: &dyn Fn(&Trace) -> Trace, setup: Setup) -> Result<Vec<TrialRun>> {
        self.dataset
            .trials
            .iter()
            .zip(&self.traces)
            .map(|(trial, t)| run_trial(trial, &change(t), Ranges::default(), setup))
            .collect()
    }
}

/// The errors (m) of the strides of `runs` that `keep` keeps.
pub fn errors(runs: &[TrialRun], keep: impl Fn(&StrideError) -> bool) -> Vec<f64> {
    runs.iter()
        .flat_map(|r| r.strides.iter().filter(|s| keep(s)).map(|s| s.error_m))
        .collect()
}

/// The trace as recorded.
pub fn unchanged(t: &Trace) -> Trace {
    t.clone()
}

/// The trace with an accelerometer offset of `mps2` along the axis that reads gravity at rest.
pub fn offset_along_gravity(t: &Trace, mps2: f64) -> Trace {
    let u = rest_up(t);
    with_accel(t, move |a| [0, 1, 2].map(|k| a[k] + mps2 * u[k]))
}

/// Each walk's left-foot minus right-foot walked distance, fraction of its distance
/// (`ipol_gait_events`: both feet walk the same path).
pub fn feet_apart(ipol: &Loaded, setup: Setup) -> Result<Vec<f64>> {
    Ok(feet(ipol, setup)?
        .values()
        .filter_map(|v| Some(v[0]? - v[1]?))
        .collect())
}

/// Per walk, each foot's walked-distance error against the walk's distance, fraction.
fn feet(
    ipol: &Loaded,
    setup: Setup,
) -> Result<std::collections::BTreeMap<String, [Option<f64>; 2]>> {
    let runs = ipol.runs(&unchanged, setup)?;
    let mut by: std::collections::BTreeMap<String, [Option<f64>; 2]> = Default::default();
    for (tr, r) in ipol.dataset.trials.iter().zip(&runs) {
        let (walk, foot) = tr.name.rsplit_once('_').unwrap_or((&tr.name, ""));
        let m = tr.distance_m.unwrap_or(20.0);
        let e = (r.walked_m - m) / m;
        let slot = by.entry(walk.to_string()).or_default();
        match foot {
            "left" => slot[0] = Some(e),
            _ => slot[1] = Some(e),
        }
    }
    Ok(by)
}

/// The least-squares lever arm of [`report`]'s second table for one dataset.
#[derive(Clone, Debug)]
pub struct LeverFit {
    /// Strides fitted.
    pub strides: usize,
    /// The pooled estimate and its standard error, m.
    pub pooled_m: (f64, f64),
    /// Per trial with at least 10 strides, the estimate after its first 10, m.
    pub after_10_m: Vec<f64>,
    /// Per trial with at least 10 strides, the estimate over all of them, m.
    pub all_m: Vec<f64>,
    /// The residual's rms about the fit (m/s) and the regressor's rms (rad/s).
    pub rms: (f64, f64),
}

/// Fits `h` in `r = h·(u₁ − u₀)` over the strides of `d` ([`cycle_ref::end_residual`]).
pub fn lever_fit(d: &Loaded) -> Result<LeverFit> {
    let mut pooled = (0.0, 0.0);
    let (mut after_10_m, mut all_m, mut all) = (Vec::new(), Vec::new(), Vec::new());
    for (trial, trace) in d.dataset.trials.iter().zip(&d.traces) {
        let p = replay::prepare(trace, Ranges::default())
            .with_context(|| format!("{}", trial.csv.display()))?;
        let run = cycle_ref::run(&p.counts, &p.clock.holes, p.config(Ranges::default()));
        let (mut num, mut den, mut n) = (0.0, 0.0, 0usize);
        for k in 0..run.strides.len() {
            let Ok(e) = cycle_ref::end_residual(&run, k) else {
                continue;
            };
            let du = [e.u1[0] - e.u0[0], e.u1[1] - e.u0[1]];
            num += e.r[0] * du[0] + e.r[1] * du[1];
            den += du[0] * du[0] + du[1] * du[1];
            n += 1;
            all.push((e.r, du));
            if n == 10 && den > 0.0 {
                after_10_m.push(num / den);
            }
        }
        if den > 0.0 && n >= 10 {
            all_m.push(num / den);
        }
        pooled.0 += num;
        pooled.1 += den;
    }
    let h = pooled.0 / pooled.1;
    let resid2: Vec<f64> = all
        .iter()
        .map(|(r, du)| (r[0] - h * du[0]).powi(2) + (r[1] - h * du[1]).powi(2))
        .collect();
    let du2: Vec<f64> = all
        .iter()
        .map(|(_, du)| du[0] * du[0] + du[1] * du[1])
        .collect();
    // Per component the residual's variance is half its squared norm's mean; the slope's
    // standard error is σ / √Σ|u₁ − u₀|².
    let se = (mean(&resid2) / 2.0).sqrt() / pooled.1.sqrt();
    Ok(LeverFit {
        strides: all.len(),
        pooled_m: (h, se),
        after_10_m,
        all_m,
        rms: (mean(&resid2).sqrt(), mean(&du2).sqrt()),
    })
}

/// The mean ZUPT error (m) and the strides of dataset `d` with `setup`, each trace changed by
/// `change`; only strides whose reference speed lies in `bin` (m/s) when given.
pub fn bias_m(
    d: &Loaded,
    change: &dyn Fn(&Trace) -> Trace,
    setup: Setup,
    bin: Option<(f64, f64)>,
) -> Result<(f64, usize)> {
    let e = errors(&d.runs(change, setup)?, |e| {
        bin.is_none_or(|(lo, hi)| e.speed_mps >= lo && e.speed_mps < hi)
    });
    Ok((mean(&e), e.len()))
}

/// The lever arm `h` under which dataset `d`'s mean ZUPT error is zero, m: the bias is
/// linear in `h` (the rolling velocity `ω × h·up` is), so the line through `h = 0` and the
/// default 80 mm gives it.
pub fn zeroing_h_m(d: &Loaded) -> Result<f64> {
    let (b0, _) = bias_m(
        d,
        &unchanged,
        &|c: &mut Config| c.sensor_height_um = 0,
        None,
    )?;
    let (b80, _) = bias_m(d, &unchanged, &after, None)?;
    Ok(-b0 / ((b80 - b0) / 0.08))
}

/// The configuration before the bias study: the rest's departure from 1 g read as a gain.
pub fn before(c: &mut Config) {
    c.gravity_reading = GravityReading::Gain;
}

/// The default: read as an offset along gravity.
pub fn after(c: &mut Config) {
    c.gravity_reading = GravityReading::Offset;
}

/// The departure left in.
pub fn ignored(c: &mut Config) {
    c.gravity_reading = GravityReading::Ignored;
}

/// What moves the bias: the bias change when one thing changes.
fn sensitivity_table(with_lengths: &[Loaded]) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "What moves the bias: the ZUPT stride's bias change (cm) when one thing changes, from the default (the rest's departure from 1 g read as an offset along gravity, h = 80 mm); clean matched strides:\n"
    )?;
    let fast = (1.5, 3.0);
    let mut t = Table::new({
        let mut h = vec![Column::from("change")];
        for d in with_lengths {
            h.push(Column::right(format!("{}: all", d.dataset.name)));
            h.push(Column::right(format!(
                "{}: {}",
                d.dataset.name,
                bin_name(fast)
            )));
        }
        h
    });
    let base: Vec<Vec<TrialRun>> = with_lengths
        .iter()
        .map(|d| d.runs(&unchanged, &after))
        .collect::<Result<_>>()?;
    let bias_of = |runs: &[TrialRun], bin: Option<(f64, f64)>| {
        mean(&errors(runs, |e| {
            bin.is_none_or(|(lo, hi)| e.speed_mps >= lo && e.speed_mps < hi)
        }))
    };
    let mut row = vec!["(the default: its bias)".to_string()];
    for b in &base {
        row.push(format!("{:+.2}", bias_of(b, None) * 100.0));
        row.push(format!("{:+.2}", bias_of(b, Some(fast)) * 100.0));
    }
    t.row(row);
    // One row: how far the bias moves, over all strides and at 1.5–3 m/s, on each dataset.
    let moved = |name: String, change: &dyn Fn(&Trace) -> Trace, setup: Setup| {
        let mut row = vec![name];
        for (d, b) in with_lengths.iter().zip(&base) {
            let r = d.runs(change, setup)?;
            for bin in [None, Some(fast)] {
                row.push(format!(
                    "{:+.2}",
                    (bias_of(&r, bin) - bias_of(b, bin)) * 100.0
                ));
            }
        }
        Ok::<_, anyhow::Error>(row)
    };
    type Change<'a> = (
        &'a str,
        Box<dyn Fn(&Trace) -> Trace>,
        Box<dyn Fn(&mut Config)>,
    );
    let offset_along_gravity = |t: &Trace| offset_along_gravity(t, 0.5);
    let mut extra: Vec<Vec<String>> = Vec::new();
    let changes: Vec<Change> = vec![
        (
            "h = 0 mm (zero velocity at the instant)",
            Box::new(unchanged),
            Box::new(|c: &mut Config| c.sensor_height_um = 0),
        ),
        (
            "h = 40 mm",
            Box::new(unchanged),
            Box::new(|c: &mut Config| c.sensor_height_um = 40_000),
        ),
        (
            "h = 120 mm",
            Box::new(unchanged),
            Box::new(|c: &mut Config| c.sensor_height_um = 120_000),
        ),
        (
            "sample clock 0.5 % fast (the rate the core is told 0.5 % low)",
            Box::new(unchanged),
            Box::new(|c: &mut Config| {
                if let Some(r) =
                    SampleRate::from_millihertz((c.rate.millihertz() as f64 / 1.005) as u32)
                {
                    c.rate = r;
                }
            }),
        ),
        (
            "the rest's departure from 1 g read as a gain (lengths in its units: before)",
            Box::new(unchanged),
            Box::new(before),
        ),
        (
            "the rest's departure from 1 g left in (the sensor's scale)",
            Box::new(unchanged),
            Box::new(ignored),
        ),
    ];
    let gain = |t: &Trace| with_accel(t, |a| a.map(|v| v * 1.01));
    for (what, reading) in [
        ("read as an offset (after)", &after as Setup),
        ("read as a gain (before)", &before),
        ("left in", &ignored),
    ] {
        for (made, change) in [
            (
                "accelerometer gain +1 % on every axis",
                &gain as &dyn Fn(&Trace) -> Trace,
            ),
            (
                "accelerometer offset +0.5 m/s² along gravity",
                &offset_along_gravity,
            ),
        ] {
            extra.push(moved(format!("{made}, {what}"), change, reading)?);
        }
    }
    for (name, change, setup) in &changes {
        t.row(moved(name.to_string(), change.as_ref(), setup.as_ref())?);
    }
    for row in extra {
        t.row(row);
    }
    s.push_str(&t.render());

    Ok(s)
}

/// The lever arm fitted to the end residuals, beside the one that zeroes each bias.
fn lever_table(with_lengths: &[Loaded], ipol: &Loaded) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nThe lever arm from the strides' end-velocity residual (least squares over strides of the residual at h = 0 against the rolling velocity per metre of h at the two instants, `r = h·(u₁ − u₀)`: what a recursive fit on the pod converges to), beside the h that zeroes each dataset's bias:\n"
    )?;
    let mut t = Table::new([
        Column::from("dataset"),
        Column::right("strides"),
        Column::right("pooled h ± SE (mm)"),
        Column::right("per trial after 10 strides: median [p10, p90] (mm)"),
        Column::right("per trial, all strides: median [p10, p90] (mm)"),
        Column::right("residual rms / |u₁ − u₀| rms"),
        Column::right("h zeroing the bias (mm)"),
    ]);
    for d in with_lengths.iter().chain(std::iter::once(ipol)) {
        let fit = lever_fit(d)?;
        let q = |v: &[f64]| {
            format!(
                "{:.0} [{:.0}, {:.0}]",
                median(v) * 1e3,
                quantile(v, 0.1) * 1e3,
                quantile(v, 0.9) * 1e3
            )
        };
        let zeroing = match with_lengths
            .iter()
            .position(|x| x.dataset.name == d.dataset.name)
        {
            Some(_) => format!("{:.0}", zeroing_h_m(d)? * 1e3),
            None => "– (no per-stride lengths)".into(),
        };
        t.row([
            d.dataset.name.clone(),
            fit.strides.to_string(),
            format!("{:.0} ± {:.0}", fit.pooled_m.0 * 1e3, fit.pooled_m.1 * 1e3),
            q(&fit.after_10_m),
            q(&fit.all_m),
            format!("{:.2} m/s / {:.2} rad/s", fit.rms.0, fit.rms.1),
            zeroing,
        ]);
    }
    s.push_str(&t.render());

    Ok(s)
}

/// What each sensor reads for gravity at rest.
fn gravity_table(with_lengths: &[Loaded], ipol: &Loaded) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nWhat each sensor reads for gravity at rest (|f| where |ω| < 0.05 rad/s for ±125 ms; standard gravity 9.807 m/s²):\n"
    )?;
    let mut t = Table::new([
        Column::from("dataset"),
        Column::from("sensor"),
        Column::right("recordings"),
        Column::right("|f| at rest, median [min, max] (m/s²)"),
        Column::right("off standard gravity (median)"),
    ]);
    let foot_of = |d: &Loaded, trial: &Trial| -> String {
        match d.dataset.name.as_str() {
            "ipol_gait_events" => trial.name.rsplit('_').next().unwrap_or("").to_string() + " foot",
            "gaitmap_walk" => format!("{} foot", trial.name),
            _ => "right foot".into(),
        }
    };
    for d in with_lengths.iter().chain(std::iter::once(ipol)) {
        let mut by: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
        for (trial, trace) in d.dataset.trials.iter().zip(&d.traces) {
            let g = rest_gravity_mps2(trace);
            if g.is_finite() {
                by.entry(foot_of(d, trial)).or_default().push(g);
            }
        }
        for (foot, g) in by {
            t.row([
                d.dataset.name.clone(),
                foot,
                g.len().to_string(),
                format!(
                    "{:.3} [{:.3}, {:.3}]",
                    median(&g),
                    quantile(&g, 0.0001),
                    quantile(&g, 1.0)
                ),
                format!("{:+.2} %", (median(&g) / 9.80665 - 1.0) * 100.0),
            ]);
        }
    }
    s.push_str(&t.render());

    Ok(s)
}

/// The bias and RMSE by dataset × mounting × pace, before and after.
fn setup_table(with_lengths: &[Loaded]) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nThe ZUPT stride by set-up, before (the rest's departure from 1 g read as a gain: lengths in units of its gravity) and after (read as an offset along gravity: removed, lengths at the sensor's scale), h = 80 mm; bias and RMSE in cm with 95 % bootstrap intervals over strides:\n"
    )?;
    let mut t = Table::new([
        Column::from("dataset"),
        Column::from("mounting"),
        Column::from("pace"),
        Column::right("strides"),
        Column::right("before: bias"),
        Column::right("before: RMSE"),
        Column::right("after: bias"),
        Column::right("after: RMSE"),
    ]);
    let turned = |t: &Trace| turned_180(t);
    for d in with_lengths {
        let mountings: Vec<(String, Vec<usize>, bool)> = match d.dataset.name.as_str() {
            "gaitmap_walk" => d
                .dataset
                .trials
                .iter()
                .enumerate()
                .flat_map(|(i, tr)| {
                    [
                        (format!("{} shoe", tr.name), vec![i], false),
                        (format!("{} shoe, turned 180°", tr.name), vec![i], true),
                    ]
                })
                .collect(),
            _ => {
                let all: Vec<usize> = (0..d.dataset.trials.len()).collect();
                vec![
                    ("right shoe".into(), all.clone(), false),
                    ("right shoe, turned 180°".into(), all, true),
                ]
            }
        };
        for (name, idx, turn) in mountings {
            let pick = |setup: Setup| -> Result<Vec<TrialRun>> {
                idx.iter()
                    .map(|&i| {
                        let tr = &d.traces[i];
                        let trace = if turn { turned(tr) } else { tr.clone() };
                        run_trial(&d.dataset.trials[i], &trace, Ranges::default(), setup)
                    })
                    .collect()
            };
            let (b, a) = (pick(&before)?, pick(&after)?);
            let mut paces: Vec<(String, Option<(f64, f64)>)> = vec![("all".into(), None)];
            paces.extend(SPEED_BINS.iter().map(|&bin| (bin_name(bin), Some(bin))));
            for (pace, bin) in paces {
                let keep = |e: &StrideError| {
                    bin.is_none_or(|(lo, hi)| e.speed_mps >= lo && e.speed_mps < hi)
                };
                let (eb, ea) = (errors(&b, keep), errors(&a, keep));
                if ea.is_empty() {
                    continue;
                }
                t.row([
                    d.dataset.name.clone(),
                    name.clone(),
                    pace,
                    ea.len().to_string(),
                    ci_cell(bootstrap(&eb, mean), true),
                    ci_cell(bootstrap(&eb, rmse), false),
                    ci_cell(bootstrap(&ea, mean), true),
                    ci_cell(bootstrap(&ea, rmse), false),
                ]);
            }
        }
    }
    s.push_str(&t.render());

    Ok(s)
}

/// The walked distance per recording, before and after.
fn walked_table(with_lengths: &[Loaded]) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\nWalked distance per recording, before / after: |error| median and worst (`pyshoe_vicon`: the trials whose reference strides follow one another over at least 10 m; the shuffling and crawling trials cover centimetres and are left out):\n"
    )?;
    let mut t = Table::new([
        Column::from("dataset"),
        Column::right("recordings"),
        Column::right("before: median / worst"),
        Column::right("after: median / worst"),
    ]);
    for d in with_lengths {
        let refs: Vec<Option<f64>> = d
            .dataset
            .trials
            .iter()
            .map(|tr| {
                let l: Vec<f64> = tr.references.iter().filter_map(|r| r.length_m).collect();
                let contiguous = tr.references.windows(2).all(|w| w[0].end == w[1].start);
                let total: f64 = l.iter().sum();
                tr.distance_m
                    .or((contiguous && !l.is_empty()).then_some(total))
                    .filter(|&m| m >= 10.0)
            })
            .collect();
        let cell = |runs: &[TrialRun]| {
            let e: Vec<f64> = runs
                .iter()
                .zip(&refs)
                .filter_map(|(r, m)| m.map(|m| ((r.walked_m - m) / m).abs()))
                .collect();
            (
                e.len(),
                format!(
                    "{:.2} % / {:.2} %",
                    median(&e) * 100.0,
                    quantile(&e, 1.0) * 100.0
                ),
            )
        };
        let (b, a) = (d.runs(&unchanged, &before)?, d.runs(&unchanged, &after)?);
        let ((n, cb), (_, ca)) = (cell(&b), cell(&a));
        t.row([d.dataset.name.clone(), n.to_string(), cb, ca]);
    }
    s.push_str(&t.render());

    Ok(s)
}

/// `ipol_gait_events`' feet against the walk and against each other.
fn feet_table(ipol: &Loaded) -> Result<String> {
    let mut s = String::new();
    writeln!(
        s,
        "\n`ipol_gait_events` (no per-stride lengths): each foot's walked distance against the 20 m of the walk (the U-turn's extra path not counted in the 20 m), and the two feet of the same walk against each other (same path; left − right, % of 20 m):\n"
    )?;
    let mut t = Table::new([
        Column::from("the rest's departure from 1 g"),
        Column::right("left foot: median error [p10, p90]"),
        Column::right("right foot: median error [p10, p90]"),
        Column::right("left − right: median [p10, p90]"),
        Column::right("|left − right|: median"),
    ]);
    for (label, setup) in [
        ("before: read as a gain", &before as Setup),
        ("left in", &ignored),
        ("after: read as an offset", &after),
    ] {
        let by = feet(ipol, setup)?;
        let left: Vec<f64> = by.values().filter_map(|v| v[0]).collect();
        let right: Vec<f64> = by.values().filter_map(|v| v[1]).collect();
        let diff: Vec<f64> = by.values().filter_map(|v| Some(v[0]? - v[1]?)).collect();
        let q = |v: &[f64]| {
            format!(
                "{:+.2} % [{:+.2}, {:+.2}]",
                median(v) * 100.0,
                quantile(v, 0.1) * 100.0,
                quantile(v, 0.9) * 100.0
            )
        };
        let abs: Vec<f64> = diff.iter().map(|x| x.abs()).collect();
        t.row([
            label.to_string(),
            q(&left),
            q(&right),
            q(&diff),
            format!("{:.2} %", median(&abs) * 100.0),
        ]);
    }
    s.push_str(&t.render());
    Ok(s)
}

/// The whole report, Markdown.
pub fn report(root: &Path) -> Result<String> {
    let with_lengths = [load(root, "gaitmap_walk")?, load(root, "pyshoe_vicon")?];
    let ipol = load(root, "ipol_gait_events")?;
    Ok([
        sensitivity_table(&with_lengths)?,
        lever_table(&with_lengths, &ipol)?,
        gravity_table(&with_lengths, &ipol)?,
        setup_table(&with_lengths)?,
        walked_table(&with_lengths)?,
        feet_table(&ipol)?,
    ]
    .concat())
}

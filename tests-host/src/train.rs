//! Training of every length model on the shared recordings, and the generated Rust source
//! the firmware compiles (`src/trained.rs`).
//!
//! Data: the core's strides on `pyshoe_vicon` and `gaitmap_walk`, matched to their
//! reference strides; a stride trains only when its reference is clean (unflagged) and the
//! core marked it valid. Features are the f64 reference features ([`crate::length_ref`]).
//!
//! - Closed-form models: least squares (SVD) on their basis terms.
//! - SVRs (`linfa-svm`, ε-SVR, RBF kernel): inputs are the [`SELECTED`] features of their
//!   segment most correlated with the length (Huang ranks by random-forest importance; a
//!   correlation ranking needs no extra model) plus the ZUPT displacement, z-scored with
//!   the training statistics. `C`, `γ` and `ε` by grid search with cross-validation
//!   grouped by trial ([`FOLDS`] folds; a walk's strides are never split between training
//!   and test).
//! - SVR-AdaBoost: AdaBoost.R2 (Drucker 1997, linear loss) with [`BOOST_ROUNDS`] members per
//!   phase, each fit on a weighted resample (seeded ChaCha8, so training is repeatable).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use gaitclip::features::{self, Features, COUNT, PER_SEGMENT, ZUPT_LENGTH};
use gaitclip::models::{Model, ModelParams, Settings, LINEAR_MODELS, MAX_TERMS};
use gaitclip::phase_stats::{Channel, Segment, StrideStats};
use gaitclip::rate::SampleRate;
use gaitclip::stride::Stride;
use gaitclip::svr::{Boosted, Svr};
use linfa::prelude::*;
use linfa_svm::Svm;
use nalgebra::{DMatrix, DVector};
use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::datasets::{self, Dataset};
use crate::matching::{self, Detected};
use crate::trace::Ranges;
use crate::{csv_trace, replay};
use crate::{length_eval, length_ref};

/// Folds of the grouped cross-validation.
pub const FOLDS: usize = 5;
/// Features per SVR chosen from its segment (the ZUPT displacement is added to them).
pub const SELECTED: usize = 8;
/// Members per AdaBoost.R2 ensemble.
pub const BOOST_ROUNDS: usize = 4;
/// Grid of `C`.
pub const GRID_C: [f64; 3] = [1.0, 10.0, 100.0];
/// Grid of `γ` (per squared z unit).
pub const GRID_GAMMA: [f64; 3] = [0.03, 0.1, 0.3];
/// Grid of `ε`, m.
pub const GRID_EPS: [f64; 2] = [0.02, 0.05];
/// Datasets with per-stride lengths, the training data.
pub const TRAINING_DATASETS: [&str; 2] = ["gaitmap_walk", "pyshoe_vicon"];
/// Seed of the AdaBoost resampling.
const SEED: u64 = 0x6a17_c11b;

/// One trial replayed through the core.
pub struct TrialRun {
    /// Dataset name.
    pub dataset: String,
    /// Trial name.
    pub trial: String,
    /// Sample rate.
    pub rate: SampleRate,
    /// The core's strides whose movement's middle lies in the trial's annotated span.
    pub strides: Vec<Stride>,
    /// Their phase statistics.
    pub stats: Vec<StrideStats>,
    /// Their f64 features.
    pub x: Vec<[f64; COUNT]>,
    /// Their fixed-point features.
    pub fixed: Vec<Features>,
    /// Reference length of each stride where it is matched to a clean reference and valid.
    pub reference: Vec<Option<f64>>,
    /// The reference stride's speed, m/s (length over the reference's duration), where
    /// there is a reference length.
    pub speed_mps: Vec<Option<f64>>,
    /// Distance walked over the span by the reference, m: the dataset's walked distance, or
    /// the sum of its reference strides where they follow one another without a break
    /// (`None` where they do not: the walk left the capture volume).
    pub reference_total_m: Option<f64>,
    /// Device settings (the walker's height where known).
    pub settings: Settings,
}

/// Replays every trial of `dataset` through the core.
pub fn run_dataset(dataset: &Dataset) -> Result<Vec<TrialRun>> {
    let ranges = Ranges::default();
    let mut out = Vec::new();
    for trial in &dataset.trials {
        let trace = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        let prepared =
            replay::prepare(&trace, ranges).with_context(|| format!("{}", trial.csv.display()))?;
        let rate = prepared.rate;
        let all = prepared.strides_with_stats(prepared.config(ranges));
        let span = trial.span_in_numbers(&prepared.clock);
        let references = trial.references_in_numbers(&prepared.clock);
        let (strides, stats): (Vec<Stride>, Vec<StrideStats>) = all
            .into_iter()
            // A stride belongs to the span when its movement's middle does: a first step
            // that ends just inside the reference's first stride is not in it.
            .filter(|(s, _)| {
                let mid = s.heel_off / 2 + s.end / 2;
                mid >= span.0 && mid < span.1
            })
            .unzip();
        let det: Vec<Detected> = strides.iter().map(Detected::from).collect();
        let scored = matching::classify(trial, &prepared.clock, &det, &references);
        // A reference that holds a movement its borders leave out measured two movements:
        // no length to compare one stride with.
        let holds_two = |r: &datasets::Reference| {
            det.iter().zip(&scored).any(|(d, c)| {
                *c == matching::Scored::Unbordered
                    && 2 * (d.foot_flat.min(r.end)).saturating_sub(d.heel_off.max(r.start))
                        >= d.foot_flat - d.heel_off
            })
        };
        let mut reference = vec![None; strides.len()];
        let mut speed_mps = vec![None; strides.len()];
        for (i, c) in scored.iter().enumerate() {
            if let matching::Scored::Found(j) = *c {
                let r = &references[j];
                if strides[i].flags.valid() && !holds_two(r) {
                    reference[i] = r.length_m;
                    let duration_s =
                        r.end.saturating_sub(r.start) as f64 / prepared.clock.rate_hz();
                    speed_mps[i] = r.length_m.map(|l| l / duration_s);
                }
            }
        }
        let lengths: Vec<f64> = trial.references.iter().filter_map(|r| r.length_m).collect();
        // The reference strides give the walk's length only when they follow one another
        // without a break (`pyshoe_vicon`'s leave the capture volume and come back).
        let contiguous = trial.references.windows(2).all(|w| w[0].end == w[1].start);
        let reference_total_m = trial
            .distance_m
            .or((contiguous && !lengths.is_empty()).then(|| lengths.iter().sum()));
        let settings = trial.height_m.map_or(Settings::DEFAULT, |h| Settings {
            height_mm: (h * 1000.0).round() as u16,
        });
        out.push(TrialRun {
            dataset: dataset.name.clone(),
            trial: trial.name.clone(),
            rate,
            x: strides
                .iter()
                .zip(&stats)
                .map(|(s, st)| length_ref::features(s, st, rate))
                .collect(),
            fixed: strides
                .iter()
                .zip(&stats)
                .map(|(s, st)| Features::of(s, st, rate))
                .collect(),
            strides,
            stats,
            reference,
            speed_mps,
            reference_total_m,
            settings,
        });
    }
    Ok(out)
}

/// One training stride.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Trial it belongs to (`dataset/trial`): the cross-validation group.
    pub group: String,
    /// f64 features.
    pub x: [f64; COUNT],
    /// Reference length, m.
    pub y: f64,
    /// Device settings.
    pub settings: Settings,
}

/// The training strides of `runs`.
pub fn samples(runs: &[TrialRun]) -> Vec<Sample> {
    let mut out = Vec::new();
    for r in runs
        .iter()
        .filter(|r| TRAINING_DATASETS.contains(&r.dataset.as_str()))
    {
        for (x, y) in r.x.iter().zip(&r.reference) {
            if let Some(y) = *y {
                out.push(Sample {
                    group: format!("{}/{}", r.dataset, r.trial),
                    x: *x,
                    y,
                    settings: r.settings,
                });
            }
        }
    }
    out
}

/// The fold of each group: groups sorted by name, dealt round-robin.
pub fn folds(groups: impl IntoIterator<Item = String>) -> BTreeMap<String, usize> {
    let mut g: Vec<String> = groups.into_iter().collect();
    g.sort();
    g.dedup();
    g.into_iter()
        .enumerate()
        .map(|(i, g)| (g, i % FOLDS))
        .collect()
}

/// SVR hyper-parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hyper {
    /// Box constraint.
    pub c: f64,
    /// Kernel width, per squared z unit.
    pub gamma: f64,
    /// Insensitive zone, m.
    pub eps: f64,
}

/// Hyper-parameters of the four SVR slots: push-off, swing, heel-strike, whole movement.
pub type HyperSet = [Hyper; 4];

/// The hyper-parameters recorded in a generated model (`gaitclip::trained::HYPER`).
pub fn hyper_from(v: &[[f64; 3]; 4]) -> HyperSet {
    v.map(|[c, gamma, eps]| Hyper { c, gamma, eps })
}
/// The segment of each SVR slot.
pub const SLOTS: [Segment; 4] = [
    Segment::PushOff,
    Segment::Swing,
    Segment::HeelStrike,
    Segment::Movement,
];

/// A trained SVR in f64.
#[derive(Clone, Debug)]
pub struct SvrF64 {
    /// Input feature indices.
    pub features: Vec<usize>,
    /// Training means.
    pub mean: Vec<f64>,
    /// Training deviations.
    pub std: Vec<f64>,
    /// Kernel width.
    pub gamma: f64,
    /// Support vectors (z-scores).
    pub support: Vec<Vec<f64>>,
    /// Dual coefficients, m.
    pub alpha: Vec<f64>,
    /// Offset, m.
    pub rho: f64,
}

impl SvrF64 {
    fn z(&self, x: &[f64; COUNT]) -> Vec<f64> {
        self.features
            .iter()
            .zip(self.mean.iter().zip(&self.std))
            .map(|(&i, (m, s))| (x[i] - m) / s)
            .collect()
    }

    /// Prediction, m.
    pub fn predict(&self, x: &[f64; COUNT]) -> f64 {
        let z = self.z(x);
        self.support
            .iter()
            .zip(&self.alpha)
            .map(|(sv, a)| {
                let d2: f64 = sv.iter().zip(&z).map(|(s, z)| (s - z) * (s - z)).sum();
                a * (-self.gamma * d2).exp()
            })
            .sum::<f64>()
            - self.rho
    }

    /// The fixed-point tables.
    pub fn quantize(&self) -> SvrQ {
        let q = |v: f64, s: f64| (v * s).round() as i64;
        SvrQ {
            features: self.features.iter().map(|&i| i as u8).collect(),
            mean_q16: self.mean.iter().map(|&m| q(m, 65536.0)).collect(),
            inv_std_q32: self
                .std
                .iter()
                .map(|&s| q(1.0 / s, 4_294_967_296.0))
                .collect(),
            gamma_q32: q(self.gamma, 4_294_967_296.0) as u64,
            support_q16: self
                .support
                .iter()
                .flat_map(|sv| sv.iter().map(|&v| q(v, 65536.0) as i32))
                .collect(),
            alpha_nm: self.alpha.iter().map(|&a| q(a, 1e9)).collect(),
            rho_nm: q(self.rho, 1e9),
        }
    }
}

/// Fixed-point tables of one SVR, owned.
#[derive(Clone, Debug, PartialEq)]
pub struct SvrQ {
    /// See [`Svr`].
    pub features: Vec<u8>,
    /// See [`Svr`].
    pub mean_q16: Vec<i64>,
    /// See [`Svr`].
    pub inv_std_q32: Vec<i64>,
    /// See [`Svr`].
    pub gamma_q32: u64,
    /// See [`Svr`].
    pub support_q16: Vec<i32>,
    /// See [`Svr`].
    pub alpha_nm: Vec<i64>,
    /// See [`Svr`].
    pub rho_nm: i64,
}

impl SvrQ {
    /// Borrowed as the core's type.
    pub fn as_svr(&self) -> Svr<'_> {
        Svr {
            features: &self.features,
            mean_q16: &self.mean_q16,
            inv_std_q32: &self.inv_std_q32,
            gamma_q32: self.gamma_q32,
            support_q16: &self.support_q16,
            alpha_nm: &self.alpha_nm,
            rho_nm: self.rho_nm,
        }
    }
}

/// An AdaBoost.R2 ensemble in f64.
#[derive(Clone, Debug)]
pub struct BoostedF64 {
    /// Members.
    pub members: Vec<SvrF64>,
    /// `ln(1/β)` per member.
    pub weights: Vec<f64>,
}

impl BoostedF64 {
    /// Weighted median, m (as [`Boosted::predict_nm`]).
    pub fn predict(&self, x: &[f64; COUNT]) -> f64 {
        let mut p: Vec<(f64, f64)> = self
            .members
            .iter()
            .zip(&self.weights)
            .map(|(m, &w)| (m.predict(x), w))
            .collect();
        p.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = p.iter().map(|p| p.1).sum();
        let mut cum = 0.0;
        for &(y, w) in &p {
            cum += w;
            if 2.0 * cum >= total {
                return y;
            }
        }
        p.last().map_or(0.0, |p| p.0)
    }

    fn weights_q16(&self) -> Vec<u32> {
        self.weights
            .iter()
            .map(|w| (w * 65536.0).round().max(0.0) as u32)
            .collect()
    }
}

/// Every trained model.
#[derive(Clone, Debug)]
pub struct Trained {
    /// Closed-form coefficients, m per basis unit, per [`Model::linear_index`].
    pub linear: [[f64; MAX_TERMS]; LINEAR_MODELS],
    /// Lu's D range, g.
    pub lu_d_range: (f64, f64),
    /// Per-phase SVRs.
    pub fusion: [SvrF64; 3],
    /// Whole-movement SVR.
    pub whole: SvrF64,
    /// Per-phase ensembles.
    pub adaboost: [BoostedF64; 3],
    /// Number of training strides.
    pub samples: usize,
}

impl Trained {
    /// The f64 prediction of `model`, m.
    pub fn predict_f64(&self, model: Model, x: &[f64; COUNT], settings: Settings) -> f64 {
        match model {
            Model::Zupt => x[ZUPT_LENGTH],
            Model::HuangSvrFusion => self.fusion.iter().map(|s| s.predict(x)).sum::<f64>() / 3.0,
            Model::HuangSvrWhole => self.whole.predict(x),
            Model::HuangSvrAdaBoost => {
                self.adaboost.iter().map(|b| b.predict(x)).sum::<f64>() / 3.0
            }
            _ => {
                let t = length_ref::basis(model, x, settings, self.lu_d_range).unwrap_or_default();
                let c = model
                    .linear_index()
                    .map_or([0.0; MAX_TERMS], |i| self.linear[i]);
                t.iter().zip(c).map(|(t, c)| t * c).sum()
            }
        }
    }

    fn linear_q(&self) -> [[i64; MAX_TERMS]; LINEAR_MODELS] {
        self.linear
            .map(|c| c.map(|c| (c * 1e6 * 65536.0).round() as i64))
    }

    fn lu_q(&self) -> (i64, i64) {
        let q = |v: f64| (v * 65536.0).round() as i64;
        (q(self.lu_d_range.0), q(self.lu_d_range.1))
    }

    /// Calls `f` with the fixed-point parameters.
    pub fn with_params<R>(&self, f: impl FnOnce(&ModelParams) -> R) -> R {
        let fusion: Vec<SvrQ> = self.fusion.iter().map(SvrF64::quantize).collect();
        let whole = self.whole.quantize();
        let boosted: Vec<Vec<SvrQ>> = self
            .adaboost
            .iter()
            .map(|b| b.members.iter().map(SvrF64::quantize).collect())
            .collect();
        let members: Vec<Vec<Svr>> = boosted
            .iter()
            .map(|m| m.iter().map(SvrQ::as_svr).collect())
            .collect();
        let weights: Vec<Vec<u32>> = self.adaboost.iter().map(BoostedF64::weights_q16).collect();
        let boost = |k: usize| Boosted {
            members: &members[k],
            weights_q16: &weights[k],
        };
        let params = ModelParams {
            linear: self.linear_q(),
            lu_d_range_q16: self.lu_q(),
            fusion: [fusion[0].as_svr(), fusion[1].as_svr(), fusion[2].as_svr()],
            whole: whole.as_svr(),
            adaboost: [boost(0), boost(1), boost(2)],
        };
        f(&params)
    }
}

/// Least squares `min ‖A c − y‖` by SVD (minimum-norm when rank-deficient, as Zhang is
/// when every walker has the default height).
pub fn least_squares(
    rows: &[[f64; MAX_TERMS]],
    y: &[f64],
    terms: usize,
) -> Result<[f64; MAX_TERMS]> {
    let a = DMatrix::from_fn(rows.len(), terms, |i, j| rows[i][j]);
    let b = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    let c = svd
        .solve(&b, 1e-9)
        .map_err(|e| anyhow::anyhow!("least squares: {e}"))?;
    let mut out = [0.0; MAX_TERMS];
    out[..terms].copy_from_slice(c.as_slice());
    Ok(out)
}

/// Number of basis terms of a closed-form model.
pub fn terms(model: Model) -> usize {
    match model {
        Model::Ladetto => 3,
        Model::Zhang => 4,
        _ => 1,
    }
}

fn fit_linear(train: &[&Sample], lu: (f64, f64)) -> Result<[[f64; MAX_TERMS]; LINEAR_MODELS]> {
    let mut out = [[0.0; MAX_TERMS]; LINEAR_MODELS];
    let y: Vec<f64> = train.iter().map(|s| s.y).collect();
    for m in Model::ALL {
        let Some(k) = m.linear_index() else { continue };
        let rows: Vec<[f64; MAX_TERMS]> = train
            .iter()
            .map(|s| length_ref::basis(m, &s.x, s.settings, lu).unwrap_or_default())
            .collect();
        out[k] = least_squares(&rows, &y, terms(m)).with_context(|| m.name())?;
    }
    Ok(out)
}

fn lu_range(train: &[&Sample]) -> (f64, f64) {
    let i = features::index(Segment::Movement, Channel::Vertical, features::Stat::Range);
    let r: Vec<f64> = train.iter().map(|s| s.x[i]).collect();
    (
        crate::stats::quantile_at_rounded_index(&r, 0.05),
        crate::stats::quantile_at_rounded_index(&r, 0.95),
    )
}

fn mean_std(v: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let n = v.clone().count() as f64;
    let m = v.clone().sum::<f64>() / n;
    let var = v.map(|x| (x - m) * (x - m)).sum::<f64>() / n;
    (m, var.sqrt())
}

/// The [`SELECTED`] features of `segment` most correlated with the length (|Pearson r|,
/// ties by index), then the ZUPT displacement.
pub fn select(train: &[&Sample], segment: Segment) -> Vec<usize> {
    let (my, sy) = mean_std(train.iter().map(|s| s.y));
    let base = segment as usize * PER_SEGMENT;
    let mut scored: Vec<(f64, usize)> = (base..base + PER_SEGMENT)
        .filter_map(|i| {
            let (mx, sx) = mean_std(train.iter().map(|s| s.x[i]));
            if sx < 1e-12 || sy < 1e-12 {
                return None;
            }
            let cov = train
                .iter()
                .map(|s| (s.x[i] - mx) * (s.y - my))
                .sum::<f64>()
                / train.len() as f64;
            Some(((cov / (sx * sy)).abs(), i))
        })
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut out: Vec<usize> = scored.into_iter().take(SELECTED).map(|s| s.1).collect();
    out.push(ZUPT_LENGTH);
    out
}

/// Fits one SVR on `train` with inputs `features`.
pub fn fit_svr(train: &[&Sample], features: &[usize], h: Hyper) -> Result<SvrF64> {
    let stats: Vec<(f64, f64)> = features
        .iter()
        .map(|&i| {
            let (m, s) = mean_std(train.iter().map(|t| t.x[i]));
            (m, if s > 1e-12 { s } else { 1.0 })
        })
        .collect();
    let n = train.len();
    let d = features.len();
    let x = Array2::from_shape_fn((n, d), |(r, c)| {
        (train[r].x[features[c]] - stats[c].0) / stats[c].1
    });
    let y = Array1::from_iter(train.iter().map(|t| t.y));
    let data = linfa::Dataset::new(x.clone(), y);
    let model = Svm::<f64, f64>::params()
        .c_svr(h.c, Some(h.eps))
        .gaussian_kernel(1.0 / h.gamma)
        // libsvm's stopping tolerance (linfa defaults to 1e-7). Not linfa's shrinking: it
        // indexes out of bounds on ε-SVR problems (linfa-svm 0.8.1, solver_smo.rs:601).
        .eps(1e-3)
        .fit(&data)
        .map_err(|e| anyhow::anyhow!("svr fit: {e}"))?;
    // linfa keeps the support vectors private: they are the rows whose weight it counts.
    let cut = 100.0 * f64::EPSILON;
    let mut support = Vec::new();
    let mut alpha = Vec::new();
    for (r, &a) in model.alpha.iter().enumerate() {
        if a.abs() > cut {
            support.push(x.row(r).to_vec());
            alpha.push(a);
        }
    }
    let out = SvrF64 {
        features: features.to_vec(),
        mean: stats.iter().map(|s| s.0).collect(),
        std: stats.iter().map(|s| s.1).collect(),
        gamma: h.gamma,
        support,
        alpha,
        rho: model.rho,
    };
    // The reconstruction must be linfa's own model.
    let theirs = model.predict(&x);
    for (r, t) in train.iter().enumerate().step_by(7) {
        let ours = out.predict(&t.x);
        if (ours - theirs[r]).abs() > 1e-9 {
            bail!(
                "SVR reconstruction differs from linfa: {ours} vs {}",
                theirs[r]
            );
        }
    }
    Ok(out)
}

fn fit_boosted(train: &[&Sample], features: &[usize], h: Hyper, seed: u64) -> Result<BoostedF64> {
    let n = train.len();
    let mut w = vec![1.0 / n as f64; n];
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = BoostedF64 {
        members: Vec::new(),
        weights: Vec::new(),
    };
    for _ in 0..BOOST_ROUNDS {
        // Weighted resample with replacement.
        let mut cdf = Vec::with_capacity(n);
        let mut acc = 0.0;
        for &wi in &w {
            acc += wi;
            cdf.push(acc);
        }
        let pick: Vec<&Sample> = (0..n)
            .map(|_| {
                let u: f64 = rng.random::<f64>() * acc;
                train[cdf.partition_point(|&c| c < u).min(n - 1)]
            })
            .collect();
        let m = fit_svr(&pick, features, h)?;
        let err: Vec<f64> = train
            .iter()
            .map(|s| (m.predict(&s.x) - s.y).abs())
            .collect();
        let max = err.iter().cloned().fold(0.0, f64::max);
        if max <= 0.0 {
            out.members.push(m);
            out.weights.push(1.0);
            break;
        }
        let loss: Vec<f64> = err.iter().map(|e| e / max).collect();
        let avg: f64 = loss.iter().zip(&w).map(|(l, w)| l * w).sum();
        if avg >= 0.5 {
            if out.members.is_empty() {
                out.members.push(m);
                out.weights.push(1.0);
            }
            break;
        }
        let beta = avg / (1.0 - avg);
        out.members.push(m);
        out.weights.push((1.0 / beta).ln());
        for (wi, l) in w.iter_mut().zip(&loss) {
            *wi *= beta.powf(1.0 - l);
        }
        let s: f64 = w.iter().sum();
        w.iter_mut().for_each(|wi| *wi /= s);
    }
    Ok(out)
}

/// Fits every model on `train` with the SVR hyper-parameters `hyper`.
pub fn fit_all(train: &[&Sample], hyper: &HyperSet) -> Result<Trained> {
    if train.len() < 10 {
        bail!("only {} training strides", train.len());
    }
    let lu = lu_range(train);
    let linear = fit_linear(train, lu)?;
    // One feature selection per slot, shared by its SVR and its boosted ensemble.
    let inputs: Vec<Vec<usize>> = SLOTS.iter().map(|&seg| select(train, seg)).collect();
    let mut svrs = Vec::new();
    for (k, f) in inputs.iter().enumerate() {
        svrs.push(fit_svr(train, f, hyper[k])?);
    }
    let mut boosted = Vec::new();
    for (k, f) in inputs.iter().take(3).enumerate() {
        boosted.push(fit_boosted(train, f, hyper[k], SEED + k as u64)?);
    }
    let whole = svrs.pop().context("whole")?;
    let fusion: [SvrF64; 3] = svrs.try_into().map_err(|_| anyhow::anyhow!("fusion"))?;
    let adaboost: [BoostedF64; 3] = boosted.try_into().map_err(|_| anyhow::anyhow!("boost"))?;
    Ok(Trained {
        linear,
        lu_d_range: lu,
        fusion,
        whole,
        adaboost,
        samples: train.len(),
    })
}

/// Cross-validated RMSE, m, of one SVR slot with hyper-parameters `h`.
fn cv_rmse(
    samples: &[Sample],
    fold: &BTreeMap<String, usize>,
    seg: Segment,
    h: Hyper,
) -> Result<f64> {
    let mut se = 0.0;
    let mut n = 0usize;
    for k in 0..FOLDS {
        let train: Vec<&Sample> = samples.iter().filter(|s| fold[&s.group] != k).collect();
        let test: Vec<&Sample> = samples.iter().filter(|s| fold[&s.group] == k).collect();
        if test.is_empty() {
            continue;
        }
        let m = fit_svr(&train, &select(&train, seg), h)?;
        for s in test {
            se += (m.predict(&s.x) - s.y).powi(2);
            n += 1;
        }
    }
    Ok((se / n.max(1) as f64).sqrt())
}

/// The grid point with the lowest cross-validated RMSE, per SVR slot, with that RMSE.
pub fn choose_hyper(samples: &[Sample]) -> Result<(HyperSet, [f64; 4])> {
    let fold = folds(samples.iter().map(|s| s.group.clone()));
    let mut grid = Vec::new();
    for c in GRID_C {
        for gamma in GRID_GAMMA {
            for eps in GRID_EPS {
                grid.push(Hyper { c, gamma, eps });
            }
        }
    }
    let mut best = [(f64::INFINITY, grid[0]); 4];
    for (k, seg) in SLOTS.iter().enumerate() {
        // The grid in parallel; the choice does not depend on the order of completion.
        let fold = &fold;
        let seg = *seg;
        let scores: Vec<Result<f64>> = std::thread::scope(|s| {
            let handles: Vec<_> = grid
                .iter()
                .map(|&h| s.spawn(move || cv_rmse(samples, fold, seg, h)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("cv thread"))
                .collect()
        });
        for (h, r) in grid.iter().zip(scores) {
            let r = r?;
            if r < best[k].0 {
                best[k] = (r, *h);
            }
        }
    }
    Ok((best.map(|b| b.1), best.map(|b| b.0)))
}

/// Loads the training datasets under `shared_datasets`.
pub fn load_training(shared_datasets: &Path) -> Result<Vec<TrialRun>> {
    let mut runs = Vec::new();
    for name in TRAINING_DATASETS {
        runs.extend(run_dataset(&datasets::load(&shared_datasets.join(name))?)?);
    }
    Ok(runs)
}

/// What `gaitclip train` produces: the models and how they were chosen.
pub struct Training {
    /// Models fitted on every training stride.
    pub trained: Trained,
    /// Hyper-parameters chosen.
    pub hyper: HyperSet,
    /// Their cross-validated RMSE, m.
    pub cv_rmse: [f64; 4],
    /// Trials trained on.
    pub trials: usize,
    /// The leave-one-dataset-out scores of every model ([`length_eval::score`] of
    /// [`length_eval::Validation::LeaveOneDatasetOut`]).
    pub lodo: Vec<length_eval::DatasetScores>,
    /// The model with the best of them ([`length_eval::lodo_best`]): the firmware's default.
    pub default_model: Model,
}

/// Trains every model on `runs`.
pub fn train(runs: &[TrialRun]) -> Result<Training> {
    let s = samples(runs);
    let (hyper, cv_rmse) = choose_hyper(&s)?;
    let refs: Vec<&Sample> = s.iter().collect();
    let trained = fit_all(&refs, &hyper)?;
    let trials = folds(s.iter().map(|s| s.group.clone())).len();
    let pred = length_eval::predictions(runs, &hyper, length_eval::Validation::LeaveOneDatasetOut)?;
    let lodo = length_eval::score(runs, &pred);
    let default_model = length_eval::lodo_best(&lodo);
    Ok(Training {
        trained,
        hyper,
        cv_rmse,
        trials,
        lodo,
        default_model,
    })
}

/// `#[cfg]` line of the tables of a model that only builds with the `all-models` feature
/// (every SVR model but the pipeline's default), or nothing.
fn gate(model: Model, default: Model) -> &'static str {
    if model == default {
        ""
    } else {
        "#[cfg(feature = \"all-models\")]\n"
    }
}

/// A `PARAMS` field: the trained value, or `absent` in builds without the model.
fn field(model: Model, default: Model, name: &str, value: &str, absent: &str) -> String {
    if model == default {
        format!("    {name}: {value},\n")
    } else {
        format!(
            "    #[cfg(feature = \"all-models\")]\n    {name}: {value},\n    #[cfg(not(feature = \"all-models\"))]\n    {name}: {absent},\n"
        )
    }
}

fn array<T: std::fmt::Display>(out: &mut String, gate: &str, name: &str, ty: &str, v: &[T]) {
    let _ = write!(out, "{gate}static {name}: [{ty}; {}] = [", v.len());
    for (i, x) in v.iter().enumerate() {
        if i % 8 == 0 {
            out.push_str("\n    ");
        } else {
            out.push(' ');
        }
        let _ = write!(out, "{x},");
    }
    out.push_str("\n];\n");
}

fn svr_source(out: &mut String, gate: &str, name: &str, s: &SvrQ) -> String {
    let features: Vec<String> = s
        .features
        .iter()
        .map(|&i| {
            let (a, b, c) = features::name_parts(i as usize);
            format!("{i} /* {a}.{b}.{c} */")
        })
        .collect();
    array(out, gate, &format!("{name}_FEATURES"), "u8", &features);
    array(out, gate, &format!("{name}_MEAN_Q16"), "i64", &s.mean_q16);
    array(
        out,
        gate,
        &format!("{name}_INV_STD_Q32"),
        "i64",
        &s.inv_std_q32,
    );
    array(
        out,
        gate,
        &format!("{name}_SUPPORT_Q16"),
        "i32",
        &s.support_q16,
    );
    array(out, gate, &format!("{name}_ALPHA_NM"), "i64", &s.alpha_nm);
    format!(
        "Svr {{\n        features: &{name}_FEATURES,\n        mean_q16: &{name}_MEAN_Q16,\n        inv_std_q32: &{name}_INV_STD_Q32,\n        gamma_q32: {},\n        support_q16: &{name}_SUPPORT_Q16,\n        alpha_nm: &{name}_ALPHA_NM,\n        rho_nm: {},\n    }}",
        s.gamma_q32, s.rho_nm
    )
}

/// The Rust source of `src/trained.rs` for `t`.
pub fn rust_source(t: &Training) -> String {
    let tr = &t.trained;
    let mut body = String::new();
    let fusion: Vec<String> = tr
        .fusion
        .iter()
        .zip(["PUSH_OFF", "SWING", "HEEL_STRIKE"])
        .map(|(s, n)| {
            let g = gate(Model::HuangSvrFusion, t.default_model);
            svr_source(&mut body, g, &format!("FUSION_{n}"), &s.quantize())
        })
        .collect();
    let whole = svr_source(
        &mut body,
        gate(Model::HuangSvrWhole, t.default_model),
        "WHOLE",
        &tr.whole.quantize(),
    );
    let boost_gate = gate(Model::HuangSvrAdaBoost, t.default_model);
    let mut boosted = Vec::new();
    for (b, n) in tr.adaboost.iter().zip(["PUSH_OFF", "SWING", "HEEL_STRIKE"]) {
        let members: Vec<String> = b
            .members
            .iter()
            .enumerate()
            .map(|(k, m)| {
                svr_source(
                    &mut body,
                    boost_gate,
                    &format!("BOOST_{n}_{k}"),
                    &m.quantize(),
                )
            })
            .collect();
        let _ = writeln!(
            body,
            "{boost_gate}static BOOST_{n}: [Svr<'static>; {}] = [\n    {},\n];",
            members.len(),
            members.join(",\n    ")
        );
        array(
            &mut body,
            boost_gate,
            &format!("BOOST_{n}_WEIGHTS_Q16"),
            "u32",
            &b.weights_q16(),
        );
        boosted.push(format!(
            "Boosted {{\n            members: &BOOST_{n},\n            weights_q16: &BOOST_{n}_WEIGHTS_Q16,\n        }}"
        ));
    }
    let mut s = String::new();
    s.push_str(
        "//! Trained stride-length models: generated by `gaitclip train`, do not edit.\n//!\n",
    );
    s.push_str("//! Regenerate with `cargo run --release --bin gaitclip -- train ../../shared/datasets`\n//! from `tests-host/`; `tests-host/tests/trained_model.rs` fails when this file is stale.\n//!\n");
    let _ = writeln!(
        s,
        "//! Trained on {} clean strides of {} trials ({}).",
        tr.samples,
        t.trials,
        TRAINING_DATASETS.join(", ")
    );
    s.push_str("//! SVR hyper-parameters (grid search, cross-validated RMSE grouped by trial):\n//!\n//! | SVR | C | γ | ε (m) | CV RMSE (m) |\n//! |---|---|---|---|---|\n");
    for ((seg, h), r) in SLOTS.iter().zip(&t.hyper).zip(&t.cv_rmse) {
        let _ = writeln!(
            s,
            "//! | {} | {} | {} | {} | {:.4} |",
            seg.name(),
            h.c,
            h.gamma,
            h.eps,
            r
        );
    }
    s.push_str("//!\n//! Leave-one-dataset-out (each training dataset predicted by a fit on the other alone), mean\n//! of the datasets' RMSE, best first:\n//!\n//! | model | mean RMSE (cm) |\n//! |---|---|\n");
    let mut ranked: Vec<(Model, f64)> = Model::ALL
        .into_iter()
        .map(|m| {
            let r: Vec<f64> = t
                .lodo
                .iter()
                .filter(|(d, _)| TRAINING_DATASETS.contains(&d.as_str()))
                .map(|(_, sc)| sc[m as usize].rmse())
                .collect();
            (m, r.iter().sum::<f64>() / r.len().max(1) as f64)
        })
        .collect();
    ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (m, r) in &ranked {
        let _ = writeln!(s, "//! | `{}` | {:.2} |", m.name(), r * 100.0);
    }
    s.push_str("\nuse crate::models::{Model, ModelParams};\nuse crate::svr::{Boosted, Svr};\n\n");
    let _ = writeln!(
        s,
        "/// The model with the best leave-one-dataset-out score: the pipeline's default\n/// ([`crate::pipeline::DEFAULT_MODEL`]).\npub const LODO_BEST: Model = Model::{:?};\n",
        t.default_model
    );
    s.push_str("/// The SVR hyper-parameters `[C, γ, ε (m)]` chosen by cross-validation, for push-off,\n/// swing, heel-strike and the whole movement: `gaitclip eval` re-fits each fold with them.\npub const HYPER: [[f64; 3]; 4] = [\n");
    for h in &t.hyper {
        let _ = writeln!(s, "    [{:?}, {:?}, {:?}],", h.c, h.gamma, h.eps);
    }
    s.push_str("];\n\n");
    s.push_str(&body);
    s.push_str("\n/// The trained models. Builds without the `all-models` feature carry the default\n/// model's SVRs only ([`ModelParams::ships`]).\npub static PARAMS: ModelParams<'static> = ModelParams {\n    linear: [\n");
    let lq = tr.linear_q();
    for m in Model::ALL {
        if let Some(k) = m.linear_index() {
            let _ = writeln!(
                s,
                "        // {}: {:?} m per basis unit\n        {:?},",
                m.name(),
                &tr.linear[k][..terms(m)],
                lq[k]
            );
        }
    }
    let lu = tr.lu_q();
    let _ = writeln!(s, "    ],\n    lu_d_range_q16: ({}, {}),", lu.0, lu.1);
    s.push_str(&field(
        Model::HuangSvrFusion,
        t.default_model,
        "fusion",
        &format!("[\n        {},\n    ]", fusion.join(",\n        ")),
        "[Svr::ABSENT; 3]",
    ));
    s.push_str(&field(
        Model::HuangSvrWhole,
        t.default_model,
        "whole",
        &whole,
        "Svr::ABSENT",
    ));
    s.push_str(&field(
        Model::HuangSvrAdaBoost,
        t.default_model,
        "adaboost",
        &format!("[\n        {},\n    ]", boosted.join(",\n        ")),
        "[Boosted::ABSENT; 3]",
    ));
    s.push_str("};\n");
    s
}

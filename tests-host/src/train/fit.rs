//! Fitting every length model to training strides: least squares (SVD) on the closed-form
//! models' basis terms; ε-SVRs with an RBF kernel (`linfa-svm`) on the [`SELECTED`] features
//! of their segment most correlated with the length plus the ZUPT displacement, z-scored
//! with the training statistics; SVR-AdaBoost (AdaBoost.R2, Drucker 1997, linear loss) with
//! [`BOOST_ROUNDS`] members per phase on seeded weighted resamples; and their quantisation
//! to the firmware's fixed point.

use anyhow::{bail, Context, Result};
use gaitclip::detect::phase_stats::{Channel, Segment};
use gaitclip::length::features::{self, COUNT, PER_SEGMENT, ZUPT_LENGTH};
use gaitclip::length::models::{Model, ModelParams, Settings, LINEAR_MODELS, MAX_TERMS};
use gaitclip::length::svr::{Boosted, Svr};
use linfa::prelude::*;
use linfa_svm::Svm;
use nalgebra::{DMatrix, DVector};
use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::reference::length_ref;

/// Features per SVR chosen from its segment (the ZUPT displacement is added to them).
pub const SELECTED: usize = 8;
/// Members per AdaBoost.R2 ensemble.
pub const BOOST_ROUNDS: usize = 4;
/// Seed of the AdaBoost resampling.
const SEED: u64 = 0x6a17_c11b;

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

/// The hyper-parameters recorded in a generated model (`gaitclip::length::trained::HYPER`).
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

    pub(crate) fn weights_q16(&self) -> Vec<u32> {
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

    pub(crate) fn linear_q(&self) -> [[i64; MAX_TERMS]; LINEAR_MODELS] {
        self.linear
            .map(|c| c.map(|c| (c * 1e6 * 65536.0).round() as i64))
    }

    pub(crate) fn lu_q(&self) -> (i64, i64) {
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
        crate::eval::stats::quantile_at_rounded_index(&r, 0.05),
        crate::eval::stats::quantile_at_rounded_index(&r, 0.95),
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

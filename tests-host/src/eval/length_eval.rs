//! Stride lengths scored against the references, every model side by side, three ways
//! ([`Validation`]):
//!
//! - **in-sample**: every model fitted on every training stride (`gaitmap_walk` and
//!   `pyshoe_vicon`), the scored ones included: what a fit can do on its own data;
//! - **5-fold by trial**: the training datasets cut into [`cross_validation::FOLDS`] folds grouped by
//!   trial, each fold predicted by models fitted on the others (the shipped SVR
//!   hyper-parameters): new walks of the same people, sensors and rooms;
//! - **leave-one-dataset-out**: each training dataset predicted by models fitted on the
//!   other alone, SVR hyper-parameters chosen there too: a new sensor, mounting, room and
//!   population, which is what a user's walks are. The shipped default is the model best
//!   here ([`lodo_best`]).
//!
//! Datasets not trained on (`ipol_gait_events`) are predicted by the fit on every training
//! stride in all three: that fit never saw them. Every prediction is the core's fixed-point
//! one. The ZUPT stride is fitted to nothing, so its three rows agree.
//!
//! Per model and dataset: RMSE, MAE and bias (predicted − reference) over matched clean
//! strides (reference unflagged, stride valid, and no second movement inside the
//! reference's borders: see [`crate::eval::matching::Scored::Unbordered`]), the same by stride speed
//! (reference length over reference duration) and by stride length, and the walked-distance
//! error per trial, `|Σ predicted − Σ reference| / Σ reference` over all the core's strides
//! in the trial's span where the trial's walked distance is known (`gaitmap_walk`: its
//! reference strides follow one another; `ipol_gait_events`: the nominal 20 m), else over
//! its scored strides (`pyshoe_vicon`, whose walks leave the capture volume) (median and
//! worst).

use std::collections::BTreeMap;

use anyhow::Result;
use gaitclip::length::models::{self, Model, ModelParams, MODELS};

use crate::eval::markdown::{Column, Table};
use crate::eval::plot::{Plot, COLOURS};
use crate::eval::stats::median;
use crate::train::cross_validation;
use crate::train::fit::{self, HyperSet, Sample, Trained};
use crate::train::training_set::{self, TrialRun, TRAINING_DATASETS};

/// Predictions of every model for every stride of every run: `[run][stride][model]`, m.
pub type Predictions = Vec<Vec<[f64; MODELS]>>;

/// Every model's length for every stride of `runs` as the firmware computes it, with the
/// models it ships ([`gaitclip::length::trained::PARAMS`]): out of sample on any recording
/// but the training datasets'.
pub fn shipped_predictions(runs: &[TrialRun]) -> Predictions {
    runs.iter()
        .map(|run| predict_run(run, &gaitclip::length::trained::PARAMS))
        .collect()
}

fn predict_run(run: &TrialRun, params: &ModelParams) -> Vec<[f64; MODELS]> {
    run.fixed
        .iter()
        .map(|f| {
            let mut p = [0.0; MODELS];
            for m in Model::ALL {
                p[m as usize] =
                    models::predict_mm(m, f, run.settings, params).unwrap_or(0) as f64 / 1e3;
            }
            p
        })
        .collect()
}

/// Cross-validated fixed-point predictions for `runs`, and the fit on all training strides.
pub fn cross_validate(runs: &[TrialRun], hyper: &HyperSet) -> Result<(Predictions, Trained)> {
    let samples = training_set::samples(runs);
    let fold = cross_validation::folds(samples.iter().map(|s| s.group.clone()));
    let fits: Vec<Result<Trained>> = std::thread::scope(|sc| {
        let handles: Vec<_> = (0..cross_validation::FOLDS)
            .map(|k| {
                let (samples, fold) = (&samples, &fold);
                sc.spawn(move || {
                    let tr: Vec<&Sample> = samples.iter().filter(|s| fold[&s.group] != k).collect();
                    fit::fit_all(&tr, hyper)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("fold thread"))
            .collect()
    });
    let fits: Vec<Trained> = fits.into_iter().collect::<Result<_>>()?;
    let all: Vec<&Sample> = samples.iter().collect();
    let full = fit::fit_all(&all, hyper)?;
    let mut out = Vec::new();
    for run in runs {
        let group = format!("{}/{}", run.dataset, run.trial);
        let model = match fold.get(&group) {
            Some(&k) => &fits[k],
            None => &full,
        };
        out.push(model.with_params(|p| predict_run(run, p)));
    }
    Ok((out, full))
}

/// How the trained models' predictions of a dataset were obtained (see the module).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    /// Fitted on every training stride.
    InSample,
    /// [`cross_validation::FOLDS`]-fold by trial.
    KFold,
    /// Fitted on the other training dataset.
    LeaveOneDatasetOut,
}

impl Validation {
    /// All three, in the order the tables give them.
    pub const ALL: [Validation; 3] = [
        Validation::InSample,
        Validation::KFold,
        Validation::LeaveOneDatasetOut,
    ];

    /// Its name in the tables.
    pub const fn name(self) -> &'static str {
        match self {
            Validation::InSample => "in-sample",
            Validation::KFold => "5-fold by trial",
            Validation::LeaveOneDatasetOut => "leave-one-dataset-out",
        }
    }
}

fn dataset_of(s: &Sample) -> &str {
    s.group.split('/').next().unwrap_or("")
}

/// Fixed-point predictions of every model for `runs`, validated as `v`: in-sample and
/// k-fold with the SVR hyper-parameters `hyper`; leave-one-dataset-out chooses its own on
/// the dataset it fits ([`cross_validation::search`], run or recorded as `how` says: the
/// searches come back with the predictions), so that nothing of the scored dataset reaches
/// the model.
pub fn predictions(
    runs: &[TrialRun],
    hyper: &HyperSet,
    v: Validation,
    how: cross_validation::Search,
) -> Result<(Predictions, Vec<cross_validation::Searched>)> {
    match v {
        Validation::KFold => Ok((cross_validate(runs, hyper)?.0, Vec::new())),
        Validation::InSample => {
            let samples = training_set::samples(runs);
            let all: Vec<&Sample> = samples.iter().collect();
            let full = fit::fit_all(&all, hyper)?;
            Ok((
                runs.iter()
                    .map(|run| full.with_params(|p| predict_run(run, p)))
                    .collect(),
                Vec::new(),
            ))
        }
        Validation::LeaveOneDatasetOut => {
            let samples = training_set::samples(runs);
            let all: Vec<&Sample> = samples.iter().collect();
            let full = fit::fit_all(&all, hyper)?;
            let mut fits: BTreeMap<&str, Trained> = BTreeMap::new();
            let mut searches = Vec::new();
            for left_out in TRAINING_DATASETS {
                let rest: Vec<Sample> = samples
                    .iter()
                    .filter(|s| dataset_of(s) != left_out)
                    .cloned()
                    .collect();
                if rest.is_empty() || rest.len() == samples.len() {
                    continue;
                }
                let found = cross_validation::search(&rest, how)?;
                let refs: Vec<&Sample> = rest.iter().collect();
                fits.insert(left_out, fit::fit_all(&refs, &found.hyper)?);
                searches.push(found);
            }
            Ok((
                runs.iter()
                    .map(|run| {
                        let model = fits.get(run.dataset.as_str()).unwrap_or(&full);
                        model.with_params(|p| predict_run(run, p))
                    })
                    .collect(),
                searches,
            ))
        }
    }
}

/// The model with the best leave-one-dataset-out score: the lowest mean over the training
/// datasets of their RMSE (each dataset weighs the same, however many strides it has).
pub fn lodo_best(scores: &[DatasetScores]) -> Model {
    let score = |m: Model| {
        let r: Vec<f64> = scores
            .iter()
            .filter(|(d, _)| TRAINING_DATASETS.contains(&d.as_str()))
            .map(|(_, s)| s[m as usize].rmse())
            .collect();
        r.iter().sum::<f64>() / r.len().max(1) as f64
    };
    Model::ALL
        .into_iter()
        .filter(|&m| !score(m).is_nan())
        .min_by(|&a, &b| score(a).total_cmp(&score(b)))
        .unwrap_or(Model::Zupt)
}

/// One model's scores on one dataset.
#[derive(Clone, Debug, Default)]
pub struct LengthScore {
    /// Matched clean strides.
    pub strides: usize,
    /// Per-stride errors, m.
    pub errors: Vec<f64>,
    /// Their reference lengths, m.
    pub reference_m: Vec<f64>,
    /// Their reference speeds, m/s.
    pub speed_mps: Vec<f64>,
    /// Walked-distance error per trial, fraction.
    pub distance: Vec<f64>,
}

/// One dataset's name and the score of every model on it (indexed by `Model as usize`).
pub type DatasetScores = (String, [LengthScore; MODELS]);

/// Stride-speed bins of the per-pace tables, m/s: slow walking, walking, fast walking,
/// jogging, running.
pub const SPEED_BINS: [(f64, f64); 5] = [
    (0.0, 1.0),
    (1.0, 1.5),
    (1.5, 2.0),
    (2.0, 3.0),
    (3.0, f64::INFINITY),
];

/// Stride-length bins, m.
pub const LENGTH_BINS: [(f64, f64); 5] = [
    (0.0, 0.6),
    (0.6, 1.0),
    (1.0, 1.4),
    (1.4, 1.8),
    (1.8, f64::INFINITY),
];

/// What a per-bin table groups by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinBy {
    /// [`SPEED_BINS`].
    Speed,
    /// [`LENGTH_BINS`].
    Length,
}

impl LengthScore {
    /// The strides whose speed (or length) falls in `[lo, hi)`.
    pub fn bin(&self, by: BinBy, (lo, hi): (f64, f64)) -> LengthScore {
        let key = match by {
            BinBy::Speed => &self.speed_mps,
            BinBy::Length => &self.reference_m,
        };
        let mut out = LengthScore::default();
        for (k, &v) in key.iter().enumerate() {
            if v >= lo && v < hi {
                out.strides += 1;
                out.errors.push(self.errors[k]);
                out.reference_m.push(self.reference_m[k]);
                out.speed_mps.push(self.speed_mps[k]);
            }
        }
        out
    }

    /// `|Σ predicted − Σ reference| / Σ reference` over the strides, fraction.
    pub fn pooled_distance_error(&self) -> f64 {
        let r: f64 = self.reference_m.iter().sum();
        self.errors.iter().sum::<f64>().abs() / r
    }

    /// RMSE, m.
    pub fn rmse(&self) -> f64 {
        (self.errors.iter().map(|e| e * e).sum::<f64>() / self.errors.len() as f64).sqrt()
    }
    /// MAE, m.
    pub fn mae(&self) -> f64 {
        self.errors.iter().map(|e| e.abs()).sum::<f64>() / self.errors.len() as f64
    }
    /// Bias, m.
    pub fn bias(&self) -> f64 {
        self.errors.iter().sum::<f64>() / self.errors.len() as f64
    }
}

/// Scores per dataset (in order of first appearance) and model.
pub fn score(runs: &[TrialRun], pred: &Predictions) -> Vec<DatasetScores> {
    let mut by: BTreeMap<String, [LengthScore; MODELS]> = BTreeMap::new();
    let mut order = Vec::new();
    for (run, p) in runs.iter().zip(pred) {
        if !by.contains_key(&run.dataset) {
            order.push(run.dataset.clone());
        }
        let s = by.entry(run.dataset.clone()).or_default();
        for m in Model::ALL {
            let k = m as usize;
            for ((r, v), p) in run.reference.iter().zip(&run.speed_mps).zip(p) {
                if let Some(r) = r {
                    s[k].strides += 1;
                    s[k].errors.push(p[k] - r);
                    s[k].reference_m.push(*r);
                    s[k].speed_mps.push(v.unwrap_or(f64::NAN));
                }
            }
            match run.reference_total_m {
                Some(total) => {
                    let sum: f64 = p.iter().map(|p| p[k]).sum();
                    s[k].distance.push((sum - total).abs() / total);
                }
                // The walk is not known end to end: the distance of its scored strides.
                None => {
                    let (mut sum, mut total) = (0.0, 0.0);
                    for (r, p) in run.reference.iter().zip(p) {
                        if let Some(r) = r {
                            sum += p[k];
                            total += r;
                        }
                    }
                    if total > 0.0 {
                        s[k].distance.push((sum - total).abs() / total);
                    }
                }
            }
        }
    }
    order
        .into_iter()
        .map(|d| {
            let s = by.remove(&d).unwrap_or_default();
            (d, s)
        })
        .collect()
}

/// The Markdown table: one row per model, per dataset RMSE / MAE / bias in cm and the
/// walked-distance error (median / worst trial, %).
pub fn table(scores: &[DatasetScores]) -> String {
    let mut header = vec!["model".to_string()];
    for (d, sc) in scores {
        let n = sc[0].strides;
        if n > 0 {
            header.push(format!("{d}: RMSE / MAE / bias, cm ({n} strides)"));
        }
        header.push(format!(
            "{d}: distance error, median / worst of {} trials",
            sc[0].distance.len()
        ));
    }
    let mut t = Table::new(header);
    for m in Model::ALL {
        let k = m as usize;
        let mut r = vec![format!("`{}`", m.name())];
        for (_, sc) in scores {
            let x = &sc[k];
            if x.strides > 0 {
                r.push(format!(
                    "{:.1} / {:.1} / {:+.1}",
                    x.rmse() * 100.0,
                    x.mae() * 100.0,
                    x.bias() * 100.0
                ));
            }
            r.push(distance_cell(&x.distance));
        }
        t.row(r);
    }
    t.render()
}

/// `median % / worst %` of walked-distance errors (fractions).
fn distance_cell(distance: &[f64]) -> String {
    let worst = distance.iter().cloned().fold(0.0, f64::max);
    format!("{:.1} % / {:.1} %", median(distance) * 100.0, worst * 100.0)
}

/// Every model's RMSE and bias (cm) per dataset three ways: one row per model, a column
/// per dataset and validation; datasets without per-stride lengths get their walked-distance
/// error (median / worst trial) instead.
pub fn three_ways_table(by: &[(Validation, Vec<DatasetScores>)]) -> String {
    let Some((_, first)) = by.first() else {
        return String::new();
    };
    let mut header = vec!["model".to_string()];
    for (d, sc) in first {
        for (v, _) in by {
            if sc[0].strides > 0 {
                header.push(format!("{d}, {}: RMSE / bias cm", v.name()));
            } else {
                header.push(format!("{d}, {}: distance error median / worst", v.name()));
            }
        }
    }
    let mut t = Table::new(header);
    for m in Model::ALL {
        let k = m as usize;
        let mut r = vec![format!("`{}`", m.name())];
        for (i, (_, sc)) in first.iter().enumerate() {
            for (_, scores) in by {
                let x = &scores[i].1[k];
                if sc[0].strides > 0 {
                    r.push(format!(
                        "{:.1} / {:+.1}",
                        x.rmse() * 100.0,
                        x.bias() * 100.0
                    ));
                } else {
                    r.push(distance_cell(&x.distance));
                }
            }
        }
        t.row(r);
    }
    t.render()
}

/// A bin's label in every table: `< hi`, `lo–hi` or `> lo`, with the unit.
pub fn bin_label((lo, hi): (f64, f64), unit: &str) -> String {
    if hi.is_infinite() {
        format!("> {lo} {unit}")
    } else if lo == 0.0 {
        format!("< {hi} {unit}")
    } else {
        format!("{lo}–{hi} {unit}")
    }
}

/// RMSE / bias (cm) per speed or length bin, one row per model, a column per dataset (with
/// per-stride lengths) and bin, and the pooled distance error of each bin's strides.
pub fn binned_table(scores: &[DatasetScores], by: BinBy) -> String {
    let bins: &[(f64, f64)] = match by {
        BinBy::Speed => &SPEED_BINS,
        BinBy::Length => &LENGTH_BINS,
    };
    let unit = match by {
        BinBy::Speed => "m/s",
        BinBy::Length => "m",
    };
    let label = |&bin: &(f64, f64)| bin_label(bin, unit);
    let with: Vec<&DatasetScores> = scores.iter().filter(|(_, s)| s[0].strides > 0).collect();
    let mut header = vec!["model".to_string()];
    for (d, sc) in &with {
        for b in bins {
            header.push(format!("{d} {} ({})", label(b), sc[0].bin(by, *b).strides));
        }
    }
    let mut t = Table::new(header);
    for m in Model::ALL {
        let mut r = vec![format!("`{}`", m.name())];
        for (_, sc) in &with {
            for b in bins {
                let x = sc[m as usize].bin(by, *b);
                if x.strides == 0 {
                    r.push("–".into());
                } else {
                    r.push(format!(
                        "{:.1} / {:+.1} / {:.1} %",
                        x.rmse() * 100.0,
                        x.bias() * 100.0,
                        x.pooled_distance_error() * 100.0
                    ));
                }
            }
        }
        t.row(r);
    }
    t.render()
}

/// Walked distance per trial by `model`: one row per trial whose walked distance is known
/// ([`TrialRun::reference_total_m`]), with the reference and the error.
pub fn walked_table(runs: &[TrialRun], pred: &Predictions, model: Model) -> String {
    let mut t = Table::new([
        Column::from("dataset"),
        Column::from("trial"),
        Column::right("strides"),
        Column::right("walked (m)"),
        Column::right("reference (m)"),
        Column::right("error"),
    ]);
    for (run, p) in runs.iter().zip(pred) {
        let Some(total) = run.reference_total_m else {
            continue;
        };
        let sum: f64 = p.iter().map(|p| p[model as usize]).sum();
        t.row([
            run.dataset.to_string(),
            run.trial.to_string(),
            p.len().to_string(),
            format!("{sum:.2}"),
            format!("{total:.2}"),
            format!("{:+.1} %", (sum - total) / total * 100.0),
        ]);
    }
    t.render()
}

/// Stride-length error of `model` against the reference stride's speed, one colour per
/// dataset with per-stride lengths, as an SVG document.
pub fn speed_plot(runs: &[TrialRun], pred: &Predictions, model: Model) -> Result<String> {
    let mut by: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (run, p) in runs.iter().zip(pred) {
        for ((r, v), p) in run.reference.iter().zip(&run.speed_mps).zip(p) {
            if let (Some(r), Some(v)) = (r, v) {
                let k = match by.iter().position(|(d, _)| *d == run.dataset) {
                    Some(k) => k,
                    None => {
                        by.push((run.dataset.clone(), Vec::new()));
                        by.len() - 1
                    }
                };
                by[k].1.push((*v, (p[model as usize] - r) * 100.0));
            }
        }
    }
    let vmax = by
        .iter()
        .flat_map(|(_, p)| p.iter().map(|p| p.0))
        .fold(1.0, f64::max)
        .ceil();
    let mut plot = Plot::new(
        &format!("{}: stride length error against speed", model.name()),
        "reference stride speed (m/s)",
        "predicted − reference (cm)",
        (0.0, vmax),
        (-25.0, 25.0),
    );
    plot.line((0.0, 0.0), (vmax, 0.0), "", true);
    for (k, (d, pts)) in by.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        plot.points(pts, colour, Some(format!("{d} ({} strides)", pts.len())));
    }
    plot.svg()
}

/// Matched clean strides of the training datasets: (reference, predicted by `model`), m.
pub fn pairs(runs: &[TrialRun], pred: &Predictions, model: Model) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (run, p) in runs.iter().zip(pred) {
        for (r, p) in run.reference.iter().zip(p) {
            if let Some(r) = r {
                out.push((*r, p[model as usize]));
            }
        }
    }
    out
}

/// A Bland–Altman plot (difference against mean, with the bias and the 95 % limits of
/// agreement) and a predicted-against-reference scatter, as SVG documents.
pub fn plots(pairs: &[(f64, f64)], model: &str) -> Result<(String, String)> {
    let n = pairs.len() as f64;
    let diffs: Vec<f64> = pairs.iter().map(|(r, p)| p - r).collect();
    let bias = diffs.iter().sum::<f64>() / n;
    let sd = (diffs.iter().map(|d| (d - bias).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let lo = pairs
        .iter()
        .map(|p| p.0.min(p.1))
        .fold(f64::INFINITY, f64::min)
        .min(0.0);
    let hi = pairs.iter().map(|p| p.0.max(p.1)).fold(0.0, f64::max);
    let span = (bias.abs() + 3.0 * sd).max(0.1);
    let mut ba = Plot::new(
        &format!(
            "Bland–Altman: {model}, {} strides (cross-validated)",
            pairs.len()
        ),
        "mean of predicted and reference stride length (m)",
        "predicted − reference (m)",
        (lo, hi),
        (-span, span),
    );
    let means: Vec<(f64, f64)> = pairs.iter().map(|(r, p)| ((r + p) / 2.0, p - r)).collect();
    ba.points(&means, COLOURS[0], None);
    ba.line(
        (lo, bias),
        (hi, bias),
        &format!("bias {:+.3} m", bias),
        false,
    );
    let (a, b) = (bias - 1.96 * sd, bias + 1.96 * sd);
    ba.line((lo, a), (hi, a), &format!("−1.96 SD {a:+.3} m"), true);
    ba.line((lo, b), (hi, b), &format!("+1.96 SD {b:+.3} m"), true);
    let mut sc = Plot::new(
        &format!(
            "{model}: predicted against reference, {} strides",
            pairs.len()
        ),
        "reference stride length (m)",
        "predicted stride length (m)",
        (lo, hi),
        (lo, hi),
    );
    sc.points(pairs, COLOURS[0], None);
    sc.line((lo, lo), (hi, hi), "y = x", true);
    Ok((ba.svg()?, sc.svg()?))
}

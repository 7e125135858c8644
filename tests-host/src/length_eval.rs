//! Stride lengths scored against the references, every model side by side.
//!
//! Trained models are scored only on strides their training never saw: the training
//! datasets are cut into [`train::FOLDS`] folds grouped by trial, each fold is predicted by
//! models fitted on the others (with the shipped SVR hyper-parameters), and datasets that
//! are not trained on (`ipol_gait_events`) are predicted by the shipped fit. Every
//! prediction is the core's fixed-point one.
//!
//! Per model and dataset: RMSE, MAE and bias (predicted − reference) over matched clean
//! strides (reference unflagged, stride valid), and the walked-distance error per trial,
//! `|Σ predicted − Σ reference| / Σ reference` over all the core's strides in the trial's
//! span (median and worst).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use anyhow::Result;
use gaitclip::models::{self, Model, ModelParams, MODELS};

use crate::train::{self, HyperSet, Sample, Trained, TrialRun};

/// Predictions of every model for every stride of every run: `[run][stride][model]`, m.
pub type Predictions = Vec<Vec<[f64; MODELS]>>;

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
    let samples = train::samples(runs);
    let fold = train::folds(samples.iter().map(|s| s.group.clone()));
    let fits: Vec<Result<Trained>> = std::thread::scope(|sc| {
        let handles: Vec<_> = (0..train::FOLDS)
            .map(|k| {
                let (samples, fold) = (&samples, &fold);
                sc.spawn(move || {
                    let tr: Vec<&Sample> = samples.iter().filter(|s| fold[&s.group] != k).collect();
                    train::fit_all(&tr, hyper)
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
    let full = train::fit_all(&all, hyper)?;
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

/// One model's scores on one dataset.
#[derive(Clone, Debug, Default)]
pub struct LengthScore {
    /// Matched clean strides.
    pub strides: usize,
    /// Per-stride errors, m.
    pub errors: Vec<f64>,
    /// Walked-distance error per trial, fraction.
    pub distance: Vec<f64>,
}

impl LengthScore {
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
pub fn score(runs: &[TrialRun], pred: &Predictions) -> Vec<(String, [LengthScore; MODELS])> {
    let mut by: BTreeMap<String, [LengthScore; MODELS]> = BTreeMap::new();
    let mut order = Vec::new();
    for (run, p) in runs.iter().zip(pred) {
        if !by.contains_key(&run.dataset) {
            order.push(run.dataset.clone());
        }
        let s = by.entry(run.dataset.clone()).or_default();
        for m in Model::ALL {
            let k = m as usize;
            for (r, p) in run.reference.iter().zip(p) {
                if let Some(r) = r {
                    s[k].strides += 1;
                    s[k].errors.push(p[k] - r);
                }
            }
            if let Some(total) = run.reference_total_m {
                let sum: f64 = p.iter().map(|p| p[k]).sum();
                s[k].distance.push((sum - total).abs() / total);
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

/// Median (mean of the middle two for an even count), NaN when empty.
fn median(v: &[f64]) -> f64 {
    let mut a = v.to_vec();
    a.sort_by(f64::total_cmp);
    match a.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => a[n / 2],
        n => (a[n / 2 - 1] + a[n / 2]) / 2.0,
    }
}

/// The Markdown table: one row per model, per dataset RMSE / MAE / bias in cm and the
/// walked-distance error (median / worst trial, %).
pub fn table(scores: &[(String, [LengthScore; MODELS])]) -> String {
    let mut s = String::from("| model |");
    let mut rule = String::from("|---|");
    for (d, sc) in scores {
        let n = sc[0].strides;
        if n > 0 {
            let _ = write!(s, " {d}: RMSE / MAE / bias, cm ({n} strides) |");
            rule.push_str("---|");
        }
        let _ = write!(
            s,
            " {d}: distance error, median / worst of {} trials |",
            sc[0].distance.len()
        );
        rule.push_str("---|");
    }
    s.push('\n');
    s.push_str(&rule);
    s.push('\n');
    for m in Model::ALL {
        let k = m as usize;
        let _ = write!(s, "| `{}` |", m.name());
        for (_, sc) in scores {
            let x = &sc[k];
            if x.strides > 0 {
                let _ = write!(
                    s,
                    " {:.1} / {:.1} / {:+.1} |",
                    x.rmse() * 100.0,
                    x.mae() * 100.0,
                    x.bias() * 100.0
                );
            }
            let worst = x.distance.iter().cloned().fold(0.0, f64::max);
            let _ = write!(
                s,
                " {:.1} % / {:.1} % |",
                median(&x.distance) * 100.0,
                worst * 100.0
            );
        }
        s.push('\n');
    }
    s
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

struct Plot {
    svg: String,
    x: (f64, f64),
    y: (f64, f64),
}

const W: f64 = 520.0;
const H: f64 = 420.0;
const MARGIN: f64 = 60.0;

impl Plot {
    fn new(title: &str, xlabel: &str, ylabel: &str, x: (f64, f64), y: (f64, f64)) -> Plot {
        let mut svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
        );
        let _ = writeln!(
            svg,
            "<text x=\"{}\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">{title}</text>",
            W / 2.0
        );
        let _ = writeln!(
            svg,
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{xlabel}</text>",
            W / 2.0,
            H - 12.0
        );
        let _ = writeln!(
            svg,
            "<text x=\"16\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 16 {})\">{ylabel}</text>",
            H / 2.0,
            H / 2.0
        );
        let mut p = Plot { svg, x, y };
        p.axes();
        p
    }

    fn px(&self, v: f64) -> f64 {
        MARGIN + (v - self.x.0) / (self.x.1 - self.x.0) * (W - 1.5 * MARGIN)
    }

    fn py(&self, v: f64) -> f64 {
        H - MARGIN - (v - self.y.0) / (self.y.1 - self.y.0) * (H - 1.8 * MARGIN)
    }

    fn axes(&mut self) {
        let (x0, x1, y0, y1) = (
            self.px(self.x.0),
            self.px(self.x.1),
            self.py(self.y.0),
            self.py(self.y.1),
        );
        let _ = writeln!(
            self.svg,
            "<rect x=\"{x0:.1}\" y=\"{y1:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"black\"/>",
            x1 - x0,
            y0 - y1
        );
        for k in 0..=4 {
            let vx = self.x.0 + (self.x.1 - self.x.0) * k as f64 / 4.0;
            let vy = self.y.0 + (self.y.1 - self.y.0) * k as f64 / 4.0;
            let _ = writeln!(
                self.svg,
                "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{vx:.2}</text>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{vy:.2}</text>",
                self.px(vx),
                y0 + 16.0,
                x0 - 4.0,
                self.py(vy) + 4.0
            );
        }
    }

    fn points(&mut self, pts: &[(f64, f64)]) {
        for &(x, y) in pts {
            let _ = writeln!(
                self.svg,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2\" fill=\"#1f77b4\" fill-opacity=\"0.5\"/>",
                self.px(x.clamp(self.x.0, self.x.1)),
                self.py(y.clamp(self.y.0, self.y.1))
            );
        }
    }

    fn line(&mut self, a: (f64, f64), b: (f64, f64), label: &str, dash: bool) {
        let _ = writeln!(
            self.svg,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#d62728\"{}/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\" fill=\"#d62728\">{label}</text>",
            self.px(a.0),
            self.py(a.1),
            self.px(b.0),
            self.py(b.1),
            if dash { " stroke-dasharray=\"5,4\"" } else { "" },
            self.px(b.0) - 2.0,
            self.py(b.1) - 4.0
        );
    }

    fn finish(mut self) -> String {
        self.svg.push_str("</svg>\n");
        self.svg
    }
}

/// A Bland–Altman plot (difference against mean, with the bias and the 95 % limits of
/// agreement) and a predicted-against-reference scatter, as SVG documents.
pub fn plots(pairs: &[(f64, f64)], model: &str) -> (String, String) {
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
    ba.points(&means);
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
    sc.points(pairs);
    sc.line((lo, lo), (hi, hi), "y = x", true);
    (ba.finish(), sc.finish())
}

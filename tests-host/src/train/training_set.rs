//! The training set: the core's strides on the datasets with per-stride lengths
//! (`pyshoe_vicon`, `gaitmap_walk`), matched to their reference strides, with the f64
//! reference features ([`crate::reference::length_ref`]) of each. Both the training ([`crate::train::training`])
//! and the evaluation of the models ([`crate::eval::length_eval`]) read it; neither is read here.
//!
//! A stride trains only when its reference is clean (unflagged) and the core marked it valid.

use std::path::Path;

use anyhow::{Context, Result};
use gaitclip::detect::phase_stats::StrideStats;
use gaitclip::length::features::{Features, COUNT};
use gaitclip::length::models::Settings;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;

use crate::eval::matching::{self, Detected};
use crate::io::datasets::{self, Dataset};
use crate::io::trace::Ranges;
use crate::reference::length_ref;
use crate::train::fit::Sample;
use crate::{io::csv_trace, replay};

/// Datasets with per-stride lengths, the training data.
pub const TRAINING_DATASETS: [&str; 2] = ["gaitmap_walk", "pyshoe_vicon"];

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
                let mid = s.events.heel_off / 2 + s.events.end / 2;
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
                    && 2 * (d.events.foot_flat.min(r.end))
                        .saturating_sub(d.events.heel_off.max(r.start))
                        >= d.events.foot_flat - d.events.heel_off
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

/// Loads the training datasets under `shared_datasets`.
pub fn load_training(shared_datasets: &Path) -> Result<Vec<TrialRun>> {
    let mut runs = Vec::new();
    for name in TRAINING_DATASETS {
        runs.extend(run_dataset(&datasets::load(&shared_datasets.join(name))?)?);
    }
    Ok(runs)
}

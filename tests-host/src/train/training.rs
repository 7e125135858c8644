//! Training of every length model on the shared recordings, and the generated Rust source
//! the firmware compiles (`src/length/trained.rs`).
//!
//! Data: the core's strides on `pyshoe_vicon` and `gaitmap_walk`, matched to their
//! reference strides; a stride trains only when its reference is clean (unflagged) and the
//! core marked it valid. Features are the f64 reference features ([`crate::reference::length_ref`]).
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
//!
//! This module gathers the training strides and runs the steps: [`crate::train::fit`] fits,
//! [`crate::train::cross_validation`] chooses the SVRs' hyper-parameters, [`crate::train::codegen`] writes
//! the source.

use anyhow::Result;
use gaitclip::length::models::Model;

use crate::eval::length_eval;
use crate::train::cross_validation::{self, folds, Search, Searched};
use crate::train::fit::{fit_all, HyperSet, Sample, Trained};
use crate::train::training_set::{samples, TrialRun};

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
    /// The grid searches behind the hyper-parameters (every training stride's first, then
    /// each leave-one-dataset-out set's), recorded in the generated source
    /// ([`cross_validation::Search::Recorded`]).
    pub searches: Vec<Searched>,
}

/// Trains every model on `runs`, searching every grid (`gaitclip train`).
pub fn train(runs: &[TrialRun]) -> Result<Training> {
    train_with(runs, Search::Run)
}

/// Trains every model on `runs`, the grid searches run or recorded as `how` says: the same
/// models either way where the recorded searches are of the same strides and code.
pub fn train_with(runs: &[TrialRun], how: Search) -> Result<Training> {
    let s = samples(runs);
    let full = cross_validation::search(&s, how)?;
    let refs: Vec<&Sample> = s.iter().collect();
    let trained = fit_all(&refs, &full.hyper)?;
    let trials = folds(s.iter().map(|s| s.group.clone())).len();
    let (pred, lodo_searches) = length_eval::predictions(
        runs,
        &full.hyper,
        length_eval::Validation::LeaveOneDatasetOut,
        how,
    )?;
    let lodo = length_eval::score(runs, &pred);
    let default_model = length_eval::lodo_best(&lodo);
    let mut searches = vec![full];
    searches.extend(lodo_searches);
    Ok(Training {
        trained,
        hyper: full.hyper,
        cv_rmse: full.cv_rmse,
        trials,
        lodo,
        default_model,
        searches,
    })
}

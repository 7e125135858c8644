//! Choosing the SVRs' `C`, `γ` and `ε`: grid search with cross-validation grouped by trial
//! ([`FOLDS`] folds; a walk's strides are never split between training and test).

use std::collections::BTreeMap;

use anyhow::Result;
use gaitclip::detect::phase_stats::Segment;

use crate::train::fit::{fit_svr, select, Hyper, HyperSet, Sample, SLOTS};

/// Folds of the grouped cross-validation.
pub const FOLDS: usize = 5;
/// Grid of `C`.
pub const GRID_C: [f64; 3] = [1.0, 10.0, 100.0];
/// Grid of `γ` (per squared z unit).
pub const GRID_GAMMA: [f64; 3] = [0.03, 0.1, 0.3];
/// Grid of `ε`, m.
pub const GRID_EPS: [f64; 2] = [0.02, 0.05];

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

//! Choosing the SVRs' `C`, `γ` and `ε`: grid search with cross-validation grouped by trial
//! ([`FOLDS`] folds; a walk's strides are never split between training and test).
//!
//! **Recorded searches.** A search is 360 SVR fits (18 grid points × 4 slots × 5 folds), a
//! minute or two of CPU for each set of training strides; `gaitclip train` runs three (every
//! training stride, and each leave-one-dataset-out set). Its result is a pure function of
//! the strides searched, the grid, the folds and the code that fits and scores them, which
//! [`search_key`] hashes; `gaitclip train` records each search it ran with its key
//! (`gaitclip::length::trained::SEARCHES`). [`Search::Recorded`] takes a recorded result
//! whose key matches instead of searching again (what `gaitclip eval` and the staleness
//! test do), and searches where none does (other datasets, changed features, changed code).

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

/// How a search's result is had.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Search {
    /// Search the grid (`gaitclip train`).
    Run,
    /// The result `gaitclip train` recorded for the same [`search_key`], if any; else search.
    Recorded,
}

/// One search's result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Searched {
    /// What was searched ([`search_key`]).
    pub key: u64,
    /// The grid point chosen per SVR slot.
    pub hyper: HyperSet,
    /// Its cross-validated RMSE, m.
    pub cv_rmse: [f64; 4],
}

/// 64-bit FNV-1a.
struct Fnv(u64);

impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// Hashes the code of a Rust source: every line but comments, without white space, so
/// that formatting and comments do not count as a change of the search.
fn code(h: &mut Fnv, source: &str) {
    for line in source.lines() {
        let line = line.trim();
        if line.starts_with("//") {
            continue;
        }
        for c in line.chars().filter(|c| !c.is_whitespace()) {
            h.bytes(c.encode_utf8(&mut [0; 4]).as_bytes());
        }
    }
}

/// The versions of the crates that fit the SVRs, from the host workspace's lock file.
fn solver_versions() -> String {
    let lock = include_str!("../../Cargo.lock");
    lock.split("[[package]]")
        .filter(|p| {
            p.lines()
                .any(|l| l.starts_with("name = \"linfa") || l.starts_with("name = \"ndarray\""))
        })
        .flat_map(|p| p.lines().take(3))
        .collect::<Vec<_>>()
        .join("\n")
}

/// What a search over `samples` is a function of, hashed (FNV-1a, 64 bits): every sample's
/// group, features, reference length and settings in order; the grid and the folds; the
/// source of this module and of the fit; the versions of the solver's crates.
pub fn search_key(samples: &[Sample]) -> u64 {
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    for s in samples {
        h.bytes(s.group.as_bytes());
        h.bytes(&[0]);
        for v in s.x.iter().chain([&s.y]) {
            h.bytes(&v.to_bits().to_le_bytes());
        }
        h.bytes(&s.settings.height_mm.to_le_bytes());
    }
    for v in GRID_C.iter().chain(&GRID_GAMMA).chain(&GRID_EPS) {
        h.bytes(&v.to_bits().to_le_bytes());
    }
    h.bytes(&(FOLDS as u64).to_le_bytes());
    for source in [include_str!("cross_validation.rs"), include_str!("fit.rs")] {
        code(&mut h, source);
    }
    h.bytes(solver_versions().as_bytes());
    h.0
}

/// The search over `samples`, run or recorded as `how` says.
pub fn search(samples: &[Sample], how: Search) -> Result<Searched> {
    let key = search_key(samples);
    if how == Search::Recorded {
        if let Some((_, hyper, cv_rmse)) = gaitclip::length::trained::SEARCHES
            .iter()
            .find(|(k, _, _)| *k == key)
        {
            return Ok(Searched {
                key,
                hyper: crate::train::fit::hyper_from(hyper),
                cv_rmse: *cv_rmse,
            });
        }
    }
    let (hyper, cv_rmse) = choose_hyper(samples)?;
    Ok(Searched {
        key,
        hyper,
        cv_rmse,
    })
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

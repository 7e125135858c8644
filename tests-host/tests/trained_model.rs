//! The shipped models (`src/length/trained.rs`) against the training code and the recordings
//! (skipped with a message when `../shared/datasets` is absent; a failure in CI):
//!
//! - the committed file is exactly what `gaitclip train` writes today (not stale): trained
//!   again with the grid searches it recorded where they are of the same strides and code
//!   (`cross_validation::Search::Recorded`), searched again where not;
//! - on every stride of every dataset, training and test alike, every model's fixed-point
//!   length agrees with the f64 model within 1 mm;
//! - the default model is the leave-one-dataset-out best and meets the issue-18 targets
//!   out of dataset: per-stride RMSE ≤ 4 cm on `gaitmap_walk`, ≤ 5 cm on `pyshoe_vicon`,
//!   |bias| ≤ 1 cm on both.

use gaitclip::length::features::Features;
use gaitclip::length::models::{self, Model};
use gaitclip::pipeline::config::DEFAULT_MODEL;
use gaitclip_host::io::datasets::root_or_skip;
use gaitclip_host::train::cross_validation::Search;
use gaitclip_host::{io::datasets, train::codegen, train::training, train::training_set};

#[test]
fn shipped_models_are_current_exact_and_meet_targets() {
    let Some(root) = root_or_skip("shipped_models_are_current_exact_and_meet_targets") else {
        return;
    };
    let mut runs = Vec::new();
    for name in ["gaitmap_walk", "pyshoe_vicon", "ipol_gait_events"] {
        runs.extend(training_set::run_dataset(&datasets::load(&root.join(name)).unwrap()).unwrap());
    }

    // 1. Not stale.
    let t = training::train_with(&runs, Search::Recorded).unwrap();
    let source = codegen::rust_source(&t);
    let committed = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../src/length/trained.rs"
    ))
    .unwrap();
    assert!(
        source == committed,
        "src/length/trained.rs is stale: regenerate it with `cargo run --release --bin gaitclip -- train` in tests-host/"
    );

    // 2. Fixed point (the shipped tables) against f64 (the fit just made), every stride.
    let mut worst = (0.0f64, "", 0usize);
    let mut n = 0usize;
    for run in &runs {
        for ((x, s), stats) in run.x.iter().zip(&run.strides).zip(&run.stats) {
            let f = Features::of(s, stats, run.rate);
            for m in Model::ALL {
                let fixed_m =
                    models::predict_um(m, &f, run.settings, &gaitclip::length::trained::PARAMS)
                        .unwrap() as f64
                        / 1e6;
                let exact = t.trained.predict_f64(m, x, run.settings);
                let d = (fixed_m - exact).abs();
                if d > worst.0 {
                    worst = (d, m.name(), n);
                }
            }
            n += 1;
        }
    }
    eprintln!(
        "fixed vs f64 over {n} strides × {} models: worst {:.3} mm ({})",
        Model::ALL.len(),
        worst.0 * 1e3,
        worst.1
    );
    assert!(worst.0 <= 1e-3, "{:.3} mm ({})", worst.0 * 1e3, worst.1);

    // 3. The default is the leave-one-dataset-out best, and meets the targets out of
    //    dataset: fitted on the other dataset, scored on this one.
    assert_eq!(
        DEFAULT_MODEL, t.default_model,
        "DEFAULT_MODEL is not the LODO best"
    );
    assert_eq!(DEFAULT_MODEL, gaitclip::length::trained::LODO_BEST);
    let get = |d: &str| &t.lodo.iter().find(|s| s.0 == d).unwrap().1[DEFAULT_MODEL as usize];
    for (name, rmse_max) in [("gaitmap_walk", 0.04), ("pyshoe_vicon", 0.05)] {
        let s = get(name);
        eprintln!(
            "{} LODO on {name}: {} strides, RMSE {:.2} cm, bias {:+.2} cm",
            DEFAULT_MODEL.name(),
            s.errors.len(),
            s.rmse() * 100.0,
            s.bias() * 100.0
        );
        assert!(
            s.errors.len() >= 40,
            "{name}: {} strides scored",
            s.errors.len()
        );
        assert!(s.rmse() <= rmse_max, "{name} LODO RMSE {}", s.rmse());
        assert!(s.bias().abs() <= 0.01, "{name} LODO bias {}", s.bias());
    }
    let gm = get("gaitmap_walk");
    assert_eq!(gm.distance.len(), 2);
    for d in &gm.distance {
        assert!(*d <= 0.03, "gaitmap walked-distance error {d}");
    }
}

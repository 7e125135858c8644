//! The shipped models (`src/trained.rs`) against the training code and the recordings
//! (skipped with a message when `../shared/datasets` is absent; a failure in CI):
//!
//! - the committed file is exactly what `gaitclip train` writes today (not stale);
//! - on every stride of every dataset, training and test alike, every model's fixed-point
//!   length agrees with the f64 model within 1 mm;
//! - the default model meets the length targets under cross-validation grouped by trial.

use gaitclip::features::Features;
use gaitclip::models::{self, Model};
use gaitclip::pipeline::DEFAULT_MODEL;
use gaitclip_host::datasets::root_or_skip;
use gaitclip_host::{eval, length_eval, train};

#[test]
fn shipped_models_are_current_exact_and_meet_targets() {
    let Some(root) = root_or_skip("shipped_models_are_current_exact_and_meet_targets") else {
        return;
    };
    let mut runs = Vec::new();
    for name in ["gaitmap_walk", "pyshoe_vicon", "ipol_gait_events"] {
        runs.extend(train::run_dataset(&eval::load(&root.join(name)).unwrap()).unwrap());
    }

    // 1. Not stale.
    let t = train::train(&runs).unwrap();
    let source = train::rust_source(&t);
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../src/trained.rs")).unwrap();
    assert!(
        source == committed,
        "src/trained.rs is stale: regenerate it with `cargo run --release --bin gaitclip -- train` in tests-host/"
    );

    // 2. Fixed point (the shipped tables) against f64 (the fit just made), every stride.
    let mut worst = (0.0f64, "", 0usize);
    let mut n = 0usize;
    for run in &runs {
        for ((x, s), stats) in run.x.iter().zip(&run.strides).zip(&run.stats) {
            let f = Features::of(s, stats, run.rate);
            for m in Model::ALL {
                let fixed_m = models::predict_um(m, &f, run.settings, &gaitclip::trained::PARAMS)
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

    // 3. Targets, cross-validated.
    let (pred, _) = length_eval::cross_validate(&runs, &t.hyper).unwrap();
    let scores = length_eval::score(&runs, &pred);
    let get = |d: &str| &scores.iter().find(|s| s.0 == d).unwrap().1[DEFAULT_MODEL as usize];
    let (gm, py) = (get("gaitmap_walk"), get("pyshoe_vicon"));
    eprintln!(
        "{}: gaitmap RMSE {:.1} cm, distance {:?}; pyshoe RMSE {:.1} cm",
        DEFAULT_MODEL.name(),
        gm.rmse() * 100.0,
        gm.distance,
        py.rmse() * 100.0
    );
    assert!(gm.rmse() <= 0.06, "gaitmap RMSE {}", gm.rmse());
    assert!(py.rmse() <= 0.10, "pyshoe RMSE {}", py.rmse());
    assert_eq!(gm.distance.len(), 2);
    for d in &gm.distance {
        assert!(*d <= 0.03, "gaitmap walked-distance error {d}");
    }
}

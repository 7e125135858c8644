//! The bias study's findings (`gaitclip bias`, docs/accuracy.md "What moves the bias between
//! set-ups"), bounded just above what was measured, so that the page stays true:
//!
//! - the default (the rest's departure from 1 g read as an offset along gravity) keeps each
//!   dataset's and shoe's ZUPT bias small, and an offset along gravity made on purpose does
//!   not move it, where read as a gain (the rule before) it moved it by centimetres;
//! - on `ipol_gait_events`, whose two feet's sensors read gravity 4.8 % and 1.0 % high, the two
//!   feet of a walk agree, where read as a gain the left walked ≈ 2.7 % less;
//! - the lever arm fitted to the strides' end residuals is not the lever arm (the reason no
//!   lever-arm estimator runs on the pod).

use gaitclip_host::eval::bias::{
    after, before, bias_m, feet_apart, lever_fit, load, offset_along_gravity, unchanged,
    zeroing_h_m,
};
use gaitclip_host::eval::stats::{median, quantile};
use gaitclip_host::io::datasets::root_or_skip;

#[test]
fn the_zupt_bias_is_small_by_dataset_and_pace_and_an_offset_along_gravity_does_not_move_it() {
    let Some(root) = root_or_skip("the_zupt_bias_is_small_by_dataset_and_pace") else {
        return;
    };
    // Measured (cm): gaitmap_walk −0.16, pyshoe_vicon +0.02; at 1.5–3 m/s −1.08 (3 strides)
    // and −0.58; pyshoe under 1 m/s +0.6, at 1.5–2 m/s −0.8.
    for (name, all_cm, bins) in [
        ("gaitmap_walk", 0.4, vec![((1.0, 1.5), 0.4)]),
        (
            "pyshoe_vicon",
            0.2,
            vec![
                ((0.0, 1.0), 0.8),
                ((1.0, 1.5), 0.3),
                ((1.5, 2.0), 1.0),
                ((2.0, 3.0), 0.5),
            ],
        ),
    ] {
        let d = load(&root, name).unwrap();
        let (b, n) = bias_m(&d, &unchanged, &after, None).unwrap();
        assert!(n > 40, "{name}: {n} strides");
        assert!(
            b.abs() * 100.0 <= all_cm,
            "{name}: bias {:+.2} cm",
            b * 100.0
        );
        for (bin, bound) in bins {
            let (b, _) = bias_m(&d, &unchanged, &after, Some(bin)).unwrap();
            assert!(
                b.abs() * 100.0 <= bound,
                "{name} {bin:?} m/s: bias {:+.2} cm",
                b * 100.0
            );
        }
        // 0.5 m/s² along gravity: measured −0.00 / −0.14 cm read as an offset; −4.53 / −3.78
        // cm read as a gain.
        let made = |t: &_| offset_along_gravity(t, 0.5);
        let (moved, _) = bias_m(&d, &made, &after, None).unwrap();
        assert!(
            (moved - b).abs() * 100.0 <= 0.3,
            "{name}: an offset along gravity moved the bias by {:+.2} cm",
            (moved - b) * 100.0
        );
        let (old, _) = bias_m(&d, &unchanged, &before, None).unwrap();
        let (old_moved, _) = bias_m(&d, &made, &before, None).unwrap();
        assert!(
            (old_moved - old) * 100.0 <= -3.0,
            "{name}: read as a gain the offset moved the bias by only {:+.2} cm",
            (old_moved - old) * 100.0
        );
    }
}

#[test]
fn the_two_feet_of_an_ipol_walk_agree_once_the_rest_gravity_is_read_as_an_offset() {
    let Some(root) = root_or_skip("the_two_feet_of_an_ipol_walk_agree") else {
        return;
    };
    let ipol = load(&root, "ipol_gait_events").unwrap();
    // Measured: left − right median −0.46 % (|·| median 2.31 %) now, −2.67 % (3.17 %) before.
    let now = feet_apart(&ipol, &after).unwrap();
    let then = feet_apart(&ipol, &before).unwrap();
    assert!(now.len() >= 70, "{} walks with both feet", now.len());
    let abs = |v: &[f64]| v.iter().map(|x| x.abs()).collect::<Vec<_>>();
    assert!(
        median(&now).abs() <= 0.008,
        "left − right {:+.2} %",
        median(&now) * 100.0
    );
    assert!(median(&abs(&now)) <= 0.026);
    assert!(
        median(&then) <= -0.02,
        "before: left − right {:+.2} %",
        median(&then) * 100.0
    );
}

#[test]
fn the_end_residual_does_not_identify_the_lever_arm() {
    let Some(root) = root_or_skip("the_end_residual_does_not_identify_the_lever_arm") else {
        return;
    };
    // Measured: pooled 171 ± 31 mm where 83 mm zeroes the bias (its 99 % interval, 2.576
    // standard errors, 91–251 mm); per trial after 10 strides p10 −611, p90 +860 mm. The
    // pooled fit was 217 ± 35 mm when this test was written and has come down as the
    // detector counted more of the dataset's slow and odd strides; it stays twice the lever
    // arm, outside its 99 % interval.
    let d = load(&root, "pyshoe_vicon").unwrap();
    let fit = lever_fit(&d).unwrap();
    let (h, se) = fit.pooled_m;
    let lever = zeroing_h_m(&d).unwrap();
    assert!(
        (h - lever).abs() > 2.576 * se,
        "the pooled fit {:.0} ± {:.0} mm agrees with the lever arm {:.0} mm",
        h * 1e3,
        se * 1e3,
        lever * 1e3
    );
    let spread = quantile(&fit.after_10_m, 0.9) - quantile(&fit.after_10_m, 0.1);
    assert!(
        spread > 0.5,
        "per trial after 10 strides the fits lie within {:.0} mm",
        spread * 1e3
    );
}

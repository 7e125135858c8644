//! `gaitclip events` on the recordings: which definition each reference's events follow
//! (docs/accuracy.md's event timing table). Bounds just above the figures measured on
//! 2026-12-04; a change to the detectors or to the definitions that moves them fails here.

use gaitclip_host::eval::event_timing::{evaluate, summary, EventErrors};
use gaitclip_host::io::datasets::{self, root_or_skip};

fn signed_and_abs(d: &[EventErrors], pick: fn(&EventErrors) -> Option<f64>) -> (f64, f64, f64) {
    let e: Vec<f64> = d.iter().filter_map(pick).collect();
    summary(&e)
}

#[test]
fn mocap_events_are_the_sagittal_rate_s_push_off_peak_and_swing_end_crossing() {
    let Some(root) =
        root_or_skip("mocap_events_are_the_sagittal_rate_s_push_off_peak_and_swing_end_crossing")
    else {
        return;
    };
    let d = evaluate(&datasets::load(&root.join("gaitmap_walk")).unwrap()).unwrap();
    assert_eq!(d.strides.len(), 49);
    let (s, a, p95) = signed_and_abs(&d.strides, |e| e.toe_off_peak);
    assert!(
        s.abs() <= 6.0 && a <= 6.0 && p95 <= 12.0,
        "toe-off peak {s} {a} {p95}"
    );
    let (s, a, p95) = signed_and_abs(&d.strides, |e| e.heel_strike_crossing);
    assert!(
        s.abs() <= 6.0 && a <= 6.0 && p95 <= 14.0,
        "heel-strike crossing {s} {a} {p95}"
    );
    // The core's heel-strike is the impact's acceleration: about the foot-slap peak, late.
    let (s, _, p95) = signed_and_abs(&d.strides, |e| Some(e.heel_strike_core));
    assert!(
        (50.0..=65.0).contains(&s) && p95 <= 80.0,
        "core heel-strike {s} {p95}"
    );
    // No movement cut short any more (its swing's end, and Huang's impact pair, were lost).
    let (_, _, p95) = signed_and_abs(&d.strides, |e| Some(e.toe_off_core));
    assert!(p95 <= 25.0, "core toe-off p95 {p95}");
    let (s, _, _) = signed_and_abs(&d.strides, |e| e.heel_strike_peak);
    assert!((40.0..=55.0).contains(&s), "foot-slap peak {s}");
}

#[test]
fn ipol_annotations_lie_about_30_ms_after_the_gyro_s_kinematic_events() {
    let Some(root) =
        root_or_skip("ipol_annotations_lie_about_30_ms_after_the_gyro_s_kinematic_events")
    else {
        return;
    };
    let d = evaluate(&datasets::load(&root.join("ipol_gait_events")).unwrap()).unwrap();
    assert!(d.strides.len() >= 2400, "{}", d.strides.len());
    let (s, _, _) = signed_and_abs(&d.strides, |e| e.toe_off_peak);
    assert!((-35.0..=-25.0).contains(&s), "toe-off peak {s}");
    let (s, _, _) = signed_and_abs(&d.strides, |e| e.heel_strike_crossing);
    assert!((-32.0..=-22.0).contains(&s), "heel-strike crossing {s}");
    let (s, a, _) = signed_and_abs(&d.strides, |e| Some(e.toe_off_core));
    assert!(
        (35.0..=45.0).contains(&s) && a <= 45.0,
        "core toe-off {s} {a}"
    );
    let (s, a, _) = signed_and_abs(&d.strides, |e| Some(e.heel_strike_core));
    assert!(
        (25.0..=35.0).contains(&s) && a <= 35.0,
        "core heel-strike {s} {a}"
    );
}

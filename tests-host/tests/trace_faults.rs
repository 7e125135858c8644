//! Faults in recorded traces: holes in the timestamps, jittered timestamps and samples at
//! the sensor's rails. A stride across a hole is reported once, invalid, without a length;
//! jitter is not a hole; a saturated stride is flagged.

use std::path::PathBuf;

use gaitclip_host::csv_trace;
use gaitclip_host::gaps::{self, Gap, GapClock, TimeError};
use gaitclip_host::replay::{replay, StrideReport};
use gaitclip_host::trace::{ImuSample, Ranges, Trace, G_MPS2};

fn demo() -> Trace {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.csv");
    csv_trace::read(&p, None).unwrap()
}

fn grid(n: usize, dt: f64) -> Vec<ImuSample> {
    (0..n)
        .map(|i| ImuSample {
            t_s: i as f64 * dt,
            ..Default::default()
        })
        .collect()
}

#[test]
fn a_hole_is_found_and_jitter_is_not() {
    let mut s = grid(20, 0.005);
    // A late stamp followed by an early one: the samples are all there.
    s[5].t_s += 0.0039;
    s[12].t_s += 0.0027;
    s[13].t_s += 0.0011;
    assert_eq!(gaps::find(&s, 200.0).unwrap(), vec![]);
    // Three samples missing after sample 9 (and a late stamp right after the hole).
    let mut h = grid(20, 0.005);
    h.drain(10..13);
    h[10].t_s += 0.003;
    assert_eq!(
        gaps::find(&h, 200.0).unwrap(),
        vec![Gap {
            before: 10,
            missing: 3
        }]
    );
    // A hole at the very end is still measured.
    let mut e = grid(10, 0.005);
    e[9].t_s += 0.05;
    assert_eq!(
        gaps::find(&e, 200.0).unwrap(),
        vec![Gap {
            before: 9,
            missing: 10
        }]
    );
}

#[test]
fn time_going_back_is_an_error_naming_the_sample() {
    let mut s = grid(10, 0.005);
    s[6].t_s = s[5].t_s;
    assert_eq!(
        gaps::find(&s, 200.0),
        Err(TimeError::NotIncreasing {
            index: 6,
            t_s: 0.025,
            previous_s: 0.025
        })
    );
    s[6].t_s = f64::NAN;
    assert!(gaps::find(&s, 200.0).is_err());
}

#[test]
fn the_clock_maps_core_numbers_across_holes() {
    let mut s = grid(20, 0.01);
    s.drain(5..8); // three missing before recording index 5
    let gaps = gaps::find(&s, 100.0).unwrap();
    let c = GapClock::new(&s, &gaps, 100.0);
    assert_eq!(c.t_s(4), 0.04);
    assert!(
        (c.t_s(6) - 0.06).abs() < 1e-12,
        "inside the hole: on the grid"
    );
    assert_eq!(c.t_s(8), 0.08);
    assert_eq!(c.recording_index(8), 5);
    assert_eq!(c.recording_index(6), 5);
    assert_eq!(c.recording_index(3), 3);
    assert!(
        (c.t_s(30) - 0.30).abs() < 1e-12,
        "past the end: extrapolated"
    );
}

/// Cuts `len` samples out of the demo walk at `at` (timestamps jump over the hole).
fn cut(at: usize, len: usize) -> Trace {
    let mut t = demo();
    t.samples.drain(at..at + len);
    t
}

fn stride_over(strides: &[StrideReport], t_s: f64) -> Option<&StrideReport> {
    strides.iter().find(|s| s.start_s < t_s && t_s < s.end_s)
}

#[test]
fn a_stride_across_a_hole_is_reported_invalid_without_a_length() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    // Into the swing of the middle stride, 120 ms (24 samples) lost.
    let mid = &whole[whole.len() / 2];
    let swing_s = (mid.toe_off_s + mid.heel_strike_s) / 2.0;
    let at = (swing_s * 200.0).round() as usize;
    let got = replay(&cut(at, 24), Ranges::default()).unwrap();
    let hole_s = at as f64 / 200.0;
    let g = stride_over(&got, hole_s).expect("the stride over the hole is reported");
    assert_eq!(g.flags, vec!["gap"]);
    assert!(!g.valid);
    assert_eq!(g.length_m, 0.0);
    assert!((g.start_s - mid.start_s).abs() < 1e-9, "{g:?} vs {mid:?}");
    assert!(g.heel_off_s <= hole_s && hole_s <= g.end_s);
    // Every other stride is found as before: as many, same times, same flags, same ZUPT.
    // Before the gap the lengths are identical; after it they may differ a little, since
    // the foot frame did not learn its heading from the broken movement.
    assert_eq!(got.len(), whole.len());
    for (a, b) in whole.iter().zip(&got) {
        if a.index != mid.index {
            assert!((a.start_s - b.start_s).abs() < 1e-9, "{a:?} vs {b:?}");
            assert!((a.end_s - b.end_s).abs() < 1e-9, "{a:?} vs {b:?}");
            assert_eq!(a.zupt_m, b.zupt_m, "{a:?} vs {b:?}");
            assert_eq!(a.flags, b.flags);
            if a.index < mid.index {
                assert_eq!(a.length_m, b.length_m, "{a:?} vs {b:?}");
            } else {
                assert!((a.length_m - b.length_m).abs() <= 0.01, "{a:?} vs {b:?}");
            }
        }
    }
}

#[test]
fn a_hole_inside_a_stance_costs_no_stride() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    // The middle of the stance between two strides, 20 ms lost.
    let k = whole.len() / 2;
    let stance_s = (whole[k].start_s + whole[k].heel_off_s) / 2.0;
    let at = (stance_s * 200.0).round() as usize;
    let got = replay(&cut(at, 4), Ranges::default()).unwrap();
    assert_eq!(got.len(), whole.len());
    assert!(got.iter().all(|s| !s.flags.contains(&"gap")), "{got:#?}");
}

#[test]
fn samples_at_the_rails_flag_the_stride() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    let mut t = demo();
    let mid = &whole[whole.len() / 2];
    // A heel strike harder than ±16 g: the sensor reads its rail.
    let i = (mid.heel_strike_s * 200.0).round() as usize;
    t.samples[i].acc_mps2[2] = 20.0 * G_MPS2;
    let got = replay(&t, Ranges::default()).unwrap();
    let g = got.iter().find(|s| s.index == mid.index).unwrap();
    assert!(g.flags.contains(&"saturated"), "{g:?}");
    assert!(!g.valid);
    // The gyro rail too (±2000 °/s = 34.9 rad/s).
    let mut t = demo();
    let j = ((mid.heel_off_s + mid.toe_off_s) / 2.0 * 200.0).round() as usize;
    t.samples[j].gyr_radps[1] = -40.0;
    let got = replay(&t, Ranges::default()).unwrap();
    let g = got.iter().find(|s| s.index == mid.index).unwrap();
    assert!(g.flags.contains(&"saturated"), "{g:?}");
    // Only that stride.
    assert_eq!(
        got.iter().filter(|s| !s.valid).count(),
        whole.iter().filter(|s| !s.valid).count() + 1
    );
}

/// The seven `pyshoe_vicon` traces whose stamps jitter (late by up to 3.9 ms, then early):
/// no hole is declared, and the strides are those of the same samples on an exact grid.
#[test]
fn jittered_pyshoe_traces_replay_as_if_on_the_grid() {
    let Some(root) = gaitclip_host::datasets::root_or_skip("jittered_pyshoe_traces") else {
        return;
    };
    let mut jittered = 0;
    let mut entries: Vec<_> = std::fs::read_dir(root.join("pyshoe_vicon"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            // Trials are named by date (`2017-11-22-11-22-03.csv`); skip the references.
            let name = p.file_name().unwrap().to_string_lossy();
            name.starts_with("20") && name.ends_with(".csv") && !name.contains(".reference")
        })
        .collect();
    entries.sort();
    for p in entries {
        let t = csv_trace::read(&p, None).unwrap();
        let dt = 1.0 / t.rate_hz;
        let max = t
            .samples
            .windows(2)
            .map(|w| w[1].t_s - w[0].t_s)
            .fold(0.0, f64::max);
        if max <= 1.5 * dt {
            continue;
        }
        jittered += 1;
        assert_eq!(
            gaps::find(&t.samples, t.rate_hz).unwrap(),
            vec![],
            "{}",
            p.display()
        );
        let mut on_grid = t.clone();
        let t0 = t.samples[0].t_s;
        for (i, s) in on_grid.samples.iter_mut().enumerate() {
            s.t_s = t0 + i as f64 * dt;
        }
        let a = replay(&t, Ranges::default()).unwrap();
        let b = replay(&on_grid, Ranges::default()).unwrap();
        assert_eq!(a.len(), b.len(), "{}", p.display());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.raw, y.raw, "{}", p.display());
            assert!((x.start_s - y.start_s).abs() < 0.005, "{}", p.display());
        }
    }
    assert_eq!(
        jittered, 7,
        "the datasets' README names seven jittered traces"
    );
}

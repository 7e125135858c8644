//! Faults in recorded traces: holes in the timestamps, jittered and re-sent stamps, and
//! samples at the sensor's rails. A short hole is bridged (the stride keeps its length,
//! flagged `bridged`); a longer one makes the stride across it a gap stride (no length, its
//! events outside the hole still found); jitter is not a hole; a re-sent sample is dropped;
//! a saturated stride is flagged.

use std::path::PathBuf;

use gaitclip::pipeline::config::{BRIDGE_MAX_MS, FILL_MAX_MS};
use gaitclip_host::io::clock::{drop_repeats, Gap, SampleClock, TimeGoesBack};
use gaitclip_host::io::csv_trace;
use gaitclip_host::io::trace::{Ranges, Trace, G_MPS2};
use gaitclip_host::replay::{replay, replay_summarised, StrideReport};

fn demo() -> Trace {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.csv");
    csv_trace::read(&p, None).unwrap()
}

fn grid(n: usize, dt: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 * dt).collect()
}

fn holes(t: &[f64], hz: f64) -> Vec<Gap> {
    SampleClock::recover(t, Some(hz)).unwrap().holes
}

#[test]
fn a_hole_is_found_and_jitter_is_not() {
    let mut s = grid(200, 0.005);
    // A late stamp followed by an early one: the samples are all there.
    s[5] += 0.0039;
    s[12] += 0.0027;
    s[13] += 0.0011;
    s[90] -= 0.0011;
    assert_eq!(holes(&s, 200.0), vec![]);
    // Three samples missing after sample 9 (and a late stamp right after the hole).
    let mut h = grid(200, 0.005);
    h.drain(10..13);
    h[10] += 0.003;
    assert_eq!(
        holes(&h, 200.0),
        vec![Gap {
            before: 10,
            missing: 3
        }]
    );
    // One sample lost, the smallest hole there is.
    let mut one = grid(200, 0.005);
    one.remove(150);
    assert_eq!(
        holes(&one, 200.0),
        vec![Gap {
            before: 150,
            missing: 1
        }]
    );
    // A hole just before the very end is still measured.
    let mut e = grid(200, 0.005);
    e[199] += 0.05;
    assert_eq!(
        holes(&e, 200.0),
        vec![Gap {
            before: 199,
            missing: 10
        }]
    );
}

#[test]
fn a_repeated_stamp_is_dropped_and_one_that_goes_back_is_an_error() {
    let mut s = grid(10, 0.005);
    s.insert(6, s[5]); // re-sent: the same stamp twice
    s.insert(8, s[7] - 0.001); // re-sent late: earlier by less than half a period
    assert_eq!(drop_repeats(&s, 0.005).unwrap().len(), 10);
    let mut b = grid(10, 0.005);
    b[6] = b[5] - 0.004; // back by 0.8 periods: not a repeat
    assert_eq!(
        drop_repeats(&b, 0.005),
        Err(TimeGoesBack {
            index: 6,
            t_s: b[6],
            previous_s: b[5],
        })
    );
}

#[test]
fn the_clock_maps_core_numbers_across_holes() {
    let mut s = grid(400, 0.01);
    s.drain(5..8); // three missing before row 5
    let c = SampleClock::recover(&s, Some(100.0)).unwrap();
    assert_eq!(
        c.holes,
        vec![Gap {
            before: 5,
            missing: 3
        }]
    );
    assert!((c.t_s(4) - 0.04).abs() < 1e-12);
    assert!(
        (c.t_s(6) - 0.06).abs() < 1e-12,
        "inside the hole: on the grid"
    );
    assert_eq!(c.number_of_row(5), 8);
    assert_eq!(c.row_of_number(8), 5);
    assert_eq!(
        c.row_of_number(6),
        5,
        "a lost sample maps to the row after it"
    );
    assert_eq!(c.row_of_number(3), 3);
    assert_eq!(c.number_at(0.081), 8);
    assert!(
        (c.t_s(500) - 5.0).abs() < 1e-9,
        "past the end: on the clock"
    );
}

/// Cuts `len` samples out of the demo walk at `at` (timestamps jump over the hole).
fn cut(at: usize, len: usize) -> Trace {
    let mut t = demo();
    t.samples.drain(at..at + len);
    t
}

/// The middle stride's swing, the sample number `ms` after its middle, in the demo walk.
fn swing_sample(whole: &[StrideReport]) -> (usize, &StrideReport) {
    let mid = &whole[whole.len() / 2];
    let swing_s = (mid.toe_off_s + mid.heel_strike_s) / 2.0;
    ((swing_s * 200.0).round() as usize, mid)
}

/// Every stride but the middle one is found as before: as many, same times; before the
/// hole the same to the bit, after it within a centimetre (the foot frame may not have
/// learnt from the broken movement).
fn others_unchanged(whole: &[StrideReport], got: &[StrideReport], mid: u32) {
    assert_eq!(got.len(), whole.len());
    for (a, b) in whole.iter().zip(got) {
        if a.index != mid {
            assert!((a.start_s - b.start_s).abs() < 1e-9, "{a:?} vs {b:?}");
            assert!((a.end_s - b.end_s).abs() < 1e-9, "{a:?} vs {b:?}");
            if a.index < mid {
                assert_eq!(a.raw, b.raw, "{a:?} vs {b:?}");
            } else {
                assert!((a.length_m - b.length_m).abs() <= 0.01, "{a:?} vs {b:?}");
                assert!((a.zupt_m - b.zupt_m).abs() <= 0.01, "{a:?} vs {b:?}");
            }
        }
    }
}

#[test]
fn a_short_hole_in_a_swing_is_bridged_and_the_stride_measured() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    let (at, mid) = swing_sample(&whole);
    // Two samples (10 ms) lost: well within the bridge limit.
    const { assert!(10 <= BRIDGE_MAX_MS) };
    let (got, summary) = replay_summarised(
        &cut(at, 2),
        Ranges::default(),
        gaitclip::pipeline::detectors::Detector::Cycle,
        gaitclip::pipeline::config::DEFAULT_MODEL,
        false,
    )
    .unwrap();
    assert_eq!((summary.bridged, summary.bridged_samples), (1, 2));
    assert_eq!((summary.gaps, summary.bridged_strides), (0, 1));
    let g = got.iter().find(|g| g.index == mid.index).unwrap();
    assert!(g.valid && g.flags.contains(&"bridged"), "{g:?}");
    assert!(
        (g.length_m - mid.length_m).abs() <= 0.01,
        "{g:?} vs {mid:?}"
    );
    for (x, y) in [
        (g.toe_off_s, mid.toe_off_s),
        (g.heel_strike_s, mid.heel_strike_s),
    ] {
        assert!((x - y).abs() <= 0.0101, "{g:?} vs {mid:?}");
    }
    others_unchanged(&whole, &got, mid.index);
}

/// `g` is estimated: flagged, and its length the mean of the two gait cycles measured last
/// before it in `all` (valid, not from or into a rest, no gap), to the millimetre.
fn assert_estimated(g: &StrideReport, all: &[StrideReport]) {
    let before: Vec<f64> = all
        .iter()
        .filter(|s| s.index < g.index)
        .filter(|s| {
            s.valid
                && !s
                    .flags
                    .iter()
                    .any(|f| ["from_rest", "to_rest", "gap"].contains(f))
        })
        .map(|s| s.length_m)
        .collect();
    assert!(before.len() >= 2, "{g:?}");
    let want = (before[before.len() - 2] + before[before.len() - 1]) / 2.0;
    assert!(g.flags.contains(&"estimated"), "{g:?}");
    assert!(
        (g.length_m - want).abs() <= 0.0011,
        "{} vs {want}",
        g.length_m
    );
}

#[test]
fn a_longer_hole_makes_a_gap_stride_that_keeps_its_events_outside_the_hole() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    let (at, mid) = swing_sample(&whole);
    // 100 ms lost in the middle of the swing: longer than the bridge, short enough to fill.
    let lost = 20;
    assert!(lost * 5 > BRIDGE_MAX_MS && lost * 5 <= FILL_MAX_MS);
    let got = replay(&cut(at, lost as usize), Ranges::default()).unwrap();
    let hole_s = at as f64 / 200.0;
    let g = got.iter().find(|g| g.index == mid.index).unwrap();
    assert!(g.flags.contains(&"gap") && !g.valid, "{g:?}");
    // No length measured across the hole (the filled movement's displacement is not one):
    // the length is the estimate.
    assert_estimated(g, &got);
    // Heel-off and foot-flat are measured as without the hole; toe-off (before the hole)
    // and heel-strike (after it) are found on the interpolated movement. The demo's smooth
    // feet have no sharp peak-valley pairs (`phases_guessed`: cluster centres), so the
    // interpolation moves them by up to 60 ms here; `gaitclip holes` measures it on real
    // walks.
    assert!((g.start_s - mid.start_s).abs() < 1e-9, "{g:?} vs {mid:?}");
    assert!(
        (g.heel_off_s - mid.heel_off_s).abs() < 1e-9,
        "{g:?} vs {mid:?}"
    );
    assert!(
        g.toe_off_s < hole_s && g.heel_strike_s > hole_s + 0.1,
        "{g:?}"
    );
    assert!(
        (g.toe_off_s - mid.toe_off_s).abs() <= 0.06,
        "{g:?} vs {mid:?}"
    );
    assert!(
        (g.heel_strike_s - mid.heel_strike_s).abs() <= 0.06,
        "{g:?} vs {mid:?}"
    );
    assert!((g.end_s - mid.end_s).abs() <= 0.0101, "{g:?} vs {mid:?}");
    others_unchanged(&whole, &got, mid.index);
}

#[test]
fn a_hole_too_long_to_fill_restarts_detection_and_the_stride_is_a_gap() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    let (at, mid) = swing_sample(&whole);
    // 250 ms lost: detection restarts after it.
    let got = replay(&cut(at, 50), Ranges::default()).unwrap();
    let hole_s = at as f64 / 200.0;
    let g = got
        .iter()
        .find(|s| s.start_s < hole_s && hole_s < s.end_s)
        .expect("the stride over the hole is reported");
    assert!(
        g.flags.contains(&"gap") && !g.valid && g.zupt_m == 0.0,
        "{g:?}"
    );
    assert_estimated(g, &got);
    assert!((g.start_s - mid.start_s).abs() < 1e-9, "{g:?} vs {mid:?}");
    assert!(
        (g.heel_off_s - mid.heel_off_s).abs() < 1e-9,
        "{g:?} vs {mid:?}"
    );
    // No event is placed after the hole: one found after it is set to the hole (its first
    // sample the detector had not seen), one found before it is kept (here heel-strike,
    // 25 ms before the hole, on the truncated movement).
    assert!(g.heel_strike_s <= hole_s + 0.0101, "hole {hole_s}: {g:?}");
    assert!(g.toe_off_s <= g.heel_strike_s, "{g:?}");
    assert_eq!(got.len(), whole.len());
    assert_eq!(got.iter().filter(|s| !s.valid).count(), 1);
}

#[test]
fn a_hole_inside_a_stance_costs_no_stride() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    // The middle of the stance between two strides before its stance instant (the cycle
    // detector's stride boundary), 20 ms lost.
    let k = whole.len() / 2;
    let stance_s = (whole[k - 1].foot_flat_s + whole[k].start_s) / 2.0;
    let at = (stance_s * 200.0).round() as usize;
    let got = replay(&cut(at, 4), Ranges::default()).unwrap();
    assert_eq!(got.len(), whole.len());
    assert!(got.iter().all(|s| !s.flags.contains(&"gap")), "{got:#?}");
    assert_eq!(
        got.iter().filter(|s| s.flags.contains(&"bridged")).count(),
        1
    );
    // A longer hole in the same stance (100 ms) is filled and costs no stride either.
    let got = replay(&cut(at, 20), Ranges::default()).unwrap();
    assert_eq!(got.len(), whole.len());
    assert!(got.iter().all(|s| s.valid), "{got:#?}");
}

#[test]
fn samples_at_the_rails_flag_the_stride() {
    let whole = replay(&demo(), Ranges::default()).unwrap();
    let mut t = demo();
    let mid = &whole[whole.len() / 2];
    // A heel strike of 12 g read at ±8 g: the accelerometer sits at its rail, what it lost
    // is put back and the stride stays valid, within 2 cm of the same spike read at ±16 g
    // (unclipped).
    let i = (mid.heel_strike_s * 200.0).round() as usize;
    t.samples[i].acc_mps2[2] = 12.0 * G_MPS2;
    let spike16 = replay(&t, Ranges::default()).unwrap();
    let at8 = Ranges {
        accel: gaitclip_mpu6050::AccelRange::G8,
        ..Ranges::default()
    };
    let got = replay(&t, at8).unwrap();
    let g = got.iter().find(|s| s.index == mid.index).unwrap();
    let w = spike16.iter().find(|s| s.index == mid.index).unwrap();
    assert!(g.flags.contains(&"accel_clipped") && g.valid, "{g:?}");
    assert!(
        (g.length_m - w.length_m).abs() <= 0.02,
        "{} vs {} unclipped",
        g.length_m,
        w.length_m
    );
    assert_eq!(got.len(), whole.len());
    // Huang's stance detector restores nothing: the stride is saturated, and estimated.
    let stance = gaitclip_host::replay::replay_model(
        &t,
        at8,
        gaitclip::pipeline::detectors::Detector::Stance,
        gaitclip::pipeline::config::DEFAULT_MODEL,
        false,
    )
    .unwrap();
    let s = stance
        .iter()
        .find(|s| s.heel_off_s <= mid.heel_strike_s && mid.heel_strike_s <= s.end_s)
        .unwrap();
    assert!(
        s.flags.contains(&"saturated") && s.flags.contains(&"estimated") && s.length_m > 0.0,
        "{s:?}"
    );
    // The gyro rail (±2000 °/s = 34.9 rad/s) is flagged, and the stride stays valid: the
    // tilt the rail lost is put back on the clipped samples.
    let mut t = demo();
    let j = ((mid.heel_off_s + mid.toe_off_s) / 2.0 * 200.0).round() as usize;
    t.samples[j].gyr_radps[1] = -40.0;
    let got = replay(&t, Ranges::default()).unwrap();
    let g = got.iter().find(|s| s.index == mid.index).unwrap();
    assert!(g.flags.contains(&"gyro_clipped") && g.valid, "{g:?}");
    assert_eq!(
        got.iter()
            .filter(|s| s.flags.contains(&"gyro_clipped"))
            .count(),
        1
    );
}

/// The seven `pyshoe_vicon` traces whose stamps jitter (late by up to 3.9 ms, then early):
/// no hole is declared, and the strides are those of the same samples on the exact grid of
/// the clock recovered from them.
#[test]
fn jittered_pyshoe_traces_replay_as_if_on_the_grid() {
    let Some(root) = gaitclip_host::io::datasets::root_or_skip("jittered_pyshoe_traces") else {
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
        let stamps: Vec<f64> = t.samples.iter().map(|s| s.t_s).collect();
        let clock = SampleClock::recover(&stamps, Some(t.rate_hz)).unwrap();
        assert_eq!(clock.holes, vec![], "{}", p.display());
        let mut on_grid = t.clone();
        for (i, s) in on_grid.samples.iter_mut().enumerate() {
            s.t_s = clock.t_s(i as u32);
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

//! Lu's peak-valley detector: each rule on a hand-made signal, the low-pass against `f64`,
//! the streaming core against the batch `f64` reference on real recordings, bounded
//! latency, gaps, and no panic on any input.
//!
//! The rule tests feed the filtered signal directly ([`PeakValleyDetector::process_filtered`])
//! as straight lines between knots, so that every extreme is a knot with an exact value.

use gaitclip::detect::peak_valley::{max_latency_ms, PeakValleyDetector, Step};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::signal::low_pass::{alpha_q16, LowPass, LOW_PASS_LSB_PER_G};
use gaitclip_host::reference::peak_valley_ref;
use gaitclip_host::{io::csv_trace, io::datasets};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const HZ: u32 = 100;

fn rate() -> SampleRate {
    SampleRate::from_hz(HZ).unwrap()
}

/// g to the low-pass unit.
fn g(v: f64) -> i32 {
    (v * LOW_PASS_LSB_PER_G as f64).round() as i32
}

/// A signal through straight lines between `(sample, g)` knots, from 0 g at sample 0.
fn signal(knots: &[(u32, f64)]) -> Vec<i32> {
    let mut out = Vec::new();
    let (mut t0, mut v0) = (0u32, 0.0);
    for &(t, v) in knots {
        for k in t0..t {
            let f = (k - t0) as f64 / (t - t0) as f64;
            out.push(g(v0 + f * (v - v0)));
        }
        (t0, v0) = (t, v);
    }
    out.push(g(v0));
    out
}

/// Runs the detector over `y` (then `flat` samples of 0 g), finishes, and returns the
/// steps with the sample each was reported at (`None` for those `finish` gave).
fn run(y: &[i32], flat: u32) -> Vec<(Step, Option<u32>)> {
    let mut d = PeakValleyDetector::new(rate());
    let mut out = Vec::new();
    let n = y.len() as u32;
    for i in 0..n + flat {
        let v = y.get(i as usize).copied().unwrap_or(0);
        if let Some(s) = d.process_filtered(i, v) {
            out.push((s, Some(i)));
        }
    }
    while let Some(s) = d.finish() {
        out.push((s, None));
    }
    assert_eq!(d.dropped(), 0);
    out
}

/// Sample numbers of the steps' peaks, with the filter's delay put back.
fn peaks(steps: &[(Step, Option<u32>)]) -> Vec<u32> {
    let delay = PeakValleyDetector::new(rate()).filter_delay();
    steps.iter().map(|(s, _)| s.peak.index + delay).collect()
}

/// A walk of `n` strides, one per second: a peak of `peak` g at +10 samples and a valley
/// of `valley` g at +40, back to 0 g between strides; starting at `t0`.
fn walk(t0: u32, n: u32, peak: f64, valley: f64) -> Vec<(u32, f64)> {
    let mut k = Vec::new();
    for i in 0..n {
        let t = t0 + 100 * i;
        k.extend([(t, 0.0), (t + 10, peak), (t + 40, valley), (t + 60, 0.0)]);
    }
    k
}

#[test]
fn a_clean_walk_gives_one_step_per_pair() {
    let s = run(&signal(&walk(50, 12, 0.5, -0.5)), 0);
    assert_eq!(peaks(&s), (0..12).map(|i| 60 + 100 * i).collect::<Vec<_>>());
    let periods: Vec<u32> = s.iter().map(|(s, _)| s.period).collect();
    assert_eq!(periods[0], 0, "a walk's first step has no period");
    assert!(periods[1..].iter().all(|&p| p == 100), "{periods:?}");
    assert!(s.iter().all(|(s, _)| s.difference() == g(0.5) - g(-0.5)));
}

#[test]
fn static_extremes_are_not_steps() {
    // Standing: ±0.005 g wobbles (a running mean of three under 0.01 g), then the walk.
    let mut k: Vec<(u32, f64)> = (0..40)
        .map(|i| (10 + 10 * i, if i % 2 == 0 { 0.005 } else { -0.005 }))
        .collect();
    k.extend(walk(500, 12, 0.5, -0.5));
    assert_eq!(run(&signal(&k), 0).len(), 12);
    // The same wobbles at 0.03 g are not static (and pass the thresholds while no walk is
    // near to set the dynamic mean): they are steps.
    let k: Vec<(u32, f64)> = (0..40)
        .map(|i| (10 + 10 * i, if i % 2 == 0 { 0.03 } else { -0.03 }))
        .collect();
    assert!(!run(&signal(&k), 0).is_empty());
}

#[test]
fn the_dynamic_threshold_drops_a_small_peak_and_th1_a_faint_walk() {
    let mut k = walk(50, 12, 0.5, -0.5);
    // Stride 6's peak is 0.1 g: under 0.4 × the mean of its ten.
    k[4 * 6 + 1].1 = 0.1;
    let s = run(&signal(&k), 0);
    assert_eq!(s.len(), 11);
    assert!(!peaks(&s).contains(&660));
    // A walk of 0.015 g peaks is above the static limit but under Th1 = 0.02 g.
    assert!(run(&signal(&walk(50, 12, 0.015, -0.5)), 0).is_empty());
}

#[test]
fn of_a_too_close_pair_the_one_nearer_zero_goes() {
    let mut k = walk(50, 12, 0.5, -0.5);
    // Stride 5 gets a second bump 20 samples (< 32 = 320 ms) after its peak, with its own
    // shallow valley: peak 0.5 at 560, valley −0.3 at 570, peak 0.45 at 580, valley −0.5
    // at 590. Without the minimum interval that would be two steps.
    let i = 4 * 5;
    k.splice(
        i + 1..i + 3,
        [(560, 0.5), (570, -0.3), (580, 0.45), (590, -0.5)],
    );
    let s = run(&signal(&k), 0);
    assert_eq!(s.len(), 12);
    let delay = PeakValleyDetector::new(rate()).filter_delay();
    let fifth = s
        .iter()
        .find(|(s, _)| s.peak.index + delay == 560)
        .expect("the 0.5 g peak");
    assert_eq!(fifth.0.valley.index + delay, 590, "the −0.5 g valley stays");
}

#[test]
fn a_neighbouring_outlier_peak_or_valley_is_removed() {
    // Stride 6's peak is 0.45 g between 1 g peaks: above 0.4 × its mean (the dynamic
    // threshold keeps it), but smaller than both differences (0.55 g > 0.1 g).
    let mut k = walk(50, 12, 1.0, -1.0);
    k[4 * 6 + 1].1 = 0.45;
    let s = run(&signal(&k), 0);
    assert_eq!(s.len(), 11, "peak outlier");
    assert!(!peaks(&s).contains(&660));
    // A −0.45 g valley between −1 g valleys (differences −0.55 g < −0.15 g).
    let mut k = walk(50, 12, 1.0, -1.0);
    k[4 * 6 + 2].1 = -0.45;
    assert_eq!(run(&signal(&k), 0).len(), 11, "valley outlier");
}

#[test]
fn unpaired_ends_are_dropped() {
    // The walk opens with a valley and closes with a peak: 11 peaks, 13 valleys in all, and
    // the pairs are the 11 peaks with the valleys after them.
    let mut k = vec![(20, -0.5), (40, 0.0)];
    k.extend(walk(50, 11, 0.5, -0.5));
    k.extend([(1160, 0.5), (1190, 0.0)]);
    let s = run(&signal(&k), 0);
    assert_eq!(s.len(), 11);
    assert_eq!(peaks(&s)[0], 60);
    assert!(s.iter().all(|(s, _)| s.peak.index < s.valley.index));
}

#[test]
fn walks_are_apart_and_a_step_comes_within_the_latency_bound() {
    // Two walks 5 s apart: each starts with a period-less step; no step pairs across.
    let mut k = walk(50, 6, 0.5, -0.5);
    k.extend(walk(1150, 6, 0.5, -0.5));
    let y = signal(&k);
    // Then 30 s of 0 g: every step must come out of `process`, by the bound.
    let s = run(&y, 3000);
    assert_eq!(s.len(), 12);
    let first: Vec<u32> = s.iter().map(|(s, _)| s.period).collect();
    assert_eq!(first.iter().filter(|&&p| p == 0).count(), 2, "{first:?}");
    let bound = rate().samples_in_ms(max_latency_ms());
    let delay = PeakValleyDetector::new(rate()).filter_delay();
    for (step, at) in &s {
        let at = at.expect("reported while sampling, not at finish");
        let valley = step.valley.index + delay;
        assert!(
            at - valley <= bound,
            "reported {} samples after its valley",
            at - valley
        );
    }
}

#[test]
fn a_gap_ends_the_walk_and_nothing_pairs_across_it() {
    let y = signal(&walk(50, 12, 0.5, -0.5));
    let mut d = PeakValleyDetector::new(rate());
    let mut steps = Vec::new();
    // Samples 0..=570 (up to stride 5's peak at 560, before its valley at 590), then a gap
    // of 29 samples, then the rest from 600 (after the valley).
    for i in 0..=570u32 {
        steps.extend(d.process_filtered(i, y[i as usize]));
    }
    d.gap();
    for i in 600..y.len() as u32 + 2000 {
        steps.extend(d.process_filtered(i, y.get(i as usize).copied().unwrap_or(0)));
    }
    while let Some(s) = d.finish() {
        steps.push(s);
    }
    let delay = d.filter_delay();
    let p: Vec<u32> = steps.iter().map(|s| s.peak.index + delay).collect();
    // Strides 0–4 before; stride 5's peak lost its valley; 6–11 after, a new walk.
    assert_eq!(p, [60, 160, 260, 360, 460, 660, 760, 860, 960, 1060, 1160]);
    assert_eq!(d.dropped(), 0);
    assert_eq!(steps.iter().filter(|s| s.period == 0).count(), 2);
    let idx: Vec<u32> = steps.iter().map(|s| s.index).collect();
    assert_eq!(idx, (0..11).collect::<Vec<_>>());
}

#[test]
fn low_pass_within_one_unit_of_f64_and_minus_3_db_at_3_hz() {
    let mut r = ChaCha8Rng::seed_from_u64(8);
    let mut worst = 0f64;
    for hz in [25, 50, 100, 200, 204, 500, 1000] {
        let rate = SampleRate::from_hz(hz).unwrap();
        let a = alpha_q16(rate) as f64 / 65_536.0;
        // Random walk over the whole i16 range, with jumps.
        let x: Vec<i16> = (0..20_000)
            .scan(0i32, |v, k| {
                *v = if k % 997 == 0 {
                    r.random_range(-32_767..=32_767)
                } else {
                    (*v + r.random_range(-2000..=2000)).clamp(-32_767, 32_767)
                };
                Some(*v as i16)
            })
            .collect();
        let mut f = LowPass::new(rate);
        let (mut y1, mut y2) = (x[0] as f64, x[0] as f64);
        for &v in &x {
            y1 += a * (v as f64 - y1);
            y2 += a * (y1 - y2);
            let out = f.process(v) as f64;
            worst = worst.max((out - y2 * 16.0).abs());
        }
        // Gain of the design at 3 Hz: two sections α / (1 − (1 − α)·e^{−jω}).
        let w = 2.0 * std::f64::consts::PI * 3.0 / hz as f64;
        let (re, im) = (1.0 - (1.0 - a) * w.cos(), (1.0 - a) * w.sin());
        let gain = a * a / (re * re + im * im);
        eprintln!("{hz} Hz: α = {a:.4}, gain at 3 Hz {gain:.4}");
        assert!((0.7068..=0.7074).contains(&gain), "{hz} Hz: gain {gain}");
    }
    eprintln!("low-pass: worst error {worst:.3} units of g/32768");
    assert!(worst <= 1.0, "worst {worst}");
}

/// A trial's vertical acceleration in g/2048 (i16) and g: specific force along the mean
/// specific force of the whole trial (gravity), minus 1 g.
fn vertical(path: &std::path::Path, rate_hz: f64) -> (Vec<i16>, Vec<f64>) {
    let t = csv_trace::read(path, Some(rate_hz)).unwrap();
    let n = t.samples.len() as f64;
    let mut up = [0.0; 3];
    for s in &t.samples {
        for (u, a) in up.iter_mut().zip(s.acc_mps2) {
            *u += a / n;
        }
    }
    let norm = up.iter().map(|v| v * v).sum::<f64>().sqrt();
    let counts: Vec<i16> = t
        .samples
        .iter()
        .map(|s| {
            let a: f64 = (0..3).map(|k| s.acc_mps2[k] * up[k] / norm).sum();
            ((a / 9.806_65 - 1.0) * 2048.0)
                .round()
                .clamp(-32_767.0, 32_767.0) as i16
        })
        .collect();
    let g = counts.iter().map(|&c| c as f64 / 2048.0).collect();
    (counts, g)
}

#[test]
fn core_agrees_with_the_batch_f64_reference_on_recordings() {
    let Some(root) =
        datasets::root_or_skip("core_agrees_with_the_batch_f64_reference_on_recordings")
    else {
        return;
    };
    let trials = [
        ("gaitmap_walk", "left", 204.8),
        ("gaitmap_walk", "right", 204.8),
        ("pyshoe_vicon", "2017-11-22-11-22-03", 200.0),
        ("pyshoe_vicon", "2017-11-22-11-25-20", 200.0),
        ("ipol_gait_events", "1-1_left", 100.0),
        ("ipol_gait_events", "10-3_right", 100.0),
    ];
    let (mut all, mut same) = (0, 0);
    for (set, trial, hz) in trials {
        let (counts, g) = vertical(&root.join(set).join(format!("{trial}.csv")), hz);
        let rate = SampleRate::from_millihertz((hz * 1000.0) as u32).unwrap();
        let mut d = PeakValleyDetector::new(rate);
        let mut core = Vec::new();
        for (i, &c) in counts.iter().enumerate() {
            core.extend(d.process(i as u32, c));
        }
        while let Some(s) = d.finish() {
            core.push(s);
        }
        assert_eq!(d.dropped(), 0, "{set}/{trial}");
        let refr = peak_valley_ref::steps(rate, &g);
        eprintln!(
            "{set}/{trial}: core {} steps, reference {}",
            core.len(),
            refr.len()
        );
        assert_eq!(core.len(), refr.len(), "{set}/{trial}: step counts differ");
        for (c, r) in core.iter().zip(&refr) {
            all += 1;
            let dp = c.peak.index.abs_diff(r.peak.index);
            let dv = c.valley.index.abs_diff(r.valley.index);
            let dd = (c.difference() as f64 / LOW_PASS_LSB_PER_G as f64
                - (r.peak.value - r.valley.value))
                .abs();
            if dp == 0 && dv == 0 && dd < 1e-3 && c.period == r.period {
                same += 1;
            } else {
                eprintln!("  differ: core {c:?}\n          ref  {r:?}");
            }
            assert!(
                dp <= 1 && dv <= 1,
                "{set}/{trial}: extremes more than a sample apart"
            );
        }
    }
    // Measured: 125 of 125.
    eprintln!("{same} of {all} steps identical (sample numbers, D within 1 mg, period)");
    assert_eq!(same, all);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any signal, any gaps: no panic, steps in order, each a positive peak before a
    /// negative valley.
    #[test]
    fn any_signal_gives_ordered_well_formed_steps(
        xs in proptest::collection::vec(any::<i16>(), 0..3000),
        gaps in proptest::collection::vec(0usize..3000, 0..4),
        smooth in 0u32..4,
    ) {
        let mut d = PeakValleyDetector::new(rate());
        let mut steps = Vec::new();
        let mut v = 0i32;
        let mut index = 0u32;
        for (i, &x) in xs.iter().enumerate() {
            if gaps.contains(&i) {
                d.gap();
                index += 17;
            }
            // Random walks of various smoothness, down to raw noise.
            v = if smooth == 0 { x as i32 } else { (v + (x as i32 >> (4 * smooth))).clamp(-32_767, 32_767) };
            steps.extend(d.process(index, v as i16));
            index += 1;
        }
        while let Some(s) = d.finish() {
            steps.push(s);
        }
        for w in steps.windows(2) {
            prop_assert!(w[0].valley.index < w[1].peak.index, "{:?} then {:?}", w[0], w[1]);
            prop_assert_eq!(w[0].index + 1, w[1].index);
        }
        for s in &steps {
            prop_assert!(s.peak.index < s.valley.index);
            prop_assert!(s.peak.value > 0 && s.valley.value < 0);
        }
    }
}

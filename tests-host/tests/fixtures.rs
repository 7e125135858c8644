//! The committed fixtures are what the simulator makes today, and the core finds their
//! strides, events and lengths.

use std::path::PathBuf;

use gaitclip::sensor::rate::SampleRate;
use gaitclip_host::io::csv_trace;
use gaitclip_host::io::trace::Ranges;
use gaitclip_host::replay::{replay, replay_counts};
use gaitclip_host::sim::fixtures::{self, FIRMWARE_TRACE};
use gaitclip_host::sim::gait_sim;

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures")
}

#[test]
fn committed_fixtures_are_not_stale() {
    let tmp = std::env::temp_dir().join(format!("gaitclip-fixtures-{}", std::process::id()));
    fixtures::write_all(&tmp).unwrap();
    for name in fixtures::file_names() {
        let fresh = std::fs::read(tmp.join(&name)).unwrap();
        let committed = std::fs::read(dir().join(&name)).unwrap_or_else(|e| {
            panic!("fixtures/{name}: {e}; regenerate with `cargo run --release -- simulate`")
        });
        assert!(
            fresh == committed,
            "fixtures/{name} is stale: regenerate with `cd tests-host && cargo run --release -- simulate`"
        );
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

#[test]
fn csv_and_register_dump_hold_the_same_counts() {
    let trace = csv_trace::read(&dir().join(format!("{FIRMWARE_TRACE}.csv")), None).unwrap();
    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    assert_eq!(trace.samples.len(), counts.len());
    let r = Ranges::default();
    for (s, c) in trace.samples.iter().zip(&counts) {
        assert_eq!(r.to_counts(s), *c);
    }
    // And the replay of either gives the same strides, at the same times (the recovered
    // clock's, which is the stamps' grid to rounding).
    let a = replay(&trace, r).unwrap();
    let b = replay_counts(&counts, SampleRate::from_hz(200).unwrap(), r, |i| {
        trace.samples[i as usize].t_s
    });
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.raw, y.raw);
        assert!((x.start_s - y.start_s).abs() < 1e-9 && (x.end_s - y.end_s).abs() < 1e-9);
    }
}

/// Every stride of every scenario is found, in order, with no extra strides: heel-off and
/// foot-flat within 60 ms of the simulator's, toe-off and heel-strike in order between
/// them, and the length within 3 % + 2 cm. Flagged strides (first, last, turns; turning on the spot is a
/// slow shuffle whose ends barely move) get three times the timing tolerance and 8 cm on length
/// (the first step's slow heel rise is in stance for the first 55 ms: 0.749 m of 0.8 m).
/// The simulator's turns on the spot (0.1 m, the foot pivoting about the vertical without
/// pitching or rolling) are not steps on the ground by the step check's measure, and are
/// refused as `no_swing`, counted (`gaitclip::detect::step_check`).
#[test]
fn replay_finds_simulated_strides() {
    use gaitclip::detect::step_check::STEP_MIN_MM;
    for sc in gait_sim::scenarios() {
        let trace = csv_trace::read(&dir().join(format!("{}.csv", sc.name)), None).unwrap();
        let all = gait_sim::simulate(&sc, Ranges::default()).truth;
        let on_the_spot = |w: &&gait_sim::TruthStride| {
            w.flag == "turn" && w.length_m * 1000.0 < STEP_MIN_MM as f64
        };
        let truth: Vec<_> = all.iter().filter(|w| !on_the_spot(w)).collect();
        let (got, summary) = gaitclip_host::replay::replay_summarised(
            &trace,
            Ranges::default(),
            gaitclip::pipeline::detectors::Detector::Cycle,
            gaitclip::pipeline::config::DEFAULT_MODEL,
            false,
        )
        .unwrap();
        assert_eq!(got.len(), truth.len(), "{}: stride count", sc.name);
        assert_eq!(
            summary.rejected["no_swing"] as usize,
            all.iter().filter(on_the_spot).count(),
            "{}: turns on the spot refused",
            sc.name
        );
        let t = |i: u32| i as f64 / sc.rate_hz;
        for (g, w) in got.iter().zip(&truth) {
            let ctx = format!("{} stride {}", sc.name, w.stride);
            let k = if w.flag.is_empty() { 1.0 } else { 3.0 };
            let len_tol = if w.flag.is_empty() {
                0.03 * w.length_m + 0.02
            } else {
                0.08
            };
            assert!(
                (g.heel_off_s - t(w.heel_off_idx)).abs() <= 0.06 * k,
                "{ctx}: heel-off {} vs {}",
                g.heel_off_s,
                t(w.heel_off_idx)
            );
            assert!(
                (g.foot_flat_s - t(w.end_idx)).abs() <= 0.06 * k,
                "{ctx}: foot-flat {} vs {}",
                g.foot_flat_s,
                t(w.end_idx)
            );
            // Events in order inside the movement; their timing is measured on real
            // recordings (tests/datasets.rs, `gaitclip eval`), not on the simulator, whose
            // push-off and impact are smooth bumps rather than the sharp peak-valley pairs of
            // real feet that Huang's splitter keys on.
            assert!(
                g.heel_off_s < g.toe_off_s
                    && g.toe_off_s < g.heel_strike_s
                    && g.heel_strike_s < g.foot_flat_s,
                "{ctx}: events out of order {g:?}"
            );
            // The simulator's truth is the foot's displacement: what the ZUPT integrator
            // measures. The learnt default model is scored on real recordings instead
            // (tests/trained_model.rs, `gaitclip eval`): simulated feet are not its domain.
            assert!(
                (g.zupt_m - w.length_m).abs() <= len_tol,
                "{ctx}: ZUPT length {} vs {}",
                g.zupt_m,
                w.length_m
            );
            assert!(g.valid, "{ctx}: flagged {:?}", g.flags);
        }
    }
}

/// The pipeline's whole state is a compile-time size: with the boards' movement buffer (5.12 s
/// at 200 Hz) under 17 KiB (16 416 B since the buffer keeps the sagittal rate beside the
/// accelerations, 2 B a sample; the boards that buffer 5.12 s have 64 KiB of RAM or more, the
/// micro:bit buffers 1.28 s).
#[test]
fn pipeline_state_is_bounded() {
    const M: usize = gaitclip::detect::seam::movement_samples(200);
    let bytes = std::mem::size_of::<
        gaitclip::pipeline::Pipeline<gaitclip::pipeline::detectors::AnyDetector<M>>,
    >();
    eprintln!("Pipeline state: {bytes} bytes");
    assert!(bytes < 17 * 1024, "{bytes}");
}

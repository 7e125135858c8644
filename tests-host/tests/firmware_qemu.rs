//! Bit-exact end to end: the firmware on the emulated Cortex-M4 (QEMU mps2-an386) and on the
//! emulated Cortex-M0 (QEMU microbit, `thumbv6m-none-eabi`, no FPU), replaying the demo
//! fixture from flash through the emulated sensor bus and the real driver, logs the same
//! per-stride integers as the host replay of the same fixture.

use gaitclip::pipeline::{Config, Detector};
use gaitclip::rate::SampleRate;
use gaitclip::sample::RawSample;
use gaitclip::stride::{Stride, StrideFlags};
use gaitclip_board::replay_holes;
use gaitclip_host::clock::Gap;
use gaitclip_host::firmware::{self, parse_stride_line, LoggedStride};
use gaitclip_host::qemu::{self, RunOptions};
use gaitclip_host::replay::replay_counts_with;
use gaitclip_host::trace::Ranges;

/// The movement buffer of the micro:bit firmware (`boards/microbit/main.rs`).
const MICROBIT_MOVEMENT_SAMPLES: usize = 256;

fn logged(s: &Stride) -> LoggedStride {
    LoggedStride::of(s)
}

/// The micro:bit firmware with the emulated sensor losing the runs of
/// `boards/common/replay_holes.rs` (a hole of every kind: bridged in swings and in a stance,
/// filled, and one that restarts detection) logs exactly the strides of the host replay of
/// the same samples with the same holes declared.
#[test]
fn qemu_m0_bridges_holes_as_the_host_replay() {
    if !qemu::available_or_skip() {
        return;
    }
    let env = [("CARGO_TARGET_DIR", "target/replay-holes".as_ref())];
    let elf = firmware::build_with(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        &["--features", "replay-holes"],
        &env,
    )
    .expect("firmware builds");
    let out = qemu::run(
        &elf,
        &RunOptions {
            machine: qemu::MACHINE_M0.into(),
            fast: true,
            extra_args: Vec::new(),
        },
        |_| {},
    )
    .expect("qemu runs");
    assert_eq!(out.status, 0, "log:\n{}", out.lines.join("\n"));
    let on_target: Vec<LoggedStride> = out
        .lines
        .iter()
        .filter_map(|l| parse_stride_line(l))
        .collect();

    // The host: the same counts without the lost samples, each run declared as a gap.
    let all = gaitclip_host::fixtures::firmware_trace_counts().unwrap();
    let (mut counts, mut gaps): (Vec<RawSample>, Vec<Gap>) = (Vec::new(), Vec::new());
    let mut lost = replay_holes::LOST.iter().peekable();
    let mut n = 0usize;
    while n < all.len() {
        if let Some(&(_, len)) = lost.next_if(|h| h.0 as usize == n) {
            gaps.push(Gap {
                before: counts.len(),
                missing: len,
            });
            n += len as usize;
            continue;
        }
        counts.push(all[n]);
        n += 1;
    }
    let ranges = Ranges::default();
    let config = Config::new(
        SampleRate::from_hz(200).unwrap(),
        ranges.accel.scale(),
        ranges.gyro.scale(),
    );
    // With the micro:bit's movement buffer (256 samples): the stride the restart breaks
    // runs into the stand after it, longer than that buffer holds (flagged too long there).
    let host_strides = {
        let mut p = gaitclip::pipeline::Pipeline::<
            gaitclip::detector::AnyDetector<MICROBIT_MOVEMENT_SAMPLES>,
        >::sized(config);
        let mut out = Vec::new();
        let mut next_gap = gaps.iter().peekable();
        for (i, s) in counts.iter().enumerate() {
            while let Some(g) = next_gap.next_if(|g| g.before <= i) {
                out.extend(p.gap(g.missing));
            }
            out.extend(p.process(s));
        }
        out.extend(std::iter::from_fn(|| p.finish()));
        out
    };
    let host: Vec<LoggedStride> = host_strides.iter().map(logged).collect();
    assert_eq!(on_target, host);
    // Every kind of hole is there: bridged strides that keep their length, gap strides
    // (the two filled holes, 30 and 60 ms, and the restart).
    let bridged = host_strides
        .iter()
        .filter(|s| s.flags.has(StrideFlags::BRIDGED) && s.flags.valid())
        .count();
    let gap = host_strides
        .iter()
        .filter(|s| s.flags.has(StrideFlags::GAP))
        .count();
    assert!(
        bridged >= 3 && gap == 3,
        "{bridged} bridged, {gap} gap: {host_strides:#?}"
    );
    let summary = out
        .lines
        .iter()
        .find(|l| l.starts_with("summary"))
        .expect("summary line");
    let lost: u32 = replay_holes::LOST.iter().map(|h| h.1).sum();
    assert!(
        summary.contains(&format!("lost_samples={lost}")),
        "{summary}"
    );
    assert!(
        summary.contains(&format!("samples={}", counts.len())),
        "{summary}"
    );
    for kind in ["bridged", "filled", "detection restarts"] {
        assert!(
            out.lines
                .iter()
                .any(|l| l.starts_with("hole of") && l.contains(kind)),
            "no `{kind}` hole in the log"
        );
    }
}

#[test]
fn qemu_m4_strides_equal_host_replay() {
    strides_equal_host_replay(
        "boards/mps2-an386",
        "mps2-an386",
        "thumbv7em-none-eabihf",
        qemu::MACHINE_M4,
        Detector::Cycle,
    );
}

#[test]
fn qemu_m0_strides_equal_host_replay() {
    strides_equal_host_replay(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        qemu::MACHINE_M0,
        Detector::Cycle,
    );
}

/// The firmware built with the `peak-valley-detector` setting, on the smallest board.
#[test]
fn qemu_m0_peak_valley_steps_equal_host_replay() {
    strides_equal_host_replay(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        qemu::MACHINE_M0,
        Detector::PeakValley,
    );
}

fn strides_equal_host_replay(
    dir: &str,
    bin: &str,
    target: &str,
    machine: &str,
    detector: Detector,
) {
    if !qemu::available_or_skip() {
        return;
    }
    let elf = firmware::build_for(dir, bin, target, detector, &[]).expect("firmware builds");
    let out = qemu::run(
        &elf,
        &RunOptions {
            machine: machine.into(),
            fast: true,
            extra_args: Vec::new(),
        },
        |_| {},
    )
    .expect("qemu runs");
    assert_eq!(
        out.status,
        0,
        "firmware exit status; log:\n{}",
        out.lines.join("\n")
    );
    let on_target: Vec<LoggedStride> = out
        .lines
        .iter()
        .filter_map(|l| parse_stride_line(l))
        .collect();

    let counts = gaitclip_host::fixtures::firmware_trace_counts().unwrap();
    let ranges = Ranges::default();
    let mut config = Config::new(
        SampleRate::from_hz(200).unwrap(),
        ranges.accel.scale(),
        ranges.gyro.scale(),
    );
    config.detector = detector;
    let host: Vec<LoggedStride> = replay_counts_with(&counts, config, |i| i as f64)
        .iter()
        .map(|s| LoggedStride::of(&s.raw))
        .collect();
    assert!(host.len() >= 20, "host found {} strides", host.len());
    assert_eq!(on_target, host);

    let summary = out
        .lines
        .iter()
        .find(|l| l.starts_with("summary"))
        .expect("summary line");
    assert!(
        summary.contains(&format!("strides={}", host.len())),
        "{summary}"
    );
    assert!(
        summary.contains(&format!("samples={}", counts.len())),
        "{summary}"
    );
    assert!(summary.contains("overruns=0"), "{summary}");
    assert!(summary.contains("bus_errors=0"), "{summary}");
    assert!(summary.contains("lost_samples=0"), "{summary}");
    assert!(
        out.lines
            .iter()
            .any(|l| l.starts_with("still: gyro_bias_mdps=")),
        "no start-up calibration report"
    );
}

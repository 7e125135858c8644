//! Bit-exact end to end: the firmware on the emulated Cortex-M4 (QEMU mps2-an386) and on the
//! emulated Cortex-M0 (QEMU microbit, `thumbv6m-none-eabi`, no FPU), replaying the demo
//! fixture from flash through the emulated sensor bus and the real driver, logs the same
//! per-stride integers as the host replay of the same fixture.

use gaitclip::pipeline::{Config, Detector};
use gaitclip::rate::SampleRate;
use gaitclip_host::firmware::{self, parse_stride_line, LoggedStride};
use gaitclip_host::qemu::{self, RunOptions};
use gaitclip_host::replay::replay_counts_with;
use gaitclip_host::trace::Ranges;

#[test]
fn qemu_m4_strides_equal_host_replay() {
    strides_equal_host_replay(
        ".",
        "mps2-an386",
        "thumbv7em-none-eabihf",
        qemu::MACHINE_M4,
        Detector::Stance,
    );
}

#[test]
fn qemu_m0_strides_equal_host_replay() {
    strides_equal_host_replay(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        qemu::MACHINE_M0,
        Detector::Stance,
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
    let mut config = Config::new(SampleRate::from_hz(200).unwrap(), ranges.accel, ranges.gyro);
    config.detector = detector;
    let host: Vec<LoggedStride> = replay_counts_with(&counts, config, |i| i as f64)
        .iter()
        .map(|s| LoggedStride {
            index: s.raw.index,
            idx: [
                s.raw.start,
                s.raw.heel_off,
                s.raw.toe_off,
                s.raw.heel_strike,
                s.raw.end,
            ],
            length_mm: s.raw.length_mm,
            climb_mm: s.raw.climb_mm,
            flags: s.raw.flags.0,
        })
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

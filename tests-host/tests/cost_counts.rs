//! The instruction counts of `gaitclip cost` are sound and repeatable: the benchmark firmware
//! (demo walk from flash) under the `qemu-insn-count` plugin finds the host replay's strides,
//! every measured call returns, and a second run counts exactly the same; with the stance
//! detector and with Lu's peak-valley detector.

use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip_host::cost::firmware::{self, repo_root};
use gaitclip_host::cost::insn_count;
use gaitclip_host::cost::qemu;
use gaitclip_host::cost::report::size_of_elf;
use gaitclip_host::replay::core_strides;

fn plugin() -> std::path::PathBuf {
    let dir = repo_root().join("tests-host");
    let status = std::process::Command::new(std::env::var("CARGO").unwrap_or("cargo".into()))
        .current_dir(&dir)
        .args([
            "build",
            "--release",
            "--quiet",
            "-p",
            "qemu-insn-count",
            "--message-format=json",
        ])
        .output()
        .expect("cargo runs");
    assert!(status.status.success(), "the plugin builds");
    // The cdylib's path, from cargo's own report of what it built.
    String::from_utf8_lossy(&status.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|v| v["target"]["name"] == "qemu_insn_count")
        .flat_map(|v| v["filenames"].as_array().cloned().unwrap_or_default())
        .filter_map(|f| f.as_str().map(std::path::PathBuf::from))
        .find(|p| p.extension().is_some_and(|e| e == "so"))
        .expect("cargo reports the plugin's .so")
}

#[test]
fn bench_counts_are_complete_and_repeatable_on_m4() {
    if !qemu::available_or_skip() {
        return;
    }
    let elf = firmware::build_in("boards/bench", "bench", "thumbv7em-none-eabihf")
        .expect("the benchmark firmware builds");
    let plugin = plugin();
    let scratch = tempdir("m4");
    let a = insn_count::run_bench(&elf, qemu::MACHINE_M4, &plugin, &scratch).expect("counted run");
    let b = insn_count::run_bench(&elf, qemu::MACHINE_M4, &plugin, &scratch).expect("counted run");

    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().expect("demo trace");
    let host = core_strides(&counts, demo_config());
    assert_eq!(a.samples as usize, counts.len());
    assert_eq!(a.strides as usize, host.len());
    assert_eq!(
        a.distance_mm,
        host.iter().map(|s| u64::from(s.length_mm)).sum::<u64>()
    );
    // Same ELF, same input: same counts, to the instruction.
    assert_eq!(a.sample, b.sample);
    assert_eq!(a.stride, b.stride);
    assert_eq!(a.models.len(), b.models.len());
    for ((na, sa), (nb, sb)) in a.models.iter().zip(&b.models) {
        assert_eq!((na, sa), (nb, sb));
    }
    // The per-stride steps nest: split and statistics inside close.
    assert!(a.split.mean + a.stats.mean < a.close.mean);
    assert!(a.sample.mean > 0.0 && a.sample.max as f64 >= a.sample.mean);
    assert!(size_of_elf(&std::fs::read(&elf).unwrap()).unwrap().flash > 0);
}

#[test]
fn peak_valley_bench_counts_are_complete_and_repeatable_on_m4() {
    if !qemu::available_or_skip() {
        return;
    }
    let elf = firmware::build_for(
        "boards/bench",
        "bench",
        "thumbv7em-none-eabihf",
        Detector::PeakValley,
        &[],
    )
    .expect("the benchmark firmware builds with the peak-valley detector");
    let plugin = plugin();
    let scratch = tempdir("m4-peak-valley");
    let a = insn_count::run_bench_peak_valley(&elf, qemu::MACHINE_M4, &plugin, &scratch)
        .expect("counted run");
    let b = insn_count::run_bench_peak_valley(&elf, qemu::MACHINE_M4, &plugin, &scratch)
        .expect("counted run");

    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().expect("demo trace");
    let mut config = demo_config();
    config.detector = Detector::PeakValley;
    let host = core_strides(&counts, config);
    assert!(
        !host.is_empty(),
        "Lu's detector finds steps in the demo walk"
    );
    assert_eq!(a.samples as usize, counts.len());
    assert_eq!(a.steps as usize, host.len());
    assert_eq!(
        a.distance_mm,
        host.iter().map(|s| u64::from(s.length_mm)).sum::<u64>()
    );
    assert_eq!((a.sample, a.step), (b.sample, b.step));
    assert_eq!(a.step.n, host.len());
    // The chain runs once per step, outside the sample path's own count.
    assert!(a.sample_all_mean > a.sample.mean);
    assert!(a.step.mean > 0.0 && a.step.max as f64 >= a.step.mean);
}

/// The M0 build (the micro:bit's memory: ≈ 8 KiB of stack beside the pipeline) runs to the
/// end with either detector; a stack overflow there locks QEMU up instead.
#[test]
fn bench_runs_to_the_end_on_m0_with_each_detector() {
    if !qemu::available_or_skip() {
        return;
    }
    let plugin = plugin();
    let scratch = tempdir("m0");
    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().expect("demo trace");
    for detector in [Detector::Cycle, Detector::PeakValley] {
        let elf = firmware::build_for("boards/bench", "bench", "thumbv6m-none-eabi", detector, &[])
            .expect("the benchmark firmware builds for the M0");
        match detector {
            Detector::PeakValley => {
                let r =
                    insn_count::run_bench_peak_valley(&elf, qemu::MACHINE_M0, &plugin, &scratch)
                        .expect("counted run on the M0");
                let mut config = demo_config();
                config.detector = Detector::PeakValley;
                let host = core_strides(&counts, config);
                assert_eq!(r.samples as usize, counts.len());
                assert_eq!(r.steps as usize, host.len());
                assert_eq!(
                    r.distance_mm,
                    host.iter().map(|s| u64::from(s.length_mm)).sum::<u64>()
                );
            }
            _ => {
                let r = insn_count::run_bench(&elf, qemu::MACHINE_M0, &plugin, &scratch)
                    .expect("counted run on the M0");
                assert_eq!(r.samples as usize, counts.len());
                assert!(r.strides > 0 && r.stride.n == r.strides as usize);
            }
        }
    }
}

fn demo_config() -> Config {
    Config::new(
        gaitclip::sensor::rate::SampleRate::from_millihertz(200_000).expect("200 Hz"),
        gaitclip_mpu6050::AccelRange::G16.scale(),
        gaitclip_mpu6050::GyroRange::Dps2000.scale(),
    )
}

/// A scratch folder of this test process and test: the plugin's output file is named by
/// the machine, and the tests run in parallel.
fn tempdir(test: &str) -> std::path::PathBuf {
    let d = repo_root()
        .join("tests-host/target/cost-test")
        .join(format!("{}-{test}", std::process::id()));
    std::fs::create_dir_all(&d).expect("scratch folder");
    d
}

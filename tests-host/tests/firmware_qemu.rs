//! Bit-exact end to end: the firmware on the emulated Cortex-M4 (QEMU mps2-an386) and on the
//! emulated Cortex-M0 (QEMU microbit, `thumbv6m-none-eabi`, no FPU), replaying the demo
//! fixture from flash through the emulated sensor bus and the real driver, logs the same
//! per-stride integers as the host replay of the same fixture.

use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip_board::sleep::{SleepPolicy, SLEEP};
use gaitclip_board::{replay_holes, replay_mpu6050, replay_still};
use gaitclip_host::cost::firmware::{self, parse_stride_line, LoggedStride};
use gaitclip_host::cost::qemu::{self, RunOptions};
use gaitclip_host::io::clock::Gap;
use gaitclip_host::io::trace::Ranges;
use gaitclip_host::replay::replay_counts_with;

/// The movement buffer of the micro:bit firmware (`boards/microbit/main.rs`).
const MICROBIT_MOVEMENT_SAMPLES: usize = 224;

/// Runs a replay firmware in QEMU (virtual time) to its exit, which must be status 0; its
/// log and the strides it logged.
fn run_to_exit(elf: &std::path::Path, machine: &str) -> (qemu::RunOutput, Vec<LoggedStride>) {
    let out = qemu::run(
        elf,
        &RunOptions {
            machine: machine.into(),
            fast: true,
            extra_args: Vec::new(),
        },
        |_| {},
    )
    .expect("qemu runs");
    assert_eq!(out.status, 0, "log:\n{}", out.lines.join("\n"));
    let strides = out
        .lines
        .iter()
        .filter_map(|l| parse_stride_line(l))
        .collect();
    (out, strides)
}

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
    let (out, on_target) = run_to_exit(&elf, qemu::MACHINE_M0);

    // The host: the same counts without the lost samples, each run declared as a gap.
    let all = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
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
    // With the micro:bit's movement buffer (224 samples): the stride the restart breaks
    // runs into the stand after it, longer than that buffer holds (flagged too long there).
    let host_strides = {
        let mut p = gaitclip::pipeline::Pipeline::<
            gaitclip::pipeline::detectors::AnyDetector<MICROBIT_MOVEMENT_SAMPLES>,
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
    strides_equal_host_replay::<{ gaitclip::detect::seam::MAX_MOVEMENT_SAMPLES }>(
        "boards/mps2-an386",
        "mps2-an386",
        "thumbv7em-none-eabihf",
        qemu::MACHINE_M4,
        Detector::Cycle,
    );
}

#[test]
fn qemu_m0_strides_equal_host_replay() {
    strides_equal_host_replay::<MICROBIT_MOVEMENT_SAMPLES>(
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
    strides_equal_host_replay::<MICROBIT_MOVEMENT_SAMPLES>(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        qemu::MACHINE_M0,
        Detector::PeakValley,
    );
}

/// The second part end to end: the M4 firmware built with `replay-lsm6dsv320x` replays the
/// stored sprint as the LSM6DSV320X's FIFO delivers it (`fixtures/sprint_40g.lsm6dsv320x`:
/// the emulated part's FIFO filled period by period, read at its watermark by the real driver,
/// the two accelerometers merged on the board) and logs the same per-stride integers as the
/// host: the same words through the same merge and the pipeline at the part's scales.
#[test]
fn qemu_m4_lsm6dsv320x_sprint_equals_host_replay() {
    use gaitclip_host::sim::sprint::{LSM_ACCEL, LSM_GYRO, LSM_HIGH_G, LSM_RATE_HZ};
    use gaitclip_lsm6dsv320x::merge::{Assembler, DualRange};
    if !qemu::available_or_skip() {
        return;
    }
    let env = [("CARGO_TARGET_DIR", "target/replay-lsm6dsv320x".as_ref())];
    let elf = firmware::build_with(
        "boards/mps2-an386",
        "mps2-an386",
        "thumbv7em-none-eabihf",
        &["--features", "replay-lsm6dsv320x"],
        &env,
    )
    .expect("firmware builds");
    let (out, on_target) = run_to_exit(&elf, qemu::MACHINE_M4);

    let words = gaitclip_host::sim::fixtures::firmware_lsm_trace_words().unwrap();
    let dual = DualRange::new(LSM_ACCEL, LSM_HIGH_G);
    let mut assembler = Assembler::new(dual);
    let mut counts: Vec<RawSample> = words.iter().filter_map(|w| assembler.push(*w)).collect();
    counts.extend(assembler.flush());
    let mut config = Config::new(
        SampleRate::from_hz(LSM_RATE_HZ).unwrap(),
        dual.scale(),
        LSM_GYRO.scale(),
    );
    config.detector = Detector::Cycle;
    const M: usize = gaitclip::detect::seam::movement_samples(LSM_RATE_HZ);
    let mut pipeline =
        gaitclip::pipeline::Pipeline::<gaitclip::pipeline::detectors::AnyDetector<M>>::sized(
            config,
        );
    let mut host: Vec<LoggedStride> = counts
        .iter()
        .filter_map(|s| pipeline.process(s))
        .map(|s| LoggedStride::of(&s))
        .collect();
    host.extend(std::iter::from_fn(|| pipeline.finish()).map(|s| LoggedStride::of(&s)));
    // The sprint's sixteen strides, all found.
    assert_eq!(host.len(), 16, "{host:#?}");
    assert_eq!(on_target, host);

    let line = |prefix: &str| {
        out.lines
            .iter()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line:\n{}", out.lines.join("\n")))
            .clone()
    };
    let summary = line("summary");
    for want in [
        format!("strides={}", host.len()),
        format!("samples={}", counts.len()),
        "overruns=0".into(),
        "bus_errors=0".into(),
        "fifo_overflows=0".into(),
        "lost_samples=0".into(),
        // Nothing at a rail: the merged counts reach ±128 g, the gyroscope ±4 000 °/s.
        "clipped=0,0,0,0,0,0".into(),
    ] {
        assert!(summary.contains(&want), "{want}: {summary}");
    }
    // The board's merge took as many axes from the high-g channel as the host's, every
    // railed axis had high-g samples, every time slot had both words.
    assert!(assembler.high_g_axes() > 0);
    assert_eq!(
        line("merge"),
        format!(
            "merge high_g_axes={} high_g_missing=0 unpaired=0 high_g_dropped=0",
            assembler.high_g_axes()
        )
    );
    // docs/sensors.md's transcript is this run's.
    transcript_printed("docs/sensors.md", "On the emulated board", &out.lines);
}

/// The firmware's strides against the host's replay with the same movement buffer of `M`
/// samples (the micro:bit keeps fewer than the host: a stride whose movement overflows it is
/// split on what it kept, on both).
fn strides_equal_host_replay<const M: usize>(
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
    let (out, on_target) = run_to_exit(&elf, machine);

    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    let ranges = Ranges::default();
    let mut config = Config::new(
        SampleRate::from_hz(200).unwrap(),
        ranges.accel.scale(),
        ranges.gyro.scale(),
    );
    config.detector = detector;
    let mut pipeline =
        gaitclip::pipeline::Pipeline::<gaitclip::pipeline::detectors::AnyDetector<M>>::sized(
            config,
        );
    let mut host: Vec<LoggedStride> = counts
        .iter()
        .filter_map(|s| pipeline.process(s))
        .map(|s| LoggedStride::of(&s))
        .collect();
    host.extend(std::iter::from_fn(|| pipeline.finish()).map(|s| LoggedStride::of(&s)));
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
    if dir == "boards/mps2-an386" && detector == Detector::Cycle {
        // The README's and docs/output.md's transcripts are this run's (`cargo emulate`).
        for doc in ["README.md", "docs/output.md"] {
            transcript_printed(doc, "What the run prints", &out.lines);
        }
    }
}

/// Every line of `doc`'s transcript of a run (the first ```` ```text ```` block after the line
/// holding `marker`; a `…` line stands for lines left out) is a line the run printed, figures
/// and all: the docs show what the firmware prints, stack and sizes included.
fn transcript_printed(doc: &str, marker: &str, log: &[String]) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(doc);
    let text = std::fs::read_to_string(&path).unwrap();
    let block: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.contains(marker))
        .skip_while(|l| *l != "```text")
        .skip(1)
        .take_while(|l| *l != "```")
        .collect();
    assert!(block.len() >= 3, "{doc}: no transcript after {marker:?}");
    for line in block.into_iter().filter(|l| l.trim() != "…") {
        assert!(
            log.iter().any(|l| l.trim_end() == line.trim_end()),
            "{doc}: the transcript's line\n  {line}\nis not what the run printed:\n{}",
            log.join("\n")
        );
    }
}

/// The demo walk with the still runs of `boards/common/src/replay_still.rs`, as the emulated
/// sensor serves it with the `replay-sleep` feature: each listed sample held for its run.
fn still_trace(counts: &[RawSample]) -> Vec<RawSample> {
    let mut out = Vec::new();
    for (i, s) in counts.iter().enumerate() {
        out.push(*s);
        for &(at, extra) in replay_still::STILL {
            if at as usize == i {
                out.extend(std::iter::repeat_n(*s, extra as usize));
            }
        }
    }
    out
}

/// The host model of the sleeping firmware on `trace`: the pipeline and the firmware's
/// sleep policy sample by sample; once a sleep is due (the queue's length past the
/// decision), the sensor's cycle mode wakes on its own clock every wake period and compares
/// with the wake-up before; on motion the gyro's settling samples are dropped and every
/// unsampled period declared as one hole. Returns the strides, the samples processed, the
/// sleeps and the periods slept (those of a sleep that lasted to the end uncounted).
fn sleeping_host_model<const M: usize>(
    trace: &[RawSample],
    config: Config,
) -> (Vec<Stride>, u32, u32, u32) {
    let mut p =
        gaitclip::pipeline::Pipeline::<gaitclip::pipeline::detectors::AnyDetector<M>>::sized(
            config,
        );
    let mut policy = SleepPolicy::new(config.rate, &SLEEP);
    let period = (config.rate.millihertz() / SLEEP.wake.rate.millihertz()) as usize;
    let threshold = replay_mpu6050::mg_to_counts(
        SLEEP.wake.threshold.mg(replay_mpu6050::REPLAY_MOTION_UNIT),
        Ranges::default().accel.afs_sel(),
    );
    let settle = SleepPolicy::settle_samples(config.rate, &SLEEP) as usize;
    let (mut strides, mut processed, mut sleeps, mut slept_total) = (Vec::new(), 0u32, 0, 0);
    let mut sleep_after = None;
    let mut pos = 0usize;
    while pos < trace.len() {
        let st = p.process(&trace[pos]);
        pos += 1;
        processed += 1;
        if policy.after_sample(p.at_rest(), st.is_some()) {
            sleep_after = Some(SleepPolicy::sleep_after(processed, REPLAY_QUEUE_LEN));
        }
        strides.extend(st);
        if sleep_after.is_some_and(|at| processed >= at) {
            sleep_after = None;
            policy.reset();
            sleeps += 1;
            let from = pos;
            let mut t = pos.div_ceil(period) * period;
            let woke = loop {
                if t >= trace.len() {
                    break None;
                }
                if t >= period
                    && replay_mpu6050::motion_between(
                        trace[t - period].accel,
                        trace[t].accel,
                        threshold,
                    )
                {
                    break Some(t + 1);
                }
                t += period;
            };
            // Asleep to the end of the recording.
            let Some(next) = woke else { break };
            let unsampled = (next - from + settle) as u32;
            slept_total += unsampled;
            pos = next + settle;
            strides.extend(p.gap(unsampled));
        }
    }
    strides.extend(std::iter::from_fn(|| p.finish()));
    (strides, processed, sleeps, slept_total)
}

/// The queue between the replay firmware's timer interrupt and its main loop
/// (`replay_app::QUEUE_LEN`).
const REPLAY_QUEUE_LEN: usize = 32;

/// The sleep replay (`replay-sleep`) of board `dir` on `machine` against the host model with
/// the board's movement buffer `M`: the same strides, sleeps, wakes and counts. Returns the
/// host model's strides and configuration (`None`: no QEMU here, skipped).
fn sleeps_and_wakes_as_the_host_model<const M: usize>(
    dir: &str,
    bin: &str,
    target: &str,
    machine: &str,
) -> Option<(Vec<Stride>, Config)> {
    if !qemu::available_or_skip() {
        return None;
    }
    let env = [("CARGO_TARGET_DIR", "target/replay-sleep".as_ref())];
    let elf = firmware::build_with(dir, bin, target, &["--features", "replay-sleep"], &env)
        .expect("firmware builds");
    let (out, on_target) = run_to_exit(&elf, machine);
    if dir == "boards/mps2-an386" {
        // docs/energy.md's transcript is this run's.
        transcript_printed(
            "docs/energy.md",
            "cargo run --release --features replay-sleep",
            &out.lines,
        );
    }

    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    let ranges = Ranges::default();
    let config = Config::new(
        SampleRate::from_hz(200).unwrap(),
        ranges.accel.scale(),
        ranges.gyro.scale(),
    );
    let (host, processed, sleeps, slept) = sleeping_host_model::<M>(&still_trace(&counts), config);
    let host_logged: Vec<LoggedStride> = host.iter().map(LoggedStride::of).collect();
    assert_eq!(on_target, host_logged);

    // It slept twice and woke once, and said so.
    assert_eq!(sleeps, 2);
    let count = |prefix: &str| out.lines.iter().filter(|l| l.starts_with(prefix)).count();
    assert_eq!(count("sleep: still for"), 2, "{}", out.lines.join("\n"));
    assert_eq!(count("wake: motion after"), 1, "{}", out.lines.join("\n"));
    let summary = out
        .lines
        .iter()
        .find(|l| l.starts_with("summary"))
        .expect("summary line");
    for field in [
        format!("samples={processed}"),
        "sleeps=2".to_string(),
        format!("slept_periods={slept}"),
        "lost_samples=0".to_string(),
        "overruns=0".to_string(),
    ] {
        assert!(summary.contains(&field), "{field} not in {summary}");
    }

    Some((host, config))
}

/// The emulated M4 board, its sensor holding still for 12 s in the middle of the demo walk
/// and 13 s at its end: the firmware sleeps after 10 s still, the sensor's cycle mode wakes it
/// on the first step, and it sleeps again to the end, logging exactly the strides of the host
/// model of the same. The step the wake-up cut into is a gap stride; the strides after it
/// come out as they do in the replay that never slept.
#[test]
fn qemu_m4_sleeps_when_still_and_wakes_as_the_host_model() {
    let Some((host, config)) = sleeps_and_wakes_as_the_host_model::<1024>(
        "boards/mps2-an386",
        "mps2-an386",
        "thumbv7em-none-eabihf",
        qemu::MACHINE_M4,
    ) else {
        return;
    };
    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    // The step the wake-up cut into is a gap stride, flagged, not dropped; every stride
    // after it has the length, events and gait of the replay that never slept (its sample
    // indices later by the periods the still runs added), but the first: after a gap it
    // times its own cycle, with no heel-strike before it.
    let awake = replay_counts_with(&counts, config, |i| i as f64);
    let wake_at = host
        .iter()
        .position(|s| s.flags.has(StrideFlags::GAP))
        .expect("a gap stride at the wake-up");
    let held: u32 = replay_still::STILL[0].1;
    let after_wake = &host[wake_at + 1..];
    assert!(after_wake.len() >= 5, "{after_wake:#?}");
    for (k, s) in after_wake.iter().enumerate() {
        let twin = awake
            .iter()
            .map(|a| &a.raw)
            .find(|a| a.events.start + held == s.events.start)
            .unwrap_or_else(|| panic!("no stride of the awake replay matches {s:#?}"));
        assert_eq!(
            (s.length_mm, s.events.end, s.events.heel_strike, s.flags),
            (
                twin.length_mm,
                twin.events.end + held,
                twin.events.heel_strike + held,
                twin.flags
            )
        );
        if k == 0 {
            assert_eq!(
                u32::from(s.gait.stride_time_ms),
                config.rate.ms_of_samples(s.events.end - s.events.start)
            );
        } else {
            assert_eq!(s.gait, twin.gait);
        }
    }
}

/// The same on the emulated M0 (micro:bit, movement buffer of 224), whose stack has the least
/// to spare: the sleep and wake paths run there too, bit-exact with the host model.
#[test]
fn qemu_m0_sleeps_when_still_and_wakes_as_the_host_model() {
    let _ = sleeps_and_wakes_as_the_host_model::<MICROBIT_MOVEMENT_SAMPLES>(
        "boards/microbit",
        "microbit",
        "thumbv6m-none-eabi",
        qemu::MACHINE_M0,
    );
}

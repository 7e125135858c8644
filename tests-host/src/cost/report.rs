//! What gaitclip costs, measured (`gaitclip cost`, run by `tests-host/cost.sh`):
//!
//! * instructions per sample and per stride on the emulated Cortex-M4 (`mps2-an386`) and
//!   Cortex-M0 (`microbit`): the benchmark firmware `boards/bench` replays a real trace from
//!   flash and QEMU runs it with the `qemu-insn-count` plugin, which counts the instructions
//!   of every call of the functions named in [`MEASURED`];
//! * flash, static RAM and the stack's high-water mark of every firmware build;
//! * host replay throughput (the criterion benchmark `benches/replay.rs`) next to gaitmap's
//!   pipeline on the same trace (`tests-host/gaitmap/`);
//! * the energy budget of the real boards ([`crate::cost::energy`]) from the instruction counts.
//!
//! The counting runs are [`crate::cost::insn_count`]; this module builds the firmware, measures
//! sizes and stacks, and writes the report.

use std::fmt::Write as _;

use anyhow::{ensure, Context, Result};
use object::{Object, ObjectSection, SectionFlags};

use gaitclip::pipeline::detectors::Detector;

use crate::cost::firmware::build_for;
use crate::cost::insn_count::{run_bench, run_bench_peak_valley, InsnReport, Stat, StepInsnReport};
use crate::cost::qemu::{self, RunOptions};
use crate::eval::markdown::{Column, Table};

/// Flash and static RAM of a firmware ELF, bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Allocated sections with contents (vector table, boot2, code, read-only data, the
    /// initial values of `.data`).
    pub flash: u64,
    /// Allocated sections in RAM (0x2000_0000..0x4000_0000): `.data`, `.bss`, `.uninit`.
    pub static_ram: u64,
}

/// [`Size`] of `elf`.
pub fn size_of_elf(elf: &[u8]) -> Result<Size> {
    let file = object::File::parse(elf).context("parsing the ELF")?;
    let (mut flash, mut static_ram) = (0, 0);
    for s in file.sections() {
        let SectionFlags::Elf { sh_flags } = s.flags() else {
            continue;
        };
        if sh_flags & u64::from(object::elf::SHF_ALLOC) == 0 {
            continue;
        }
        if s.kind() != object::SectionKind::UninitializedData && s.size() > 0 {
            flash += s.size();
        }
        if (0x2000_0000..0x4000_0000).contains(&s.address()) {
            static_ram += s.size();
        }
    }
    Ok(Size { flash, static_ram })
}

/// The `stack used=N of M bytes` line of a QEMU board's run.
pub fn parse_stack_line(lines: &[String]) -> Option<(u32, u32)> {
    lines.iter().find_map(|l| {
        let rest = l.strip_prefix("stack used=")?;
        let (used, rest) = rest.split_once(" of ")?;
        let size = rest.strip_suffix(" bytes")?;
        Some((used.parse().ok()?, size.parse().ok()?))
    })
}

/// Mean samples per second of criterion's estimate file (`…/new/estimates.json`) for a
/// benchmark of `elements` samples per iteration.
pub fn criterion_samples_per_s(estimates_json: &str, elements: u64) -> Result<f64> {
    let v: serde_json::Value = serde_json::from_str(estimates_json)?;
    let ns = v["mean"]["point_estimate"]
        .as_f64()
        .context("criterion estimates without mean.point_estimate")?;
    ensure!(ns > 0.0, "criterion mean of {ns} ns");
    Ok(elements as f64 / (ns * 1e-9))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_stack_line() {
        let l = vec![
            "summary x".to_string(),
            "stack used=7188 of 52056 bytes".into(),
        ];
        assert_eq!(parse_stack_line(&l), Some((7188, 52056)));
    }
}

/// Where `gaitclip cost` finds what `cost.sh` prepared.
#[derive(Clone, Debug)]
pub struct Inputs {
    /// The built `qemu-insn-count` plugin.
    pub plugin: std::path::PathBuf,
    /// `../shared/datasets`.
    pub datasets: std::path::PathBuf,
    /// criterion's estimates of `benches/replay.rs`.
    pub criterion_estimates: std::path::PathBuf,
    /// The JSON line `gaitmap/bench_gaitmap.py` printed.
    pub gaitmap_json: std::path::PathBuf,
    /// Scratch folder (the trace module, the plugin's output).
    pub scratch: std::path::PathBuf,
}

/// The trace every figure is measured on: a real recording, so that the stride work is
/// that of real walking (26 strides per gaitmap's pipeline, 38.7 s).
pub const TRACE: (&str, &str, f64) = ("gaitmap_walk", "left", 204.8);

/// A firmware build whose size is reported.
#[derive(Clone, Copy, Debug)]
pub struct Build {
    /// Name in the table.
    pub label: &'static str,
    /// Package folder, from the repository root.
    pub dir: &'static str,
    /// Binary.
    pub bin: &'static str,
    /// Target triple.
    pub target: &'static str,
    /// The QEMU machine it runs on, if any (its stack is measured there).
    pub machine: Option<&'static str>,
    /// The step detector it is built with (see [`build_for`]).
    pub detector: Detector,
    /// A feature that builds it with another sensor (into `target/<feature>`, as the test
    /// command builds the boards' variants), or `None` for the MPU6050.
    pub sensor: Option<&'static str>,
}

/// The firmware builds whose size is reported.
pub const BUILDS: [Build; 11] = [
    Build {
        label: "mps2-an386 (QEMU, M4F)",
        dir: "boards/mps2-an386",
        bin: "mps2-an386",
        target: "thumbv7em-none-eabihf",
        machine: Some(qemu::MACHINE_M4),
        detector: Detector::Cycle,
        sensor: None,
    },
    Build {
        label: "mps2-an386 (QEMU, M4F), peak-valley detector",
        dir: "boards/mps2-an386",
        bin: "mps2-an386",
        target: "thumbv7em-none-eabihf",
        machine: Some(qemu::MACHINE_M4),
        detector: Detector::PeakValley,
        sensor: None,
    },
    Build {
        label: "microbit (QEMU, M0)",
        dir: "boards/microbit",
        bin: "microbit",
        target: "thumbv6m-none-eabi",
        machine: Some(qemu::MACHINE_M0),
        detector: Detector::Cycle,
        sensor: None,
    },
    Build {
        label: "microbit (QEMU, M0), peak-valley detector",
        dir: "boards/microbit",
        bin: "microbit",
        target: "thumbv6m-none-eabi",
        machine: Some(qemu::MACHINE_M0),
        detector: Detector::PeakValley,
        sensor: None,
    },
    Build {
        label: "nrf52840-dk (M4F)",
        dir: "boards/nrf52840-dk",
        bin: "nrf52840-dk",
        target: "thumbv7em-none-eabihf",
        machine: None,
        detector: Detector::Cycle,
        sensor: None,
    },
    Build {
        label: "nRF52840-DK + Bluetooth RSC foot pod (trouble-host, SoftDevice Controller)",
        dir: "boards/nrf52840-ble",
        bin: "nrf52840-ble",
        target: "thumbv7em-none-eabihf",
        machine: None,
        detector: Detector::Cycle,
        sensor: None,
    },
    Build {
        label: "rp-pico (M0+)",
        dir: "boards/rp-pico",
        bin: "rp-pico",
        target: "thumbv6m-none-eabi",
        machine: None,
        detector: Detector::Cycle,
        sensor: None,
    },
    Build {
        label: "mps2-an386 (QEMU, M4F), LSM6DSV320X sprint replay",
        dir: "boards/mps2-an386",
        bin: "mps2-an386",
        target: "thumbv7em-none-eabihf",
        machine: Some(qemu::MACHINE_M4),
        detector: Detector::Cycle,
        sensor: Some("replay-lsm6dsv320x"),
    },
    Build {
        label: "nrf52840-dk (M4F), LSM6DSV320X",
        dir: "boards/nrf52840-dk",
        bin: "nrf52840-dk",
        target: "thumbv7em-none-eabihf",
        machine: None,
        detector: Detector::Cycle,
        sensor: Some("lsm6dsv320x"),
    },
    Build {
        label: "nRF52840-DK + Bluetooth RSC foot pod, LSM6DSV320X",
        dir: "boards/nrf52840-ble",
        bin: "nrf52840-ble",
        target: "thumbv7em-none-eabihf",
        machine: None,
        detector: Detector::Cycle,
        sensor: Some("lsm6dsv320x"),
    },
    Build {
        label: "rp-pico (M0+), LSM6DSV320X",
        dir: "boards/rp-pico",
        bin: "rp-pico",
        target: "thumbv6m-none-eabi",
        machine: None,
        detector: Detector::Cycle,
        sensor: Some("lsm6dsv320x"),
    },
];

/// Measures everything and returns the Markdown report.
pub fn report(inp: &Inputs) -> Result<String> {
    use crate::io::trace::Ranges;
    std::fs::create_dir_all(&inp.scratch)?;
    let (dataset, trial, rate_hz) = TRACE;
    let csv = inp.datasets.join(dataset).join(format!("{trial}.csv"));
    let trace = crate::io::csv_trace::read(&csv, Some(rate_hz))?;
    let ranges = Ranges::default();
    let counts: Vec<_> = trace.samples.iter().map(ranges.converter()).collect();
    let name = format!("{dataset}_{trial}");
    crate::sim::fixtures::write_trace_module(
        &inp.scratch,
        &name,
        &format!("`{dataset}/{trial}.csv` for the cost benchmark; written by `gaitclip cost`."),
        rate_hz,
        ranges,
        &counts,
    )?;
    let module = inp.scratch.join(format!("{name}.rs"));
    let env = [("GAITCLIP_BENCH_TRACE", module.as_os_str())];
    let config = gaitclip::pipeline::config::Config::new(
        trace.sample_rate().context("trace rate")?,
        ranges.accel.scale(),
        ranges.gyro.scale(),
    );
    let host = crate::replay::core_strides(&counts, config);
    let host_mm: u64 = host.iter().map(|s| u64::from(s.length_mm)).sum();

    // Four benchmark runs and every size build: minutes of cargo and QEMU.
    let bar = crate::progress::bar(4 + BUILDS.len() as u64, "cost");
    bar.enable_steady_tick(std::time::Duration::from_millis(500));
    let mut insns = Vec::new();
    for (target, machine, args) in [
        (
            "thumbv7em-none-eabihf",
            qemu::MACHINE_M4,
            &["--features", "all-models"][..],
        ),
        ("thumbv6m-none-eabi", qemu::MACHINE_M0, &[][..]),
    ] {
        bar.set_message(format!("the benchmark on {machine}"));
        let elf = crate::cost::firmware::build_with("boards/bench", "bench", target, args, &env)?;
        let r = run_bench(&elf, machine, &inp.plugin, &inp.scratch)?;
        bar.inc(1);
        ensure!(
            r.samples as usize == counts.len(),
            "{machine}: the benchmark replayed {} of {} samples",
            r.samples,
            counts.len()
        );
        if machine == qemu::MACHINE_M4 {
            ensure!(
                (r.strides as usize, r.distance_mm) == (host.len(), host_mm),
                "{machine}: {} strides / {} mm, the host replay {} / {host_mm}",
                r.strides,
                r.distance_mm,
                host.len()
            );
        }
        insns.push(r);
    }

    // Lu's detector: no movement buffer, so both machines must find the host's steps.
    let mut lu_config = config;
    lu_config.detector = Detector::PeakValley;
    let lu_host = crate::replay::core_strides(&counts, lu_config);
    let lu_host_mm: u64 = lu_host.iter().map(|s| u64::from(s.length_mm)).sum();
    let mut lu_insns = Vec::new();
    for (target, machine) in [
        ("thumbv7em-none-eabihf", qemu::MACHINE_M4),
        ("thumbv6m-none-eabi", qemu::MACHINE_M0),
    ] {
        bar.set_message(format!("Lu's benchmark on {machine}"));
        let elf = build_for("boards/bench", "bench", target, Detector::PeakValley, &env)?;
        let r = run_bench_peak_valley(&elf, machine, &inp.plugin, &inp.scratch)?;
        bar.inc(1);
        ensure!(
            (r.samples as usize, r.steps as usize, r.distance_mm)
                == (counts.len(), lu_host.len(), lu_host_mm),
            "{machine}, peak-valley: {} samples, {} steps / {} mm; the host replay {} / {} / {lu_host_mm}",
            r.samples,
            r.steps,
            r.distance_mm,
            counts.len(),
            lu_host.len()
        );
        lu_insns.push(r);
    }

    let mut sizes = Vec::new();
    for b in BUILDS {
        let (label, machine) = (b.label, b.machine);
        bar.set_message(format!("size of {label}"));
        bar.inc(1);
        let elf = match b.sensor {
            None => build_for(b.dir, b.bin, b.target, b.detector, &[])?,
            Some(feature) => {
                let dir = format!("target/{feature}");
                crate::cost::firmware::build_with(
                    b.dir,
                    b.bin,
                    b.target,
                    &["--features", feature],
                    &[("CARGO_TARGET_DIR", dir.as_ref())],
                )?
            }
        };
        let size = size_of_elf(&std::fs::read(&elf)?)?;
        let stack = match machine {
            Some(m) => {
                let run = qemu::run(
                    &elf,
                    &RunOptions {
                        machine: m.into(),
                        fast: true,
                        extra_args: Vec::new(),
                    },
                    |_| {},
                )?;
                ensure!(run.status == 0, "{label} exited with {}", run.status);
                Some(parse_stack_line(&run.lines).context("no `stack used` line")?)
            }
            None => None,
        };
        sizes.push((label, size, stack));
    }

    bar.finish_and_clear();
    let estimates = std::fs::read_to_string(&inp.criterion_estimates).with_context(|| {
        format!(
            "reading {} (run benches/replay.rs)",
            inp.criterion_estimates.display()
        )
    })?;
    let host_rate = criterion_samples_per_s(&estimates, counts.len() as u64)?;
    let gm: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&inp.gaitmap_json)
            .with_context(|| format!("reading {}", inp.gaitmap_json.display()))?,
    )?;
    let gm_rate = gm["samples_per_s"]
        .as_f64()
        .context("gaitmap samples_per_s")?;

    Ok(render(&Report {
        trace: format!(
            "`{dataset}/{trial}` ({} samples at {rate_hz} Hz, {} strides)",
            counts.len(),
            host.len()
        ),
        insns,
        lu_insns,
        sizes,
        host_rate,
        gaitmap: gm,
        gaitmap_rate: gm_rate,
    }))
}

/// A build's name, size and stack (bytes used, region), where it was run.
type BuildSize<'a> = (&'a str, Size, Option<(u32, u32)>);

struct Report<'a> {
    trace: String,
    insns: Vec<InsnReport>,
    lu_insns: Vec<StepInsnReport>,
    sizes: Vec<BuildSize<'a>>,
    host_rate: f64,
    gaitmap: serde_json::Value,
    gaitmap_rate: f64,
}

fn verdict(ok: bool) -> &'static str {
    if ok {
        "met"
    } else {
        "**not met**"
    }
}

/// The columns of an instruction table.
fn insn_table() -> Table {
    Table::new([
        Column::from("step"),
        Column::right("M4 mean"),
        Column::right("M4 max"),
        Column::right("M0 mean"),
        Column::right("M0 max"),
    ])
}

/// An instruction row: `step`, then the M4 and M0 mean and max.
fn insn_row(t: &mut Table, step: impl Into<String>, m4: &Stat, m0: &Stat) {
    t.row([
        step.into(),
        format!("{:.0}", m4.mean),
        m4.max.to_string(),
        format!("{:.0}", m0.mean),
        m0.max.to_string(),
    ]);
}

/// The row of the mean over all samples, strides spread over them (no max).
fn insn_all_row(t: &mut Table, step: &str, m4_mean: f64, m0_mean: f64) {
    t.row([
        step.to_string(),
        format!("{m4_mean:.0}"),
        String::new(),
        format!("{m0_mean:.0}"),
        String::new(),
    ]);
}

fn render(r: &Report) -> String {
    let mut o = String::new();
    let (m4, m0) = (&r.insns[0], &r.insns[1]);
    let _ = writeln!(o, "### Instructions\n");
    let _ = writeln!(
        o,
        "Counted by the `qemu-insn-count` plugin on the benchmark firmware (`boards/bench`), \
         which replays {} from flash; every call counted, callees included. The sample path \
         leaves out the per-stride steps, listed below it.\n",
        r.trace
    );
    let mut cycle = insn_table();
    insn_row(
        &mut cycle,
        "per sample: sample path",
        &m4.sample,
        &m0.sample,
    );
    insn_all_row(
        &mut cycle,
        "per sample: all work, strides spread over the samples",
        m4.sample_all_mean,
        m0.sample_all_mean,
    );
    insn_row(
        &mut cycle,
        format!(
            "per stride: pipeline, default model (`{}`)",
            m4.default_model
        ),
        &m4.stride,
        &m0.stride,
    );
    for (step, a, b) in [
        (
            "· phases, statistics, ZUPT (`CycleDetector::close`)",
            &m4.close,
            &m0.close,
        ),
        ("· · phase split (`phases::split`)", &m4.split, &m0.split),
        (
            "· · phase statistics (`StrideStats::measure`)",
            &m4.stats,
            &m0.stats,
        ),
        (
            "· features and default model (`LengthChain::measure`)",
            &m4.measure,
            &m0.measure,
        ),
        ("features (`Features::of`)", &m4.features, &m0.features),
    ] {
        insn_row(&mut cycle, step, a, b);
    }
    for (name, s) in &m4.models {
        match m0.models.iter().find(|(n, _)| n == name) {
            Some((_, m0s)) => insn_row(&mut cycle, format!("model `{name}`"), s, m0s),
            None => {
                cycle.row([
                    format!("model `{name}`"),
                    format!("{:.0}", s.mean),
                    s.max.to_string(),
                    "not in the M0 build".to_string(),
                    String::new(),
                ]);
            }
        }
    }
    o.push_str(&cycle.render());
    let (l4, l0) = (&r.lu_insns[0], &r.lu_insns[1]);
    let _ = writeln!(
        o,
        "\nWith Lu's peak-valley detector (the benchmark built with `peak-valley-detector`), on \
         the same trace ({} steps, as the host replay finds them):\n",
        l4.steps
    );
    let mut lu = insn_table();
    insn_row(
        &mut lu,
        "per sample: sample path (low-pass, peak-valley rules)",
        &l4.sample,
        &l0.sample,
    );
    insn_all_row(
        &mut lu,
        "per sample: all work, steps spread over the samples",
        l4.sample_all_mean,
        l0.sample_all_mean,
    );
    insn_row(
        &mut lu,
        "per step: Lu's chain (`lu::lu_chain_um`)",
        &l4.step,
        &l0.step,
    );
    o.push_str(&lu.render());
    let _ = writeln!(o, "\n### Size\n");
    let _ = writeln!(
        o,
        "Release builds (`opt-level = \"s\"`, fat LTO). Flash: allocated sections with \
         contents; static RAM: allocated sections in RAM; stack: high-water mark of the \
         painted stack after replaying the demo walk in QEMU.\n"
    );
    let mut sizes = Table::new([
        Column::from("build"),
        Column::right("flash (B)"),
        Column::right("static RAM (B)"),
        Column::right("stack used / region (B)"),
    ]);
    for (label, s, stack) in &r.sizes {
        let st = match stack {
            Some((u, n)) => format!("{u} / {n}"),
            None => "not run (no board here)".into(),
        };
        sizes.row([
            label.to_string(),
            s.flash.to_string(),
            s.static_ram.to_string(),
            st,
        ]);
    }
    o.push_str(&sizes.render());
    let _ = writeln!(
        o,
        "\nThe boards without an emulator paint their stack too where they can: the Bluetooth \
         build prints its high-water mark in its status line every minute (`ble … stack \
         used=N of M bytes`), so that figure comes from a board. Its static RAM includes the \
         SoftDevice Controller's memory and every task's future (embassy keeps them in \
         statics)."
    );
    let _ = writeln!(o, "\n### Host replay\n");
    let mut host = Table::new([
        Column::from(format!("pipeline on {}", r.trace)),
        Column::right("samples/s"),
    ]);
    host.row([
        "gaitclip `replay` (criterion mean)".to_string(),
        format!("{:.0}", r.host_rate),
    ]);
    host.row([
        format!(
            "gaitmap 2.6.0 MAD pipeline (median of {} runs after a first of {:.2} s)",
            r.gaitmap["runs"].as_u64().unwrap_or(0),
            r.gaitmap["first_run_s"].as_f64().unwrap_or(f64::NAN)
        ),
        format!("{:.0}", r.gaitmap_rate),
    ]);
    host.row([
        "ratio".to_string(),
        format!("{:.0}×", r.host_rate / r.gaitmap_rate),
    ]);
    o.push_str(&host.render());
    let nrf = r
        .sizes
        .iter()
        .find(|(l, _, _)| l.starts_with("nrf52840-dk"));
    let _ = writeln!(o, "\n### Goals\n");
    let mut goals = Table::new([
        Column::from("goal"),
        Column::right("measured"),
        Column::from(""),
    ]);
    let mut goal = |what: &str, measured: String, ok: bool| {
        goals.row([what.to_string(), measured, verdict(ok).to_string()]);
    };
    goal(
        "≤ 150 instructions per sample on M4 (mean)",
        format!("{:.0}", m4.sample.mean),
        m4.sample.mean <= 150.0,
    );
    goal(
        "≤ 400 instructions per sample on M0 (mean)",
        format!("{:.0}", m0.sample.mean),
        m0.sample.mean <= 400.0,
    );
    goal(
        "≤ 30 000 instructions per stride, default model (M4 mean)",
        format!("{:.0}", m4.stride.mean),
        m4.stride.mean <= 30_000.0,
    );
    if let Some((_, s, _)) = nrf {
        goal(
            "nRF52840 flash ≤ 48 KiB (49 152 B)",
            s.flash.to_string(),
            s.flash <= 49_152,
        );
        goal(
            "nRF52840 static RAM ≤ 12 KiB (12 288 B)",
            s.static_ram.to_string(),
            s.static_ram <= 12_288,
        );
    }
    let ratio = r.host_rate / r.gaitmap_rate;
    goal(
        "host replay ≥ 100× gaitmap",
        format!("{ratio:.0}×"),
        ratio >= 100.0,
    );
    o.push_str(&goals.render());
    let _ = writeln!(o, "\n### Energy\n");
    o.push_str(&crate::cost::energy::report(
        m4.sample_all_mean,
        m0.sample_all_mean,
    ));
    o
}

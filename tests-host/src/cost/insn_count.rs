//! Instruction counts of the benchmark firmware (`boards/bench`) under QEMU: the
//! `qemu-insn-count` plugin counts the instructions of every call of the functions named in
//! [`MEASURED`] (or [`MEASURED_PEAK_VALLEY`]), found by their symbols in the ELF; this module
//! runs QEMU with it and reads the counts back. [`crate::cost::report`] writes the report.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use object::{Object, ObjectSymbol, SymbolKind};

use crate::cost::qemu::{self, RunOptions};

/// The functions whose calls are counted: (key, demangled name without hash). The
/// `bench::` ones are the benchmark firmware's wrappers; the others are the core's
/// per-stride steps, out of line (`#[inline(never)]`) in every build.
pub const MEASURED: [(&str, &str); 7] = [
    ("sample", "bench::bench_sample"),
    ("features", "bench::bench_features"),
    ("model", "bench::bench_model"),
    ("close", "gaitclip::detect::cycle::CycleDetector<_>::close"),
    ("measure", "gaitclip::length::models::LengthChain::measure"),
    ("split", "gaitclip::detect::phases::split"),
    (
        "stats",
        "gaitclip::detect::phase_stats::StrideStats::measure",
    ),
];

/// The functions counted in the benchmark built with `peak-valley-detector` (Lu's
/// detector): the sample path, and Lu's chain on each step, out of line in every build.
pub const MEASURED_PEAK_VALLEY: [(&str, &str); 2] = [
    ("sample", "bench::bench_sample"),
    ("step", "gaitclip::length::lu::lu_chain_um"),
];

/// Instructions of each call of one function, in the order the calls returned.
#[derive(Clone, Debug, Default)]
pub struct Calls {
    /// Callees included.
    pub inclusive: Vec<u64>,
    /// Without the calls of other measured functions made inside.
    pub own: Vec<u64>,
}

/// Mean and maximum of a set of counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stat {
    /// Number of values.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Maximum.
    pub max: u64,
}

impl Stat {
    /// Of `v` (all zero when empty).
    pub fn of(v: &[u64]) -> Stat {
        if v.is_empty() {
            return Stat::default();
        }
        Stat {
            n: v.len(),
            mean: v.iter().sum::<u64>() as f64 / v.len() as f64,
            max: v.iter().copied().max().unwrap_or(0),
        }
    }
}

/// Parses the plugin's output: `call NAME INCLUSIVE OWN` lines (any `open` or `lost` line
/// is an error: a measured call whose return was not seen).
pub fn parse_counts(text: &str) -> Result<HashMap<String, Calls>> {
    let mut out: HashMap<String, Calls> = HashMap::new();
    for (i, line) in text.lines().enumerate() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.as_slice() {
            ["call", name, inc, own] => {
                let c = out.entry(name.to_string()).or_default();
                c.inclusive
                    .push(inc.parse().with_context(|| format!("line {}", i + 1))?);
                c.own
                    .push(own.parse().with_context(|| format!("line {}", i + 1))?);
            }
            ["total", _] => {}
            _ => bail!("instruction counts, line {}: unexpected `{line}`", i + 1),
        }
    }
    Ok(out)
}

/// Entry addresses of the `measured` functions ((key, demangled name), as [`MEASURED`]) in
/// `elf`.
pub fn entry_addresses(
    elf: &[u8],
    measured: &[(&'static str, &str)],
) -> Result<Vec<(&'static str, u64)>> {
    let file = object::File::parse(elf).context("parsing the ELF")?;
    let mut found = Vec::new();
    for &(key, name) in measured {
        let addrs: Vec<u64> = file
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text)
            .filter(|s| {
                s.name()
                    .is_ok_and(|n| format!("{:#}", rustc_demangle::demangle(n)) == name)
            })
            .map(|s| s.address())
            .collect();
        match addrs.as_slice() {
            [a] => found.push((key, *a)),
            [] => bail!("`{name}` is not in the ELF (inlined or renamed?)"),
            _ => bail!("`{name}` is in the ELF {} times", addrs.len()),
        }
    }
    Ok(found)
}

/// Instruction counts of one benchmark run.
#[derive(Clone, Debug)]
pub struct InsnReport {
    /// QEMU machine.
    pub machine: String,
    /// Samples replayed.
    pub samples: u32,
    /// Strides found.
    pub strides: u32,
    /// Their summed length, mm.
    pub distance_mm: u64,
    /// The sample path: `Pipeline::process` without the per-stride steps.
    pub sample: Stat,
    /// Everything per sample, the per-stride steps spread over the samples (mean only).
    pub sample_all_mean: f64,
    /// `CycleDetector::close`: phases, phase statistics, ZUPT displacement.
    pub close: Stat,
    /// `phases::split` (inside close).
    pub split: Stat,
    /// `StrideStats::measure` (inside close).
    pub stats: Stat,
    /// `LengthChain::measure`: features and the default model.
    pub measure: Stat,
    /// close + measure of each stride: the pipeline's per-stride work.
    pub stride: Stat,
    /// `Features::of`.
    pub features: Stat,
    /// The default model's name.
    pub default_model: String,
    /// Each model the build carries: name and its `predict_mm` call.
    pub models: Vec<(String, Stat)>,
}

/// Instruction counts of one run of the benchmark built with `peak-valley-detector`.
#[derive(Clone, Debug)]
pub struct StepInsnReport {
    /// QEMU machine.
    pub machine: String,
    /// Samples replayed.
    pub samples: u32,
    /// Steps found (each a stride record).
    pub steps: u32,
    /// Their summed length, mm.
    pub distance_mm: u64,
    /// The sample path: `Pipeline::process` with the low-pass and Lu's rules, without
    /// `lu::lu_chain_um`.
    pub sample: Stat,
    /// Everything per sample, the steps' chain spread over the samples (mean only).
    pub sample_all_mean: f64,
    /// `lu::lu_chain_um`: Lu's chain (D, f, fuzzy K, Weinberg) on one step.
    pub step: Stat,
}

/// What one counted run printed and counted.
struct CountedRun {
    calls: HashMap<String, Calls>,
    lines: Vec<String>,
    /// samples, strides, distance_mm of the `bench samples=…` line.
    summary: (u32, u32, u64),
}

/// Runs the benchmark firmware `elf` on `machine` under the counting plugin, counting the
/// `measured` functions.
fn counted_run(
    elf: &Path,
    machine: &str,
    plugin: &Path,
    scratch: &Path,
    measured: &[(&'static str, &str)],
) -> Result<CountedRun> {
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let entries = entry_addresses(&bytes, measured)?;
    let out = scratch.join(format!("insn-count-{machine}.txt"));
    let mut arg = plugin.display().to_string();
    for (key, addr) in &entries {
        let _ = write!(arg, ",fn={key}@{addr:#x}");
    }
    let _ = write!(arg, ",out={}", out.display());
    let run = qemu::run(
        elf,
        &RunOptions {
            machine: machine.into(),
            fast: false,
            extra_args: vec!["-plugin".into(), arg],
        },
        |_| {},
    )?;
    ensure!(
        run.status == 0,
        "benchmark firmware on {machine} exited with {}: {:?}",
        run.status,
        run.lines
    );
    let text = std::fs::read_to_string(&out)
        .with_context(|| format!("reading the plugin's output {}", out.display()))?;
    let calls = parse_counts(&text)?;
    let mut summary = None;
    for line in &run.lines {
        if let Some(rest) = line.strip_prefix("bench samples=") {
            let v: Vec<u64> = rest
                .split(|c: char| !c.is_ascii_digit())
                .filter_map(|t| t.parse().ok())
                .collect();
            ensure!(v.len() == 3, "bench summary `{line}`");
            summary = Some((v[0] as u32, v[1] as u32, v[2]));
        }
    }
    Ok(CountedRun {
        calls,
        summary: summary.with_context(|| format!("{machine}: no `bench samples=` line"))?,
        lines: run.lines,
    })
}

/// Runs the benchmark firmware `elf` (stance detector) on `machine` under the counting
/// plugin `plugin`.
pub fn run_bench(elf: &Path, machine: &str, plugin: &Path, scratch: &Path) -> Result<InsnReport> {
    let run = counted_run(elf, machine, plugin, scratch, &MEASURED)?;
    let get = |k: &str| run.calls.get(k).cloned().unwrap_or_default();
    let (samples, strides, distance_mm) = run.summary;
    let (mut models, mut default_model) = (Vec::new(), String::new());
    for line in &run.lines {
        if let Some(m) = line.strip_prefix("bench model=") {
            models.push(m.to_string());
        } else if let Some(m) = line.strip_prefix("bench default=") {
            default_model = m.to_string();
        }
    }
    let (sample, close, measure, model) =
        (get("sample"), get("close"), get("measure"), get("model"));
    let n = strides as usize;
    ensure!(
        sample.own.len() == samples as usize,
        "{machine}: {} sample calls counted for {samples} samples",
        sample.own.len()
    );
    ensure!(
        close.inclusive.len() == n && measure.inclusive.len() == n,
        "{machine}: close/measure counted {}/{} times for {n} strides",
        close.inclusive.len(),
        measure.inclusive.len()
    );
    ensure!(
        !models.is_empty() && model.inclusive.len() == n * models.len(),
        "{machine}: {} model calls for {n} strides × {} models",
        model.inclusive.len(),
        models.len()
    );
    let per_stride: Vec<u64> = close
        .inclusive
        .iter()
        .zip(&measure.inclusive)
        .map(|(a, b)| a + b)
        .collect();
    let models = models
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let v: Vec<u64> = model
                .inclusive
                .iter()
                .skip(k)
                .step_by(models.len())
                .copied()
                .collect();
            (name.clone(), Stat::of(&v))
        })
        .collect();
    Ok(InsnReport {
        machine: machine.into(),
        samples,
        strides,
        distance_mm,
        sample: Stat::of(&sample.own),
        sample_all_mean: sample.inclusive.iter().sum::<u64>() as f64 / samples.max(1) as f64,
        close: Stat::of(&close.inclusive),
        split: Stat::of(&get("split").inclusive),
        stats: Stat::of(&get("stats").inclusive),
        measure: Stat::of(&measure.inclusive),
        stride: Stat::of(&per_stride),
        features: Stat::of(&get("features").inclusive),
        default_model,
        models,
    })
}

/// Runs the benchmark firmware `elf` built with `peak-valley-detector` on `machine` under the
/// counting plugin `plugin`.
pub fn run_bench_peak_valley(
    elf: &Path,
    machine: &str,
    plugin: &Path,
    scratch: &Path,
) -> Result<StepInsnReport> {
    let run = counted_run(elf, machine, plugin, scratch, &MEASURED_PEAK_VALLEY)?;
    let get = |k: &str| run.calls.get(k).cloned().unwrap_or_default();
    let (samples, steps, distance_mm) = run.summary;
    let (sample, step) = (get("sample"), get("step"));
    ensure!(
        run.lines.iter().any(|l| l == "bench default=lu_fuzzy"),
        "{machine}: the benchmark did not run Lu's chain (built without peak-valley-detector?)"
    );
    ensure!(
        sample.own.len() == samples as usize,
        "{machine}: {} sample calls counted for {samples} samples",
        sample.own.len()
    );
    ensure!(
        step.inclusive.len() == steps as usize,
        "{machine}: lu_chain_um counted {} times for {steps} steps",
        step.inclusive.len()
    );
    Ok(StepInsnReport {
        machine: machine.into(),
        samples,
        steps,
        distance_mm,
        sample: Stat::of(&sample.own),
        // The steps held to the end come out of `take` after the last sample, outside
        // `bench_sample`: every step's chain is added to the samples' own work.
        sample_all_mean: (sample.own.iter().sum::<u64>() + step.inclusive.iter().sum::<u64>())
            as f64
            / samples.max(1) as f64,
        step: Stat::of(&step.inclusive),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_plugin_output_and_rejects_open_calls() {
        let c = parse_counts("call sample 10 7\ncall sample 12 12\ntotal 99\n").unwrap();
        assert_eq!(c["sample"].inclusive, vec![10, 12]);
        assert_eq!(c["sample"].own, vec![7, 12]);
        let s = Stat::of(&c["sample"].own);
        assert_eq!((s.n, s.mean, s.max), (2, 9.5, 12));
        assert!(parse_counts("open sample 5\n").is_err());
        assert!(parse_counts("lost close\n").is_err());
    }
}

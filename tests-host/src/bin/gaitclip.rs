//! `gaitclip`: the host command line.
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};
use gaitclip::detect::phases::PhaseMethod;
use gaitclip::length::models::Model;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip_host::eval::scoring;
use gaitclip_host::io::recording::{self, ReadError};
use gaitclip_host::io::trace::{Ranges, Trace};
use gaitclip_host::io::units::{AccUnit, Front, GyroUnit, Units};
use gaitclip_host::stream::StreamError;
use gaitclip_host::{
    eval::length_eval, eval::matching, eval::tables, io::datasets, io::mcap_io, replay,
    sim::fixtures, train::codegen, train::fit, train::training, train::training_set,
};

#[derive(Parser)]
#[command(
    name = "gaitclip",
    version,
    about = "Replay IMU traces through the gaitclip firmware core"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Replay a CSV or MCAP trace through the firmware core and print one line per stride.
    Replay {
        /// The trace: `.csv` (t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z in m/s², rad/s) or `.mcap`.
        trace: PathBuf,
        /// Sample rate in Hz (default: meta.json beside a CSV, else the timestamps).
        #[arg(long)]
        rate: Option<f64>,
        /// One JSON object per stride per line.
        #[arg(long)]
        json: bool,
        /// Step detector: `cycle` (one zero-velocity instant per gait cycle at every pace,
        /// the firmware's default), `stance` (Huang's variance + IQR stance detector) or `lu`
        /// (Lu's peak-valley detection, measured by Lu's chain: `--model lu_fuzzy`).
        #[arg(long, value_name = "NAME", value_parser = detector_names(), default_value = Detector::Cycle.name())]
        detector: String,
        /// Length model for `length_m` (default: the firmware's; `lu_fuzzy` with `--detector lu`).
        #[arg(long, value_name = "NAME", value_parser = model_names())]
        model: Option<String>,
        /// Add every model's length (`lengths_m` in JSON, a line of them under each stride
        /// otherwise), with the `cycle` or `stance` detector (`lu` has Lu's chain only).
        #[arg(long)]
        all_models: bool,
        /// Also write the samples and the strides to this MCAP file (opens in Foxglove).
        #[arg(long, value_name = "FILE")]
        mcap_out: Option<PathBuf>,
        /// The accelerometer's nominal full scale, g (default: `acc_range_g` of a meta.json
        /// beside the file, else ±16 g). Each axis's rail is learnt from flat runs at its
        /// extremes; without one, this is its rail.
        #[arg(long, value_name = "G")]
        acc_range_g: Option<f64>,
        /// The gyroscope's nominal full scale, °/s (default: `gyro_range_dps` of a meta.json,
        /// else ±2000 °/s); rails learnt as for the accelerometer.
        #[arg(long, value_name = "DPS")]
        gyro_range_dps: Option<f64>,
        #[command(flatten)]
        units: UnitArgs,
    },
    /// The Bluetooth foot pod on the host: the pod's own Bluetooth code over an HCI
    /// controller, serving the strides of a replayed recording as the board serves a walk.
    Pod {
        /// The HCI controller: `tcp:HOST:PORT` (an H4 controller listening on TCP, such as
        /// Bumble's `tcp-server:`) or `serial:PATH[@BAUD]` (a UART controller; 1000000 baud
        /// by default).
        #[arg(long, value_name = "TRANSPORT", value_parser = hci_transport)]
        hci: gaitclip_host::pod::Hci,
        /// The recording to replay (CSV or MCAP, as `replay` reads them).
        trace: PathBuf,
        /// Sample rate in Hz (default: meta.json beside a CSV, else the timestamps).
        #[arg(long)]
        rate: Option<f64>,
        /// Replay this many times faster than real time.
        #[arg(long, default_value_t = 1.0)]
        speed: f64,
        /// Hold the replay until a central has subscribed to RSC Measurement.
        #[arg(long)]
        wait_for_central: bool,
        /// The battery level served, % (the board reads its supply).
        #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u8).range(0..=100))]
        battery_percent: u8,
        /// Step detector, as for `replay`.
        #[arg(long, value_name = "NAME", value_parser = detector_names(), default_value = Detector::Cycle.name())]
        detector: String,
        /// Strides and Bluetooth events as JSON lines.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        units: UnitArgs,
    },
    /// Score stride detection, gait events, phases and stance against the ground truth of
    /// dataset folders (`../shared/datasets/<name>`); prints Markdown tables.
    Eval {
        /// Dataset folders.
        #[arg(required = true)]
        datasets: Vec<PathBuf>,
        /// Also run each trace after this many random rotations (a clip mounted any way).
        #[arg(long, default_value_t = 0)]
        rotate: usize,
        /// Seed of the rotations.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Phase splitter: Huang's major peak-valley pairs or the augmented version.
        #[arg(long, value_enum, default_value_t = PhasesArg::Augmented)]
        phases: PhasesArg,
        /// Write the default model's Bland–Altman plot, predicted-vs-reference scatter and
        /// error against speed (SVG, leave-one-dataset-out) into this folder.
        #[arg(long, value_name = "DIR")]
        plots: Option<PathBuf>,
        /// The stance detector's thresholds for the detection tables, as
        /// `STD,IQR,GYRO` in (m/s²)², (m/s²)² and rad/s (default: the shipped 6,6,0.7).
        #[arg(long, value_name = "STD,IQR,GYRO", value_parser = stance_limits)]
        stance: Option<gaitclip::detect::stance::StanceLimits>,
    },
    /// Compare the per-stride gait parameters (times, cadence, velocity, lift, turning,
    /// walking/running) with the references of dataset folders; prints Markdown tables.
    Gait {
        /// Dataset folders.
        #[arg(required = true)]
        datasets: Vec<PathBuf>,
    },
    /// Train every stride-length model on the shared datasets with per-stride lengths and
    /// write the generated Rust source the firmware compiles.
    Train {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
        /// Output file.
        #[arg(long, default_value = "../src/length/trained.rs")]
        out: PathBuf,
    },
    /// Measure instructions per sample and stride (QEMU), firmware sizes and stacks, host
    /// replay throughput against gaitmap; print Markdown. Run through `tests-host/cost.sh`,
    /// which prepares the plugin, the criterion benchmark and gaitmap's figures.
    Cost {
        /// The qemu-insn-count plugin (.so).
        #[arg(long)]
        plugin: PathBuf,
        /// criterion's estimates.json of benches/replay.rs.
        #[arg(long)]
        criterion: PathBuf,
        /// JSON printed by gaitmap/bench_gaitmap.py.
        #[arg(long)]
        gaitmap: PathBuf,
        /// The shared datasets folder.
        #[arg(long, default_value = "../../shared/datasets")]
        datasets: PathBuf,
        /// Scratch folder.
        #[arg(long, default_value = "target/cost")]
        scratch: PathBuf,
    },
    /// Print the energy budget of the real boards (docs/energy.md's tables; `cost`
    /// prints the same from the instructions it measures) for given instruction counts per
    /// sample of walking, strides included.
    Energy {
        /// Instructions per sample on the Cortex-M4 (the nRF52840 builds).
        #[arg(long)]
        m4: f64,
        /// Instructions per sample on the Cortex-M0 (the Pico build).
        #[arg(long)]
        m0: f64,
    },
    /// Put the sensor to sleep at every stand of the datasets and say when the wake rule
    /// would wake it: early in the stand, how far into the walk, or not at all (docs/energy.md's
    /// wake table).
    Wake {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Cut holes of 1–16 samples into the walking strides of the datasets with per-stride
    /// references and print what bridging them costs, by hole length (docs/clocks-and-holes.md's hole
    /// table, and the bridge limit it gives).
    Holes {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Sweep the ZUPT stride's physical settings on the datasets with per-stride lengths:
    /// the sensor's height above the rolling contact, and the gyro's full-scale range
    /// (clipping), by stride speed (docs/accuracy.md's tables).
    ZuptSweep {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// What moves the ZUPT stride's bias between set-ups (the lever arm, the clock, the
    /// accelerometer's gain and offset, the unit of length), the lever arm the strides give,
    /// and the bias by dataset × mounting × pace before and after (docs/accuracy.md).
    Bias {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Time the core's toe-offs and heel-strikes against `gaitmap_walk`'s mocap events and
    /// `ipol_gait_events`' annotations, beside the same events read from the foot's sagittal
    /// angular rate (docs/accuracy.md's event timing table).
    Events {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Clip `gaitmap_walk` and `pyshoe_vicon` at ±8 g, ±4 g and ±12 g and compare each clipped
    /// stride with its unclipped self, with the loss left in and put back.
    Clipping {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Simulate a sprint past the MPU6050's rails (40 g and 70 g touch-downs, toe-off beyond
    /// 2 000 °/s), record it as the MPU6050 and as the LSM6DSV320X would, and compare the
    /// strides with the truth (docs/sensors.md's table).
    Sprint,
    /// Replay the datasets at their own rate and decimated to lower rates, and compare the
    /// strides.
    Rates {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// The stance instant by pace against the Vicon foot marker of `pyshoe_vicon`: how
    /// still the foot is there, what the rolling contact imposes, the duty factor.
    Running {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// What a level landing, a touch-down step or the end rest's gravity would do to the
    /// length of strides whose length is known (the `f64` twin's integration).
    Constraints {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// The walk-jog-run-sprint courses of `esangeni_course` against their geometry: the
    /// total, the forward, backward and sideways parts (split by the foot's heading), strides
    /// by gait class, |climb| per stride, flags.
    Course {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// What each stride flag costs: the flags as they occur on the datasets against their
    /// references, and made on purpose (holes, clipping) against the strides undegraded.
    Flags {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
    },
    /// Replay recordings of daily life labelled by activity (`hugadb_daily`) and count the
    /// strides the core reports by activity: where people walk, and where nobody does.
    Daily {
        /// The dataset folder (`../shared/datasets/hugadb_daily`).
        #[arg(default_value = "../../shared/datasets/hugadb_daily")]
        dir: PathBuf,
    },
    /// Regenerate the measured tables of `docs/` (the blocks marked `<!-- generated: gaitclip
    /// NAME -->`) from the datasets; `--check` writes nothing and fails on a stale block.
    Docs {
        /// The folder holding the datasets (`../shared/datasets`).
        #[arg(default_value = "../../shared/datasets")]
        datasets: PathBuf,
        /// Only check that every block is current.
        #[arg(long)]
        check: bool,
    },
    /// Regenerate the simulated fixtures (traces with ground truth) into a folder.
    Simulate {
        /// Output folder.
        #[arg(long, default_value = "../fixtures")]
        out: PathBuf,
    },
}

/// The units of a recording's values, where they are not the datasets' m/s² and rad/s, and
/// whether a `--rate` given wins over the stamps.
#[derive(clap::Args)]
struct UnitArgs {
    /// Replay at `--rate` even where the stamps' own rate is more than 10 % off it (without
    /// this, that contradiction is an error: a wrong rate gives wrong lengths).
    #[arg(long, requires = "rate")]
    rate_overrides_stamps: bool,
    /// The accelerometer's unit: `m/s^2`, `g` or `mg` (default: `units.acc` of a meta.json
    /// beside the file, else m/s²). A recording whose stillest quarter does not read about 1 g in it is
    /// refused, naming the unit it looks like.
    #[arg(long, value_name = "UNIT", value_parser = acc_unit)]
    acc_unit: Option<AccUnit>,
    /// The gyroscope's unit: `rad/s` or `deg/s` (default: `units.gyr` of a meta.json beside
    /// the file, else rad/s). A gyro faster than any IMU, or one that barely turns while the
    /// foot steps, is refused, naming the unit it looks like.
    #[arg(long, value_name = "UNIT", value_parser = gyr_unit)]
    gyr_unit: Option<GyroUnit>,
}

impl UnitArgs {
    /// The units declared on the command line, over `meta.json`'s (`None`: the file's own).
    fn units(&self, trace: &Path) -> anyhow::Result<Option<Units>> {
        Ok(recording::declared_units(
            trace,
            self.acc_unit,
            self.gyr_unit,
        )?)
    }
}

fn acc_unit(s: &str) -> Result<AccUnit, String> {
    Units::from_names(Some(s), None)
        .map(|u| u.acc)
        .map_err(|e| e.to_string())
}

fn gyr_unit(s: &str) -> Result<GyroUnit, String> {
    Units::from_names(None, Some(s))
        .map(|u| u.gyro)
        .map_err(|e| e.to_string())
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum PhasesArg {
    MajorPairs,
    Augmented,
}

impl From<PhasesArg> for PhaseMethod {
    fn from(p: PhasesArg) -> Self {
        match p {
            PhasesArg::MajorPairs => PhaseMethod::MajorPairs,
            PhasesArg::Augmented => PhaseMethod::Augmented,
        }
    }
}

fn stance_limits(v: &str) -> Result<gaitclip::detect::stance::StanceLimits, String> {
    let parts: Vec<f64> = v
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    let milli = |x: f64| -> Result<u32, String> {
        (x.is_finite() && x > 0.0 && x < 4e6)
            .then(|| (x * 1000.0).round() as u32)
            .ok_or_else(|| format!("{x} is not a positive threshold"))
    };
    match parts[..] {
        [std, iqr, gyro] => Ok(gaitclip::detect::stance::StanceLimits {
            std_milli: milli(std)?,
            iqr_milli: milli(iqr)?,
            gyro_mradps: milli(gyro)?,
        }),
        _ => Err("three numbers: STD,IQR,GYRO".into()),
    }
}

fn detector_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(Detector::ALL.iter().map(|d| d.name()))
}

fn model_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(Model::ALL.map(|m| m.name()))
}

/// Exit statuses, from BSD's sysexits so that scripts can tell bad input from a bug. A
/// command line clap cannot parse exits with 2; a panic (a bug) with Rust's 101.
mod status {
    /// The input is malformed: a CSV cell, a column, an MCAP record, timestamps.
    pub const BAD_INPUT: u8 = 65;
    /// An input file cannot be opened or read.
    pub const NO_INPUT: u8 = 66;
    /// Anything else: gaitclip's own fault.
    pub const INTERNAL: u8 = 70;
    /// An output file cannot be written.
    pub const CANT_WRITE: u8 = 74;
    /// Options that do not go together.
    pub const USAGE: u8 = 2;
}

/// Options that do not go together (exit status 2, as for clap's own usage errors).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
struct UsageError(&'static str);

/// Creating or writing an output file failed.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {source}")]
struct WriteError {
    path: PathBuf,
    source: std::io::Error,
}

/// The exit status for an error: by the first typed cause in its chain.
fn status_of(e: &anyhow::Error) -> u8 {
    use gaitclip_host::io::clock::TimeGoesBack;
    use gaitclip_host::io::csv_trace::CsvError;
    use gaitclip_host::io::mcap_io::McapError;
    for cause in e.chain() {
        let cause: &(dyn std::error::Error + 'static) = match cause.downcast_ref::<ReadError>() {
            Some(ReadError::Csv(c)) => c,
            Some(ReadError::Mcap(m)) => m,
            Some(ReadError::RateContradicts { .. }) => return status::BAD_INPUT,
            None => cause,
        };
        if let Some(c) = cause.downcast_ref::<CsvError>() {
            return match c {
                CsvError::Io { .. } => status::NO_INPUT,
                _ => status::BAD_INPUT,
            };
        }
        if let Some(m) = cause.downcast_ref::<McapError>() {
            return match m {
                McapError::Io { .. } => status::NO_INPUT,
                McapError::Write(_) => status::CANT_WRITE,
                _ => status::BAD_INPUT,
            };
        }
        if cause.is::<replay::ReplayError>() || cause.is::<TimeGoesBack>() {
            return status::BAD_INPUT;
        }
        if cause.is::<WriteError>() {
            return status::CANT_WRITE;
        }
        if cause.is::<UsageError>() {
            return status::USAGE;
        }
    }
    // A dataset folder of the user's that cannot be scored: not a file there, or bad input.
    if e.downcast_ref::<datasets::DatasetError>().is_some() {
        let missing = e.chain().any(|c| {
            c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
        });
        return if missing {
            status::NO_INPUT
        } else {
            status::BAD_INPUT
        };
    }
    status::INTERNAL
}

fn main() -> ExitCode {
    // A closed pipe (`gaitclip replay walk.csv | head -1`) ends the command as it ends `cat`:
    // quietly, by SIGPIPE (status 141 in a shell), not by a panic in `println!`.
    sigpipe::reset();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let status = status_of(&e);
            let kind = match status {
                status::BAD_INPUT => "bad input",
                status::NO_INPUT => "cannot read input",
                status::CANT_WRITE => "cannot write output",
                status::USAGE => "usage",
                _ => "internal error",
            };
            eprintln!("gaitclip: {kind}: {}", causes(&e));
            ExitCode::from(status)
        }
    }
}

/// A stride as `replay` prints it without `--json`: its number, times, length, the four
/// phases labelled (from the start's foot-flat to heel-off, heel-off to toe-off, the swing,
/// heel-strike to the end's foot-flat), the stance and swing times (docs/host-tool.md), and
/// its flags, on valid strides too.
fn text_line(s: &replay::StrideReport) -> String {
    let ms = |a: f64, b: f64| ((b - a) * 1e3).round();
    let flags = match (s.valid, s.flags.is_empty()) {
        (true, true) => String::new(),
        (true, false) => format!("  flags {}", s.flags.join(",")),
        (false, _) => format!("  INVALID ({})", s.flags.join(",")),
    };
    format!(
        "stride {:3}  start {:8.3} s  dur {:5.3} s  length {:5.3} m  stance {:5.3} s  swing {:5.3} s  phases: flat {:.0} ms, push-off {:.0} ms, swing {:.0} ms, landing {:.0} ms{flags}",
        s.index,
        s.start_s,
        s.end_s - s.start_s,
        s.length_m,
        s.stance_time_s,
        s.swing_time_s,
        ms(s.start_s, s.heel_off_s),
        ms(s.heel_off_s, s.toe_off_s),
        ms(s.toe_off_s, s.heel_strike_s),
        ms(s.heel_strike_s, s.end_s),
    )
}

/// The error and its causes, `: `-separated, each said once: a message that already ends
/// with its cause's text (`{path}: {source}`) does not repeat it.
fn causes(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.ends_with(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}

fn hci_transport(s: &str) -> Result<gaitclip_host::pod::Hci, String> {
    s.parse()
}

fn read_trace(path: &Path, rate: Option<f64>, units: &UnitArgs) -> anyhow::Result<Trace> {
    let o = recording::ReadOptions {
        rate_hz: rate,
        rate_overrides_stamps: units.rate_overrides_stamps,
        units: units.units(path)?,
        front: Front::CommandLine,
    };
    Ok(recording::read(path, &o)?)
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.cmd {
        Cmd::Replay {
            trace,
            rate,
            json,
            detector,
            model,
            all_models,
            mcap_out,
            acc_range_g,
            gyro_range_dps,
            units,
        } => {
            let detector = Detector::from_name(&detector).context("unknown detector")?;
            let model = match model.as_deref() {
                Some(name) => Model::from_name(name).context("unknown model")?,
                None => detector.length_model(gaitclip::pipeline::config::DEFAULT_MODEL),
            };
            if detector
                .own_model()
                .is_some_and(|own| model != own || all_models)
            {
                return Err(UsageError(
                    "the lu detector's steps are measured by Lu's own chain only: --model lu_fuzzy, without --all-models",
                )
                .into());
            }
            // A recording is replayed as a stream, in constant memory
            // (`gaitclip_host::stream`); one written back out (`--mcap-out`), whole.
            let streamed = mcap_out.is_none();
            let (mut t, stream) = if streamed {
                let o = recording::ReadOptions {
                    rate_hz: rate,
                    rate_overrides_stamps: units.rate_overrides_stamps,
                    units: units.units(&trace)?,
                    front: Front::CommandLine,
                };
                let s = gaitclip_host::stream::Streamed::open(&trace, &o)?;
                (Trace::default(), Some(s))
            } else {
                (read_trace(&trace, rate, &units)?, None)
            };
            for (given, name) in [
                (acc_range_g, "--acc-range-g"),
                (gyro_range_dps, "--gyro-range-dps"),
            ] {
                if given.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
                    return Err(UsageError(match name {
                        "--acc-range-g" => "--acc-range-g must be a positive number of g",
                        _ => "--gyro-range-dps must be a positive number of °/s",
                    })
                    .into());
                }
            }
            let show = |s: &replay::StrideReport| -> anyhow::Result<()> {
                if json {
                    println!("{}", serde_json::to_string(s)?);
                } else {
                    println!("{}", text_line(s));
                    if let Some(all) = &s.lengths_m {
                        let cols: Vec<String> =
                            all.iter().map(|(k, v)| format!("{k} {v:.3}")).collect();
                        println!("           {}", cols.join("  "));
                    }
                }
                Ok(())
            };
            let (strides, summary) = match stream {
                Some(mut s) => {
                    s.given.acc_g = acc_range_g.or(s.given.acc_g);
                    s.given.gyro_dps = gyro_range_dps.or(s.given.gyro_dps);
                    let mut failed = None;
                    let (summary, _) = s
                        .replay(Ranges::default(), detector, model, all_models, |r| {
                            if failed.is_none() {
                                failed = show(&r).err();
                            }
                        })
                        // The causes the whole-recording replay would give, typed as its.
                        .map_err(|e| match e {
                            StreamError::Read(r) => anyhow::Error::from(r),
                            StreamError::Replay(r) => anyhow::Error::from(r),
                        })
                        .with_context(|| trace.display().to_string())?;
                    if let Some(e) = failed {
                        return Err(e);
                    }
                    (Vec::new(), summary)
                }
                None => {
                    t.given.acc_g = acc_range_g.or(t.given.acc_g);
                    t.given.gyro_dps = gyro_range_dps.or(t.given.gyro_dps);
                    let (strides, summary) = replay::replay_summarised(
                        &t,
                        Ranges::default(),
                        detector,
                        model,
                        all_models,
                    )
                    .with_context(|| trace.display().to_string())?;
                    strides.iter().try_for_each(show)?;
                    (strides, summary)
                }
            };
            for m in &summary.rejected_movements {
                if json {
                    println!(
                        "{}",
                        serde_json::to_string(&serde_json::json!({ "rejected": m }))?
                    );
                } else {
                    println!(
                        "not a step  start {:8.3} s  dur {:5.3} s  {}  swing {}°  moved {:.3} m",
                        m.start_s,
                        m.end_s - m.start_s,
                        m.reason,
                        m.swing_deg,
                        m.horizontal_m
                    );
                }
            }
            if json {
                println!(
                    "{}",
                    serde_json::to_string(&serde_json::json!({ "summary": summary }))?
                );
            } else {
                println!("{}", summary.line());
            }
            if summary.core_rate_hz < replay::LOW_RATE_HZ {
                eprintln!(
                    "gaitclip: warning: {} is at {:.1} Hz, below {} Hz: gait events are coarse and lengths are not checked at this rate",
                    trace.display(),
                    summary.core_rate_hz,
                    replay::LOW_RATE_HZ
                );
            }
            if let Some(out) = mcap_out {
                let f = std::fs::File::create(&out).map_err(|source| WriteError {
                    path: out.clone(),
                    source,
                })?;
                mcap_io::write(
                    std::io::BufWriter::new(f),
                    &t.samples,
                    &strides,
                    Some(&summary),
                )?;
                eprintln!("wrote {}", out.display());
            }
        }
        Cmd::Pod {
            hci,
            trace,
            rate,
            speed,
            wait_for_central,
            battery_percent,
            detector,
            json,
            units,
        } => {
            if !(speed.is_finite() && speed > 0.0) {
                return Err(UsageError("--speed must be a positive number").into());
            }
            let detector = Detector::from_name(&detector).context("unknown detector")?;
            let t = read_trace(&trace, rate, &units)?;
            gaitclip_host::pod::run(gaitclip_host::pod::PodOptions {
                hci,
                trace: t,
                speed,
                wait_for_central,
                battery_percent,
                configure: Box::new(move |c: &mut Config| {
                    c.detector = detector;
                    c.model = detector.length_model(c.model);
                }),
                json,
            })?;
        }
        Cmd::Gait { datasets } => {
            let mut results = Vec::new();
            for dir in &datasets {
                let d = datasets::load(dir)?;
                results.push((
                    d.name.clone(),
                    gaitclip_host::eval::gait_eval::evaluate(&d)?,
                ));
            }
            print!("{}", gaitclip_host::eval::gait_eval::table(&results));
        }
        Cmd::Eval {
            datasets,
            rotate,
            seed,
            phases,
            plots,
            stance,
        } => {
            let run_with = |which: Detector| {
                scoring::core_detector(move |c: &mut Config| {
                    c.phases = phases.into();
                    c.detector = which;
                    if let Some(limits) = stance {
                        c.stance = limits;
                    }
                })
            };
            let detectors: Vec<(Detector, _)> =
                Detector::ALL.iter().map(|&d| (d, run_with(d))).collect();
            let mut results = Vec::new();
            let mut side_by_side = Vec::new();
            let mut runs = Vec::new();
            let mut loaded = Vec::new();
            let bar = gaitclip_host::progress::bar(
                (datasets.len() * (detectors.len() + 1)) as u64 + 1,
                "eval",
            );
            bar.enable_steady_tick(std::time::Duration::from_millis(500));
            for dir in &datasets {
                bar.set_message(format!("loading {}", dir.display()));
                let d = datasets::load(dir)?;
                loaded.push(d.clone());
                let mut tallies = Vec::new();
                for (k, (which, det)) in detectors.iter().enumerate() {
                    bar.set_message(format!("{}: the {} detector", d.name, which.name()));
                    bar.inc(1);
                    // The default detector gets the rotations and the event table.
                    let r = scoring::evaluate(&d, det, if k == 0 { rotate } else { 0 }, seed)?;
                    tallies.push((*which, r.tally.clone()));
                    if k == 0 {
                        results.push(r);
                    }
                }
                side_by_side.push((d.name.clone(), tallies));
                bar.set_message(format!("{}: every length model", d.name));
                bar.inc(1);
                runs.extend(training_set::run_dataset(&d)?);
            }
            bar.set_message("the recordings as read");
            bar.inc(1);
            let data_table = tables::data_table(&loaded)?;
            bar.finish_and_clear();
            println!("The folders and what their truth scores:\n");
            print!("{}", tables::truth_table(&datasets, &loaded));
            println!("\nThe recordings as read (stamps, repeated samples, holes and what the core did with them):\n");
            print!("{data_table}");
            println!(
                "\nStrides, gait events and phases by the default detector (`{}`):\n",
                Detector::ALL[0].name()
            );
            print!("{}", tables::table(&results));
            let rows: Vec<(&str, &str, &matching::Tally)> = side_by_side
                .iter()
                .flat_map(|(name, t)| t.iter().map(move |(d, t)| (name.as_str(), d.name(), t)))
                .collect();
            println!("\nStep detectors side by side (cycle: every-pace stance instants, the default; stance: Huang's variance + IQR stance detector; lu: Lu's peak-valley detection):\n");
            print!("{}", tables::detectors_table(&rows));
            let trained_on: Vec<&str> = training_set::TRAINING_DATASETS
                .into_iter()
                .filter(|n| {
                    runs.iter().any(|r| {
                        r.dataset == *n
                            && !training_set::samples(std::slice::from_ref(r)).is_empty()
                    })
                })
                .collect();
            if trained_on.len() < training_set::TRAINING_DATASETS.len() {
                // Recordings of one's own (or one training dataset): nothing to train on and
                // leave out, so the models the firmware ships are scored on them as they
                // are, out of sample.
                let shipped = length_eval::shipped_predictions(&runs);
                let scores = length_eval::score(&runs, &shipped);
                println!(
                    "\nStride length by the models the firmware ships (trained on {}; out of sample on recordings they were not trained on). Leave-one-dataset-out needs both training datasets and is not run; no best model is named. Datasets without per-stride lengths: walked-distance error per trial:\n",
                    training_set::TRAINING_DATASETS.join(" and ")
                );
                print!("{}", length_eval::table(&scores));
                println!("\nWalked distance per trial, default model (datasets that give the walk's length):\n");
                print!(
                    "{}",
                    length_eval::walked_table(
                        &runs,
                        &shipped,
                        gaitclip::pipeline::config::DEFAULT_MODEL
                    )
                );
                return Ok(());
            }
            let hyper = fit::hyper_from(&gaitclip::length::trained::HYPER);
            let mut by = Vec::new();
            for v in length_eval::Validation::ALL {
                let (pred, _) = length_eval::predictions(
                    &runs,
                    &hyper,
                    v,
                    gaitclip_host::train::cross_validation::Search::Recorded,
                )?;
                by.push((v, length_eval::score(&runs, &pred), pred));
            }
            let scores: Vec<_> = by.iter().map(|(v, s, _)| (*v, s.clone())).collect();
            println!("\nStride length, every model three ways (in-sample; 5-fold by trial; leave-one-dataset-out: fitted on the other training dataset alone). Datasets without per-stride lengths: walked-distance error per trial:\n");
            print!("{}", length_eval::three_ways_table(&scores));
            let (_, lodo, lodo_pred) = &by[2];
            println!(
                "\nBest leave-one-dataset-out (mean of the two datasets' RMSE): `{}`; the firmware's default: `{}`.",
                length_eval::lodo_best(lodo).name(),
                gaitclip::pipeline::config::DEFAULT_MODEL.name()
            );
            println!(
                "\nLeave-one-dataset-out in full (RMSE / MAE / bias; walked distance per trial):\n"
            );
            print!("{}", length_eval::table(lodo));
            println!("\nLeave-one-dataset-out by stride speed (RMSE / bias cm / distance error of the bin's strides; strides per bin in the header):\n");
            print!(
                "{}",
                length_eval::binned_table(lodo, length_eval::BinBy::Speed)
            );
            println!("\nLeave-one-dataset-out by stride length:\n");
            print!(
                "{}",
                length_eval::binned_table(lodo, length_eval::BinBy::Length)
            );
            println!("\nWalked distance per trial, default model (datasets that give the walk's length; `ipol_gait_events`: 20 m nominal, the U-turn's extra path not counted):\n");
            print!(
                "{}",
                length_eval::walked_table(
                    &runs,
                    lodo_pred,
                    gaitclip::pipeline::config::DEFAULT_MODEL
                )
            );
            if let Some(dir) = plots {
                let model = gaitclip::pipeline::config::DEFAULT_MODEL;
                std::fs::create_dir_all(&dir)?;
                let pairs = length_eval::pairs(&runs, lodo_pred, model);
                let mut files = Vec::new();
                if !pairs.is_empty() {
                    let (ba, sc) = length_eval::plots(&pairs, model.name())?;
                    files.push(("bland_altman.svg", ba));
                    files.push(("scatter.svg", sc));
                }
                files.push((
                    "error_by_speed.svg",
                    length_eval::speed_plot(&runs, lodo_pred, model)?,
                ));
                for (name, svg) in files {
                    let p = dir.join(name);
                    std::fs::write(&p, svg).with_context(|| format!("writing {}", p.display()))?;
                    eprintln!("wrote {}", p.display());
                }
            }
        }
        Cmd::Train { datasets, out } => {
            let bar = gaitclip_host::progress::bar(2, "train");
            bar.enable_steady_tick(std::time::Duration::from_millis(500));
            bar.set_message("replaying the training datasets");
            let runs = training_set::load_training(&datasets)?;
            bar.inc(1);
            bar.set_message("three grid searches of 360 SVR fits each, then every model");
            let t = training::train(&runs)?;
            bar.finish_and_clear();
            std::fs::write(&out, codegen::rust_source(&t))
                .with_context(|| format!("writing {}", out.display()))?;
            eprintln!(
                "trained on {} strides of {} trials; best leave-one-dataset-out (the default): {}; wrote {}",
                t.trained.samples,
                t.trials,
                t.default_model.name(),
                out.display()
            );
        }
        Cmd::Cost {
            plugin,
            criterion,
            gaitmap,
            datasets,
            scratch,
        } => {
            let abs = |p: PathBuf| std::path::absolute(&p).unwrap_or(p);
            let report =
                gaitclip_host::cost::report::report(&gaitclip_host::cost::report::Inputs {
                    plugin: abs(plugin),
                    datasets: abs(datasets),
                    criterion_estimates: abs(criterion),
                    gaitmap_json: abs(gaitmap),
                    scratch: abs(scratch),
                })?;
            print!("{report}");
        }
        Cmd::Energy { m4, m0 } => print!("{}", gaitclip_host::cost::energy::report(m4, m0)),
        Cmd::Wake { datasets } => {
            print!("{}", gaitclip_host::eval::wake_eval::report(&datasets)?.1)
        }
        Cmd::Holes { datasets } => {
            print!("{}", gaitclip_host::eval::hole_sweep::report(&datasets)?);
        }
        Cmd::ZuptSweep { datasets } => {
            print!("{}", gaitclip_host::eval::zupt_sweep::report(&datasets)?);
        }
        Cmd::Bias { datasets } => {
            print!("{}", gaitclip_host::eval::bias::report(&datasets)?);
        }
        Cmd::Events { datasets } => {
            print!("{}", gaitclip_host::eval::event_timing::report(&datasets)?);
        }
        Cmd::Clipping { datasets } => {
            print!("{}", gaitclip_host::eval::clip_sweep::report(&datasets)?);
        }
        Cmd::Sprint => {
            print!(
                "{}",
                gaitclip_host::eval::sprint_sim::report(std::path::Path::new("."))?
            );
        }
        Cmd::Rates { datasets } => {
            print!("{}", gaitclip_host::eval::rate_sweep::report(&datasets)?);
        }
        Cmd::Running { datasets } => {
            print!("{}", gaitclip_host::eval::running::report(&datasets)?);
        }
        Cmd::Constraints { datasets } => {
            print!("{}", gaitclip_host::eval::constraints::report(&datasets)?);
        }
        Cmd::Course { datasets } => {
            print!("{}", gaitclip_host::eval::course::report(&datasets)?);
        }
        Cmd::Daily { dir } => print!("{}", gaitclip_host::eval::daily::report(&dir)?),
        Cmd::Flags { datasets } => {
            print!("{}", gaitclip_host::eval::flag_costs::report(&datasets)?);
        }
        Cmd::Docs { datasets, check } => {
            let exe = std::env::current_exe().context("the path of this binary")?;
            let pages = gaitclip_host::eval::docs::regenerate(
                &gaitclip_host::eval::docs::docs_dir(),
                &datasets,
                &exe,
            )?;
            let mut stale = Vec::new();
            for p in &pages {
                if p.stale.is_empty() {
                    continue;
                }
                stale.push(format!("{}: {}", p.path.display(), p.stale.join(", ")));
                if !check {
                    std::fs::write(&p.path, &p.text).map_err(|source| WriteError {
                        path: p.path.clone(),
                        source,
                    })?;
                }
            }
            match (check, stale.is_empty()) {
                (_, true) => eprintln!("docs: every generated block is current"),
                (false, false) => eprintln!("docs: rewrote {}", stale.join("; ")),
                (true, false) => anyhow::bail!("docs: stale blocks: {}", stale.join("; ")),
            }
        }
        Cmd::Simulate { out } => {
            fixtures::write_all(&out)?;
            eprintln!("wrote fixtures to {}", out.display());
        }
    }
    Ok(())
}

//! `gaitclip`: the host command line.
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};
use gaitclip::phases::PhaseMethod;
use gaitclip::pipeline::Config;
use gaitclip_host::eval::{self, Detected};
use gaitclip_host::trace::{Ranges, Trace};
use gaitclip_host::{csv_trace, fixtures, mcap_io, replay};

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
        /// Also write the samples and the strides to this MCAP file (opens in Foxglove).
        #[arg(long, value_name = "FILE")]
        mcap_out: Option<PathBuf>,
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
    },
    /// Regenerate the simulated fixtures (traces with ground truth) into a folder.
    Simulate {
        /// Output folder.
        #[arg(long, default_value = "../fixtures")]
        out: PathBuf,
    },
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gaitclip: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn read_trace(path: &Path, rate: Option<f64>) -> anyhow::Result<Trace> {
    let is_mcap = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    Ok(if is_mcap {
        mcap_io::read(path, rate)?
    } else {
        csv_trace::read(path, rate)?
    })
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.cmd {
        Cmd::Replay {
            trace,
            rate,
            json,
            mcap_out,
        } => {
            let t = read_trace(&trace, rate)?;
            let strides = replay::replay(&t, Ranges::default())?;
            for s in &strides {
                if json {
                    println!("{}", serde_json::to_string(s)?);
                } else {
                    println!(
                        "stride {:3}  start {:8.3} s  dur {:5.3} s  length {:5.3} m  phases {:3.0}/{:3.0}/{:3.0}/{:3.0} ms{}",
                        s.index,
                        s.start_s,
                        s.end_s - s.start_s,
                        s.length_m,
                        (s.heel_off_s - s.start_s) * 1e3,
                        (s.toe_off_s - s.heel_off_s) * 1e3,
                        (s.heel_strike_s - s.toe_off_s) * 1e3,
                        (s.end_s - s.heel_strike_s) * 1e3,
                        if s.valid { String::new() } else { format!("  INVALID ({})", s.flags.join(",")) }
                    );
                }
            }
            let total: f64 = strides.iter().map(|s| s.length_m).sum();
            eprintln!("{} strides, {:.3} m in total", strides.len(), total);
            if let Some(out) = mcap_out {
                let f = std::fs::File::create(&out)
                    .with_context(|| format!("creating {}", out.display()))?;
                mcap_io::write(std::io::BufWriter::new(f), &t.samples, &strides)?;
                eprintln!("wrote {}", out.display());
            }
        }
        Cmd::Eval {
            datasets,
            rotate,
            seed,
            phases,
        } => {
            let detector = |t: &Trace, r: Ranges| -> anyhow::Result<Vec<Detected>> {
                let rate = t
                    .sample_rate()
                    .ok_or(replay::ReplayError::Rate(t.rate_hz))?;
                let mut config = Config::new(rate, r.accel, r.gyro);
                config.phases = phases.into();
                let counts: Vec<_> = t.samples.iter().map(|s| r.to_counts(s)).collect();
                Ok(replay::core_strides(&counts, config)
                    .iter()
                    .map(Detected::from)
                    .collect())
            };
            let mut results = Vec::new();
            for dir in &datasets {
                let d = eval::load(dir)?;
                results.push(eval::evaluate(&d, &detector, rotate, seed)?);
            }
            print!("{}", eval::table(&results));
        }
        Cmd::Simulate { out } => {
            fixtures::write_all(&out)?;
            eprintln!("wrote fixtures to {}", out.display());
        }
    }
    Ok(())
}

//! `gaitclip`: the host command line.
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use gaitclip_host::{csv_trace, fixtures, replay, trace::Ranges};

#[derive(Parser)]
#[command(name = "gaitclip", version, about = "Replay IMU traces through the gaitclip firmware core")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Replay a CSV or MCAP trace and print one line per stride.
    Replay {
        /// The trace (.csv, .mcap).
        trace: PathBuf,
        /// Sample rate in Hz (default: meta.json beside the file, else the timestamps).
        #[arg(long)]
        rate: Option<f64>,
        /// One JSON object per stride per line.
        #[arg(long)]
        json: bool,
    },
    /// Regenerate the simulated fixtures (traces with ground truth) into a folder.
    Simulate {
        /// Output folder.
        #[arg(long, default_value = "../fixtures")]
        out: PathBuf,
    },
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

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.cmd {
        Cmd::Replay { trace, rate, json } => {
            let t = csv_trace::read(&trace, rate)?;
            let strides = replay::replay(&t, Ranges::default())?;
            for s in &strides {
                if json {
                    println!("{}", serde_json::to_string(s)?);
                } else {
                    println!(
                        "stride {:3} start {:8.3} s dur {:5.3} s length {:5.3} m valid {}",
                        s.index, s.start_s, s.end_s - s.start_s, s.length_m, s.valid
                    );
                }
            }
            let total: f64 = strides.iter().map(|s| s.length_m).sum();
            eprintln!("{} strides, {:.2} m", strides.len(), total);
        }
        Cmd::Simulate { out } => {
            fixtures::write_all(&out)?;
            eprintln!("wrote fixtures to {}", out.display());
        }
    }
    Ok(())
}

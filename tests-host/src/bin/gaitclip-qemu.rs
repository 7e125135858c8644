//! `gaitclip-qemu [--fast] [--machine M] ELF`: runs gaitclip firmware in QEMU, prints its defmt
//! log as text and exits with the firmware's exit status. Used as the cargo runner of the
//! firmware crate (through `boards/qemu-run`).
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use gaitclip_host::cost::qemu::{self, RunOptions};

#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// QEMU machine.
    #[arg(long, default_value = qemu::MACHINE_M4)]
    machine: String,
    /// Virtual time that skips idle periods: fast and repeatable instead of real time.
    #[arg(long)]
    fast: bool,
    /// The firmware ELF.
    elf: PathBuf,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let opts = RunOptions {
        machine: a.machine,
        fast: a.fast,
        extra_args: Vec::new(),
    };
    match qemu::run(&a.elf, &opts, |l| println!("{l}")) {
        Ok(out) if out.status == 0 => ExitCode::SUCCESS,
        Ok(out) => {
            eprintln!("gaitclip-qemu: firmware exited with status {}", out.status);
            ExitCode::from(1)
        }
        Err(e) => {
            eprintln!("gaitclip-qemu: {e:#}");
            ExitCode::from(2)
        }
    }
}

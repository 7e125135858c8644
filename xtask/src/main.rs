//! `cargo emulate` (an alias in `.cargo/config.toml`): runs the firmware on the emulated
//! board, after making sure the machine can build it.
//!
//! A plain `cargo run --target thumbv7em-none-eabihf` fails with "can't find crate for
//! `core`" where the pinned toolchain is installed without its Cortex-M targets: rustup adds
//! the targets of `rust-toolchain.toml` only when it installs the toolchain, not to one that
//! is already there. This task runs on the host target, which every toolchain has, and
//! readies the rest before building the firmware:
//!
//! 1. `rustup toolchain install` — the pinned toolchain with its targets and components
//!    (quick and idempotent when they are there);
//! 2. flip-link, the firmware's linker (`cargo install --locked flip-link` when missing);
//! 3. `qemu-system-arm` (`boards/install-qemu`, from Debian when missing);
//!
//! then `cargo run --release -p <board> --target <its target> <args>`, whose runner
//! (`boards/run`) starts QEMU and decodes the defmt log.
//!
//! `cargo emulate [--board mps2-an386|microbit] [CARGO ARGS…] [-- RUNNER ARGS…]`: e.g.
//! `cargo emulate --features peak-valley-detector`, `cargo emulate -- --fast`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

/// The emulated boards: package and target.
const BOARDS: [(&str, &str, &str); 2] = [
    ("mps2-an386", "gaitclip-mps2-an386", "thumbv7em-none-eabihf"),
    ("microbit", "gaitclip-microbit", "thumbv6m-none-eabi"),
];

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) != Some("emulate") {
        eprintln!(
            "usage: cargo emulate [--board mps2-an386|microbit] [CARGO ARGS…] [-- RUNNER ARGS…]"
        );
        return ExitCode::from(2);
    }
    args.remove(0);
    let mut board = BOARDS[0];
    // `--board` is ours, before any `--`; the rest goes to `cargo run` as written.
    let ours = args.iter().position(|a| a == "--").unwrap_or(args.len());
    if let Some(i) = args[..ours].iter().position(|a| a == "--board") {
        let name = args.get(i + 1).cloned().unwrap_or_default();
        match BOARDS.iter().find(|b| b.0 == name) {
            Some(b) => board = *b,
            None => {
                let names: Vec<&str> = BOARDS.iter().map(|b| b.0).collect();
                eprintln!(
                    "--board {name:?}: the emulated boards are {}",
                    names.join(", ")
                );
                return ExitCode::from(2);
            }
        }
        args.drain(i..(i + 2).min(args.len()));
    }
    match emulate(board, &args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("cargo emulate: {e}");
            ExitCode::FAILURE
        }
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Runs `cmd`, an error naming it when it cannot start or fails.
fn run(cmd: &mut Command) -> Result<(), String> {
    let what = format!("{cmd:?}");
    match cmd.status() {
        Ok(s) if s.success() => Ok(()),
        Ok(s) => Err(format!("{what} failed ({s})")),
        Err(e) => Err(format!("{what} could not start: {e}")),
    }
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).any(|d| d.join(program).is_file()))
        .unwrap_or(false)
}

fn emulate(
    (name, package, target): (&str, &str, &str),
    args: &[String],
) -> Result<ExitCode, String> {
    let root = root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    eprintln!("== cargo emulate: the pinned toolchain with its targets (rustup toolchain install)");
    // rustup reads rust-toolchain.toml in the current folder, unless RUSTUP_TOOLCHAIN (which
    // rustup's cargo proxy set for this process) overrides it: then it would install the
    // toolchain by name, without the file's targets.
    run(Command::new("rustup")
        .args(["toolchain", "install"])
        .env_remove("RUSTUP_TOOLCHAIN")
        .current_dir(&root))?;
    if !on_path("flip-link") {
        eprintln!("== flip-link is missing: cargo install --locked flip-link");
        run(Command::new(&cargo).args(["install", "--locked", "flip-link"]))?;
    }
    run(Command::new("bash").arg(root.join("boards/install-qemu")))?;
    eprintln!("== the firmware on the emulated {name} ({target})");
    let status = Command::new(&cargo)
        .args(["run", "--release", "-p", package, "--target", target])
        .args(args)
        .current_dir(&root)
        .status()
        .map_err(|e| format!("{cargo} run could not start: {e}"))?;
    Ok(match status.code() {
        Some(c) => ExitCode::from(c.clamp(0, 255) as u8),
        None => ExitCode::FAILURE,
    })
}

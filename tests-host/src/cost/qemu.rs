//! Runs a firmware ELF in QEMU and decodes its defmt log (semihosting transport) to text.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{bail, Context};

/// QEMU machines gaitclip firmware runs on.
pub const MACHINE_M4: &str = "mps2-an386";
/// The Cortex-M0 machine: BBC micro:bit (nRF51822, 16 KiB RAM).
pub const MACHINE_M0: &str = "microbit";

/// For tests: true when `qemu-system-arm` runs; otherwise prints that the test was
/// skipped and returns false. In CI (`CI=true`) a missing QEMU is a failure, not a skip.
pub fn available_or_skip() -> bool {
    let ok = Command::new("qemu-system-arm")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            !std::env::var("CI").is_ok_and(|v| v == "true"),
            "qemu-system-arm is missing in CI (apt-get install qemu-system-arm)"
        );
        eprintln!("SKIPPED: qemu-system-arm is not installed");
    }
    ok
}

/// How to run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// QEMU machine name.
    pub machine: String,
    /// Deterministic virtual time that skips idle periods (`-icount shift=0,sleep=off`): the
    /// run takes milliseconds instead of the trace's duration, and is repeatable.
    pub fast: bool,
    /// Extra QEMU arguments (a `-plugin` for instruction counts, say).
    pub extra_args: Vec<String>,
}

/// Output of a run.
#[derive(Clone, Debug)]
pub struct RunOutput {
    /// Decoded log lines, in order.
    pub lines: Vec<String>,
    /// QEMU's exit status (the firmware's semihosting exit code).
    pub status: i32,
}

/// Runs `elf`, calling `on_line` for each decoded log line as it arrives.
pub fn run(
    elf: &Path,
    opts: &RunOptions,
    mut on_line: impl FnMut(&str),
) -> anyhow::Result<RunOutput> {
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let table = defmt_decoder::Table::parse(&bytes)
        .with_context(|| format!("reading the defmt table of {}", elf.display()))?
        .with_context(|| format!("{} has no defmt data", elf.display()))?;
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args([
        "-M",
        &opts.machine,
        "-nographic",
        "-monitor",
        "none",
        "-serial",
        "none",
    ])
    .args(["-semihosting-config", "enable=on,target=native"]);
    if opts.fast {
        cmd.args(["-icount", "shift=0,sleep=off"]);
    }
    cmd.args(&opts.extra_args);
    cmd.arg("-kernel").arg(elf);
    let mut child = cmd
        .stdout(Stdio::piped())
        .stdin(Stdio::null())
        .spawn()
        .context("starting qemu-system-arm (install it: apt-get install qemu-system-arm)")?;
    let mut stdout = child.stdout.take().context("qemu stdout")?;
    let mut decoder = table.new_stream_decoder();
    let mut lines = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        let n = stdout.read(&mut buf).context("reading qemu output")?;
        if n == 0 {
            break;
        }
        decoder.received(&buf[..n]);
        loop {
            match decoder.decode() {
                Ok(frame) => {
                    let line = frame.display_message().to_string();
                    on_line(&line);
                    lines.push(line);
                }
                Err(defmt_decoder::DecodeError::UnexpectedEof) => break,
                Err(defmt_decoder::DecodeError::Malformed) => {
                    bail!("malformed defmt frame in the firmware output")
                }
            }
        }
    }
    let status = child.wait().context("waiting for qemu")?;
    Ok(RunOutput {
        lines,
        status: status.code().unwrap_or(-1),
    })
}

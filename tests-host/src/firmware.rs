//! Builds a board's firmware (a package of the root workspace, under `boards/`) and parses its
//! stride log, for tests that compare it with the host replay.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};

/// The repository root (the core library and the firmware's workspace).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Builds `bin` for `target` in release mode from the board package in `dir` (relative to the
/// repository root: `boards/mps2-an386`, `boards/bench`, …) and returns the ELF path.
pub fn build_in(dir: &str, bin: &str, target: &str) -> anyhow::Result<PathBuf> {
    build_with(dir, bin, target, &[], &[])
}

/// [`build_in`] with extra cargo arguments (`--features …`) and environment variables (a
/// `CARGO_TARGET_DIR` among them, relative to the repository root, keeps a variant's ELF
/// apart from the workspace's `target/`).
pub fn build_with(
    dir: &str,
    bin: &str,
    target: &str,
    args: &[&str],
    env: &[(&str, &std::ffi::OsStr)],
) -> anyhow::Result<PathBuf> {
    let root = repo_root();
    let target_dir = env
        .iter()
        .find(|(k, _)| *k == "CARGO_TARGET_DIR")
        .map_or_else(|| root.join("target"), |(_, v)| root.join(v));
    let status = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .current_dir(root.join(dir))
        .env_remove("CARGO_BUILD_TARGET")
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("CARGO_TARGET_DIR")
        .envs(
            env.iter()
                .copied()
                .filter(|(k, _)| *k != "CARGO_TARGET_DIR"),
        )
        .args(["build", "--release", "--bin", bin, "--target", target])
        .arg("--target-dir")
        .arg(&target_dir)
        .args(args)
        .status()
        .context("running cargo build for the firmware")?;
    if !status.success() {
        bail!("firmware build failed ({status})");
    }
    Ok(target_dir.join(target).join("release").join(bin))
}

/// The cargo feature, on every board and the benchmark, that builds the firmware with Lu's
/// peak-valley detector instead of the stance detector.
pub const PEAK_VALLEY_FEATURE: &str = "peak-valley-detector";

/// [`build_with`] for `detector`: with [`Detector::PeakValley`], the firmware built with
/// [`PEAK_VALLEY_FEATURE`] into `target/peak-valley`, so that the default build's ELF stays.
pub fn build_for(
    dir: &str,
    bin: &str,
    target: &str,
    detector: gaitclip::pipeline::Detector,
    env: &[(&str, &std::ffi::OsStr)],
) -> anyhow::Result<PathBuf> {
    use gaitclip::pipeline::Detector;
    match detector {
        // The firmware's default detector.
        Detector::Cycle => build_with(dir, bin, target, &[], env),
        Detector::PeakValley => {
            let mut env = env.to_vec();
            env.push(("CARGO_TARGET_DIR", "target/peak-valley".as_ref()));
            build_with(dir, bin, target, &["--features", PEAK_VALLEY_FEATURE], &env)
        }
        other => {
            anyhow::bail!(
                "the firmware runs the cycle or the peak-valley detector, not {}",
                other.name()
            )
        }
    }
}

/// The integers of one `stride …` log line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoggedStride {
    /// Stride index.
    pub index: u32,
    /// start, heel_off, toe_off, heel_strike, end sample indices.
    pub idx: [u32; 5],
    /// Length, mm.
    pub length_mm: u32,
    /// Climb, mm.
    pub climb_mm: i32,
    /// Flag bits.
    pub flags: u16,
}

/// Parses a line written by `boards/common/stride_log.rs`; `None` for other lines.
pub fn parse_stride_line(line: &str) -> Option<LoggedStride> {
    let rest = line.strip_prefix("stride ")?;
    let mut fields = rest.split_whitespace();
    let index = fields.next()?.parse().ok()?;
    let (mut len, mut climb, mut flags, mut idx) = (None, None, None, None);
    for f in fields {
        if let Some(v) = f.strip_prefix("len=") {
            len = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("climb=") {
            climb = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("flags=") {
            flags = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("idx=") {
            let v: Vec<u32> = v.split(',').filter_map(|x| x.parse().ok()).collect();
            idx = v.try_into().ok();
        }
    }
    Some(LoggedStride {
        index,
        idx: idx?,
        length_mm: len?,
        climb_mm: climb?,
        flags: flags?,
    })
}

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
        // Built as shipped: not through clippy-driver, which does not generate rustc's code
        // (the test command lints the host crates through it).
        .env_remove("RUSTC_WORKSPACE_WRAPPER")
        .env_remove("CLIPPY_ARGS")
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
    detector: gaitclip::pipeline::detectors::Detector,
    env: &[(&str, &std::ffi::OsStr)],
) -> anyhow::Result<PathBuf> {
    use gaitclip::pipeline::detectors::Detector;
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
    /// Gait parameters: stance time, swing time (ms), stance ‰, velocity (mm/s), cadence
    /// (steps/min), lift (mm), heading change (centidegrees), and the gait's name.
    pub gait: [i32; 7],
    /// `walking`, `running`, `stairs_up`, `stairs_down` or `unknown`.
    pub gait_name: String,
    /// The swing, degrees, and the time before the stride since the last one: still and
    /// moving, ms.
    pub swing_and_before: [u32; 3],
}

impl LoggedStride {
    /// What the firmware logs of a stride.
    pub fn of(s: &gaitclip::record::stride::Stride) -> Self {
        let g = &s.gait;
        LoggedStride {
            index: s.index,
            idx: [
                s.events.start,
                s.events.heel_off,
                s.events.toe_off,
                s.events.heel_strike,
                s.events.end,
            ],
            length_mm: s.length_mm,
            climb_mm: s.climb_mm,
            flags: s.flags.0,
            gait: [
                g.stance_time_ms as i32,
                g.swing_time_ms as i32,
                g.stance_permille as i32,
                g.gait_velocity_mm_s as i32,
                g.cadence_spm as i32,
                s.max_sensor_lift_mm as i32,
                s.turning_angle_cdeg as i32,
            ],
            gait_name: g.gait.name().to_string(),
            swing_and_before: [s.swing_deg as u32, s.between.still_ms, s.between.moving_ms],
        }
    }
}

/// Parses a line written by `boards/common/stride_log.rs`; `None` for other lines.
pub fn parse_stride_line(line: &str) -> Option<LoggedStride> {
    let rest = line.strip_prefix("stride ")?;
    let mut fields = rest.split_whitespace();
    let index = fields.next()?.parse().ok()?;
    let (mut len, mut climb, mut flags, mut idx) = (None, None, None, None);
    let (mut gait, mut gait_name, mut swing, mut before) = (None, None, None, None);
    let mut after_gait = false;
    for f in fields {
        if after_gait {
            gait_name = Some(f.to_string());
            after_gait = false;
            continue;
        }
        if let Some(v) = f.strip_prefix("len=") {
            len = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("climb=") {
            climb = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("flags=") {
            flags = v.parse().ok();
        } else if let Some(v) = f.strip_prefix("idx=") {
            let v: Vec<u32> = v.split(',').filter_map(|x| x.parse().ok()).collect();
            idx = v.try_into().ok();
        } else if let Some(v) = f.strip_prefix("swing=") {
            swing = v.parse::<u32>().ok();
        } else if let Some(v) = f.strip_prefix("before=") {
            let v: Vec<u32> = v.split(',').filter_map(|x| x.parse().ok()).collect();
            before = <[u32; 2]>::try_from(v).ok();
        } else if let Some(v) = f.strip_prefix("gait=") {
            let v: Vec<i32> = v.split(',').filter_map(|x| x.parse().ok()).collect();
            gait = v.try_into().ok();
            after_gait = true;
        }
    }
    Some(LoggedStride {
        index,
        idx: idx?,
        length_mm: len?,
        climb_mm: climb?,
        flags: flags?,
        gait: gait?,
        gait_name: gait_name?,
        swing_and_before: {
            let b = before?;
            [swing?, b[0], b[1]]
        },
    })
}

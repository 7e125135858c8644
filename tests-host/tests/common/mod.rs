//! What the CLI tests share: running the `gaitclip` binary this package built, and folders of
//! their own to write into.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `gaitclip args`: its exit status, standard output and standard error.
pub fn gaitclip(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A simulated recording of ours in `fixtures/` (no third-party data).
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures")
        .join(name)
}

/// An empty folder of this test process's own, `tag` naming it.
pub fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gaitclip-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

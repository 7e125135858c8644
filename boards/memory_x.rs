//! The build script of every board package (`build = "../memory_x.rs"` in its Cargo.toml):
//! puts the board's `memory.x`, beside its Cargo.toml, on the linker search path, where
//! cortex-m-rt's `link.x` includes it.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let memory = dir.join("memory.x");
    fs::copy(&memory, out.join("memory.x")).expect("memory.x is beside the board's Cargo.toml");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
}

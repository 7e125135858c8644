//! Picks the memory map of the board the target runs on (mps2-an386 for thumbv7em, the
//! micro:bit for thumbv6m) and the trace to replay: `GAITCLIP_BENCH_TRACE` names a trace
//! module written by `gaitclip cost` (a real recording, kept out of the repository), else the
//! simulated demo walk of `fixtures/` is used.
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let armv6m = target.starts_with("thumbv6m");
    let memory = if armv6m {
        "../microbit/memory.x"
    } else {
        "../../memory.x"
    };
    fs::copy(memory, out.join("memory.x")).expect("the board's memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo::rustc-check-cfg=cfg(armv6m)");
    if armv6m {
        println!("cargo:rustc-cfg=armv6m");
    }

    println!("cargo:rerun-if-env-changed=GAITCLIP_BENCH_TRACE");
    let module = env::var_os("GAITCLIP_BENCH_TRACE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../../fixtures/demo_walk.rs"));
    println!("cargo:rerun-if-changed={}", module.display());
    let text = fs::read_to_string(&module)
        .unwrap_or_else(|e| panic!("reading the trace module {}: {e}", module.display()));
    // Inner doc comments cannot sit in an `include!`d file; the registers file is named by
    // the module's `include_bytes!` relative to it, so it is copied beside it.
    let body: String = text
        .lines()
        .filter(|l| !l.starts_with("//!"))
        .map(|l| format!("{l}\n"))
        .collect();
    fs::write(out.join("trace.rs"), body).expect("writing trace.rs");
    let registers = text
        .split("include_bytes!(\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .expect("the trace module includes its registers file");
    let from = module.with_file_name(registers);
    println!("cargo:rerun-if-changed={}", from.display());
    fs::copy(&from, out.join(registers))
        .unwrap_or_else(|e| panic!("copying {}: {e}", from.display()));
}

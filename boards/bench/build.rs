//! Picks the memory map of the board the target runs on (mps2-an386 for thumbv7em, the
//! micro:bit for thumbv6m) and the trace to replay: `GAITCLIP_BENCH_TRACE` names a trace
//! module written by `gaitclip cost` (a real recording, kept out of the repository), else the
//! simulated demo walk of `fixtures/` is used. The trace is stored without its temperature
//! registers (see [`motion_registers`]).
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let armv6m = target.starts_with("thumbv6m");
    let memory = if armv6m {
        "../microbit/memory.x"
    } else {
        "../mps2-an386/memory.x"
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
    let registers = text
        .split("include_bytes!(\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .expect("the trace module includes its registers file");
    let from = module.with_file_name(registers);
    println!("cargo:rerun-if-changed={}", from.display());
    let bytes = fs::read(&from).unwrap_or_else(|e| panic!("reading {}: {e}", from.display()));
    let (motion, temperature) =
        motion_registers(&bytes).unwrap_or_else(|e| panic!("the trace {}: {e}", from.display()));
    fs::write(out.join("motion.bin"), motion).expect("writing motion.bin");
    // Inner doc comments cannot sit in an `include!`d file, and the registers are replaced
    // by their compact form below.
    let mut body: String = text
        .lines()
        .filter(|l| !l.starts_with("//!") && !l.contains("REGISTERS"))
        .map(|l| format!("{l}\n"))
        .collect();
    body.push_str(&format!(
        "/// Every sample's accelerometer and gyroscope registers (0x3B..=0x40, 0x43..=0x48), \
         {MOTION_BYTES} bytes each.\n\
         pub static MOTION_REGISTERS: &[u8] = include_bytes!(\"motion.bin\");\n\
         /// The temperature registers (0x41, 0x42), the same in every sample.\n\
         pub const TEMPERATURE: [u8; 2] = {temperature:?};\n\
         /// Bytes per sample in [`MOTION_REGISTERS`].\n\
         pub const MOTION_BYTES: usize = {MOTION_BYTES};\n"
    ));
    fs::write(out.join("trace.rs"), body).expect("writing trace.rs");
}

/// A sample's register block (0x3B..=0x48): accelerometer, temperature, gyroscope.
const SAMPLE_BYTES: usize = 14;
/// Its accelerometer and gyroscope bytes.
const MOTION_BYTES: usize = 12;

/// The registers without the temperature, which the pipeline never reads: a real trace of
/// 7 928 samples is then 95 kB instead of 111 kB, which leaves the micro:bit's 256 KiB of
/// flash room for the firmware. The temperature must be the same in every sample (the
/// recordings have none; the demo walk's is constant), so the benchmark can put it back and
/// feed the pipeline exactly the trace's bytes.
fn motion_registers(bytes: &[u8]) -> Result<(Vec<u8>, [u8; 2]), String> {
    if !bytes.len().is_multiple_of(SAMPLE_BYTES) {
        return Err(format!(
            "{} bytes, not a whole number of {SAMPLE_BYTES}-byte samples",
            bytes.len()
        ));
    }
    let temperature = match bytes.get(6..8) {
        Some(&[h, l]) => [h, l],
        _ => return Err("no samples".into()),
    };
    let mut motion = Vec::with_capacity(bytes.len() / SAMPLE_BYTES * MOTION_BYTES);
    for (i, s) in bytes.chunks_exact(SAMPLE_BYTES).enumerate() {
        if s[6..8] != temperature {
            return Err(format!(
                "sample {i} has temperature registers {:?}, sample 0 {temperature:?}; the \
                 benchmark stores one temperature",
                &s[6..8]
            ));
        }
        motion.extend_from_slice(&s[..6]);
        motion.extend_from_slice(&s[8..]);
    }
    Ok((motion, temperature))
}

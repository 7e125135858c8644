//! Cost benchmark firmware: replays a trace stored in flash through the core, with each step
//! whose instructions `gaitclip cost` counts in a function of its own, called with `bl`:
//!
//! * [`bench_sample`]: one sample from its 14 register bytes through [`Pipeline::process`].
//!   Inside it, the per-stride work runs in `CycleDetector::close` (phases, phase statistics,
//!   the ZUPT displacement with its tilt restored) and `LengthChain::measure` (features and the default model), which
//!   the counting plugin measures apart, so the per-sample figure is the sample path alone.
//! * [`bench_features`] and [`bench_model`]: the features of each stride and every model this
//!   build carries, one call each, in [`Model::ALL`] order (printed at the end).
//!
//! With the `peak-valley-detector` feature the pipeline runs Lu's detector instead: the
//! sample path then covers its low-pass and rules, and each step's length (Lu's chain) is
//! counted in `gaitclip::length::lu::lu_chain_um`; there are no features or models to call.
//!
//! No interrupts run: the counts are the pipeline's own. The board is the QEMU machine of the
//! target (mps2-an386 for thumbv7em, microbit for thumbv6m), with the movement buffer of the
//! firmware that board ships.

#![no_std]
#![no_main]

mod trace {
    include!(concat!(env!("OUT_DIR"), "/trace.rs"));
}

use core::hint::black_box;

use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::debug;
use defmt_semihosting as _;
use gaitclip::detect::phase_stats::StrideStats;
use gaitclip::length::features::Features;
use gaitclip::length::models::{self, Model, Settings};
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;
use gaitclip_board::Steps;
use gaitclip_mpu6050::{AccelRange, GyroRange, SAMPLE_BYTES};
use static_cell::ConstStaticCell;

/// The movement buffer of the firmware on the same board (see `boards/microbit/main.rs`).
#[cfg(armv6m)]
const MOVEMENT_SAMPLES: usize = 256;
#[cfg(not(armv6m))]
const MOVEMENT_SAMPLES: usize =
    gaitclip::detect::seam::movement_samples(trace::RATE_MILLIHERTZ.div_ceil(1000));

const fn unwrap<T: Copy>(v: Option<T>) -> T {
    match v {
        Some(v) => v,
        None => panic!("the trace module's rate and ranges are checked at compile time"),
    }
}

const RATE: SampleRate = unwrap(SampleRate::from_millihertz(trace::RATE_MILLIHERTZ));
const CONFIG: Config = {
    let mut c = Config::new(
        RATE,
        unwrap(AccelRange::from_afs_sel(trace::ACCEL_AFS_SEL)).scale(),
        unwrap(GyroRange::from_fs_sel(trace::GYRO_FS_SEL)).scale(),
    );
    c.detector = gaitclip_board::DETECTOR;
    c
};

/// The pipeline with the firmware's detector (the cycle detector, or Lu's with the
/// `peak-valley-detector` feature), as the board ships it.
type BenchPipeline = Pipeline<Steps<MOVEMENT_SAMPLES>>;
static PIPELINE: ConstStaticCell<BenchPipeline> = ConstStaticCell::new(Pipeline::with_detector(
    CONFIG,
    Steps::new(&CONFIG.detect()),
));

/// What the benchmark found: strides and their summed length.
#[derive(Default)]
struct Totals {
    strides: u32,
    distance_mm: u64,
}

#[entry]
fn main() -> ! {
    let pipeline = PIPELINE.take();
    let (mut samples, mut totals) = (0u32, Totals::default());
    for block in trace::MOTION_REGISTERS.chunks_exact(trace::MOTION_BYTES) {
        samples += 1;
        if let Ok(motion) = <&[u8; trace::MOTION_BYTES]>::try_from(block) {
            if let Some(s) = bench_sample(pipeline, &registers(motion)) {
                on_stride(&mut totals, pipeline, &s);
            }
        }
    }
    drain(pipeline, &mut totals);
    defmt::println!(
        "bench samples={=u32} strides={=u32} distance_mm={=u64}",
        samples,
        totals.strides,
        totals.distance_mm
    );
    // The order of the `bench_model` calls of each stride.
    if CONFIG.detector != Detector::PeakValley {
        for model in Model::ALL.iter().filter(|m| CONFIG.params.ships(**m)) {
            defmt::println!("bench model={=str}", model.name());
        }
    }
    defmt::println!("bench default={=str}", CONFIG.length_model().name());
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
}

/// Counts a stride and, unless it is a peak-valley step, calls its features and every model.
// Not inlined, nor is `drain`: their strides and features (≈ 1.3 KiB) would otherwise sit in
// `main`'s frame under the whole sample path, and the M0's stack is ≈ 8 KiB.
#[inline(never)]
fn on_stride(totals: &mut Totals, pipeline: &BenchPipeline, s: &Stride) {
    totals.strides += 1;
    totals.distance_mm += u64::from(s.length_mm);
    if CONFIG.detector == Detector::PeakValley {
        // Lu's chain measured the step inside the pipeline; no features, no models.
        return;
    }
    let Some(stats) = pipeline.stats(s) else {
        // A gap stride: no length, no features.
        return;
    };
    let f = bench_features(s, stats);
    for model in Model::ALL {
        if CONFIG.params.ships(model) {
            bench_model(model, &f);
        }
    }
}

/// The strides still held at the end of the trace.
#[inline(never)]
fn drain(pipeline: &mut BenchPipeline, totals: &mut Totals) {
    while let Some(s) = pipeline.finish() {
        on_stride(totals, pipeline, &s);
    }
}

/// A sample's register block as the sensor gives it, from its stored accelerometer and
/// gyroscope bytes and the trace's temperature (see `build.rs`).
const fn registers(motion: &[u8; trace::MOTION_BYTES]) -> [u8; SAMPLE_BYTES] {
    let mut regs = [0u8; SAMPLE_BYTES];
    let mut i = 0;
    while i < 6 {
        regs[i] = motion[i];
        regs[i + 8] = motion[i + 6];
        i += 1;
    }
    regs[6] = trace::TEMPERATURE[0];
    regs[7] = trace::TEMPERATURE[1];
    regs
}

/// One sample through the per-sample path: decoding its registers and the pipeline.
#[inline(never)]
fn bench_sample(pipeline: &mut BenchPipeline, regs: &[u8; SAMPLE_BYTES]) -> Option<Stride> {
    let s = gaitclip_mpu6050::sample::from_be_bytes(regs);
    // black_box keeps the call a `bl` with a return (no tail call) for the counter to see.
    black_box(pipeline.process(&s))
}

/// The features of one stride.
#[inline(never)]
fn bench_features(s: &Stride, stats: &StrideStats) -> Features {
    black_box(Features::of(s, stats, RATE))
}

/// One model's length of one stride.
#[inline(never)]
fn bench_model(model: Model, f: &Features) -> Option<u32> {
    black_box(models::predict_mm(
        model,
        f,
        Settings::DEFAULT,
        CONFIG.params,
    ))
}

#[exception]
unsafe fn HardFault(_ef: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::println!("bench: hard fault");
    debug::exit(debug::EXIT_FAILURE);
    // Without a debugger attached semihosting returns: sleep.
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::println!("bench: {}", defmt::Display2Format(info));
    debug::exit(debug::EXIT_FAILURE);
    // Without a debugger attached semihosting returns: sleep.
    loop {
        cortex_m::asm::wfi();
    }
}

//! # gaitclip-board — what every gaitclip firmware shares
//!
//! A board is a `main.rs` that wires its peripherals (I²C, the INT pin or a timer, a UART) to
//! the parts here and keeps the [`gaitclip::pipeline::Pipeline`] in a static sized for its
//! RAM; everything between the sensor's registers and the log lines lives in this crate:
//!
//! - [`imu_sampler`]: the interrupt side, one data-ready pulse → one sample (or a FIFO
//!   burst) into an SPSC queue, bus errors counted and retried, lost samples declared as
//!   gaps.
//! - [`live_settings`]: the rate, ranges and FIFO burst of the boards with a real sensor.
//! - [`startup`]: what the user is told while the core calibrates itself.
//! - [`serial_line`]: the line protocol of the UART output.
//! - [`sleep`]: when the clip sleeps (still for 10 s) and how it wakes on the first step.
//! - [`rsc`]: the Bluetooth Running Speed and Cadence encodings and the foot pod's state, and
//!   with the `ble` feature `rsc_gatt`, its GATT server on trouble-host.
//! - [`replay_mpu6050`], [`replay_holes`] and [`replay_still`]: an MPU6050 on an emulated
//!   I²C bus serving a stored trace (losing samples, standing still, sleeping in its cycle
//!   mode), for the QEMU boards and the host tests; [`replay_lsm6dsv320x`]: an LSM6DSV320X
//!   serving a stored FIFO the same way.
//! - On a Cortex-M only: `live_app` (the main loop of a board with a real sensor),
//!   `stride_log` (defmt and the serial line), `registers` (memory-mapped peripherals),
//!   and with the `replay` feature
//!   `replay_app` (the QEMU firmware) and `stack_paint` (the stack's high-water mark), and
//!   with `replay-lsm6dsv320x` `replay_lsm_app` (the QEMU firmware on the LSM6DSV320X).
//!
//! The parts above `live_app` build on the host, where `tests-host` checks them against
//! mocked buses.

#![no_std]
#![deny(missing_docs)]

use gaitclip::pipeline::detectors::Detector;

/// The firmware's step detector: one stance instant per gait cycle (the every-pace
/// detector, [`gaitclip::detect::cycle`]), unless the board is built with the `peak-valley-detector`
/// feature (Lu's detection and chain, [`gaitclip::detect::peak_valley`]). A board's pipeline is a
/// `Pipeline<Steps<M>>` made with `Steps::new`, `M` its movement buffer: it links only this
/// detector.
#[cfg(not(feature = "peak-valley-detector"))]
pub type Steps<const M: usize> = gaitclip::detect::cycle::CycleDetector<M>;
/// The firmware's step detector (see the other configuration's documentation).
#[cfg(feature = "peak-valley-detector")]
pub type Steps<const M: usize> = gaitclip::detect::peak_valley::PeakValleySteps;
/// The name of [`Steps`], for the configuration and the logs.
pub const DETECTOR: Detector = if cfg!(feature = "peak-valley-detector") {
    Detector::PeakValley
} else {
    Detector::Cycle
};

pub mod imu_sampler;
pub mod live_settings;
pub mod replay_holes;
pub mod replay_lsm6dsv320x;
pub mod replay_mpu6050;
pub mod replay_still;
pub mod rsc;
#[cfg(feature = "ble")]
pub mod rsc_gatt;
pub mod serial_line;
pub mod sleep;
pub mod startup;

#[cfg(target_os = "none")]
pub mod live_app;
#[cfg(target_os = "none")]
pub mod registers;
#[cfg(all(target_os = "none", feature = "replay"))]
pub mod replay_app;
#[cfg(all(target_os = "none", feature = "replay-lsm6dsv320x"))]
pub mod replay_lsm_app;
#[cfg(all(target_os = "none", feature = "paint-stack"))]
pub mod stack_paint;
#[cfg(target_os = "none")]
pub mod stride_log;

/// The simulated demo walk the QEMU boards replay (`fixtures/demo_walk.rs`, written by
/// `gaitclip fixtures`).
#[cfg(all(target_os = "none", feature = "replay"))]
#[path = "../../../fixtures/demo_walk.rs"]
pub mod trace;

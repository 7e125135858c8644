//! # gaitclip-lsm6dsv320x — ST's LSM6DSV320X as gaitclip reads it
//!
//! The LSM6DSV320X carries, on one die, a low-g accelerometer (±2 to ±16 g), a high-g
//! accelerometer (±32 to ±320 g) and a gyroscope to ±4 000 °/s: a sprinting foot's
//! touch-down (tens of g) and toe-off (beyond 2 000 °/s), where the MPU6050 sits at both of
//! its rails, stay in range.
//!
//! What this crate holds so far, each piece without a bus so that it is tested alone:
//!
//! - [`range`]: the three channels' full-scale ranges, their register field values and their
//!   sensitivities, as the seam's scales ([`gaitclip_imu::AccelScale`],
//!   [`gaitclip_imu::GyroScale`]);
//! - [`fifo`]: one FIFO word (a tag byte, then three little-endian words), and its tags;
//! - [`merge`]: the two accelerometers merged into one unclipped specific force, in fixed
//!   point ([`merge::DualRange`]), and the FIFO's words assembled into the pipeline's
//!   [`gaitclip_imu::RawSample`]s at the low-g rate ([`merge::Assembler`]).
//!
//! The bus driver (typestate modes, blocking and async, FIFO watermark, wake-up) is not here
//! yet.
//!
//! ## Sources
//!
//! Register addresses, field values and sensitivities as ST publishes them in its own
//! driver, `lsm6dsv320x-rs` 2.x (`src/register/main.rs`, the `from_fs*_to_mg` and
//! `from_fs*_to_mdps` conversions), which follow the datasheet's tables. ST rounds its
//! sensitivities to three decimals (0.488 mg per count at ±16 g is 1/2 048 g, 10.417 mg at
//! ±320 g is 1/96 g); the scales here are the exact binary ones those round.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod fifo;
pub mod merge;
pub mod range;

pub use range::{AccelRange, GyroRange, HighGRange};

//! # gaitclip-lsm6dsv320x — ST's LSM6DSV320X as gaitclip reads it
//!
//! The LSM6DSV320X carries, on one die, a low-g accelerometer (±2 to ±16 g), a high-g
//! accelerometer (±32 to ±320 g) and a gyroscope to ±4 000 °/s: a sprinting foot's
//! touch-down (tens of g) and toe-off (beyond 2 000 °/s), where the MPU6050 sits at both of
//! its rails, stay in range.
//!
//! What this crate holds, each piece tested alone:
//!
//! - [`range`]: the three channels' full-scale ranges, their register field values and their
//!   sensitivities, as the seam's scales ([`gaitclip_imu::AccelScale`],
//!   [`gaitclip_imu::GyroScale`]);
//! - [`fifo`]: one FIFO word (a tag byte, then three little-endian words), and its tags;
//! - [`merge`]: the two accelerometers merged into one unclipped specific force, in fixed
//!   point ([`merge::DualRange`]), and the FIFO's words assembled into the pipeline's
//!   [`gaitclip_imu::RawSample`]s at the low-g rate ([`merge::Assembler`]);
//! - the bus driver, [`blocking::Lsm6dsv320x`] and [`asynch::Lsm6dsv320x`];
//! - [`source`]: the handle a board's sampler drives ([`blocking::Lsm6dsv320xSource`]), the
//!   seam's [`gaitclip_imu::source`] traits on top of the driver and the merge.
//!
//! ## The bus driver
//!
//! **Modes are types**, as in gaitclip's MPU6050 driver: fresh from `new` a driver is
//! [`mode::Unconfigured`]; `init` (ST's reset procedure, then the ranges, the rates and the
//! FIFO, from any mode) makes it [`mode::Sampling`], where the FIFO is read;
//! `enter_motion_wake` makes it [`mode::MotionWake`] (the low-g accelerometer alone in
//! low-power mode, INT1 latched on wake-up), where only the wake-up source can be read, and
//! `leave_motion_wake` brings it back. A failed mode change hands the driver back in its old
//! mode inside [`ModeChangeError`].
//!
//! **Written once.** Every configuration sequence is a `const fn` list of register steps
//! ([`program`]); the driver that runs them and reads the FIFO is one async source from which
//! `maybe-async-cfg` makes the blocking twin ([`blocking`], on [`embedded_hal::i2c::I2c`]) beside
//! the async one ([`asynch`], on [`embedded_hal_async::i2c::I2c`]). `tests/bus.rs` spells out
//! every transaction, from ST's register map, and runs each case on both.
//!
//! **One transfer per register or FIFO word**, so a bus error surfaces as [`Error::Bus`] and
//! the caller decides whether to retry. A FIFO overrun empties the FIFO and is
//! [`Error::FifoOverflow`]: the caller declares a gap.
//!
//! **No heap, no panics, no `unsafe`.** Capacities are the caller's slices.
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

mod bus;
mod error;
pub mod fifo;
pub mod merge;
pub mod program;
pub mod range;
pub mod register;
mod settings;
pub mod source;

/// The driver and the sampler's handle, blocking (on [`embedded_hal`]).
pub mod blocking {
    pub use crate::bus::blocking::*;
    pub use crate::source::blocking::*;
}
/// The driver and the sampler's handle, async (on [`embedded_hal_async`]).
pub mod asynch {
    pub use crate::bus::asynch::*;
    pub use crate::source::asynch::*;
}
pub use error::{Error, ModeChangeError};
/// The driver's modes, as types (shared by gaitclip's drivers).
pub use gaitclip_regbus::mode;
pub use range::{AccelRange, GyroRange, HighGRange};
pub use register::{FIFO_CAPACITY_WORDS, WHO_AM_I_VALUE};
pub use settings::{Address, Config, FifoStatus, HighG, HighGOdr, MotionWakeConfig, Odr};

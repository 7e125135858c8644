//! # gaitclip-mpu6050 — an MPU6050 driver for embedded-hal 1.0, blocking and async
//!
//! What gaitclip needs from the part, and nothing it does not: probing `WHO_AM_I`, reset and
//! configuration for a requested output rate, one-burst sample reads, the data-ready
//! interrupt, the FIFO with overflow detection, and the low-power wait for the first step
//! (the accelerometer alone in cycle mode with the motion interrupt).
//!
//! ## Design
//!
//! **Modes are types.** A driver is [`Mpu6050<I, Mode>`](blocking::Mpu6050): fresh from
//! [`new`](blocking::Mpu6050::new) it is [`mode::Unconfigured`]; [`init`](blocking::Mpu6050::init)
//! (a reset, from any mode) makes it [`mode::Sampling`], where samples, the FIFO and the
//! data-ready interrupt are; [`enter_motion_wake`](blocking::Mpu6050::enter_motion_wake) makes it
//! [`mode::MotionWake`], where only the interrupt status can be read, and
//! [`leave_motion_wake`](blocking::Mpu6050::leave_motion_wake) brings it back. Reading a sample
//! from a part in its motion wait does not compile. A failed mode change hands the driver back
//! in its old mode inside [`ModeChangeError`], so the caller can retry or reset it, as
//! eldruin's drivers do; the part may then be half-way, which [`init`](blocking::Mpu6050::init)
//! always cures.
//!
//! **One register program, one driver source, two ways to run it.** Every configuration
//! sequence is a list of register steps built by a `const fn` ([`program`]); the driver that
//! executes them and the reads is written once, async, and `maybe-async-cfg` makes the
//! blocking driver ([`blocking`], on [`embedded_hal::i2c::I2c`]) from it beside the async one
//! ([`asynch`], on [`embedded_hal_async::i2c::I2c`], for an executor that sleeps the core
//! while the transfer runs), so they cannot drift apart; the tests check both against the
//! same bus transactions.
//!
//! **Every register access is one `write` or `write_read`**, so a bus error surfaces as
//! [`Error::Bus`] and the caller decides whether to retry. The driver keeps no state about
//! the bus beyond its typestate: anything a board does to the bus to recover it
//! ([`blocking::Mpu6050::bus_mut`]) is safe.
//!
//! **No heap, no panics, no `unsafe`.** Capacities are the caller's slices.
//!
//! ```no_run
//! # fn demo<I: embedded_hal::i2c::I2c, D: embedded_hal::delay::DelayNs>(i2c: I, delay: &mut D)
//! #     -> Result<(), gaitclip_mpu6050::Error<I::Error>> {
//! use gaitclip_mpu6050::blocking::Mpu6050;
//! use gaitclip_mpu6050::{Address, Config, OutputRate};
//! let imu = Mpu6050::new(i2c, Address::Ad0Low);
//! let config = Config::new(OutputRate::from_hz(200).unwrap());
//! let mut imu = imu.init(delay, &config).map_err(|e| e.error)?;
//! let sample = imu.read_sample()?;
//! # let _ = sample; Ok(()) }
//! ```
//!
//! ## Sources
//!
//! MPU-6000/MPU-6050 Register Map and Descriptions rev 4.2 (RM-MPU-6000A-00); Product
//! Specification rev 3.4 (PS-MPU-6000A-00). Where the two disagree (the motion threshold's
//! unit) the caller says which its parts follow ([`MotionThresholdUnit`]).

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod bus;
mod error;
pub mod program;
mod range;
pub mod register;
pub mod sample;
mod settings;
mod source;

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
pub use gaitclip_imu::{AccelScale, GyroScale, RawSample};
/// The driver's modes, as types (shared by gaitclip's drivers).
pub use gaitclip_regbus::mode;
pub use range::{AccelRange, GyroRange};
pub use register::{FIFO_CAPACITY_BYTES, RESET_DELAY_MS, WHO_AM_I_VALUE};
pub use sample::SAMPLE_BYTES;
pub use settings::{
    Address, Config, InterruptStatus, MotionThreshold, MotionThresholdUnit, MotionWakeConfig,
    OutputRate, WakeRate,
};

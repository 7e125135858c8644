//! The sensor settings of the boards with a real sensor, one module per part; the part a
//! board is built with (the MPU6050, or with the feature `lsm6dsv320x` the LSM6DSV320X) is
//! re-exported here, so a board's `main.rs` names no part: it takes [`source`] (or
//! [`async_source`]) on its bus, [`MODE`], [`CONFIG`], [`RATE`], [`SLEEP`] and the
//! capacities from here.
//!
//! A third part is a driver crate that implements the seam's source traits
//! ([`gaitclip_imu::source`]), a module here with the same names, and a feature that picks
//! it.

pub mod lsm6dsv320x;
pub mod mpu6050;

#[cfg(feature = "lsm6dsv320x")]
pub use lsm6dsv320x::*;
#[cfg(not(feature = "lsm6dsv320x"))]
pub use mpu6050::*;

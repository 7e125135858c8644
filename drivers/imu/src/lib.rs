//! # gaitclip-imu — what the pipeline takes from an inertial sensor
//!
//! The seam between a sensor's driver and the gaitclip core. A driver crate (one per part,
//! `drivers/<part>/`) turns its registers or FIFO words into these records; the core computes
//! on nothing else, so it does not know which part it has:
//!
//! - [`RawSample`]: one sample in counts, sensor axes, accelerometer and gyroscope;
//! - [`AccelScale`] and [`GyroScale`]: the counts' units (counts per g, counts per °/s as a
//!   ratio, since ST's 70 mdps per count is not a whole number of tenths of a count per °/s);
//! - [`Scales`]: both, what a driver's configuration says its samples are in.
//!
//! Where a reading clips is the core's business (`gaitclip::sensor::sample::Rails`): real
//! parts clip below their nominal range, so it is learnt or given, never assumed here. The
//! rate is the core's `SampleRate`, in mHz.
//!
//! What a board's sampler needs of a part (start it, read a sample or a FIFO burst, wait for
//! motion and come back) is the trait [`source::blocking::ImuSource`] and its async twin,
//! behind the feature `source`, which every driver crate implements and the core never
//! enables.
//!
//! `no_std`, no heap, no `unsafe`; no dependencies without `source`.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod sample;
mod scale;
#[cfg(feature = "source")]
pub mod source;

pub use sample::RawSample;
pub use scale::{AccelScale, GyroScale, Scales};

//! The modes a gaitclip sensor driver is in, as types: a driver is `Driver<I, Mode>`, and
//! what a mode does not offer does not compile.

/// A mode of a part. Sealed: only the three below.
pub trait Mode: sealed::Sealed {}

/// Not configured by the driver yet: fresh from `new`, or handed back by a driver that
/// forgot what it reached. Only probing and `init` are offered.
#[derive(Debug)]
pub struct Unconfigured;

/// Sampling at the configured rate: samples, the FIFO and their interrupt.
#[derive(Debug)]
pub struct Sampling;

/// The low-power wait for motion: the accelerometer alone, its interrupt latched on motion.
/// Only the interrupt status, leaving, and `init` are offered.
#[derive(Debug)]
pub struct MotionWake;

impl Mode for Unconfigured {}
impl Mode for Sampling {}
impl Mode for MotionWake {}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Unconfigured {}
    impl Sealed for super::Sampling {}
    impl Sealed for super::MotionWake {}
}

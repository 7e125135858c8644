//! The driver's modes, as types (the second parameter of [`crate::blocking::Lsm6dsv320x`]
//! and [`crate::asynch::Lsm6dsv320x`]).

/// A mode of the part. Sealed: only the three below.
pub trait Mode: sealed::Sealed {}

/// Not configured by this driver yet: fresh from `new`. Only probing and `init` are offered.
#[derive(Debug)]
pub struct Unconfigured;

/// Sampling at the configured rates: the FIFO.
#[derive(Debug)]
pub struct Sampling;

/// Waiting for motion: the low-g accelerometer alone in low-power mode, INT1 latched on
/// wake-up. Only the wake-up source, leaving, and `init` are offered.
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

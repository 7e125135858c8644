//! The driver's modes, as types ([`crate::blocking::Mpu6050`]'s and
//! [`crate::asynch::Mpu6050`]'s second parameter).

/// A mode of the part. Sealed: only the three below.
pub trait Mode: sealed::Sealed {}

/// Not configured by this driver yet: fresh from `new`. Only probing, the interrupt status
/// and [`init`](crate::blocking::Mpu6050::init) are offered.
#[derive(Debug)]
pub struct Unconfigured;

/// Sampling all six axes at the configured rate: samples, the FIFO and the data-ready
/// interrupt.
#[derive(Debug)]
pub struct Sampling;

/// The low-power wait for motion: the accelerometer alone in cycle mode, the gyro in
/// standby, INT latched on motion. Only the interrupt status, leaving, and `init` are offered.
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

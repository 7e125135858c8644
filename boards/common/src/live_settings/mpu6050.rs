//! The MPU6050's settings on every board with a real one: one place, so that the
//! nRF52840, Bluetooth and Pico builds measure the same way and the energy budget
//! (`gaitclip cost`) reads the same figures the firmware uses.

use gaitclip::pipeline::config::Config;
use gaitclip::sensor::rate::SampleRate;
use gaitclip_mpu6050 as mpu6050;
use gaitclip_mpu6050::{AccelRange, Address, GyroRange, MotionWakeConfig};

use crate::imu_sampler::ReadMode;
use crate::sleep::SleepSettings;

/// The part, for the logs.
pub const NAME: &str = "MPU6050";
/// The blocking sampler's handle on a bus `I`.
pub type Source<I> = mpu6050::blocking::Mpu6050Source<I>;
/// The async sampler's handle on a bus `I`.
pub type AsyncSource<I> = mpu6050::asynch::Mpu6050Source<I>;
/// Where the part sits on the bus: AD0 to ground.
pub const ADDRESS: Address = Address::Ad0Low;

/// Output data rate of the sensor, Hz.
pub const RATE_HZ: u16 = 200;
/// Data-ready pulses per FIFO burst: 8 samples (40 ms) per I2C transaction at 200 Hz.
pub const FIFO_BATCH: u8 = 8;
/// Queue between the INT handler and the main loop: 0.64 s at 200 Hz.
pub const QUEUE_LEN: usize = 128;
/// ±16 g: a running heel strike reaches 10 g at the shoe.
pub const ACCEL: AccelRange = AccelRange::G16;
/// ±2000 °/s: a sprinting swing reaches 1 500 °/s.
pub const GYRO: GyroRange = GyroRange::Dps2000;
/// The movement buffer: [`gaitclip::detect::seam::MAX_MOVEMENT_MS`] at [`RATE_HZ`] (1 024 samples).
pub const MOVEMENT_SAMPLES: usize = gaitclip::detect::seam::movement_samples(RATE_HZ as u32);
/// [`RATE_HZ`] as the core's rate.
pub const RATE: SampleRate = sample_rate(RATE_HZ);
/// The sensor's configuration.
pub const SENSOR: mpu6050::Config = sensor_config(RATE_HZ, ACCEL, GYRO);
/// The pipeline's configuration.
pub const CONFIG: Config = config(RATE, ACCEL, GYRO);
/// How the sampler reads it: the FIFO every [`FIFO_BATCH`] data-ready pulses.
pub const MODE: ReadMode = ReadMode::Fifo { batch: FIFO_BATCH };
/// When it sleeps and how it wakes ([`crate::sleep::SLEEP`]).
pub const SLEEP: SleepSettings<MotionWakeConfig> = crate::sleep::SLEEP;

/// The blocking sampler's handle on `bus`, with [`SENSOR`].
pub fn source<I: embedded_hal::i2c::I2c>(bus: I) -> Source<I> {
    Source::new(mpu6050::blocking::Mpu6050::new(bus, ADDRESS), SENSOR)
}

/// The async sampler's handle on `bus`, with [`SENSOR`].
pub fn async_source<I: embedded_hal_async::i2c::I2c>(bus: I) -> AsyncSource<I> {
    AsyncSource::new(mpu6050::asynch::Mpu6050::new(bus, ADDRESS), SENSOR)
}

/// The pipeline's configuration for samples at `rate` in the given ranges, with the
/// firmware's [`crate::DETECTOR`].
pub const fn config(rate: SampleRate, accel: AccelRange, gyro: GyroRange) -> Config {
    let mut c = Config::new(rate, accel.scale(), gyro.scale());
    c.detector = crate::DETECTOR;
    c
}

/// The sample rate of a sensor output rate in Hz (checked at compile time).
pub const fn sample_rate(hz: u16) -> SampleRate {
    match SampleRate::from_hz(hz as u32) {
        Some(r) => r,
        None => panic!("unsupported rate"),
    }
}

/// The MPU6050's configuration for an output rate in Hz and the ranges (checked at compile
/// time).
pub const fn sensor_config(hz: u16, accel: AccelRange, gyro: GyroRange) -> mpu6050::Config {
    mpu6050::Config {
        rate: match mpu6050::OutputRate::from_hz(hz) {
            Some(r) => r,
            None => panic!("unsupported output rate"),
        },
        accel,
        gyro,
    }
}

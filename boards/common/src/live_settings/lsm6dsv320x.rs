//! The LSM6DSV320X's settings on every board built with it (feature `lsm6dsv320x`): the
//! same rate, ranges and FIFO on the nRF52840, Bluetooth and Pico builds.

use gaitclip::pipeline::config::Config;
use gaitclip::sensor::rate::SampleRate;
use gaitclip_lsm6dsv320x as lsm;
use gaitclip_lsm6dsv320x::merge::DualRange;
use gaitclip_lsm6dsv320x::{Address, MotionWakeConfig, Odr};

use crate::imu_sampler::ReadMode;
use crate::sleep::SleepSettings;

/// The part, for the logs.
pub const NAME: &str = "LSM6DSV320X";
/// The blocking sampler's handle on a bus `I`.
pub type Source<I> = lsm::blocking::Lsm6dsv320xSource<I>;
/// The async sampler's handle on a bus `I`.
pub type AsyncSource<I> = lsm::asynch::Lsm6dsv320xSource<I>;
/// Where the part sits on the bus: SA0 to ground.
pub const ADDRESS: Address = Address::Sa0Low;

/// Output data rate of the low-g accelerometer and the gyroscope, Hz: the part's rates
/// double from 7.5 Hz, and 240 Hz is the first at or above the MPU6050 builds' 200 Hz.
pub const RATE_HZ: u16 = 240;
/// The part's configuration: ±16 g, ±4 000 °/s, the high-g channel at ±128 g and 960 Hz,
/// the FIFO's watermark at 48 words (eight periods of one low-g, one gyroscope and four
/// high-g words: 33 ms).
pub const SENSOR: lsm::Config = lsm::Config::new(match Odr::from_hz(RATE_HZ as u32) {
    Some(odr) => odr,
    None => panic!("unsupported output rate"),
});
/// The two accelerometers as the FIFO's samples merge them.
pub const DUAL: DualRange = SENSOR.dual_range();
/// Queue between the INT handler and the main loop: 0.53 s at 240 Hz.
pub const QUEUE_LEN: usize = 128;
/// The movement buffer: [`gaitclip::detect::seam::MAX_MOVEMENT_MS`] at [`RATE_HZ`].
pub const MOVEMENT_SAMPLES: usize = gaitclip::detect::seam::movement_samples(RATE_HZ as u32);
/// [`RATE_HZ`] as the core's rate.
pub const RATE: SampleRate = super::mpu6050::sample_rate(RATE_HZ);
/// The pipeline's configuration: the merged counts' scale (the high-g channel's) and the
/// gyroscope's, with the firmware's [`crate::DETECTOR`].
pub const CONFIG: Config = {
    let mut c = Config::new(RATE, DUAL.scale(), SENSOR.gyro.scale());
    c.detector = crate::DETECTOR;
    c
};
/// How the sampler reads it: the FIFO whenever INT1 says it holds its watermark.
pub const MODE: ReadMode = SENSOR.read_mode();
/// When it sleeps and how it wakes: still for 10 s as the MPU6050 builds, then the low-g
/// accelerometer alone at 15 Hz waking on 94 mg ([`MotionWakeConfig::DEFAULT`]). The 80 ms
/// dropped after waking are not the LSM6DSV320X's own gyroscope turn-on time (its
/// datasheet's table is not among the cited sources) but the longest ST quotes for its
/// LSM6DS family; dropping more than needed only delays the first sample kept.
pub const SLEEP: SleepSettings<MotionWakeConfig> = SleepSettings {
    still_ms: crate::sleep::SLEEP.still_ms,
    wake: MotionWakeConfig::DEFAULT,
    settle_ms: 80,
};

/// The blocking sampler's handle on `bus`, with [`SENSOR`].
pub fn source<I: embedded_hal::i2c::I2c>(bus: I) -> Source<I> {
    Source::new(lsm::blocking::Lsm6dsv320x::new(bus, ADDRESS), SENSOR)
}

/// The async sampler's handle on `bus`, with [`SENSOR`].
pub fn async_source<I: embedded_hal_async::i2c::I2c>(bus: I) -> AsyncSource<I> {
    AsyncSource::new(lsm::asynch::Lsm6dsv320x::new(bus, ADDRESS), SENSOR)
}

//! What the pipeline needs to know about the data and how to measure it ([`Config`]), and
//! the limits it works within: the holes it bridges or fills, the model it ships with.
//! Above every stage: it names the detector, the length model and their settings, and hands
//! each stage its part ([`Config::detect`]).

use crate::detect::phases::PhaseMethod;
use crate::detect::seam::{DetectConfig, MIN_MOVEMENT_MS};
use crate::detect::stance::StanceLimits;
use crate::detect::zupt::GravityReading;
use crate::length::models::{Model, ModelParams, Settings};
use crate::pipeline::detectors::Detector;
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::Rails;
use crate::sensor::units::{AccelScale, GyroScale};

/// Longest hole of lost samples that is bridged: interpolated across when the next sample
/// arrives, the stride it falls in flagged [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED) and still measured.
/// Chosen by measurement (`gaitclip holes`, its table in docs/clocks-and-holes.md): the longest hole
/// whose mean |length error| against the uncut recordings stays ≤ 1 cm at the recordings'
/// rate and at half of it (with the cycle detector and the ZUPT stride as the default:
/// 30 ms holes cost 10.6 mm at 100 Hz in clusters in the swing; 30 ms until then).
pub const BRIDGE_MAX_MS: u32 = 20;
/// Longest hole interpolated at all. A longer hole than [`BRIDGE_MAX_MS`], up to this, is
/// filled too so that the stride's events outside it are still found, but a stride whose
/// movement it falls in is a [`StrideFlags::GAP`](crate::record::stride::StrideFlags::GAP) stride without a length. Anything longer
/// restarts detection after it. At most [`MIN_MOVEMENT_MS`]: the samples one call then
/// feeds are fewer than separate two strides, so one call never has two to report.
pub const FILL_MAX_MS: u32 = MIN_MOVEMENT_MS;
const _: () = assert!(BRIDGE_MAX_MS <= FILL_MAX_MS && FILL_MAX_MS <= MIN_MOVEMENT_MS);

/// The model the firmware ships with as its stride length: the one with the best
/// leave-one-dataset-out score, as `gaitclip train` measured it
/// ([`crate::length::trained::LODO_BEST`]; the length tables of docs/accuracy.md).
pub const DEFAULT_MODEL: Model = crate::length::trained::LODO_BEST;

/// What the pipeline needs to know about the data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Sample rate.
    pub rate: SampleRate,
    /// Accelerometer scale of the counts (counts per g), as the sensor's driver gives it.
    pub accel: AccelScale,
    /// Gyroscope scale of the counts (counts per °/s), as the sensor's driver gives it.
    pub gyro: GyroScale,
    /// Where each axis clips, counts ([`Rails::FULL_SCALE`] for a part read live; a replayed
    /// recording's are learnt from its data or given).
    pub rails: Rails,
    /// Whether the cycle detector puts back what a clipped accelerometer lost
    /// ([`crate::detect::clipping`]; true). A setting so that the clipping sweep can measure what
    /// the restoration does.
    pub restore_accel: bool,
    /// Step detector.
    pub detector: Detector,
    /// Phase splitter version.
    pub phases: PhaseMethod,
    /// The model that fills in [`Stride::length_mm`](crate::record::stride::Stride::length_mm).
    pub model: Model,
    /// Device settings of the models (the wearer's height).
    pub settings: Settings,
    /// Trained coefficients and SVRs.
    pub params: &'static ModelParams<'static>,
    /// Longest hole bridged, ms ([`BRIDGE_MAX_MS`]; clamped to [`FILL_MAX_MS`]). A setting
    /// so that the hole-length sweep can measure what each limit costs.
    pub bridge_max_ms: u32,
    /// The stance detector's thresholds ([`StanceLimits::DEFAULT`]); a setting for the
    /// threshold sweep of [`crate::detect::stance`].
    pub stance: StanceLimits,
    /// The sensor's height above the foot's rolling contact, µm
    /// ([`crate::detect::cycle::SENSOR_HEIGHT_UM`]): where the clip sits on the shoe.
    pub sensor_height_um: u32,
    /// What the accelerometer's reading of gravity at rest, where it is not 1 g, is taken
    /// to be ([`GravityReading::Offset`]; the others for the bias study's comparison).
    pub gravity_reading: GravityReading,
    /// Whether a stride must be a step on the ground to count ([`crate::detect::step_check`];
    /// true). A setting so that what the check refuses can be measured against what it lets
    /// through.
    pub check_steps: bool,
}

impl Config {
    /// The default configuration for data at `rate` in the given scales: the cycle
    /// detector, the augmented phase splitter, the [`DEFAULT_MODEL`] with the shipped
    /// [`crate::length::trained::PARAMS`], and the default height.
    pub const fn new(rate: SampleRate, accel: AccelScale, gyro: GyroScale) -> Self {
        Config {
            rate,
            accel,
            gyro,
            rails: Rails::FULL_SCALE,
            restore_accel: true,
            detector: Detector::Cycle,
            phases: PhaseMethod::Augmented,
            model: DEFAULT_MODEL,
            settings: Settings::DEFAULT,
            params: &crate::length::trained::PARAMS,
            bridge_max_ms: BRIDGE_MAX_MS,
            stance: StanceLimits::DEFAULT,
            sensor_height_um: crate::detect::cycle::SENSOR_HEIGHT_UM,
            gravity_reading: GravityReading::Offset,
            check_steps: true,
        }
    }

    /// The model behind the strides' lengths: [`Config::model`], unless the detector measures
    /// with its own chain (Lu's fuzzy Weinberg for the peak-valley detector).
    pub const fn length_model(&self) -> Model {
        self.detector.length_model(self.model)
    }

    /// What the detector is made from ([`DetectConfig`]).
    pub const fn detect(&self) -> DetectConfig {
        DetectConfig {
            rate: self.rate,
            accel: self.accel,
            gyro: self.gyro,
            rails: self.rails,
            phases: self.phases,
            stance: self.stance,
            sensor_height_um: self.sensor_height_um,
            restore_accel: self.restore_accel,
            gravity_reading: self.gravity_reading,
        }
    }
}

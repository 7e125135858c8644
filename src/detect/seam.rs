//! The seam between the pipeline and its step detector: what every detector is given and
//! what it must do.
//!
//! A step detector turns the stream of samples, raw and in the foot frame, into stride
//! records. The pipeline ([`crate::pipeline::Pipeline`]) owns everything before it (mean
//! filter, rest test, foot frame, the delay lines that keep each raw sample with its
//! foot-frame value) and everything after it (the length models, the gait parameters); a
//! detector sees one [`Input`] per sample and hands back at most one [`Stride`] per call.
//! It is made from a [`DetectConfig`], the part of the pipeline's configuration it needs, so
//! that no detector knows the stages after it. The built-in detectors are listed beside the
//! pipeline ([`crate::pipeline::detectors`]).

use crate::detect::foot_frame::FootFrameEstimator;
use crate::detect::phase_stats::StrideStats;
use crate::detect::phases::PhaseMethod;
use crate::detect::stance::StanceLimits;
use crate::detect::step_check::StepLedger;
use crate::detect::zupt::GravityReading;
use crate::record::stride::{StepAmplitude, Stride};
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::{Origin, Rails, RawSample};
use crate::sensor::units::{AccelScale, FootAccel, GyroScale};

/// Capacity of the delay lines that align raw samples and foot-frame samples with the
/// (centred) stance decision: ≥ stance delay (63) + filter delay (7) + 1.
pub const DELAY_CAPACITY: usize = 128;

/// The longest movement (heel-off to foot-flat) kept for the phases, ms, at any rate: a
/// walking movement lasts 0.5–1 s, a slow backward one 2 s. A longer one is closed at the next
/// stance but flagged [`crate::record::stride::StrideFlags::TOO_LONG`]; its ZUPT length,
/// integrated sample by sample, does not depend on the buffer.
pub const MAX_MOVEMENT_MS: u32 = 5120;

/// Movement buffer capacity that holds [`MAX_MOVEMENT_MS`] at `rate_hz`: 1 024 samples
/// (6 KiB) at the boards' 200 Hz, 5 120 at 1 kHz. A board short of RAM picks fewer and
/// flags longer movements sooner.
pub const fn movement_samples(rate_hz: u32) -> usize {
    (rate_hz as usize * MAX_MOVEMENT_MS as usize).div_ceil(1000)
}

/// Default capacity of the movement buffer: [`MAX_MOVEMENT_MS`] at the fastest supported
/// rate (1 kHz), so that a pipeline made without naming one (the host's) sizes the buffer by
/// time at any rate.
pub const MAX_MOVEMENT_SAMPLES: usize = movement_samples(1000);
/// A movement shorter than this is a wobble of a foot still on the ground, not a step.
pub const MIN_MOVEMENT_MS: u32 = 150;
/// At most this much of a stance counts toward the stride that leaves it: a user who stood
/// for a minute before walking has a first stride of one step, not of a minute.
pub const MAX_STANCE_IN_STRIDE_MS: u32 = 1000;

/// Samples of a movement kept at `rate` in a buffer of `capacity`: [`MAX_MOVEMENT_MS`], at
/// most the capacity.
pub const fn max_movement(rate: SampleRate, capacity: usize) -> usize {
    let n = rate.samples_in_ms(MAX_MOVEMENT_MS) as usize;
    if n < capacity {
        n
    } else {
        capacity
    }
}

/// What a detector is made from: the sensor's rate, scales and rails, and the settings of
/// the detection (the pipeline's configuration gives it, `Config::detect`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DetectConfig {
    /// Sample rate.
    pub rate: SampleRate,
    /// Accelerometer scale of the counts.
    pub accel: AccelScale,
    /// Gyroscope scale of the counts.
    pub gyro: GyroScale,
    /// Where each axis clips.
    pub rails: Rails,
    /// Phase splitter version.
    pub phases: PhaseMethod,
    /// Huang's stance detector's thresholds.
    pub stance: StanceLimits,
    /// The sensor's height above the foot's rolling contact, µm.
    pub sensor_height_um: u32,
    /// Whether the cycle detector puts back what a clipped accelerometer lost.
    pub restore_accel: bool,
    /// What the rest's reading of gravity is taken to be.
    pub gravity_reading: GravityReading,
}

/// The delay lines: the last [`DELAY_CAPACITY`] raw samples' accelerations and angular
/// rates (no temperature: no stage after the delay reads it), their mean-filtered foot-frame
/// values and where each came from, by sample number. The detectors' centred windows decide
/// about a sample well after it was fed; these give them back what it was.
#[derive(Clone, Debug)]
pub struct DelayLines {
    accel: [[i16; 3]; DELAY_CAPACITY],
    gyro: [[i16; 3]; DELAY_CAPACITY],
    foot: [FootAccel; DELAY_CAPACITY],
    /// One bit per slot: the sample was interpolated ([`Origin::Bridged`]).
    bridged: u128,
    /// One bit per slot: the sample was interpolated ([`Origin::Filled`]).
    filled: u128,
}

const _: () = assert!(DELAY_CAPACITY == 128, "one bit per slot in a u128");

impl DelayLines {
    /// Empty lines.
    pub const fn new() -> Self {
        DelayLines {
            accel: [[0; 3]; DELAY_CAPACITY],
            gyro: [[0; 3]; DELAY_CAPACITY],
            foot: [FootAccel([0; 3]); DELAY_CAPACITY],
            bridged: 0,
            filled: 0,
        }
    }

    /// Stores sample number `index` and where it came from.
    pub fn push(&mut self, index: u32, s: &RawSample, origin: Origin) {
        self.accel[slot(index)] = s.accel;
        self.gyro[slot(index)] = s.gyro;
        let bit = 1u128 << slot(index);
        self.bridged &= !bit;
        self.filled &= !bit;
        match origin {
            Origin::Measured => {}
            Origin::Bridged => self.bridged |= bit,
            Origin::Filled => self.filled |= bit,
        }
    }

    /// Stores the mean-filtered foot-frame value computed when sample `index` was fed.
    pub fn set_foot(&mut self, index: u32, foot: FootAccel) {
        self.foot[slot(index)] = foot;
    }

    /// Raw sample number `at` (if it is still in the line), its temperature 0.
    pub const fn raw(&self, at: u32) -> RawSample {
        RawSample {
            accel: self.accel[slot(at)],
            gyro: self.gyro[slot(at)],
            temp: 0,
        }
    }

    /// The foot-frame value computed when sample `at` was fed.
    pub const fn foot(&self, at: u32) -> FootAccel {
        self.foot[slot(at)]
    }

    /// Whether sample `at` was measured or interpolated.
    pub const fn origin(&self, at: u32) -> Origin {
        let bit = 1u128 << slot(at);
        if self.bridged & bit != 0 {
            Origin::Bridged
        } else if self.filled & bit != 0 {
            Origin::Filled
        } else {
            Origin::Measured
        }
    }
}

impl Default for DelayLines {
    fn default() -> Self {
        Self::new()
    }
}

/// The delay-line slot of sample number `i`.
const fn slot(i: u32) -> usize {
    i as usize & (DELAY_CAPACITY - 1)
}

/// What a detector is given for each sample, once the foot frame exists.
pub struct Input<'a> {
    /// Number of the newest sample.
    pub index: u32,
    /// The newest raw sample.
    pub newest: &'a RawSample,
    /// Where it came from.
    pub origin: Origin,
    /// Its mean filter's output in the foot frame, `[forward, left, up − g]` (g/2048): the
    /// mean of a window centred [`Input::filter_delay`] samples back.
    pub foot: FootAccel,
    /// Samples by which the mean filter delays.
    pub filter_delay: u32,
    /// Inputs since the last restart (start or a long hole).
    pub since_reset: u32,
    /// The delay lines, the newest sample included.
    pub lines: &'a DelayLines,
    /// The foot frame and the rest calibration behind it.
    pub frame: &'a FootFrameEstimator,
    /// Accelerometer counts per g.
    pub accel_lsb_per_g: i32,
    /// The rest test's decision this input brought, and the sample it is about
    /// ([`crate::detect::rest`]; none until its window has filled).
    pub rest: Option<(u32, bool)>,
    /// The step check's ledger of the samples so far (the rest decisions and rotations up
    /// to the one in [`Input::rest`]).
    pub steps: &'a StepLedger,
}

/// What a detector is given when the samples stop: at a hole too long to interpolate, and at
/// the end of a recording.
pub struct Drain<'a> {
    /// Number of the next sample that would have been fed.
    pub next: u32,
    /// Samples by which the mean filter delays.
    pub filter_delay: u32,
    /// The delay lines.
    pub lines: &'a DelayLines,
}

/// A step detector: samples in, strides out, at most one per call.
pub trait StepDetector {
    /// Samples between the newest input and the sample a decision is about.
    fn delay(&self, filter_delay: u32) -> u32;

    /// Feeds one sample; a stride it lets the detector report goes into `out` if `out` is
    /// free, else it is held and reported at the next chance (several samples are fed in
    /// one call after a hole).
    fn process(&mut self, x: &Input<'_>, out: &mut Option<Stride>);

    /// Samples were lost and detection restarts after them: the stride in progress becomes
    /// a gap stride. Returns a stride that was complete before the hole, if one was held.
    fn restart(&mut self, x: &Drain<'_>) -> Option<Stride>;

    /// Keeps `stride` (released while filling a hole with no call to report it from) and
    /// reports it before anything else.
    fn hold(&mut self, stride: Stride);

    /// At the end of a recording: the strides still held or in flight, one per call, until
    /// `None`.
    fn finish(&mut self, x: &Drain<'_>) -> Option<Stride>;

    /// The phase statistics of stride `index` while they are kept (the features' input).
    fn stats(&self, index: u32) -> Option<&StrideStats>;

    /// The peak-valley amplitude of step `index` while it is kept, for a detector whose
    /// records are steps measured by Lu's chain (none by default).
    fn step(&self, _index: u32) -> Option<StepAmplitude> {
        None
    }

    /// Strides or steps that could not be reported (none by construction; counted so that
    /// a test would see one).
    fn dropped(&self) -> u32;

    /// Whether the detector reports its strides seconds after they ended, by design (Lu's
    /// rules look up to 16 s ahead): later than the step check's record of the samples
    /// reaches back ([`crate::detect::step_check`]), so its strides count unjudged (the
    /// pipeline counts them, [`crate::detect::step_check::Rejected::unchecked`]). False by
    /// default: a detector that reports within a stride or two is judged on what the record
    /// still holds.
    fn reports_late(&self) -> bool {
        false
    }
}

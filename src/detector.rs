//! The seam between the pipeline and its step detector.
//!
//! A step detector turns the stream of samples, raw and in the foot frame, into stride
//! records. The [`crate::pipeline::Pipeline`] owns everything before it (mean filter, rest
//! test, foot frame, the delay lines that keep each raw sample with its foot-frame value)
//! and everything after it (the length models); a detector sees one [`Input`] per sample and
//! hands back at most one [`Stride`] per call. Three are built in, one file each:
//!
//! | [`Detector`] | type | file |
//! |---|---|---|
//! | `cycle` (default) | [`crate::cycle::CycleDetector`] | `src/cycle.rs` |
//! | `stance` | [`crate::stride::StanceStrides`] | `src/stride.rs` (Huang's detector in `src/stance.rs`) |
//! | `lu` | [`crate::peak_valley::PeakValleySteps`] | `src/peak_valley.rs` |
//!
//! A firmware names the one it runs in its pipeline's type (`Pipeline<CycleDetector<256>>`)
//! and links only that one; the host tools choose at run time through [`AnyDetector`], which
//! holds one of them. Adding a detector is a file with a type that implements
//! [`StepDetector`] and has a `const fn new(&Config) -> Self`, its `pub mod` line in
//! `lib.rs`, and one line in the `detectors!` list at the end of this file.

use crate::foot_frame::FootFrameEstimator;
use crate::models::{LengthChain, Model};
use crate::phase_stats::StrideStats;
use crate::pipeline::{Config, DELAY_CAPACITY};
use crate::sample::RawSample;
use crate::stride::{Origin, Stride};
use crate::units::FootAccel;

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
    /// The model behind its strides' lengths, if it measures them with its own chain
    /// whatever the configured model (Lu's detector: his fuzzy Weinberg).
    const OWN_MODEL: Option<Model> = None;

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

    /// Fills in a released stride's length: by default the configured model on its
    /// features.
    fn measure(&self, s: &mut Stride, chain: &LengthChain) {
        chain.measure(s, self.stats(s.index));
    }

    /// Strides or steps that could not be reported (none by construction; counted so that
    /// a test would see one).
    fn dropped(&self) -> u32;
}

/// Declares the detectors: the [`Detector`] names and [`AnyDetector`], which runs the one a
/// [`Config`] names. One line per detector: `Variant("name") => Type,` (the type may use the
/// movement buffer's `M`), with doc comments if it wants more than its name.
macro_rules! detectors {
    ($($(#[$doc:meta])* $v:ident($name:literal) => $ty:ty,)+) => {
        /// Which step detector segments the walk (the host's `--detector`; a firmware's
        /// pipeline type).
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Detector {
            $(#[doc = concat!("`", $name, "`.")] $(#[$doc])* $v,)+
        }

        impl Detector {
            /// Every detector, the default first.
            pub const ALL: &'static [Detector] = &[$(Detector::$v),+];

            /// The name `--detector` takes.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Detector::$v => $name,)+
                }
            }

            /// The detector called `name`.
            pub fn from_name(name: &str) -> Option<Detector> {
                Detector::ALL.iter().copied().find(|d| d.name() == name)
            }

            /// The model it measures its strides with whatever the configured one, if any
            /// ([`StepDetector::OWN_MODEL`]).
            pub const fn own_model(self) -> Option<Model> {
                own_model::<1>(self)
            }

            /// The model behind its strides' lengths when `configured` is the configured one.
            pub const fn length_model(self, configured: Model) -> Model {
                match self.own_model() {
                    Some(m) => m,
                    None => configured,
                }
            }
        }

        const fn own_model<const M: usize>(d: Detector) -> Option<Model> {
            match d {
                $(Detector::$v => <$ty as StepDetector>::OWN_MODEL,)+
            }
        }

        /// One of the detectors, chosen at run time by [`Config::detector`] (the host tools).
        /// A pipeline runs one detector for its life, so they share their memory.
        #[derive(Clone, Debug)]
        #[allow(clippy::large_enum_variant)] // sharing the memory is the point
        pub enum AnyDetector<const M: usize> {
            $(#[doc = concat!("`", $name, "`.")] $(#[$doc])* $v($ty),)+
        }

        impl<const M: usize> AnyDetector<M> {
            /// The detector `config` names.
            pub const fn new(config: &Config) -> Self {
                match config.detector {
                    $(Detector::$v => AnyDetector::$v(<$ty>::new(config)),)+
                }
            }
        }

        impl<const M: usize> StepDetector for AnyDetector<M> {
            fn delay(&self, filter_delay: u32) -> u32 {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::delay(d, filter_delay),)+
                }
            }
            fn process(&mut self, x: &Input<'_>, out: &mut Option<Stride>) {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::process(d, x, out),)+
                }
            }
            fn restart(&mut self, x: &Drain<'_>) -> Option<Stride> {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::restart(d, x),)+
                }
            }
            fn hold(&mut self, stride: Stride) {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::hold(d, stride),)+
                }
            }
            fn finish(&mut self, x: &Drain<'_>) -> Option<Stride> {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::finish(d, x),)+
                }
            }
            fn stats(&self, index: u32) -> Option<&StrideStats> {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::stats(d, index),)+
                }
            }
            fn measure(&self, s: &mut Stride, chain: &LengthChain) {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::measure(d, s, chain),)+
                }
            }
            fn dropped(&self) -> u32 {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::dropped(d),)+
                }
            }
        }
    };
}

detectors! {
    /// One zero-velocity instant per gait cycle at every pace ([`crate::cycle`]), strides
    /// from instant to instant with the rolling-contact ZUPT, events and phases by Huang's
    /// splitter, every length model: the default.
    Cycle("cycle") => crate::cycle::CycleDetector<M>,
    /// Stance to stance (Huang's variance + IQR zero-velocity detector, the paper's
    /// method), with gait events, phases, the ZUPT displacement and every length model.
    Stance("stance") => crate::stride::StanceStrides<M>,
    /// Lu's peak-valley detection on vertical acceleration, measured by Lu's chain whatever
    /// the configured model. A stride record is one of its steps: `start`, `heel_off` and
    /// `toe_off` are its peak, `heel_strike` and `end` its valley; no stance, phases, ZUPT
    /// displacement or climb are measured (flag `PHASES_GUESSED`, and `FROM_REST` on a
    /// walk's first step).
    PeakValley("lu") => crate::peak_valley::PeakValleySteps,
}

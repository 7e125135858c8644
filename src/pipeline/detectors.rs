//! The step detectors the pipeline can run, one line each.
//!
//! | [`Detector`] | type | file |
//! |---|---|---|
//! | `cycle` (default) | [`crate::detect::cycle::CycleDetector`] | `src/detect/cycle.rs` |
//! | `stance` | [`crate::detect::stance_strides::StanceStrides`] | `src/detect/stance_strides.rs` (Huang's detector in `src/detect/stance.rs`) |
//! | `lu` | [`crate::detect::peak_valley::PeakValleySteps`] | `src/detect/peak_valley.rs` |
//!
//! A firmware names the one it runs in its pipeline's type (`Pipeline<CycleDetector<256>>`)
//! and links only that one; the host tools choose at run time through [`AnyDetector`], which
//! holds one of them. Adding a detector is a file under `src/detect/` with a type that
//! implements [`StepDetector`] and has a `const fn new(&DetectConfig) -> Self`, its `pub mod`
//! line in `src/detect/mod.rs`, and one line in the `detectors!` list at the end of this file.

use crate::detect::phase_stats::StrideStats;
use crate::detect::seam::DetectConfig;
use crate::detect::seam::{Drain, Input, StepDetector};
use crate::length::models::Model;
use crate::record::stride::{StepAmplitude, Stride};

/// Declares the detectors: the [`Detector`] names and [`AnyDetector`], which runs the one a
/// [`Config`](crate::pipeline::config::Config) names. One line per detector: `Variant("name") => Type,` (the type may use the
/// movement buffer's `M`), with doc comments if it wants more than its name; the second
/// argument is the model it measures with whatever the configured one, if any.
macro_rules! detectors {
    ($($(#[$doc:meta])* $v:ident($name:literal, $own:expr) => $ty:ty,)+) => {
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
            /// (Lu's detector: his fuzzy Weinberg on each step).
            pub const fn own_model(self) -> Option<Model> {
                match self {
                    $(Detector::$v => $own,)+
                }
            }

            /// The model behind its strides' lengths when `configured` is the configured one.
            pub const fn length_model(self, configured: Model) -> Model {
                match self.own_model() {
                    Some(m) => m,
                    None => configured,
                }
            }
        }

        /// One of the detectors, chosen at run time by
        /// [`Config::detector`](crate::pipeline::config::Config::detector) (the host tools).
        /// A pipeline runs one detector for its life, so they share their memory.
        #[derive(Clone, Debug)]
        #[allow(clippy::large_enum_variant)] // sharing the memory is the point
        pub enum AnyDetector<const M: usize> {
            $(#[doc = concat!("`", $name, "`.")] $(#[$doc])* $v($ty),)+
        }

        impl<const M: usize> AnyDetector<M> {
            /// The detector `which`, for data described by `config`.
            pub const fn new(which: Detector, config: &DetectConfig) -> Self {
                match which {
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
            fn step(&self, index: u32) -> Option<StepAmplitude> {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::step(d, index),)+
                }
            }
            fn dropped(&self) -> u32 {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::dropped(d),)+
                }
            }
            fn reports_late(&self) -> bool {
                match self {
                    $(AnyDetector::$v(d) => StepDetector::reports_late(d),)+
                }
            }
        }
    };
}

detectors! {
    /// One zero-velocity instant per gait cycle at every pace ([`crate::detect::cycle`]), strides
    /// from instant to instant with the rolling-contact ZUPT, events and phases by Huang's
    /// splitter, every length model: the default.
    Cycle("cycle", None) => crate::detect::cycle::CycleDetector<M>,
    /// Stance to stance (Huang's variance + IQR zero-velocity detector, the paper's
    /// method), with gait events, phases, the ZUPT displacement and every length model.
    Stance("stance", None) => crate::detect::stance_strides::StanceStrides<M>,
    /// Lu's peak-valley detection on vertical acceleration, measured by Lu's chain whatever
    /// the configured model. A stride record is one of its steps: `start`, `heel_off` and
    /// `toe_off` are its peak, `heel_strike` and `end` its valley; no stance, phases, ZUPT
    /// displacement or climb are measured (flag `PHASES_GUESSED`, and `FROM_REST` on a
    /// walk's first step).
    PeakValley("lu", Some(Model::LuFuzzy)) => crate::detect::peak_valley::PeakValleySteps,
}

//! The per-sample pipeline, composed in card order:
//!
//! ```text
//! raw sample ─┬─ mean filter ─┬─ rest test ─→ foot-frame estimator ─┐ (frame)
//!             │               └──────────── rotate into the foot frame ─→ stance detector
//!             └─ delay line ───────────────────────────────────────────→ stride tracker
//!                                  (phases, ZUPT displacement, phase stats, flags)
//!                                                   stride ─→ features ─→ length model
//! ```
//!
//! Each stage is fed only the records of the stage before it. The delays of the centred
//! windows are undone by delay lines, so that every stride index is the number of the raw
//! sample it names.
//!
//! **Three detectors.** [`Detector::Cycle`] (the default) replaces the stance detector and
//! stride tracker above by [`crate::cycle::CycleDetector`]: one zero-velocity instant per
//! gait cycle, strides from instant to instant, the same phases, ZUPT and models.
//! [`Detector::Stance`] is the chain above (Huang's method). [`Detector::PeakValley`] replaces the stance detector and stride tracker with Lu's
//! peak-valley detector ([`crate::peak_valley`]) on the foot frame's vertical acceleration,
//! and measures each of its steps with Lu's own chain, fuzzy `k` and Weinberg
//! ([`crate::models::lu_chain_um`]):
//!
//! ```text
//! raw sample ─ mean filter ─ rotate into the foot frame ─ vertical ─ peak-valley detector
//!                                                          step ─→ D, f ─→ fuzzy k ─→ Weinberg
//! ```

use crate::bridge;
use crate::cycle::{Calibration, CycleConfig, CycleDetector};
use crate::features::Features;
use crate::foot_frame::FootFrameEstimator;
use crate::foot_frame::FOOT_LSB_PER_G;
use crate::mean_filter::MeanFilter;
use crate::models::{self, Model, ModelParams, Settings};
use crate::peak_valley::{PeakValleyDetector, Step};
use crate::phase_stats::StrideStats;
use crate::phases::PhaseMethod;
use crate::rate::SampleRate;
use crate::rest::{RestDetector, RestThresholds};
use crate::sample::{AccelRange, GyroRange, RawSample};
use crate::stance::{StanceDetector, StanceLimits, StanceThresholds};
use crate::stride::{
    Origin, Stride, StrideFlags, StrideTracker, MAX_MOVEMENT_SAMPLES, MAX_STRIDE_MM,
    MIN_MOVEMENT_MS,
};

/// Capacity of the mean filter; the window used is the power of two nearest
/// [`MEAN_FILTER_MS`] at the sample rate, at most this.
pub const MEAN_FILTER_CAPACITY: usize = 16;
/// Mean-filter window, ms (4 samples at 200 Hz, 16 at 1 kHz).
pub const MEAN_FILTER_MS: u32 = 20;
/// Capacity of the delay lines that align raw samples and foot-frame samples with the
/// (centred) stance decision: ≥ stance delay (63) + filter delay (7) + 1.
pub const DELAY_CAPACITY: usize = 128;

/// Longest hole of lost samples that is bridged: interpolated across when the next sample
/// arrives, the stride it falls in flagged [`StrideFlags::BRIDGED`] and still measured.
/// Chosen by measurement (`gaitclip holes`, the README's hole table): the longest hole
/// whose mean |length error| against the uncut recordings stays ≤ 1 cm at the recordings'
/// rate and at half of it (with the cycle detector and the ZUPT stride as the default:
/// 30 ms holes cost 10.6 mm at 100 Hz in clusters in the swing; 30 ms until then).
pub const BRIDGE_MAX_MS: u32 = 20;
/// Longest hole interpolated at all. A longer hole than [`BRIDGE_MAX_MS`], up to this, is
/// filled too so that the stride's events outside it are still found, but a stride whose
/// movement it falls in is a [`StrideFlags::GAP`] stride without a length. Anything longer
/// restarts detection after it. At most [`MIN_MOVEMENT_MS`]: the samples one call then
/// feeds are fewer than separate two strides, so one call never has two to report.
pub const FILL_MAX_MS: u32 = MIN_MOVEMENT_MS;
const _: () = assert!(BRIDGE_MAX_MS <= FILL_MAX_MS && FILL_MAX_MS <= MIN_MOVEMENT_MS);

/// The model the firmware ships with as its stride length: the one with the best
/// leave-one-dataset-out score, as `gaitclip train` measured it
/// ([`crate::trained::LODO_BEST`]; the README's length tables).
pub const DEFAULT_MODEL: Model = crate::trained::LODO_BEST;

/// Which step detector segments the walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detector {
    /// One zero-velocity instant per gait cycle at every pace ([`crate::cycle`]), strides
    /// from instant to instant with the rolling-contact ZUPT, events and phases by Huang's
    /// splitter, every length model: the default.
    Cycle,
    /// Stance to stance (Huang's variance + IQR zero-velocity detector, the paper's
    /// method), with gait events, phases, the ZUPT displacement and every length model.
    Stance,
    /// Lu's peak-valley detection on vertical acceleration, measured by Lu's chain whatever
    /// the configured model. A stride record is one of its steps: `start`, `heel_off` and
    /// `toe_off` are its peak, `heel_strike` and `end` its valley; no stance, phases, ZUPT
    /// displacement or climb are measured (flag `PHASES_GUESSED`, and `FROM_REST` on a
    /// walk's first step).
    PeakValley,
}

impl Detector {
    /// Both, default first.
    pub const ALL: [Detector; 3] = [Detector::Cycle, Detector::Stance, Detector::PeakValley];

    /// The name `--detector` takes.
    pub const fn name(self) -> &'static str {
        match self {
            Detector::Cycle => "cycle",
            Detector::Stance => "stance",
            Detector::PeakValley => "lu",
        }
    }

    /// The detector called `name`.
    pub fn from_name(name: &str) -> Option<Detector> {
        Detector::ALL.into_iter().find(|d| d.name() == name)
    }
}

/// What the pipeline needs to know about the data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Sample rate.
    pub rate: SampleRate,
    /// Accelerometer range the counts are in.
    pub accel: AccelRange,
    /// Gyroscope range the counts are in.
    pub gyro: GyroRange,
    /// Step detector.
    pub detector: Detector,
    /// Phase splitter version.
    pub phases: PhaseMethod,
    /// The model that fills in [`Stride::length_mm`].
    pub model: Model,
    /// Device settings of the models (the wearer's height).
    pub settings: Settings,
    /// Trained coefficients and SVRs.
    pub params: &'static ModelParams<'static>,
    /// Longest hole bridged, ms ([`BRIDGE_MAX_MS`]; clamped to [`FILL_MAX_MS`]). A setting
    /// so that the hole-length sweep can measure what each limit costs.
    pub bridge_max_ms: u32,
    /// The stance detector's thresholds ([`StanceLimits::DEFAULT`]); a setting for the
    /// threshold sweep of [`crate::stance`].
    pub stance: StanceLimits,
    /// The sensor's height above the foot's rolling contact, µm
    /// ([`crate::cycle::SENSOR_HEIGHT_UM`]): where the clip sits on the shoe.
    pub sensor_height_um: u32,
}

impl Config {
    /// The default configuration for data at `rate` in the given ranges: the stance
    /// detector, the augmented phase splitter, the [`DEFAULT_MODEL`] with the shipped
    /// [`crate::trained::PARAMS`], and the default height.
    pub const fn new(rate: SampleRate, accel: AccelRange, gyro: GyroRange) -> Self {
        Config {
            rate,
            accel,
            gyro,
            detector: Detector::Cycle,
            phases: PhaseMethod::Augmented,
            model: DEFAULT_MODEL,
            settings: Settings::DEFAULT,
            params: &crate::trained::PARAMS,
            bridge_max_ms: BRIDGE_MAX_MS,
            stance: StanceLimits::DEFAULT,
            sensor_height_um: crate::cycle::SENSOR_HEIGHT_UM,
        }
    }

    /// The model behind the strides' lengths: [`Config::model`] for the stance detector,
    /// Lu's fuzzy Weinberg (his whole chain) for the peak-valley detector.
    pub const fn length_model(&self) -> Model {
        match self.detector {
            Detector::Cycle | Detector::Stance => self.model,
            Detector::PeakValley => Model::LuFuzzy,
        }
    }
}

const fn log2_nearest(n: u32) -> u32 {
    // Largest power of two ≤ n, moved up when n is nearer the next one.
    let mut k = 0;
    while k < 31 && (1u32 << (k + 1)) <= n {
        k += 1;
    }
    if k < 31 && n - (1 << k) > (1 << (k + 1)) - n {
        k + 1
    } else {
        k
    }
}

/// Holes of lost samples the pipeline has met, by what it did with them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HoleCounts {
    /// Holes bridged ([`BRIDGE_MAX_MS`] or shorter).
    pub bridged: u32,
    /// Samples interpolated across them.
    pub bridged_samples: u32,
    /// Longer holes ([`FILL_MAX_MS`] or shorter) filled for the events: gaps.
    pub filled: u32,
    /// Samples interpolated across them.
    pub filled_samples: u32,
    /// Holes after which detection restarted: gaps.
    pub restarted: u32,
    /// Samples lost in them.
    pub restarted_samples: u32,
}

impl HoleCounts {
    /// Holes that are gaps (filled or restarted): the strides their movements fall in have
    /// no length.
    pub const fn gaps(&self) -> u32 {
        self.filled.saturating_add(self.restarted)
    }

    /// Samples lost in the gaps.
    pub const fn gap_samples(&self) -> u32 {
        self.filled_samples.saturating_add(self.restarted_samples)
    }
}

/// What [`Pipeline::gap`] does with a hole of a given length (on its own: holes declared
/// one after the other add up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoleKind {
    /// Interpolated; the stride keeps its length ([`StrideFlags::BRIDGED`]).
    Bridged,
    /// Interpolated for the events; a stride whose movement it falls in is a gap stride.
    Filled,
    /// Detection restarts after it; the stride in progress is a gap stride.
    Restart,
}

/// A hole waiting for the samples after it, to be interpolated across.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct PendingHole {
    missing: u32,
    origin: Origin,
    /// A bridged hole waits for two samples after it (a cubic through two samples either
    /// side): the first of them, held until the second arrives.
    after: Option<RawSample>,
}

/// What one call's samples released, not yet measured: a stride of the stance detector's
/// tracker (written into place by it, no copy on the way) or a peak-valley step.
#[derive(Default)]
struct Released {
    stride: Option<Stride>,
    step: Option<Step>,
}

impl Released {
    fn is_empty(&self) -> bool {
        self.stride.is_none() && self.step.is_none()
    }
}

/// The step detector's state. A pipeline runs one detector for its life, so the two share
/// their memory: the peak-valley detector costs no RAM on a board that uses the stance one.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // sharing the memory is the point
enum Segmenter<const M: usize> {
    Cycle(CycleDetector<M>),
    Stance {
        stance: StanceDetector,
        tracker: StrideTracker<M>,
    },
    PeakValley(PeakValleyDetector),
}

/// From raw samples to strides, with a movement buffer of `M` samples
/// ([`MAX_MOVEMENT_SAMPLES`] by default, 6 KiB; see [`Pipeline::sized`]).
#[derive(Clone, Debug)]
pub struct Pipeline<const M: usize = MAX_MOVEMENT_SAMPLES> {
    filter: MeanFilter<MEAN_FILTER_CAPACITY>,
    rest: RestDetector,
    frame: FootFrameEstimator,
    segmenter: Segmenter<M>,
    rate: SampleRate,
    /// Accelerometer counts per g.
    accel_lsb_per_g: i32,
    model: Model,
    settings: Settings,
    params: &'static ModelParams<'static>,
    raw_line: [RawSample; DELAY_CAPACITY],
    foot_line: [[i16; 3]; DELAY_CAPACITY],
    /// One bit per delay-line slot: the sample was interpolated ([`Origin::Bridged`]).
    bridged_line: u128,
    /// One bit per delay-line slot: the sample was interpolated ([`Origin::Filled`]).
    filled_line: u128,
    /// Longest hole bridged / filled, samples.
    bridge_max: u32,
    fill_max: u32,
    /// A hole to interpolate across at the next sample.
    hole: PendingHole,
    /// A step released while filling a hole with no sample to report it from.
    held_step: Option<Step>,
    holes: HoleCounts,
    /// Samples between an input and the raw sample the rest decision is about.
    rest_delay: u32,
    /// Samples between an input and the raw sample the stance decision is about.
    delay: u32,
    /// Number of the next input sample.
    next: u32,
    /// Inputs since the last reset (start or gap).
    since_reset: u32,
    /// Inputs fed to the stance detector since the last reset.
    stance_fed: u32,
    last_decision: bool,
}

impl Pipeline {
    /// A pipeline for data described by `config`, with the default movement buffer.
    pub const fn new(config: Config) -> Self {
        Self::sized(config)
    }
}

impl<const M: usize> Pipeline<M> {
    /// A pipeline for data described by `config` that keeps at most `M` samples of a
    /// movement (6 bytes each). A board short of RAM picks fewer: `M` must cover the
    /// longest walking movement at its rate (about 1 s), or strides come out
    /// [`crate::stride::StrideFlags::TOO_LONG`].
    pub const fn sized(config: Config) -> Self {
        let filter =
            MeanFilter::with_len_log2(log2_nearest(config.rate.samples_in_ms(MEAN_FILTER_MS)));
        let rest = RestDetector::new(RestThresholds::new(config.rate, config.accel, config.gyro));
        let stance = StanceDetector::new(StanceThresholds::with_limits(
            config.rate,
            config.gyro,
            config.stance,
        ));
        let rest_delay = rest.delay() + filter.delay();
        let cycle = CycleConfig::new(
            config.rate,
            config.accel,
            config.gyro,
            config.phases,
            config.sensor_height_um,
        );
        let delay = match config.detector {
            Detector::Cycle => cycle.delay(),
            _ => stance.delay() + filter.delay(),
        };
        Pipeline {
            filter,
            rest,
            frame: FootFrameEstimator::new(config.rate, config.accel, config.gyro),
            segmenter: match config.detector {
                Detector::Cycle => Segmenter::Cycle(CycleDetector::new(cycle)),
                Detector::Stance => Segmenter::Stance {
                    stance,
                    tracker: StrideTracker::sized(config.rate, config.gyro, config.phases),
                },
                Detector::PeakValley => Segmenter::PeakValley(PeakValleyDetector::new(config.rate)),
            },
            rate: config.rate,
            accel_lsb_per_g: config.accel.lsb_per_g() as i32,
            model: config.model,
            settings: config.settings,
            params: config.params,
            raw_line: [RawSample {
                accel: [0; 3],
                gyro: [0; 3],
                temp: 0,
            }; DELAY_CAPACITY],
            foot_line: [[0; 3]; DELAY_CAPACITY],
            bridged_line: 0,
            filled_line: 0,
            bridge_max: config
                .rate
                .samples_in_ms(if config.bridge_max_ms < FILL_MAX_MS {
                    config.bridge_max_ms
                } else {
                    FILL_MAX_MS
                }),
            fill_max: config.rate.samples_in_ms(FILL_MAX_MS),
            hole: PendingHole {
                missing: 0,
                origin: Origin::Measured,
                after: None,
            },
            held_step: None,
            holes: HoleCounts {
                bridged: 0,
                bridged_samples: 0,
                filled: 0,
                filled_samples: 0,
                restarted: 0,
                restarted_samples: 0,
            },
            rest_delay,
            delay,
            next: 0,
            since_reset: 0,
            stance_fed: 0,
            last_decision: false,
        }
    }

    /// Latency of the stance decision in samples. A stride is reported when the stance
    /// after it ends: by the call that feeds the next heel-off + `latency`, or
    /// [`crate::stride::MAX_STANCE_IN_STRIDE_MS`] into that stance + `latency`.
    pub const fn latency(&self) -> u32 {
        self.delay
    }

    /// Number of the next sample to be fed.
    pub const fn next_index(&self) -> u32 {
        self.next
    }

    /// The foot frame found so far, if any: set once the clip has been still for
    /// [`crate::foot_frame::FIRST_FRAME_AFTER_MS`], its heading learnt from the first steps.
    pub const fn foot_frame(&self) -> Option<crate::foot_frame::FootFrame> {
        self.frame.frame()
    }

    /// Gyroscope bias measured over the last rest period, counts of the configured range
    /// (zero until the clip has been still once).
    pub const fn gyro_bias(&self) -> [i32; 3] {
        self.frame.gyro_bias()
    }

    /// What the cycle detector judges the newest decision with: gyro bias and gravity from
    /// the steadiest still blocks ([`crate::foot_frame::FootFrameEstimator::still_calibration`]),
    /// or the foot frame's rest before the first block qualifies, and the foot's standing up.
    /// `None` before the foot frame exists. After [`Pipeline::process`] it is what the
    /// decision about sample `next_index() − 1 − latency()` used (the host's f64 twin
    /// replays strides with it).
    pub fn cycle_calibration(&self) -> Option<Calibration> {
        let frame = self.frame.frame()?;
        let (gyro_bias, gravity_counts) = self.frame.still_calibration().unwrap_or((
            self.frame.gyro_bias(),
            frame.gravity() * self.accel_lsb_per_g / FOOT_LSB_PER_G,
        ));
        Some(Calibration {
            gyro_bias,
            gravity_counts,
            up: frame.up_row(),
        })
    }

    /// Feeds one sample; returns a stride when one can be reported. After a hole that
    /// [`Pipeline::gap`] keeps, the samples it lost are first interpolated: a bridged hole
    /// by the cubic through the two samples either side of it (this sample is then held
    /// until the next one arrives, one sample period late), a filled one on the straight
    /// line between the samples either side.
    // Not inlined: the caller's frame (a board's main loop) then holds no stage's
    // temporaries, and a hole's interpolation nests no deeper than a sample's stages.
    #[inline(never)]
    pub fn process(&mut self, s: &RawSample) -> Option<Stride> {
        let mut out = Released {
            stride: None,
            step: self.held_step.take(),
        };
        if self.hole.missing > 0 {
            self.after_hole(s, &mut out);
        } else {
            self.step(s, Origin::Measured, &mut out);
        }
        self.measure_released(out)
    }

    /// [`Pipeline::process`] with a hole pending. Not inlined: the interpolation's
    /// temporaries then take stack only after a hole, not on every sample's path (the M0's
    /// stack has a few hundred bytes to spare).
    #[inline(never)]
    fn after_hole(&mut self, s: &RawSample, out: &mut Released) {
        if self.hole.origin == Origin::Bridged && self.hole.after.is_none() && self.since_reset >= 2
        {
            self.hole.after = Some(*s);
            return;
        }
        let hole = core::mem::take(&mut self.hole);
        self.fill(hole, Some(s), out);
    }

    /// Fills a bridged hole up to the sample it holds, when no sample will follow it
    /// (another hole, or the end). What that releases is held: a stride by the tracker,
    /// reported at its next release, a step until the next sample. Not inlined, for the
    /// stack (see [`Pipeline::after_hole`]).
    #[inline(never)]
    fn flush_held(&mut self) {
        if self.hole.after.is_none() {
            return;
        }
        let hole = core::mem::take(&mut self.hole);
        let mut out = Released::default();
        self.fill(hole, None, &mut out);
        if let (Some(s), Segmenter::Stance { tracker, .. }) = (out.stride, &mut self.segmenter) {
            tracker.hold(s);
        }
        if out.step.is_some() {
            self.held_step = out.step;
        }
    }

    /// Feeds the interpolated samples of `hole`, the sample it held and `next`; with no
    /// `next` (another hole, or the end) the hole is filled on the straight line to the
    /// sample it held.
    #[inline(never)]
    fn fill(&mut self, hole: PendingHole, next: Option<&RawSample>, out: &mut Released) {
        let m = hole.missing;
        let p0 = self.raw_line[slot(self.next.wrapping_sub(1))];
        let pm1 = self.raw_line[slot(self.next.wrapping_sub(2))];
        match (hole.after, next) {
            (Some(q0), Some(q1)) => {
                for k in 1..=m {
                    let x = bridge::cubic(&[pm1, p0, q0, *q1], k, m);
                    self.step(&x, hole.origin, out);
                }
                self.step(&q0, Origin::Measured, out);
                self.step(q1, Origin::Measured, out);
            }
            (Some(q0), None) | (None, Some(&q0)) => {
                for k in 1..=m {
                    let x = bridge::linear(&p0, &q0, k, m + 1);
                    self.step(&x, hole.origin, out);
                }
                self.step(&q0, Origin::Measured, out);
            }
            (None, None) => {}
        }
    }

    /// The phase statistics of `stride` (the features' input), from its close until the
    /// stride after the next one closes: for a host to compute every model's features for
    /// the strides it is handed. `None` for the peak-valley detector's steps, for gap
    /// strides, and once they are gone.
    pub fn stats(&self, stride: &Stride) -> Option<&StrideStats> {
        match &self.segmenter {
            Segmenter::Cycle(c) => c.stats(stride.index),
            Segmenter::Stance { tracker, .. } => tracker.stats(stride.index),
            Segmenter::PeakValley(_) => None,
        }
    }

    /// The holes met so far, by what was done with them.
    pub const fn holes(&self) -> HoleCounts {
        self.holes
    }

    /// One sample through the stages; what it releases goes into `out` (at most one thing
    /// per call of [`Pipeline::process`], see [`FILL_MAX_MS`]; a second stride would be
    /// held back by the tracker, a second step by the peak-valley detector).
    #[inline(never)]
    fn step(&mut self, s: &RawSample, origin: Origin, out: &mut Released) {
        let index = self.next;
        self.next = self.next.wrapping_add(1);
        self.raw_line[slot(index)] = *s;
        let bit = 1u128 << slot(index);
        self.bridged_line &= !bit;
        self.filled_line &= !bit;
        match origin {
            Origin::Measured => {}
            Origin::Bridged => self.bridged_line |= bit,
            Origin::Filled => self.filled_line |= bit,
        }
        self.since_reset = self.since_reset.saturating_add(1);
        let filtered = self.filter.process(s.accel);
        if let Some(rest) = self.rest.process(filtered, s.gyro) {
            if self.since_reset > self.rest_delay {
                let at = index.wrapping_sub(self.rest_delay);
                self.frame.process(&self.raw_line[slot(at)], rest);
            }
        }
        let Some(frame) = self.frame.frame() else {
            return;
        };
        let foot = frame.apply(filtered);
        let cal = match self.segmenter {
            Segmenter::Cycle(_) => self.cycle_calibration(),
            _ => None,
        };
        let (stance, tracker) = match &mut self.segmenter {
            Segmenter::Cycle(cycle) => {
                self.foot_line[slot(index)] = foot;
                self.stance_fed = self.stance_fed.saturating_add(1);
                if self.since_reset <= self.delay + self.filter.delay() {
                    return;
                }
                // The decision is about the sample `delay` back; its mean-filtered foot-frame
                // value was computed `filter delay` inputs after it.
                let at = index.wrapping_sub(self.delay);
                let foot_at = at.wrapping_add(self.filter.delay());
                let (raw, foot) = (self.raw_line[slot(at)], self.foot_line[slot(foot_at)]);
                let origin = origin_of(self.bridged_line, self.filled_line, at);
                let Some(cal) = cal else {
                    return;
                };
                cycle.process_into(s, at, &raw, foot, origin, &cal, &mut out.stride);
                return;
            }
            Segmenter::Stance { stance, tracker } => (stance, tracker),
            Segmenter::PeakValley(peaks) => {
                // The filtered value is the mean of a window centred `delay` samples back.
                let at = index.wrapping_sub(self.filter.delay());
                if out.is_empty() {
                    out.step = peaks.process(at, foot[2]);
                } else {
                    peaks.feed(at, foot[2]);
                }
                return;
            }
        };
        self.foot_line[slot(index)] = foot;
        let Some(decision) = stance.process(foot, s.gyro) else {
            return;
        };
        self.stance_fed = self.stance_fed.saturating_add(1);
        self.last_decision = decision;
        if self.since_reset <= self.delay {
            return;
        }
        let at = index.wrapping_sub(self.delay);
        let foot_at = index.wrapping_sub(stance.delay());
        let (raw, foot) = (self.raw_line[slot(at)], self.foot_line[slot(foot_at)]);
        let origin = origin_of(self.bridged_line, self.filled_line, at);
        tracker.process_into(at, &raw, foot, decision, origin, &mut out.stride);
    }

    /// Measures what a call released.
    fn measure_released(&self, mut out: Released) -> Option<Stride> {
        if let Some(s) = out.stride.as_mut() {
            self.measure(s);
            return out.stride;
        }
        out.step.map(|s| self.measure_step(s))
    }

    /// Declares `missing` samples lost (FIFO overflow, a sensor that stopped answering, a
    /// jump in timestamps). What happens depends on how long the hole is:
    ///
    /// - **Up to [`BRIDGE_MAX_MS`]: bridged.** Nothing happens until the next sample; then
    ///   the missing samples are interpolated (linearly, per axis) between the samples
    ///   either side and fed as if measured. The stride they fall in is flagged
    ///   [`StrideFlags::BRIDGED`] and keeps its length and events.
    /// - **Up to [`FILL_MAX_MS`]: filled.** Interpolated the same way, so that detection
    ///   goes on and the events outside the hole are found, but a stride whose movement the
    ///   hole falls in is a [`StrideFlags::GAP`] stride, without a length (an event found
    ///   inside the hole is set to its first sample). In a stance, where the foot is at rest
    ///   either side, it only flags the stride [`StrideFlags::BRIDGED`].
    /// - **Longer: detection restarts.** The samples still in the delay line are drained as
    ///   at [`Pipeline::finish`], the stride in progress becomes a [`StrideFlags::GAP`]
    ///   stride (no length; heel-off and foot-flat measured, toe-off and heel-strike set to
    ///   the first missing sample; reported once the next stance is found after the gap),
    ///   and detection restarts after it. Returns the stride the drain let the tracker
    ///   report or that it held, complete and measured as usual. With
    ///   [`Detector::PeakValley`] the steps in flight are decided as at the end of a
    ///   recording and come out of the next calls to [`Pipeline::process`].
    ///
    /// Holes declared one after the other without a sample between add up. The samples
    /// fed are numbered on past the missing ones either way, so that indices keep
    /// counting sensor periods. [`Pipeline::holes`] counts what was done.
    // Not inlined: its strides would otherwise sit in the caller's frame on the sample path.
    #[inline(never)]
    pub fn gap(&mut self, missing: u32) -> Option<Stride> {
        if missing == 0 {
            return None;
        }
        // A bridged hole holding the sample after it is filled up to that sample now: the
        // new hole follows it.
        self.flush_held();
        let total = self.hole.missing.saturating_add(missing);
        if self.next > 0 && total <= self.fill_max {
            // Kept for the next sample to interpolate towards; counted as what it became.
            let (was, now) = (self.hole.origin, self.origin_for(total));
            self.uncount(self.hole);
            self.hole = PendingHole {
                missing: total,
                origin: now,
                after: None,
            };
            self.count(self.hole);
            if now == Origin::Filled && was != Origin::Filled {
                // A movement with a long hole in it does not teach the foot frame.
                self.frame.gap();
            }
            return None;
        }
        // Too long to interpolate (or nothing before it): a pending part joins it.
        self.uncount(self.hole);
        self.hole = PendingHole::default();
        self.holes.restarted = self.holes.restarted.saturating_add(1);
        self.holes.restarted_samples = self.holes.restarted_samples.saturating_add(total);
        if let Some(s) = self.held_step.take() {
            self.restart_after(total);
            return Some(self.measure_step(s));
        }
        self.restart_after(total)
    }

    /// What a hole of `missing` samples, on its own, becomes.
    pub const fn hole_kind(&self, missing: u32) -> HoleKind {
        if missing <= self.bridge_max {
            HoleKind::Bridged
        } else if missing <= self.fill_max {
            HoleKind::Filled
        } else {
            HoleKind::Restart
        }
    }

    fn origin_for(&self, missing: u32) -> Origin {
        if missing <= self.bridge_max {
            Origin::Bridged
        } else {
            Origin::Filled
        }
    }

    fn count(&mut self, h: PendingHole) {
        let c = &mut self.holes;
        match h.origin {
            Origin::Bridged => {
                c.bridged = c.bridged.saturating_add(1);
                c.bridged_samples = c.bridged_samples.saturating_add(h.missing);
            }
            Origin::Filled => {
                c.filled = c.filled.saturating_add(1);
                c.filled_samples = c.filled_samples.saturating_add(h.missing);
            }
            Origin::Measured => {}
        }
    }

    fn uncount(&mut self, h: PendingHole) {
        let c = &mut self.holes;
        if h.missing == 0 {
            return;
        }
        match h.origin {
            Origin::Bridged => {
                c.bridged = c.bridged.saturating_sub(1);
                c.bridged_samples = c.bridged_samples.saturating_sub(h.missing);
            }
            Origin::Filled => {
                c.filled = c.filled.saturating_sub(1);
                c.filled_samples = c.filled_samples.saturating_sub(h.missing);
            }
            Origin::Measured => {}
        }
    }

    /// The hole is too long to interpolate: drain, close the stride as a gap stride and
    /// start detection afresh after `missing` samples.
    fn restart_after(&mut self, missing: u32) -> Option<Stride> {
        // The drain runs on one stance decision, so it makes one transition at most, and
        // then the tracker holds nothing to hand back; should both ever carry a stride, the
        // later one stays held (reported after the gap), so nothing is lost.
        let drained = self.drain();
        let out = match &mut self.segmenter {
            Segmenter::Cycle(cycle) => {
                cycle.gap();
                drained
            }
            Segmenter::Stance { stance, tracker } => {
                stance.reset();
                match (drained, tracker.gap()) {
                    (Some(a), Some(b)) => {
                        tracker.hold(b);
                        Some(a)
                    }
                    (a, b) => a.or(b),
                }
            }
            Segmenter::PeakValley(peaks) => {
                peaks.gap();
                None
            }
        };
        self.next = self.next.wrapping_add(missing);
        self.since_reset = 0;
        self.stance_fed = 0;
        self.filter = MeanFilter::with_len_log2(self.filter.window().trailing_zeros());
        self.rest.reset();
        self.frame.gap();
        // Measured last and once: a single stride on this frame while the models run keeps
        // the gap path's stack no deeper than a sample's.
        out.map(|s| self.measured(s))
    }

    /// Drains the samples still in the delay line at the end of a recording, with the last
    /// stance decision, and returns the strides still held (at most two: one closed by the
    /// drained samples, one waiting for its following stance to end, or a gap stride still
    /// open). With [`Detector::PeakValley`] the first step still in flight; the others come
    /// from [`Pipeline::take`].
    pub fn finish(&mut self) -> [Option<Stride>; 2] {
        // The sample held after a bridged hole is the last: fill up to it.
        self.flush_held();
        let flushed_step = self.held_step.take();
        if self.hole.missing > 0 {
            // A hole at the very end has no sample after it to interpolate towards: the
            // recording simply ended before it (counted as lost).
            let hole = core::mem::take(&mut self.hole);
            self.uncount(hole);
            self.holes.restarted = self.holes.restarted.saturating_add(1);
            self.holes.restarted_samples =
                self.holes.restarted_samples.saturating_add(hole.missing);
        }
        let drained = self.drain();
        if let Segmenter::Cycle(cycle) = &mut self.segmenter {
            let mut last = None;
            cycle.finish(&mut last);
            self.since_reset = 0;
            self.stance_fed = 0;
            return [last.map(|s| self.measured(s)), None];
        }
        let Segmenter::Stance { tracker, .. } = &mut self.segmenter else {
            return match flushed_step {
                Some(s) => [Some(self.measure_step(s)), self.take()],
                None => [self.take(), None],
            };
        };
        let first = drained.or_else(|| tracker.finish());
        let second = tracker.finish();
        let out = [
            first.map(|s| self.measured(s)),
            second.map(|s| self.measured(s)),
        ];
        self.since_reset = 0;
        self.stance_fed = 0;
        out
    }

    /// After [`Pipeline::finish`]: the next stride still held, until `None`. The stance
    /// detector holds none beyond what `finish` returns; the peak-valley detector holds the
    /// steps its look-ahead was waiting on (up to half its [`crate::peak_valley::EXTREMES_CAPACITY`]).
    pub fn take(&mut self) -> Option<Stride> {
        match &mut self.segmenter {
            Segmenter::Cycle(_) | Segmenter::Stance { .. } => None,
            Segmenter::PeakValley(peaks) => {
                let step = peaks.finish();
                step.map(|s| self.measure_step(s))
            }
        }
    }

    /// Feeds the tracker the samples still in the delay line, with the last stance decision;
    /// returns the stride they let it report, if any, not yet measured.
    fn drain(&mut self) -> Option<Stride> {
        let mut closed = None;
        let Segmenter::Stance { stance, tracker } = &mut self.segmenter else {
            return None;
        };
        // The tracker has had samples up to `next − 1 − delay`; the foot-frame values reach
        // `next − 1 − filter delay`, so that many more can be drained.
        let fd = self.filter.delay();
        let pending = if self.stance_fed == 0 {
            0
        } else {
            stance.delay()
        };
        for k in (0..pending).rev() {
            let at = self.next.wrapping_sub(1 + fd).wrapping_sub(k);
            let foot_at = at.wrapping_add(fd);
            let (raw, foot) = (self.raw_line[slot(at)], self.foot_line[slot(foot_at)]);
            let origin = origin_of(self.bridged_line, self.filled_line, at);
            if let Some(st) = tracker.process(at, &raw, foot, self.last_decision, origin) {
                closed = Some(st);
            }
        }
        // Drained once: a second drain before new samples would feed them again.
        self.stance_fed = 0;
        closed
    }

    /// One of Lu's steps as a stride record, measured by Lu's chain.
    #[inline(never)]
    fn measure_step(&self, step: Step) -> Stride {
        let mut flags = StrideFlags::PHASES_GUESSED;
        if step.period == 0 {
            flags |= StrideFlags::FROM_REST;
        }
        let mut s = Stride {
            index: step.index,
            start: step.peak.index,
            heel_off: step.peak.index,
            toe_off: step.peak.index,
            heel_strike: step.valley.index,
            foot_flat: step.valley.index,
            end: step.valley.index,
            flags: StrideFlags(flags),
            ..Stride::default()
        };
        set_length(
            &mut s,
            models::um_to_mm(models::lu_chain_um(&step, self.rate)),
        );
        s
    }

    /// Fills in the stride's length from the configured model; a malformed trained model
    /// falls back to the ZUPT displacement, which needs no training.
    // Not inlined: the per-stride work stays out of the per-sample frame (stack), and
    // `gaitclip cost` counts it apart from the sample path.
    #[inline(never)]
    fn measure(&self, s: &mut Stride) {
        if s.flags.has(StrideFlags::GAP) {
            // No length across a gap; `length_mm` stays 0.
            return;
        }
        // The ZUPT model, the fallback, needs no statistics: empty ones if they were gone.
        let f = if self.model == Model::Zupt {
            Features::zupt_only(s)
        } else {
            let stats = self.stats(s).unwrap_or(&StrideStats::EMPTY);
            Features::of(s, stats, self.rate)
        };
        let mm = models::predict_mm(self.model, &f, self.settings, self.params)
            .or_else(|| models::predict_mm(Model::Zupt, &f, self.settings, self.params))
            .unwrap_or(0);
        set_length(s, mm);
    }

    /// [`Pipeline::measure`] on a stride that is handed back.
    fn measured(&self, mut s: Stride) -> Stride {
        self.measure(&mut s);
        s
    }
}

/// The delay-line slot of sample number `i`.
const fn slot(i: u32) -> usize {
    i as usize & (DELAY_CAPACITY - 1)
}

/// Whether sample `at`, still in the delay line, was measured or interpolated: its bit in
/// the `bridged` and `filled` masks.
const fn origin_of(bridged: u128, filled: u128, at: u32) -> Origin {
    let bit = 1u128 << slot(at);
    if bridged & bit != 0 {
        Origin::Bridged
    } else if filled & bit != 0 {
        Origin::Filled
    } else {
        Origin::Measured
    }
}

/// Sets a stride's length, clamped to [`MAX_STRIDE_MM`] and flagged
/// [`StrideFlags::IMPLAUSIBLE`] above it.
fn set_length(s: &mut Stride, mm: u32) {
    if mm > MAX_STRIDE_MM {
        s.flags.0 |= StrideFlags::IMPLAUSIBLE;
    }
    s.length_mm = mm.min(MAX_STRIDE_MM);
}

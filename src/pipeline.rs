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
//! **Two detectors.** [`Detector::Stance`] (the default) is the chain above.
//! [`Detector::PeakValley`] replaces the stance detector and stride tracker with Lu's
//! peak-valley detector ([`crate::peak_valley`]) on the foot frame's vertical acceleration,
//! and measures each of its steps with Lu's own chain, fuzzy `k` and Weinberg
//! ([`crate::models::lu_chain_um`]):
//!
//! ```text
//! raw sample ─ mean filter ─ rotate into the foot frame ─ vertical ─ peak-valley detector
//!                                                          step ─→ D, f ─→ fuzzy k ─→ Weinberg
//! ```

use crate::features::Features;
use crate::foot_frame::FootFrameEstimator;
use crate::mean_filter::MeanFilter;
use crate::models::{self, Model, ModelParams, Settings};
use crate::peak_valley::{PeakValleyDetector, Step};
use crate::phases::PhaseMethod;
use crate::rate::SampleRate;
use crate::rest::{RestDetector, RestThresholds};
use crate::sample::{AccelRange, GyroRange, RawSample};
use crate::stance::{StanceDetector, StanceThresholds};
use crate::stride::{Stride, StrideFlags, StrideTracker, MAX_MOVEMENT_SAMPLES, MAX_STRIDE_MM};

/// Capacity of the mean filter; the window used is the power of two nearest
/// [`MEAN_FILTER_MS`] at the sample rate, at most this.
pub const MEAN_FILTER_CAPACITY: usize = 16;
/// Mean-filter window, ms (4 samples at 200 Hz, 16 at 1 kHz).
pub const MEAN_FILTER_MS: u32 = 20;
/// Capacity of the delay lines that align raw samples and foot-frame samples with the
/// (centred) stance decision: ≥ stance delay (63) + filter delay (7) + 1.
pub const DELAY_CAPACITY: usize = 128;

/// The model the firmware ships with as its stride length (see the README's length
/// table for why).
pub const DEFAULT_MODEL: Model = Model::HuangSvrFusion;

/// Which step detector segments the walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detector {
    /// Stance to stance (Huang's zero-velocity detector), with gait events, phases, the
    /// ZUPT displacement and every length model: the default.
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
    pub const ALL: [Detector; 2] = [Detector::Stance, Detector::PeakValley];

    /// The name `--detector` takes.
    pub const fn name(self) -> &'static str {
        match self {
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
            detector: Detector::Stance,
            phases: PhaseMethod::Augmented,
            model: DEFAULT_MODEL,
            settings: Settings::DEFAULT,
            params: &crate::trained::PARAMS,
        }
    }

    /// The model behind the strides' lengths: [`Config::model`] for the stance detector,
    /// Lu's fuzzy Weinberg (his whole chain) for the peak-valley detector.
    pub const fn length_model(&self) -> Model {
        match self.detector {
            Detector::Stance => self.model,
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

/// The step detector's state. A pipeline runs one detector for its life, so the two share
/// their memory: the peak-valley detector costs no RAM on a board that uses the stance one.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // sharing the memory is the point
enum Segmenter<const M: usize> {
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
    model: Model,
    settings: Settings,
    params: &'static ModelParams<'static>,
    raw_line: [RawSample; DELAY_CAPACITY],
    foot_line: [[i16; 3]; DELAY_CAPACITY],
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
        let stance = StanceDetector::new(StanceThresholds::new(config.rate, config.gyro));
        let rest_delay = rest.delay() + filter.delay();
        let delay = stance.delay() + filter.delay();
        Pipeline {
            filter,
            rest,
            frame: FootFrameEstimator::new(config.rate, config.accel),
            segmenter: match config.detector {
                Detector::Stance => Segmenter::Stance {
                    stance,
                    tracker: StrideTracker::sized(config.rate, config.gyro, config.phases),
                },
                Detector::PeakValley => Segmenter::PeakValley(PeakValleyDetector::new(config.rate)),
            },
            rate: config.rate,
            model: config.model,
            settings: config.settings,
            params: config.params,
            raw_line: [RawSample {
                accel: [0; 3],
                gyro: [0; 3],
                temp: 0,
            }; DELAY_CAPACITY],
            foot_line: [[0; 3]; DELAY_CAPACITY],
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

    /// Feeds one sample; returns a stride when one can be reported.
    pub fn process(&mut self, s: &RawSample) -> Option<Stride> {
        let index = self.next;
        self.next = self.next.wrapping_add(1);
        let slot = |i: u32| i as usize & (DELAY_CAPACITY - 1);
        self.raw_line[slot(index)] = *s;
        self.since_reset = self.since_reset.saturating_add(1);
        let filtered = self.filter.process(s.accel);
        if let Some(rest) = self.rest.process(filtered, s.gyro) {
            if self.since_reset > self.rest_delay {
                let at = index.wrapping_sub(self.rest_delay);
                self.frame.process(&self.raw_line[slot(at)], rest);
            }
        }
        let frame = self.frame.frame()?;
        let foot = frame.apply(filtered);
        let (stance, tracker) = match &mut self.segmenter {
            Segmenter::Stance { stance, tracker } => (stance, tracker),
            Segmenter::PeakValley(peaks) => {
                // The filtered value is the mean of a window centred `delay` samples back.
                let at = index.wrapping_sub(self.filter.delay());
                let step = peaks.process(at, foot[2]);
                return step.map(|s| self.measure_step(s));
            }
        };
        self.foot_line[slot(index)] = foot;
        let decision = stance.process(foot, s.gyro)?;
        self.stance_fed = self.stance_fed.saturating_add(1);
        self.last_decision = decision;
        if self.since_reset <= self.delay {
            return None;
        }
        let at = index.wrapping_sub(self.delay);
        let foot_at = index.wrapping_sub(stance.delay());
        let (raw, foot) = (self.raw_line[slot(at)], self.foot_line[slot(foot_at)]);
        let stride = tracker.process(at, &raw, foot, decision);
        stride.map(|s| self.measure(s))
    }

    /// Declares `missing` samples lost (FIFO overflow, a sensor that stopped answering, a
    /// jump in timestamps). The samples still in the delay line are drained as at
    /// [`Pipeline::finish`], the stride in progress becomes a
    /// [`crate::stride::StrideFlags::GAP`] stride (no length, reported once the next stance
    /// is found after the gap), and detection restarts after it. Returns the stride the drain
    /// let the tracker report or that it held, complete and measured as usual.
    ///
    /// With [`Detector::PeakValley`] the steps in flight are decided as at the end of a
    /// recording and come out of the next calls to [`Pipeline::process`].
    // Not inlined: its strides would otherwise sit in the caller's frame on the sample path.
    #[inline(never)]
    pub fn gap(&mut self, missing: u32) -> Option<Stride> {
        // The drain runs on one stance decision, so it makes one transition at most, and
        // then the tracker holds nothing to hand back; should both ever carry a stride, the
        // later one stays held (reported after the gap), so nothing is lost.
        let drained = self.drain();
        let out = match &mut self.segmenter {
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
        out.map(|s| self.measure(s))
    }

    /// Drains the samples still in the delay line at the end of a recording, with the last
    /// stance decision, and returns the strides still held (at most two: one closed by the
    /// drained samples, one waiting for its following stance to end, or a gap stride still
    /// open). With [`Detector::PeakValley`] the first step still in flight; the others come
    /// from [`Pipeline::take`].
    pub fn finish(&mut self) -> [Option<Stride>; 2] {
        let drained = self.drain();
        let Segmenter::Stance { tracker, .. } = &mut self.segmenter else {
            return [self.take(), None];
        };
        let first = drained.or_else(|| tracker.finish());
        let second = tracker.finish();
        let out = [
            first.map(|s| self.measure(s)),
            second.map(|s| self.measure(s)),
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
            Segmenter::Stance { .. } => None,
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
        let slot = |i: u32| i as usize & (DELAY_CAPACITY - 1);
        for k in (0..pending).rev() {
            let at = self.next.wrapping_sub(1 + fd).wrapping_sub(k);
            let foot_at = at.wrapping_add(fd);
            let (raw, foot) = (self.raw_line[slot(at)], self.foot_line[slot(foot_at)]);
            if let Some(st) = tracker.process(at, &raw, foot, self.last_decision) {
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
    fn measure(&self, mut s: Stride) -> Stride {
        if s.flags.has(StrideFlags::GAP) {
            // No length across a gap; `length_mm` stays 0.
            return s;
        }
        let f = Features::of(&s, self.rate);
        let mm = models::predict_mm(self.model, &f, self.settings, self.params)
            .or_else(|| models::predict_mm(Model::Zupt, &f, self.settings, self.params))
            .unwrap_or(0);
        set_length(&mut s, mm);
        s
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

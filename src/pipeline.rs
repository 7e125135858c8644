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
//! **Three detectors** behind one seam ([`crate::detect::seam::StepDetector`]; the pipeline is
//! generic over it): the default [`crate::detect::cycle::CycleDetector`] replaces the stance
//! detector and stride tracker above by one zero-velocity instant per gait cycle, strides
//! from instant to instant, the same phases, ZUPT and models;
//! [`crate::detect::stance_strides::StanceStrides`] is the chain above (Huang's method);
//! [`crate::detect::peak_valley::PeakValleySteps`] is Lu's peak-valley detector on the foot frame's
//! vertical acceleration, each step measured with Lu's own chain, fuzzy `k` and Weinberg
//! ([`crate::length::lu::lu_chain_um`]):
//!
//! ```text
//! raw sample ─ mean filter ─ rotate into the foot frame ─ vertical ─ peak-valley detector
//!                                                          step ─→ D, f ─→ fuzzy k ─→ Weinberg
//! ```

pub mod config;
pub mod detectors;

use crate::detect::cycle::Calibration;
use crate::detect::foot_frame::FootFrameEstimator;
use crate::detect::phase_stats::StrideStats;
use crate::detect::rest::{RestDetector, RestThresholds};
use crate::detect::seam::{DelayLines, Drain, Input, StepDetector, MAX_MOVEMENT_SAMPLES};
use crate::detect::step_check::{Path, Rate, Rejected, RejectedMovement, StepLedger};
use crate::gait::GaitTimer;
use crate::length::estimate::LengthEstimator;
use crate::length::models::LengthChain;
use crate::pipeline::config::{Config, FILL_MAX_MS};
use crate::pipeline::detectors::AnyDetector;
use crate::record::stride::{Between, Stride, StrideFlags};
use crate::sensor::sample::{Origin, Rails, RawSample};
use crate::signal::bridge;
use crate::signal::mean_filter::MeanFilter;

/// Capacity of the mean filter; the window used is the power of two nearest
/// [`MEAN_FILTER_MS`] at the sample rate, at most this.
pub const MEAN_FILTER_CAPACITY: usize = 16;
/// Mean-filter window, ms (4 samples at 200 Hz, 16 at 1 kHz).
pub const MEAN_FILTER_MS: u32 = 20;
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
    /// Holes bridged ([`BRIDGE_MAX_MS`](crate::pipeline::config::BRIDGE_MAX_MS) or shorter).
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

/// The time outside the strides that counted, by what the foot did ([`Between`], summed):
/// what the wearer did when not walking.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BetweenTotals {
    /// At rest, ms.
    pub still_ms: u64,
    /// Moving without a step, ms.
    pub moving_ms: u64,
}

impl BetweenTotals {
    fn add(&mut self, b: Between) {
        self.still_ms = self.still_ms.saturating_add(b.still_ms as u64);
        self.moving_ms = self.moving_ms.saturating_add(b.moving_ms as u64);
    }
}

/// What [`Pipeline::gap`] does with a hole of a given length (on its own: holes declared
/// one after the other add up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoleKind {
    /// Interpolated; the stride keeps its length ([`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED)).
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

/// From raw samples to strides, through the step detector `D` (by default the one the
/// [`Config`] names, with the default movement buffer of [`MAX_MOVEMENT_SAMPLES`] samples).
#[derive(Clone, Debug)]
pub struct Pipeline<D = AnyDetector<MAX_MOVEMENT_SAMPLES>> {
    filter: MeanFilter<MEAN_FILTER_CAPACITY>,
    rest: RestDetector,
    frame: FootFrameEstimator,
    detector: D,
    lines: DelayLines,
    chain: LengthChain,
    /// A length for the strides that could not be measured, from those that were.
    estimate: LengthEstimator,
    /// The last stage: gait parameters from the events and the length.
    gait: GaitTimer,
    /// The rests and rotations of every sample, which a stride must show to count
    /// ([`crate::detect::step_check`]), and the movements refused.
    ledger: StepLedger,
    check_steps: bool,
    rejected: Rejected,
    /// The last movement refused, until [`Pipeline::take_rejected`] takes it.
    last_rejected: Option<RejectedMovement>,
    /// Strides that counted so far: the next one's [`Stride::index`].
    counted: u32,
    /// The last two strides' numbers and the detector's numbers of their movements (whose
    /// statistics the detector keeps by its own numbering).
    numbered: [(u32, u32); 2],
    between: BetweenTotals,
    /// Accelerometer counts per g.
    accel_lsb_per_g: i32,
    /// Longest hole bridged / filled, samples.
    bridge_max: u32,
    fill_max: u32,
    /// A hole to interpolate across at the next sample.
    hole: PendingHole,
    holes: HoleCounts,
    /// Samples between an input and the raw sample the rest decision is about.
    rest_delay: u32,
    /// Number of the next input sample.
    next: u32,
    /// Inputs since the last reset (start or gap).
    since_reset: u32,
    /// [`Pipeline::finish`] has flushed what was pending and is handing out what is held.
    finishing: bool,
    /// The rest test's latest decision (false until its window has filled).
    at_rest: bool,
    /// Where each axis clips, and the measured samples at a rail per axis (accelerometer x,
    /// y, z, gyroscope x, y, z).
    rails: Rails,
    clipped: [u32; 6],
}

impl Pipeline {
    /// A pipeline for data described by `config`, with the detector it names
    /// ([`Config::detector`]) and the default movement buffer.
    pub const fn new(config: Config) -> Self {
        Self::sized(config)
    }
}

impl<const M: usize> Pipeline<AnyDetector<M>> {
    /// A pipeline for data described by `config`, with the detector it names, that keeps
    /// at most `M` samples of a movement (6 bytes each). A board short of RAM picks fewer:
    /// `M` must cover the longest walking movement at its rate (about 1 s), or strides come
    /// out [`crate::record::stride::StrideFlags::TOO_LONG`].
    pub const fn sized(config: Config) -> Self {
        Self::with_detector(config, AnyDetector::new(config.detector, &config.detect()))
    }
}

impl<D: StepDetector> Pipeline<D> {
    /// A pipeline for data described by `config` through `detector` (made from the same
    /// configuration): a firmware names its detector's type, and links only that one.
    pub const fn with_detector(config: Config, detector: D) -> Self {
        let filter =
            MeanFilter::with_len_log2(log2_nearest(config.rate.samples_in_ms(MEAN_FILTER_MS)));
        let rest = RestDetector::new(RestThresholds::new(config.rate, config.accel, config.gyro));
        let rest_delay = rest.delay() + filter.delay();
        Pipeline {
            filter,
            rest,
            frame: FootFrameEstimator::new(config.rate, config.accel, config.gyro),
            detector,
            lines: DelayLines::new(),
            gait: GaitTimer::new(config.rate),
            ledger: StepLedger::new(config.rate, config.gyro),
            check_steps: config.check_steps,
            last_rejected: None,
            counted: 0,
            numbered: [(u32::MAX, u32::MAX); 2],
            rejected: Rejected {
                by_reason: [0; 4],
                unchecked: 0,
            },
            between: BetweenTotals {
                still_ms: 0,
                moving_ms: 0,
            },
            estimate: LengthEstimator::new(),
            chain: LengthChain {
                model: config.length_model(),
                settings: config.settings,
                params: config.params,
                rate: config.rate,
            },
            accel_lsb_per_g: config.accel.lsb_per_g() as i32,
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
            holes: HoleCounts {
                bridged: 0,
                bridged_samples: 0,
                filled: 0,
                filled_samples: 0,
                restarted: 0,
                restarted_samples: 0,
            },
            rest_delay,
            next: 0,
            since_reset: 0,
            finishing: false,
            at_rest: false,
            rails: config.rails,
            clipped: [0; 6],
        }
    }

    /// Samples read at a rail so far, per axis: accelerometer x, y, z, gyroscope x, y, z
    /// (interpolated samples are not counted). What a board's summary reports.
    pub const fn clipped_samples(&self) -> [u32; 6] {
        self.clipped
    }

    /// Latency of the detector's decision in samples: the decision about a sample is made
    /// when this many more have been fed. A stride is reported at the decision that closes
    /// it (for the stance detector, when the stance after it ends, or
    /// [`crate::detect::seam::MAX_STANCE_IN_STRIDE_MS`] into it).
    pub fn latency(&self) -> u32 {
        self.detector.delay(self.filter.delay())
    }

    /// Whether the clip is still: the orientation-free rest test ([`crate::detect::rest`]) on the
    /// latest window of samples, false until a window has filled after the start or a
    /// restart. What a board's sleep policy watches.
    pub const fn at_rest(&self) -> bool {
        self.at_rest
    }

    /// Number of the next sample to be fed.
    pub const fn next_index(&self) -> u32 {
        self.next
    }

    /// The step detector.
    pub const fn detector(&self) -> &D {
        &self.detector
    }

    /// The foot frame found so far, if any: set once the clip has been still for
    /// [`crate::detect::foot_frame::FIRST_FRAME_AFTER_MS`], its heading learnt from the first steps.
    pub const fn foot_frame(&self) -> Option<crate::detect::foot_frame::FootFrame> {
        self.frame.frame()
    }

    /// Gyroscope bias measured over the last rest period, counts of the configured range
    /// (zero until the clip has been still once).
    pub const fn gyro_bias(&self) -> [i32; 3] {
        self.frame.gyro_bias()
    }

    /// What the cycle detector judges the newest decision with ([`Calibration::of`]).
    /// After [`Pipeline::process`] it is what the decision about sample
    /// `next_index() − 1 − latency()` used (the host's f64 twin replays strides with it).
    pub fn cycle_calibration(&self) -> Option<Calibration> {
        Calibration::of(&self.frame, self.accel_lsb_per_g)
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
        self.finishing = false;
        let mut out = None;
        if self.hole.missing > 0 {
            self.after_hole(s, &mut out);
        } else {
            self.step(s, Origin::Measured, &mut out);
        }
        out.and_then(|st| self.accept(st))
    }

    /// [`Pipeline::process`] with a hole pending. Not inlined: the interpolation's
    /// temporaries then take stack only after a hole, not on every sample's path (the M0's
    /// stack has a few hundred bytes to spare).
    #[inline(never)]
    fn after_hole(&mut self, s: &RawSample, out: &mut Option<Stride>) {
        if self.hole.origin == Origin::Bridged && self.hole.after.is_none() && self.since_reset >= 2
        {
            self.hole.after = Some(*s);
            return;
        }
        let hole = core::mem::take(&mut self.hole);
        self.fill(hole, Some(s), out);
    }

    /// Fills a bridged hole up to the sample it holds, when no sample will follow it
    /// (another hole, or the end). What that releases the detector holds and reports at its
    /// next release. Not inlined, for the stack (see [`Pipeline::after_hole`]).
    #[inline(never)]
    fn flush_held(&mut self) {
        if self.hole.after.is_none() {
            return;
        }
        let hole = core::mem::take(&mut self.hole);
        let mut out = None;
        self.fill(hole, None, &mut out);
        if let Some(s) = out {
            self.detector.hold(s);
        }
    }

    /// Feeds the interpolated samples of `hole`, the sample it held and `next`; with no
    /// `next` (another hole, or the end) the hole is filled on the straight line to the
    /// sample it held.
    #[inline(never)]
    fn fill(&mut self, hole: PendingHole, next: Option<&RawSample>, out: &mut Option<Stride>) {
        let m = hole.missing;
        let p0 = self.lines.raw(self.next.wrapping_sub(1));
        let pm1 = self.lines.raw(self.next.wrapping_sub(2));
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
        let movement = self
            .numbered
            .iter()
            .find(|(index, _)| *index == stride.index)
            .map(|(_, m)| *m)?;
        self.detector.stats(movement)
    }

    /// The holes met so far, by what was done with them.
    pub const fn holes(&self) -> HoleCounts {
        self.holes
    }

    /// One sample through the stages; what it releases goes into `out` (at most one stride
    /// per call of [`Pipeline::process`], see [`FILL_MAX_MS`]; a second one the detector
    /// holds back).
    #[inline(never)]
    fn step(&mut self, s: &RawSample, origin: Origin, out: &mut Option<Stride>) {
        let index = self.next;
        self.next = self.next.wrapping_add(1);
        self.lines.push(index, s, origin);
        self.since_reset = self.since_reset.saturating_add(1);
        if origin == Origin::Measured {
            let bits = self.rails.clipped_axes(s);
            if bits != 0 {
                self.count_clipped(bits);
            }
        }
        let filtered = self.filter.process(s.accel);
        let mut decision = None;
        if let Some(rest) = self.rest.process(filtered, s.gyro) {
            self.at_rest = rest;
            if self.since_reset > self.rest_delay {
                let at = index.wrapping_sub(self.rest_delay);
                let raw = self.lines.raw(at);
                self.frame.process(&raw, rest);
                self.note_motion(at, rest, &raw);
                decision = Some((at, rest));
            }
        }
        let Some(frame) = self.frame.frame() else {
            return;
        };
        let foot = frame.apply(filtered);
        self.lines.set_foot(index, foot);
        let input = Input {
            index,
            newest: s,
            origin,
            foot,
            filter_delay: self.filter.delay(),
            since_reset: self.since_reset,
            lines: &self.lines,
            frame: &self.frame,
            accel_lsb_per_g: self.accel_lsb_per_g,
            rest: decision,
            steps: &self.ledger,
        };
        self.detector.process(&input, out);
    }

    /// Sample `at` (raw, at rest or not) into the step check's ledger, with its rate about the
    /// steps' pitch axis once that is known.
    fn note_motion(&mut self, at: u32, rest: bool, raw: &RawSample) {
        let rate = match self.frame.frame() {
            Some(f) => {
                let b = self.frame.gyro_bias();
                let w = [
                    raw.gyro[0] as i32 - b[0],
                    raw.gyro[1] as i32 - b[1],
                    raw.gyro[2] as i32 - b[2],
                ];
                Rate::Level(f.level_rates(&w))
            }
            None => Rate::Unknown,
        };
        self.ledger.process(at, rest, rate);
    }

    /// The step check's record of rests and rotations.
    pub const fn step_ledger(&self) -> &StepLedger {
        &self.ledger
    }

    /// Movements the step check refused, by reason.
    pub const fn rejected(&self) -> Rejected {
        self.rejected
    }

    /// The last movement the step check refused since this was last called (a log or a host
    /// that reports them takes it after each call that fed samples; an older one not taken
    /// is only counted).
    pub fn take_rejected(&mut self) -> Option<RejectedMovement> {
        self.last_rejected.take()
    }

    /// The time outside the strides that counted, still and moving, so far (the time after
    /// the last stride is added when [`Pipeline::finish`] has handed out every stride).
    pub const fn between(&self) -> BetweenTotals {
        self.between
    }

    /// Declares `missing` samples lost (FIFO overflow, a sensor that stopped answering, a
    /// jump in timestamps). What happens depends on how long the hole is:
    ///
    /// - **Up to [`BRIDGE_MAX_MS`](crate::pipeline::config::BRIDGE_MAX_MS): bridged.** Nothing happens until the next sample; then
    ///   the missing samples are interpolated (a cubic through the two samples either side)
    ///   and fed as if measured. The stride they fall in is flagged
    ///   [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED) and keeps its length and events.
    /// - **Up to [`FILL_MAX_MS`]: filled.** Interpolated on a straight line, so that
    ///   detection goes on and the events outside the hole are found, but a stride whose
    ///   movement the hole falls in is a [`StrideFlags::GAP`](crate::record::stride::StrideFlags::GAP) stride, without a length (an
    ///   event found inside the hole is set to its first sample). In a stance, where the
    ///   foot is at rest either side, it only flags the stride [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED).
    /// - **Longer: detection restarts.** The detector drains what it can
    ///   ([`StepDetector::restart`]), the stride in progress becomes a
    ///   [`StrideFlags::GAP`](crate::record::stride::StrideFlags::GAP) stride (no length; reported once the next stance is found
    ///   after the gap), and detection restarts after it. Returns the stride that was
    ///   complete before the hole, if the detector held one, measured as usual.
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
        self.restart_after(total)
    }

    /// Counts the axes of `bits` ([`Rails::clipped_axes`]). Off the sample path's frame.
    #[inline(never)]
    fn count_clipped(&mut self, bits: u8) {
        for (k, c) in self.clipped.iter_mut().enumerate() {
            if bits & (1 << k) != 0 {
                *c = c.saturating_add(1);
            }
        }
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

    /// Counts hole `h` as what it became.
    fn count(&mut self, h: PendingHole) {
        self.tally(h, u32::saturating_add);
    }

    /// Takes back [`Pipeline::count`] of `h`: a pending hole grew into another kind.
    fn uncount(&mut self, h: PendingHole) {
        if h.missing > 0 {
            self.tally(h, u32::saturating_sub);
        }
    }

    fn tally(&mut self, h: PendingHole, op: fn(u32, u32) -> u32) {
        let c = &mut self.holes;
        let (holes, samples) = match h.origin {
            Origin::Bridged => (&mut c.bridged, &mut c.bridged_samples),
            Origin::Filled => (&mut c.filled, &mut c.filled_samples),
            Origin::Measured => return,
        };
        *holes = op(*holes, 1);
        *samples = op(*samples, h.missing);
    }

    /// The hole is too long to interpolate: the detector drains and closes the stride as
    /// a gap stride, and detection starts afresh after `missing` samples.
    fn restart_after(&mut self, missing: u32) -> Option<Stride> {
        let (next, filter_delay, lines) = (self.next, self.filter.delay(), &self.lines);
        let out = self.detector.restart(&Drain {
            next,
            filter_delay,
            lines,
        });
        self.estimate.restarted_at(self.next);
        // Measured before the hole's time is handed out: the stride is before it.
        let out = out.and_then(|s| self.accept(s));
        self.ledger.hole(self.next, missing);
        self.next = self.next.wrapping_add(missing);
        self.since_reset = 0;
        self.filter = MeanFilter::with_len_log2(self.filter.window().trailing_zeros());
        self.rest.reset();
        self.at_rest = false;
        self.frame.gap();
        out
    }

    /// At the end of a recording: the strides still held or in flight, one per call, until
    /// `None` (the samples still in the delay lines are drained first, and a bridged hole's
    /// held sample is filled up to). Feeding a sample afterwards starts afresh.
    pub fn finish(&mut self) -> Option<Stride> {
        if !self.finishing {
            self.finishing = true;
            // The sample held after a bridged hole is the last: fill up to it.
            self.flush_held();
            if self.hole.missing > 0 {
                // A hole at the very end has no sample after it to interpolate towards: the
                // recording simply ended before it (counted as lost).
                let hole = core::mem::take(&mut self.hole);
                self.uncount(hole);
                self.holes.restarted = self.holes.restarted.saturating_add(1);
                self.holes.restarted_samples =
                    self.holes.restarted_samples.saturating_add(hole.missing);
            }
        }
        loop {
            let (next, filter_delay, lines) = (self.next, self.filter.delay(), &self.lines);
            let out = self.detector.finish(&Drain {
                next,
                filter_delay,
                lines,
            });
            match out {
                None => {
                    self.since_reset = 0;
                    let b = self.ledger.tail();
                    self.between.add(b);
                    return None;
                }
                Some(s) => {
                    if let Some(s) = self.accept(s) {
                        return Some(s);
                    }
                }
            }
        }
    }

    /// The step check ([`crate::detect::step_check`]) on a stride the detector handed out,
    /// then the stages after it; `None` (counted by reason) for a movement that is not a step
    /// on the ground. A gap stride is not checked: the hole took part of what it would be
    /// judged on, and it is flagged already.
    #[inline(never)]
    fn accept(&mut self, mut s: Stride) -> Option<Stride> {
        let evidence = self.ledger.evidence(&s);
        s.swing_deg = evidence.swing_deg.min(u16::MAX as u32) as u16;
        // A detector that reports seconds late (Lu's) is beyond the ledger's reach: its
        // strides count unjudged, all of them, so that its counts do not depend on how
        // late each one came.
        let unjudgeable = self.detector.reports_late();
        if self.check_steps && !s.flags.has(StrideFlags::GAP) && unjudgeable {
            self.rejected.unchecked = self.rejected.unchecked.saturating_add(1);
        } else if self.check_steps && !s.flags.has(StrideFlags::GAP) {
            let verdict = evidence.judge(Path::of(&s));
            self.ledger.judged(&s, &evidence, verdict);
            if let Err(why) = verdict {
                let n = &mut self.rejected.by_reason[why as usize];
                *n = n.saturating_add(1);
                self.last_rejected = Some(RejectedMovement {
                    start: s.events.start,
                    end: s.events.end,
                    movement: (s.events.heel_off, s.events.foot_flat),
                    reason: why,
                    swing_deg: s.swing_deg,
                    swing_peak_mradps: evidence.swing_peak_mradps,
                    rest: (evidence.rest_before, evidence.rest_after),
                    horizontal_mm: s.zupt_um / 1000,
                    climb_mm: s.climb_mm,
                    lift_mm: s.max_sensor_lift_mm,
                });
                return None;
            }
        }
        s.between = self.ledger.between(s.events.start, s.events.end);
        self.between.add(s.between);
        self.complete(&mut s);
        // Numbered among the strides that count (the detector numbers every movement).
        let movement = s.index;
        s.index = self.counted;
        self.numbered[(self.counted & 1) as usize] = (self.counted, movement);
        self.counted = self.counted.wrapping_add(1);
        Some(s)
    }

    /// The stages after the detector: the length (measured, or estimated where it could
    /// not be), then the gait parameters that need it.
    fn complete(&mut self, s: &mut Stride) {
        let (stats, step) = (self.detector.stats(s.index), self.detector.step(s.index));
        self.chain.measure(s, stats, step);
        self.estimate.process(s);
        self.gait.process(s);
    }
}

//! Lu et al. 2020's peak-valley step detection (§2), streaming and in integers.
//!
//! A second step detector beside the stance-based one ([`crate::detect::stance`]): it looks only at
//! the vertical acceleration of the foot frame with gravity removed, and counts a step for
//! every *peak followed by a valley* that survives Lu's rules against over-counting.
//!
//! ```text
//! vertical (g/2048) ─ 3 Hz low-pass ─ extremes ─ static ─ dynamic threshold ─ minimum interval
//!                                      ─ neighbouring difference ─ peak-valley sequence ─ Step
//! ```
//!
//! 1. **Low-pass** ([`crate::signal::low_pass`]): −3 dB at 3 Hz at every sample rate.
//! 2. **Extremes**: a peak is a local maximum above zero, a valley a local minimum below
//!    zero (negative peaks and positive valleys are ignored); on a plateau, its last sample.
//!    None is taken in the filter's first delay after a start or a gap (it is settling).
//! 3. **Static** (eq. 2): a peak whose running mean with the next two peaks is below
//!    [`STATIC_G`] (0.01 g) is the sensor at rest and is removed; valleys likewise above
//!    −0.01 g.
//! 4. **Dynamic threshold** (eq. 3, 4): of what remains, a peak is kept if it is at least
//!    `c` = 0.4 times the mean of itself and the next nine peaks and at least `Th1` = 0.02 g;
//!    a valley if it is at most 0.4 times its mean and at most `Th2` = −0.02 g.
//! 5. **Minimum interval**: of two peaks (valleys) closer than [`MIN_INTERVAL_MS`] (16
//!    samples at the paper's 50 Hz), the one closer to zero is removed, and the survivor is
//!    compared with the next.
//! 6. **Neighbouring difference** (eq. 5): with `Δ₁ = y_prev − y₀`, `Δ₂ = y_next − y₀`, a peak
//!    `y₀` smaller than both differences, both above 0.1 g, is an outlier between two true
//!    peaks; a valley greater than both, both below −0.15 g, likewise.
//! 7. **Peak-valley sequence**: in time order, of two peaks (valleys) in a row the one closer
//!    to zero is removed; a peak then pairs with the valley after it. A valley that opens a
//!    walk and a peak that closes one are unpaired ends and removed. Each pair is a
//!    [`Step`].
//!
//! **From a batch method to a stream.** The paper runs each rule over a whole recording. Here
//! every rule decides an extreme as soon as it has the successors the rule needs (two more
//! for the static rule, nine for the dynamic threshold, one for the others), or once no such
//! successor can come soon enough: the static rule, the neighbouring difference and the
//! sequence look at most [`WALK_GAP_MS`] ahead (extremes further apart belong to different
//! walks), the dynamic threshold [`DYNAMIC_LOOKAHEAD_MS`], the minimum interval its own
//! interval. A rule short of successors does what the paper does for the last nine peaks of
//! a recording: it takes the mean of the last ten (three) extremes it has seen. The same
//! happens for everything in flight at a gap or the end of a recording
//! ([`PeakValleyDetector::finish`]). Decisions depend only on sample numbers, never on when
//! the samples arrived, so the host's `f64` reference, written as the batch method with these
//! look-ahead limits, finds the same steps.
//!
//! **Latency.** A step is reported once its valley has been through every rule: in walking,
//! when nine more peaks and nine more valleys have been seen (measured in the pipeline:
//! 4–10 s on real walks); never later than [`max_latency_ms`] (16.32 s) after its valley,
//! plus the filter's delay (about 64 ms).
//!
//! **Scaling.** Thresholds are in g and apply to the low-pass output (g/32 768); the foot
//! frame is in g whatever the sensor's full scale, so they do not depend on it. Intervals
//! are in ms and rounded to samples at the pipeline's rate.
//!
//! **Bounded state.** At most [`EXTREMES_CAPACITY`] extremes are in flight (the ones waiting
//! on the dynamic threshold and everything after them). An extreme that finds the buffer full
//! is dropped and counted ([`PeakValleyDetector::dropped`]); none was on the six recordings of
//! the host's agreement test.

use heapless::Vec;

use crate::detect::phase_stats::StrideStats;
use crate::detect::seam::{DetectConfig, Drain, Input, StepDetector};
use crate::record::stride::{StepAmplitude, Stride, StrideEvents, StrideFlags};
use crate::sensor::rate::SampleRate;
use crate::signal::low_pass::{LowPass, LOW_PASS_LSB_PER_G};

const fn g_milli(mg: i32) -> i32 {
    // Rounded to the nearest low-pass unit (g/32 768).
    let v = mg as i64 * LOW_PASS_LSB_PER_G as i64;
    (if v >= 0 {
        (v + 500) / 1000
    } else {
        (v - 500) / 1000
    }) as i32
}

/// Static rule: the running mean of three peaks below this (valleys above its negative) is
/// the sensor at rest. 0.01 g = 328 units of g/32 768.
pub const STATIC_G: i32 = g_milli(10);
/// Extremes in the static rule's running mean.
pub const STATIC_WINDOW: usize = 3;
/// Extremes in the dynamic threshold's mean (the extreme and the next nine).
pub const DYNAMIC_WINDOW: usize = 10;
/// The dynamic threshold's `c` = 0.4, as `C_NUM / C_DEN`.
pub const C_NUM: i64 = 2;
/// See [`C_NUM`].
pub const C_DEN: i64 = 5;
/// `Th1`: the smallest peak kept, 0.02 g = 655 units.
pub const TH1_G: i32 = g_milli(20);
/// `Th2`: the largest valley kept, −0.02 g = −655 units.
pub const TH2_G: i32 = g_milli(-20);
/// Minimum interval between two peaks (valleys): 16 samples at the paper's 50 Hz, 320 ms
/// (a step frequency of 3.1 Hz).
pub const MIN_INTERVAL_MS: u32 = 320;
/// Neighbouring difference of an outlier peak: both differences above 0.1 g = 3277 units.
pub const NEIGHBOUR_PEAK_G: i32 = g_milli(100);
/// Neighbouring difference of an outlier valley: both below −0.15 g = −4915 units.
pub const NEIGHBOUR_VALLEY_G: i32 = g_milli(-150);
/// Extremes further apart than this belong to different walks: the static rule, the
/// neighbouring difference and the sequence look this far ahead at most. 2 s is one stride
/// of a foot at the paper's slowest step frequency (1 Hz).
pub const WALK_GAP_MS: u32 = 2_000;
/// How far ahead the dynamic threshold looks for its nine successors: nine steps at 1 Hz,
/// and a second to spare.
pub const DYNAMIC_LOOKAHEAD_MS: u32 = 10_000;
/// Extremes in flight, both kinds (12 bytes each).
pub const EXTREMES_CAPACITY: usize = 64;

/// The longest a step waits after its valley, ms, besides the filter's delay:
/// each rule's look-ahead behind the one before it (static, dynamic, interval, neighbours,
/// then the sequence's own walk gap behind all four).
pub const fn max_latency_ms() -> u32 {
    3 * WALK_GAP_MS + DYNAMIC_LOOKAHEAD_MS + MIN_INTERVAL_MS
}

/// Peak or valley.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A local maximum above zero.
    Peak = 0,
    /// A local minimum below zero.
    Valley = 1,
}

/// An extreme of the low-passed vertical acceleration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extreme {
    /// Sample number (of the unfiltered signal when reported in a [`Step`]).
    pub index: u32,
    /// Low-passed vertical acceleration, g/32 768 ([`LOW_PASS_LSB_PER_G`]).
    pub value: i32,
    /// Peak or valley.
    pub kind: Kind,
}

impl Extreme {
    /// Farther from zero than `other` (ties: no).
    fn beats(&self, other: &Extreme) -> bool {
        self.value.unsigned_abs() > other.value.unsigned_abs()
    }
}

/// One of Lu's steps: a peak and the valley after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// Running step number, from 0.
    pub index: u32,
    /// The peak; its sample number has the filter's delay taken off.
    pub peak: Extreme,
    /// The valley after it.
    pub valley: Extreme,
    /// Samples from the previous step's peak in the same walk; 0 for the first step of a
    /// walk (its frequency is unknown).
    pub period: u32,
}

impl Step {
    /// Lu's `D` (eq. 11): peak minus valley, g/32 768.
    pub const fn difference(&self) -> i32 {
        self.peak.value.saturating_sub(self.valley.value)
    }
}

/// Rules an extreme has passed, in order.
const IDENTIFIED: u8 = 0;
const NOT_STATIC: u8 = 1;
const ABOVE_THRESHOLD: u8 = 2;
const SPACED: u8 = 3;
const NOT_OUTLIER: u8 = 4;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct InFlight {
    e: Extreme,
    /// Rules passed.
    passed: u8,
    /// Stretch of samples without a gap it belongs to: rules never look across a gap.
    segment: u8,
}

/// The last `N` values a rule judged, oldest first, with their segments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct History<const N: usize> {
    values: [(u8, i32); N],
    len: usize,
}

impl<const N: usize> History<N> {
    const fn new() -> Self {
        History {
            values: [(0, 0); N],
            len: 0,
        }
    }

    fn push(&mut self, segment: u8, v: i32) {
        if self.len == N {
            self.values.copy_within(1.., 0);
            self.values[N - 1] = (segment, v);
        } else {
            self.values[self.len] = (segment, v);
            self.len += 1;
        }
    }

    /// The values of `segment`, oldest first.
    fn of(&self, segment: u8) -> impl Iterator<Item = i32> + Clone + '_ {
        self.values[..self.len]
            .iter()
            .filter(move |(s, _)| *s == segment)
            .map(|&(_, v)| v)
    }
}

/// What a rule can say about an extreme yet.
enum Look {
    /// It has all the successors it needs.
    Enough,
    /// It has fewer, and no more can come in time.
    Short,
    /// It must wait.
    Wait,
}

/// `a` is at or after `b`, in wrapping sample numbers.
const fn reached(a: u32, b: u32) -> bool {
    (a.wrapping_sub(b) as i32) >= 0
}

/// Lu's peak-valley step detector over a stream of vertical accelerations.
#[derive(Clone, Debug)]
pub struct PeakValleyDetector {
    rate: SampleRate,
    filter: LowPass,
    delay: u32,
    walk_gap: u32,
    dynamic_lookahead: u32,
    min_interval: u32,
    // Extreme finder.
    started: bool,
    /// Extremes before this sample number are the filter settling from its first input.
    settled_at: u32,
    last: i32,
    direction: i8,
    candidate: Extreme,
    // Rules.
    in_flight: Vec<InFlight, EXTREMES_CAPACITY>,
    static_seen: [History<{ STATIC_WINDOW - 1 }>; 2],
    dynamic_seen: [History<{ DYNAMIC_WINDOW - 1 }>; 2],
    kept: [Option<(u8, Extreme)>; 2],
    // Sequence.
    run: Option<Extreme>,
    run_last: u32,
    run_segment: u8,
    segment: u8,
    open_peak: Option<Extreme>,
    last_step_peak: Option<u32>,
    ready: Option<Step>,
    steps: u32,
    /// Sample number by which some look-ahead may run out.
    wake_at: u32,
    /// Decisions may be possible without a new sample (after a gap, or a step was ready).
    dirty: bool,
    flushing: bool,
    dropped: u32,
}

impl PeakValleyDetector {
    /// A detector for samples at `rate`.
    pub const fn new(rate: SampleRate) -> Self {
        let filter = LowPass::new(rate);
        let delay = filter.delay();
        let unknown = Extreme {
            index: 0,
            value: 0,
            kind: Kind::Peak,
        };
        PeakValleyDetector {
            rate,
            filter,
            delay,
            walk_gap: rate.samples_in_ms(WALK_GAP_MS),
            dynamic_lookahead: rate.samples_in_ms(DYNAMIC_LOOKAHEAD_MS),
            min_interval: rate.samples_in_ms(MIN_INTERVAL_MS),
            started: false,
            settled_at: 0,
            last: 0,
            direction: 0,
            candidate: unknown,
            in_flight: Vec::new(),
            static_seen: [History::new(), History::new()],
            dynamic_seen: [History::new(), History::new()],
            kept: [None, None],
            run: None,
            run_last: 0,
            run_segment: 0,
            segment: 0,
            open_peak: None,
            last_step_peak: None,
            ready: None,
            steps: 0,
            wake_at: 0,
            dirty: false,
            flushing: false,
            dropped: 0,
        }
    }

    /// Samples by which the low-pass delays the extremes (taken off the steps' indices).
    pub const fn filter_delay(&self) -> u32 {
        self.delay
    }

    /// Extremes dropped because [`EXTREMES_CAPACITY`] were in flight.
    pub const fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Feeds sample number `index`'s vertical acceleration (g/2048, gravity removed);
    /// returns a step when one is complete. Sample numbers must increase by one between
    /// calls, except across [`PeakValleyDetector::finish`].
    pub fn process(&mut self, index: u32, vertical: i16) -> Option<Step> {
        let y = self.filter.process(vertical);
        self.process_filtered(index, y)
    }

    /// [`PeakValleyDetector::process`] after the low-pass: `y` is the filtered vertical
    /// acceleration, g/32 768. The steps' sample numbers still have
    /// [`PeakValleyDetector::filter_delay`] taken off. For tests of the rules on hand-made
    /// signals, and for a caller with its own filter.
    pub fn process_filtered(&mut self, index: u32, y: i32) -> Option<Step> {
        self.feed_filtered(index, y);
        self.ready.take()
    }

    /// [`PeakValleyDetector::process`] without handing out a step: one that is ready stays
    /// ready for the next call (the pipeline feeds several samples in one call when it
    /// bridges a hole, and reports one step per call).
    pub fn feed(&mut self, index: u32, vertical: i16) {
        let y = self.filter.process(vertical);
        self.feed_filtered(index, y);
    }

    fn feed_filtered(&mut self, index: u32, y: i32) {
        let found = self.find(index, y);
        if let Some(e) = found {
            let x = InFlight {
                e,
                passed: IDENTIFIED,
                segment: self.segment,
            };
            if self.in_flight.push(x).is_err() {
                self.dropped = self.dropped.saturating_add(1);
            }
        }
        if found.is_some() || self.dirty || reached(index, self.wake_at) {
            self.decide();
        }
    }

    /// Samples were lost: the filter starts afresh, and what is in flight is decided as at
    /// the end of a recording (no rule looks across the gap), one step per following
    /// sample. The sample numbers fed next go on past the missing ones.
    pub fn gap(&mut self) {
        self.segment = self.segment.wrapping_add(1);
        self.filter.reset();
        self.started = false;
        self.dirty = true;
    }

    /// Decides everything in flight with what has been seen (as at the end of a recording)
    /// and returns one step per call; once it returns `None` the detector is empty and
    /// starts afresh at its next sample (after a gap), its step count going on.
    pub fn finish(&mut self) -> Option<Step> {
        self.flushing = true;
        self.decide();
        let out = self.ready.take();
        if out.is_none() {
            let (steps, dropped, segment) = (self.steps, self.dropped, self.segment);
            *self = Self::new(self.rate);
            self.steps = steps;
            self.dropped = dropped;
            self.segment = segment.wrapping_add(1);
        }
        out
    }

    /// Turns of the filtered signal: a peak when it starts to fall from above zero, a
    /// valley when it starts to rise from below zero.
    fn find(&mut self, index: u32, y: i32) -> Option<Extreme> {
        if !self.started {
            self.started = true;
            self.settled_at = index.wrapping_add(self.delay);
            self.last = y;
            self.direction = 0;
            self.candidate = Extreme {
                index,
                value: y,
                kind: Kind::Peak,
            };
            return None;
        }
        let mut out = None;
        if y > self.last {
            if self.direction < 0 && self.candidate.value < 0 {
                out = Some(Extreme {
                    kind: Kind::Valley,
                    ..self.candidate
                });
            }
            self.direction = 1;
        } else if y < self.last {
            if self.direction > 0 && self.candidate.value > 0 {
                out = Some(Extreme {
                    kind: Kind::Peak,
                    ..self.candidate
                });
            }
            self.direction = -1;
        }
        if out.is_some_and(|e| !reached(e.index, self.settled_at)) {
            // Before the filter's delay has passed, an extreme would be dated before the
            // first sample; the filter is still settling from it.
            out = None;
        }
        // The newest sample is the candidate: the extreme of a run is its last sample, so
        // no extreme still to come lies before it (the watermark the rules wait on).
        self.candidate = Extreme {
            index,
            value: y,
            kind: Kind::Peak,
        };
        self.last = y;
        out
    }

    /// No extreme of `segment` still to come lies before this sample number.
    fn watermark_reached(&self, segment: u8, deadline: u32) -> bool {
        self.flushing
            || segment != self.segment
            || (self.started && reached(self.candidate.index, deadline))
    }

    /// Runs the rules until nothing more can be decided or a step is ready.
    fn decide(&mut self) {
        if self.ready.is_some() {
            // The step before is still to be handed out: decide again at the next call.
            self.dirty = true;
            return;
        }
        self.dirty = false;
        self.wake_at = self.candidate.index.wrapping_add(self.walk_gap);
        while self.ready.is_none() {
            let mut progressed = false;
            for rule in [NOT_STATIC, ABOVE_THRESHOLD, SPACED, NOT_OUTLIER] {
                for kind in [Kind::Peak, Kind::Valley] {
                    while self.ready.is_none() && self.apply(rule, kind) {
                        progressed = true;
                    }
                }
            }
            if self.ready.is_none() && self.sequence() {
                progressed = true;
            }
            if !progressed {
                return;
            }
        }
        // A step is ready: more may be decidable at once.
        self.dirty = true;
    }

    fn later_wake(&mut self, deadline: u32) {
        if reached(self.wake_at, deadline) {
            self.wake_at = deadline;
        }
    }

    /// Successors of the extreme at `at` of its kind that passed `passed` rules, up to
    /// `need`, with sample numbers before `deadline`; their positions go into `out`.
    fn look(
        &mut self,
        at: usize,
        passed: u8,
        need: usize,
        horizon: u32,
        out: &mut Vec<usize, DYNAMIC_WINDOW>,
    ) -> Look {
        let InFlight { e, segment, .. } = self.in_flight[at];
        let deadline = e.index.wrapping_add(horizon);
        for (j, x) in self.in_flight.iter().enumerate().skip(at + 1) {
            if x.e.kind != e.kind {
                continue;
            }
            if out.len() == need {
                return Look::Enough;
            }
            if x.segment != segment || reached(x.e.index, deadline) {
                return Look::Short;
            }
            if x.passed < passed {
                return Look::Wait;
            }
            let _ = out.push(j);
        }
        if out.len() == need {
            Look::Enough
        } else if self.watermark_reached(segment, deadline) {
            Look::Short
        } else {
            self.later_wake(deadline);
            Look::Wait
        }
    }

    /// Applies `rule` to the oldest extreme of `kind` waiting for it; true if it decided.
    fn apply(&mut self, rule: u8, kind: Kind) -> bool {
        let Some(at) = self
            .in_flight
            .iter()
            .position(|x| x.e.kind == kind && x.passed == rule - 1)
        else {
            return false;
        };
        let InFlight { e, segment, .. } = self.in_flight[at];
        let k = kind as usize;
        let peak = kind == Kind::Peak;
        let mut next: Vec<usize, DYNAMIC_WINDOW> = Vec::new();
        let keep = match rule {
            NOT_STATIC => {
                let look = self.look(at, IDENTIFIED, STATIC_WINDOW - 1, self.walk_gap, &mut next);
                if let Look::Wait = look {
                    return false;
                }
                let seen = self.static_seen[k];
                let (sum, n) = self.window_sum(seen.of(segment), e, &next, STATIC_WINDOW);
                self.static_seen[k].push(segment, e.value);
                if peak {
                    sum >= STATIC_G as i64 * n
                } else {
                    sum <= -(STATIC_G as i64) * n
                }
            }
            ABOVE_THRESHOLD => {
                let look = self.look(
                    at,
                    NOT_STATIC,
                    DYNAMIC_WINDOW - 1,
                    self.dynamic_lookahead,
                    &mut next,
                );
                if let Look::Wait = look {
                    return false;
                }
                let seen = self.dynamic_seen[k];
                let (sum, n) = self.window_sum(seen.of(segment), e, &next, DYNAMIC_WINDOW);
                self.dynamic_seen[k].push(segment, e.value);
                let v = e.value as i64 * C_DEN * n;
                if peak {
                    v >= C_NUM * sum && e.value >= TH1_G
                } else {
                    v <= C_NUM * sum && e.value <= TH2_G
                }
            }
            SPACED => {
                match self.look(at, ABOVE_THRESHOLD, 1, self.min_interval, &mut next) {
                    Look::Wait => return false,
                    Look::Enough => {
                        // Too close: the one nearer zero goes, the survivor meets the next.
                        let j = next[0];
                        let gone = if self.in_flight[j].e.beats(&e) { at } else { j };
                        self.in_flight.remove(gone);
                        return true;
                    }
                    Look::Short => true,
                }
            }
            _ => {
                let look = self.look(at, SPACED, 1, self.walk_gap, &mut next);
                if let Look::Wait = look {
                    return false;
                }
                let prev = self.kept[k]
                    .filter(|(s, p)| *s == segment && e.index.wrapping_sub(p.index) < self.walk_gap)
                    .map(|(_, p)| p);
                let outlier = match (prev, next.first()) {
                    (Some(p), Some(&j)) => {
                        let (y0, d1, d2) = (
                            e.value as i64,
                            p.value as i64 - e.value as i64,
                            self.in_flight[j].e.value as i64 - e.value as i64,
                        );
                        if peak {
                            let t = NEIGHBOUR_PEAK_G as i64;
                            y0 < d1 && y0 < d2 && d1 > t && d2 > t
                        } else {
                            let t = NEIGHBOUR_VALLEY_G as i64;
                            y0 > d1 && y0 > d2 && d1 < t && d2 < t
                        }
                    }
                    _ => false,
                };
                if !outlier {
                    self.kept[k] = Some((segment, e));
                }
                !outlier
            }
        };
        if keep {
            self.in_flight[at].passed = rule;
        } else {
            self.in_flight.remove(at);
        }
        true
    }

    /// Sum and count of the window of `width` values that starts at `e` and goes on into
    /// `next`; when `next` is short, the window is the last `width` values seen, ending at
    /// the newest (the paper's rule for the end of a recording).
    fn window_sum(
        &self,
        seen: impl Iterator<Item = i32> + Clone,
        e: Extreme,
        next: &[usize],
        width: usize,
    ) -> (i64, i64) {
        let later = next.iter().map(|&j| self.in_flight[j].e.value as i64);
        let total = seen.clone().count() + 1 + next.len();
        let skip = total.saturating_sub(width);
        let all = seen
            .map(|v| v as i64)
            .chain(core::iter::once(e.value as i64))
            .chain(later);
        let mut sum = 0i64;
        let mut n = 0i64;
        for v in all.skip(skip) {
            sum += v;
            n += 1;
        }
        (sum, n)
    }

    /// Feeds the sequence the oldest extreme once it has passed every rule, and ends a walk
    /// when nothing can follow its last extreme in time; true if it did either.
    fn sequence(&mut self) -> bool {
        let front = self.in_flight.first().copied();
        if self.run.is_some() {
            let deadline = self.run_last.wrapping_add(self.walk_gap);
            let ended = match front {
                Some(f) if f.segment != self.run_segment => true,
                // In time to follow the walk: it waits on the front's rules, which set their
                // own wake-ups. (A wake-up at this deadline would soon lie in the past and
                // run the rules on every sample until the front is decided.)
                Some(f) if !reached(f.e.index, deadline) => false,
                _ => {
                    let ended = self.watermark_reached(self.run_segment, deadline);
                    if !ended {
                        self.later_wake(deadline);
                    }
                    ended
                }
            };
            if ended {
                self.end_walk();
                return true;
            }
        }
        let Some(front) = front.filter(|f| f.passed == NOT_OUTLIER) else {
            return false;
        };
        self.in_flight.remove(0);
        let x = front.e;
        match self.run {
            Some(r) if r.kind == x.kind => {
                if x.beats(&r) {
                    self.run = Some(x);
                }
            }
            Some(r) => {
                self.close_run(r, false);
                self.run = Some(x);
            }
            None => self.run = Some(x),
        }
        self.run_last = x.index;
        self.run_segment = front.segment;
        true
    }

    fn end_walk(&mut self) {
        if let Some(r) = self.run.take() {
            self.close_run(r, true);
        }
        self.open_peak = None;
        self.last_step_peak = None;
    }

    /// The best extreme of a run of one kind is final: a peak waits for its valley, a
    /// valley completes the step of the peak before it.
    fn close_run(&mut self, r: Extreme, walk_ends: bool) {
        match r.kind {
            Kind::Peak => self.open_peak = if walk_ends { None } else { Some(r) },
            Kind::Valley => {
                if let Some(p) = self.open_peak.take() {
                    let period = self.last_step_peak.map_or(0, |q| p.index.wrapping_sub(q));
                    self.last_step_peak = Some(p.index);
                    let undo = |mut x: Extreme| {
                        x.index = x.index.wrapping_sub(self.delay);
                        x
                    };
                    self.ready = Some(Step {
                        index: self.steps,
                        peak: undo(p),
                        valley: undo(r),
                        period,
                    });
                    self.steps = self.steps.wrapping_add(1);
                }
            }
        }
    }
}

/// Lu's detector as a step detector ([`crate::detect::seam::StepDetector`]): fed the foot frame's
/// vertical acceleration, each of its steps becomes a stride record, and its amplitude
/// ([`StepDetector::step`]) what the length stage measures it with: Lu's own chain
/// ([`crate::length::lu::lu_chain_um`]) whatever the configured model.
#[derive(Clone, Debug)]
pub struct PeakValleySteps {
    peaks: PeakValleyDetector,
    /// A step released while filling a hole with no call to report it from.
    held: Option<Stride>,
    /// The amplitudes of the last two steps released, by step index parity, with the index
    /// they belong to.
    amplitudes: [(u32, StepAmplitude); 2],
}

impl PeakValleySteps {
    /// The detector for data described by `config`.
    pub const fn new(config: &DetectConfig) -> Self {
        PeakValleySteps {
            peaks: PeakValleyDetector::new(config.rate),
            held: None,
            amplitudes: [(
                u32::MAX,
                StepAmplitude {
                    peak_to_valley: 0,
                    period: 0,
                },
            ); 2],
        }
    }

    /// One step as a stride record (its length the length stage's), its amplitude kept.
    #[inline(never)]
    pub fn record_step(&mut self, step: Step) -> Stride {
        self.amplitudes[(step.index & 1) as usize] = (
            step.index,
            StepAmplitude {
                peak_to_valley: step.difference(),
                period: step.period,
            },
        );
        let mut flags = StrideFlags::PHASES_GUESSED;
        if step.period == 0 {
            flags |= StrideFlags::FROM_REST;
        }
        Stride {
            index: step.index,
            events: StrideEvents {
                start: step.peak.index,
                heel_off: step.peak.index,
                toe_off: step.peak.index,
                heel_strike: step.valley.index,
                foot_flat: step.valley.index,
                end: step.valley.index,
            },
            flags: StrideFlags(flags),
            ..Stride::default()
        }
    }
}

impl StepDetector for PeakValleySteps {
    fn delay(&self, filter_delay: u32) -> u32 {
        filter_delay + self.peaks.filter_delay()
    }

    fn reports_late(&self) -> bool {
        true
    }

    fn process(&mut self, x: &Input<'_>, out: &mut Option<Stride>) {
        if out.is_none() {
            *out = self.held.take();
        }
        // The filtered value is the mean of a window centred `filter_delay` samples back.
        let at = x.index.wrapping_sub(x.filter_delay);
        if out.is_none() {
            *out = self
                .peaks
                .process(at, x.foot.up())
                .map(|s| self.record_step(s));
        } else {
            self.peaks.feed(at, x.foot.up());
        }
    }

    fn restart(&mut self, _: &Drain<'_>) -> Option<Stride> {
        self.peaks.gap();
        self.held.take()
    }

    fn hold(&mut self, stride: Stride) {
        if self.held.is_none() {
            self.held = Some(stride);
        }
    }

    fn finish(&mut self, _: &Drain<'_>) -> Option<Stride> {
        if let Some(s) = self.held.take() {
            return Some(s);
        }
        self.peaks.finish().map(|s| self.record_step(s))
    }

    fn stats(&self, _: u32) -> Option<&StrideStats> {
        None
    }

    fn step(&self, index: u32) -> Option<StepAmplitude> {
        let (at, a) = self.amplitudes[(index & 1) as usize];
        (at == index).then_some(a)
    }

    fn dropped(&self) -> u32 {
        self.peaks.dropped()
    }
}

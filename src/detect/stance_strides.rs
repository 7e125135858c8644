//! Strides from stance to stance, their gait events, and their length.
//!
//! A stride runs from one foot-flat (start of a stance) to the next. Inside it:
//!
//! ```text
//!  start (foot-flat)   heel_off       toe_off          heel_strike   end (next foot-flat)
//!  |---- stance -------|-- push-off --|----- swing -----|-- heel-strike --|
//! ```
//!
//! Heel-off and foot-flat are the edges of the stances ([`crate::detect::stance`]); toe-off and
//! heel-strike come from Huang's splitter ([`crate::detect::phases`]) run on the movement's
//! foot-frame acceleration. A stride carries the ZUPT displacement of the movement
//! ([`crate::detect::zupt`]); the integer summaries of its acceleration phase by phase
//! ([`crate::detect::phase_stats`]), which the length models' features need, stay with the tracker
//! ([`StrideTracker::stats`]: ten times the record's size, they need not travel with it);
//! the pipeline fills in the length.
//!
//! **What is and is not a stride.** A movement shorter than [`MIN_MOVEMENT_MS`] is a wobble
//! of a foot on the ground and merges into the stance; standing still therefore yields no
//! strides at all. The first step after standing is flagged [`StrideFlags::FROM_REST`], the
//! last one before standing (the final half-stride) [`StrideFlags::TO_REST`], and a stride
//! whose heading changed by more than 45° (a turn, or turning on the spot)
//! [`StrideFlags::TURN`]. To know whether a stride was the last one, a stride is reported
//! when the stance after it ends (the next heel-off), or once that stance has lasted
//! [`MAX_STANCE_IN_STRIDE_MS`]: the latency is the following stance, at most one second.
//!
//! **Gaps.** A gap in the samples (a FIFO overflow, a sensor that stopped answering, a jump
//! in a recording's timestamps) leaves the stride around it without a trustworthy length or
//! events. It is still reported, once, flagged [`StrideFlags::GAP`] and with no length, so that
//! a stride count stays right and nothing is silently measured across the hole: a stride is a
//! gap stride when the gap fell into its movement, or into the stance before a movement that
//! followed the gap. A gap inside a stance that goes on after it costs nothing.
//!
//! Streaming and bounded: the only per-stride memory is the movement's foot-frame
//! acceleration, a buffer of `M` samples of which at most [`MAX_MOVEMENT_MS`](crate::detect::seam::MAX_MOVEMENT_MS) are used
//! ([`movement_samples`](crate::detect::seam::movement_samples) holds that at a rate; a board with little RAM picks fewer); a longer
//! movement is still closed at the next stance but flagged [`StrideFlags::TOO_LONG`] and split
//! on what was kept.

use heapless::Vec;

use crate::detect::phase_stats::{StrideStats, CHANNELS};
use crate::detect::phases::{self, PhaseMethod};
use crate::detect::rest::RestSums;
use crate::detect::seam::{
    max_movement, DetectConfig, Drain, Input, StepDetector, MAX_MOVEMENT_SAMPLES,
    MAX_STANCE_IN_STRIDE_MS, MIN_MOVEMENT_MS,
};
use crate::detect::stance::{StanceDetector, StanceThresholds};
use crate::detect::zupt::{GravityReading, ZuptIntegrator};
use crate::record::stride::{Stride, StrideEvents, StrideFlags};
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::{Origin, Rails, RawSample};
use crate::sensor::units::{AccelScale, FootAccel, GyroScale};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// No stance seen yet: nothing to integrate from.
    Unprimed,
    Stance,
    Moving,
    /// Samples were lost while a stride was (or may have been) in progress; waiting for the
    /// next stance to close it as a [`StrideFlags::GAP`] stride.
    Gap,
}

/// Turns stance decisions into strides, keeping at most `M` samples of a movement.
#[derive(Clone, Debug)]
pub struct StrideTracker<const M: usize = MAX_MOVEMENT_SAMPLES> {
    state: State,
    min_movement: u32,
    max_stance: u32,
    zupt: ZuptIntegrator,
    stance_start: u32,
    heel_off: u32,
    stance_sums: RestSums,
    movement: Vec<[i16; CHANNELS], M>,
    /// Samples of a movement kept: [`MAX_MOVEMENT_MS`] at the rate, at most `M`.
    max_movement: usize,
    flags: u16,
    /// First and last [`Origin::Filled`] sample of the movement, if any.
    filled: Option<(u32, u32)>,
    /// Last interpolated sample of the current stance, if any.
    stance_bridged_at: Option<u32>,
    next_index: u32,
    phase_method: PhaseMethod,
    merge_samples: u32,
    /// The last closed stride, held until the stance after it ends.
    pending: Option<Stride>,
    /// First sample lost in the gap being bridged ([`State::Gap`]).
    gap_at: u32,
    /// Whether the foot was moving when the gap began.
    gap_in_movement: bool,
    /// Movement samples seen since the gap ended.
    moving_after_gap: u32,
    /// Number of the last sample fed, plus one.
    fed_end: u32,
    /// Strides neither reported nor held ([`StrideTracker::dropped`]).
    dropped: u32,
    /// The phase statistics of the last two strides closed, by stride index parity, with
    /// the index they belong to: a stride's stay until the one after the next is closed.
    stats: [(u32, StrideStats); 2],
    /// Where each axis clips.
    rails: Rails,
}

impl StrideTracker {
    /// A tracker with the default movement buffer ([`MAX_MOVEMENT_SAMPLES`]) for a sample
    /// rate and the sensor's ranges, splitting phases with `phase_method`.
    pub const fn new(
        rate: SampleRate,
        accel: AccelScale,
        gyro: GyroScale,
        phase_method: PhaseMethod,
    ) -> Self {
        Self::sized(rate, accel, gyro, phase_method)
    }
}

impl<const M: usize> StrideTracker<M> {
    /// A tracker with a movement buffer of `M` samples.
    pub const fn sized(
        rate: SampleRate,
        accel: AccelScale,
        gyro: GyroScale,
        phase_method: PhaseMethod,
    ) -> Self {
        StrideTracker {
            state: State::Unprimed,
            min_movement: rate.samples_in_ms(MIN_MOVEMENT_MS),
            max_stance: rate.samples_in_ms(MAX_STANCE_IN_STRIDE_MS),
            zupt: ZuptIntegrator::new(rate, accel, gyro),
            stance_start: 0,
            heel_off: 0,
            stance_sums: RestSums::new(),
            movement: Vec::new(),
            max_movement: max_movement(rate, M),
            flags: 0,
            filled: None,
            stance_bridged_at: None,
            next_index: 0,
            phase_method,
            merge_samples: rate.samples_in_ms(phases::MERGE_MS),
            pending: None,
            gap_at: 0,
            gap_in_movement: false,
            moving_after_gap: 0,
            fed_end: 0,
            dropped: 0,
            stats: [
                (u32::MAX, StrideStats::EMPTY),
                (u32::MAX, StrideStats::EMPTY),
            ],
            rails: Rails::FULL_SCALE,
        }
    }

    /// The tracker with each axis clipping at `rails` (by default the counts' extremes).
    pub const fn with_rails(mut self, rails: Rails) -> Self {
        self.rails = rails;
        self
    }

    /// The tracker reading the rest's departure from 1 g as `reading` says
    /// ([`GravityReading::Offset`] by default).
    pub const fn with_gravity_reading(
        mut self,
        rate: SampleRate,
        accel: AccelScale,
        gyro: GyroScale,
        reading: GravityReading,
    ) -> Self {
        self.zupt = ZuptIntegrator::reading(rate, accel, gyro, reading);
        self
    }

    /// Samples were lost after the last one fed (the samples the tracker has not seen count
    /// as lost). The stride in progress (if the foot was moving) becomes a
    /// [`StrideFlags::GAP`] stride, closed at the next stance; returns the last stride closed
    /// before the gap, which is complete and was still held.
    pub fn gap(&mut self) -> Option<Stride> {
        let at = self.fed_end;
        match self.state {
            State::Unprimed | State::Gap => {}
            State::Stance => {
                self.state = State::Gap;
                self.gap_at = at;
                self.gap_in_movement = false;
                self.heel_off = at;
                self.moving_after_gap = 0;
            }
            State::Moving => {
                self.state = State::Gap;
                self.gap_at = at;
                self.gap_in_movement = true;
                self.moving_after_gap = 0;
            }
        }
        self.pending.take()
    }

    /// Holds `stride` again (see [`crate::pipeline::Pipeline::gap`]): it is reported with the
    /// next one released. Only called with nothing held; a stride held already is kept.
    pub fn hold(&mut self, stride: Stride) {
        if self.pending.is_none() {
            self.pending = Some(stride);
        }
    }

    /// Returns a stride still held at the end of a recording, one per call: the stride
    /// waiting for the stance after it (the recording ended in that stance, so it is the last
    /// before rest), or else a gap stride still open, closed at the end.
    pub fn finish(&mut self) -> Option<Stride> {
        if let Some(mut s) = self.pending.take() {
            if self.state != State::Gap {
                s.flags.0 |= StrideFlags::TO_REST;
            }
            return Some(s);
        }
        if self.state == State::Gap {
            self.state = State::Unprimed;
            if self.gap_stride_happened() {
                return Some(self.close_gap(self.fed_end));
            }
        }
        None
    }

    /// A stride went through the gap if the foot was moving when it began, or moved for at
    /// least a step's minimum after it.
    fn gap_stride_happened(&self) -> bool {
        self.gap_in_movement || self.moving_after_gap >= self.min_movement
    }

    /// The [`StrideFlags::GAP`] stride from the stance before the gap to `end`.
    #[inline(never)] // as `close`: off the per-sample frame
    fn close_gap(&mut self, end: u32) -> Stride {
        let max_start = self.heel_off.wrapping_sub(self.max_stance);
        let stance = self.heel_off.wrapping_sub(self.stance_start);
        let start = if stance > self.max_stance {
            max_start
        } else {
            self.stance_start
        };
        let mut flags = StrideFlags::GAP | self.stance_flags(start);
        if self.gap_in_movement {
            flags |= self.flags & (StrideFlags::SATURATED | StrideFlags::BRIDGED);
        }
        let index = self.next_index;
        self.next_index = self.next_index.wrapping_add(1);
        Stride {
            index,
            events: StrideEvents {
                start,
                heel_off: self.heel_off,
                toe_off: self.gap_at,
                heel_strike: self.gap_at,
                foot_flat: end,
                end,
            },
            flags: StrideFlags(flags),
            ..Stride::default()
        }
    }

    fn clear_stance(&mut self) {
        self.stance_sums = RestSums::new();
        self.stance_bridged_at = None;
    }

    /// [`StrideFlags::BRIDGED`] if an interpolated sample of the stance before heel-off lies
    /// at or after `start`, the stride's first sample.
    fn stance_flags(&self, start: u32) -> u16 {
        match self.stance_bridged_at {
            Some(at) if at.wrapping_sub(start) < self.heel_off.wrapping_sub(start) => {
                StrideFlags::BRIDGED
            }
            _ => 0,
        }
    }

    /// Feeds sample number `index`: its raw values, its mean-filtered foot-frame
    /// acceleration `[forward, left, up − g]` (g/2048), whether the foot is in stance and
    /// where the sample came from. Returns the stride, if any, that this sample lets it
    /// report.
    pub fn process(
        &mut self,
        index: u32,
        s: &RawSample,
        foot: FootAccel,
        stance: bool,
        origin: Origin,
    ) -> Option<Stride> {
        let mut out = None;
        self.process_into(index, s, foot, stance, origin, &mut out);
        out
    }

    /// [`StrideTracker::process`], the stride it lets the tracker report put into `out`
    /// (no copy of it on this frame; the pipeline feeds several samples per call after a
    /// hole, and the M0's stack is short). A stride released while `out` is taken is held
    /// back and released at the next chance (by construction it cannot happen: two
    /// releases are a movement apart).
    pub fn process_into(
        &mut self,
        index: u32,
        s: &RawSample,
        foot: FootAccel,
        stance: bool,
        origin: Origin,
        out: &mut Option<Stride>,
    ) {
        self.fed_end = index.wrapping_add(1);
        self.transition(index, s, foot, stance, out);
        if origin != Origin::Measured {
            self.mark(index, origin);
        }
    }

    /// The phase statistics of stride number `index`, while they are kept: from its close
    /// until the stride after the next one closes (a stride is measured as it is released,
    /// long before). `None` for a stride whose statistics are gone, and for a gap stride.
    pub fn stats(&self, index: u32) -> Option<&StrideStats> {
        let (at, stats) = &self.stats[(index & 1) as usize];
        (*at == index).then_some(stats)
    }

    /// Strides the tracker could neither report nor hold (three at once): none by
    /// construction, counted so that a test would see one.
    pub const fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Hands the held stride out into `out`, if there is one and `out` is free.
    fn release(&mut self, out: &mut Option<Stride>, to_rest: bool) {
        if out.is_none() {
            *out = self.pending.take();
            if to_rest {
                if let Some(st) = out {
                    st.flags.0 |= StrideFlags::TO_REST;
                }
            }
        }
    }

    /// Holds `stride` as the one waiting for the stance after it; one still held is
    /// handed out first (it cannot be: a stance always precedes a movement).
    fn hold_new(&mut self, stride: Stride, out: &mut Option<Stride>) {
        if self.pending.is_some() {
            self.release(out, false);
        }
        if self.pending.is_none() {
            self.pending = Some(stride);
        } else {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Notes an interpolated sample in the stance or movement it now belongs to.
    fn mark(&mut self, index: u32, origin: Origin) {
        match (self.state, origin) {
            (State::Moving, Origin::Filled) => {
                self.flags |= StrideFlags::GAP;
                let first = self.filled.map_or(index, |f| f.0);
                self.filled = Some((first, index));
            }
            (State::Moving, _) => self.flags |= StrideFlags::BRIDGED,
            (State::Stance, _) => self.stance_bridged_at = Some(index),
            // Before the first stance, or in a gap: nothing it could belong to yet.
            (State::Unprimed | State::Gap, _) => {}
        }
    }

    fn transition(
        &mut self,
        index: u32,
        s: &RawSample,
        foot: FootAccel,
        stance: bool,
        out: &mut Option<Stride>,
    ) {
        match (self.state, stance) {
            (State::Gap, false) => {
                self.moving_after_gap = self.moving_after_gap.saturating_add(1);
            }
            (State::Gap, true) => {
                let stride = self.gap_stride_happened().then(|| self.close_gap(index));
                self.state = State::Stance;
                self.stance_start = index;
                self.clear_stance();
                self.accumulate_stance(s);
                // Nothing is held in a gap ([`Self::gap`] handed it out), but never lose one.
                if let Some(st) = stride {
                    self.hold_new(st, out);
                }
            }
            (State::Unprimed, false) => {}
            (State::Unprimed, true) => {
                self.state = State::Stance;
                self.stance_start = index;
                self.clear_stance();
                self.accumulate_stance(s);
            }
            (State::Stance, true) => {
                self.accumulate_stance(s);
                if index.wrapping_sub(self.stance_start) > self.max_stance {
                    self.release(out, true);
                }
            }
            (State::Stance, false) => {
                if self.zupt.start(&self.stance_sums) {
                    self.state = State::Moving;
                    self.heel_off = index;
                    self.movement.clear();
                    self.flags = 0;
                    self.filled = None;
                    self.accumulate_movement(s, foot);
                    self.release(out, false);
                }
            }
            (State::Moving, false) => {
                self.accumulate_movement(s, foot);
            }
            (State::Moving, true) => {
                let moved = index.wrapping_sub(self.heel_off);
                self.state = State::Stance;
                if moved < self.min_movement {
                    // A wobble: the stance goes on, with its start and sums as they were; a
                    // hole bridged in the wobble is a hole bridged in the stance.
                    if self.flags & (StrideFlags::BRIDGED | StrideFlags::GAP) != 0 {
                        self.stance_bridged_at = Some(index.wrapping_sub(1));
                    }
                    self.accumulate_stance(s);
                    return;
                }
                // A stride still held here had no stance after it long enough to end it:
                // cannot happen (a stance always precedes a movement), but never lose one.
                if self.pending.is_some() {
                    self.release(out, false);
                }
                self.close(index);
                self.stance_start = index;
                self.clear_stance();
                self.accumulate_stance(s);
            }
        }
    }

    fn accumulate_stance(&mut self, s: &RawSample) {
        self.stance_sums.add(s);
    }

    fn accumulate_movement(&mut self, s: &RawSample, foot: FootAccel) {
        self.zupt.process(s, &self.rails);
        if self.movement.len() >= self.max_movement
            || self
                .movement
                .push([foot.up(), foot.forward(), foot.magnitude_minus_g()])
                .is_err()
        {
            self.flags |= StrideFlags::TOO_LONG;
        }
        if self.rails.accel_clipped(s) || self.rails.gyro_clipped(s) {
            self.flags |= StrideFlags::SATURATED;
        }
    }

    /// Closes the movement at `foot_flat` into the held stride (which is free). Not
    /// inlined: see [`StrideStats::measure`].
    #[inline(never)]
    fn close(&mut self, foot_flat: u32) {
        let split = phases::split(&self.movement, self.phase_method, self.merge_samples);
        let mut flags = self.flags;
        if !split.found {
            flags |= StrideFlags::PHASES_GUESSED;
        }
        if self.zupt.turned_over_45_deg() {
            flags |= StrideFlags::TURN;
        }
        let stance = self.heel_off.wrapping_sub(self.stance_start);
        let start = if stance > self.max_stance {
            flags |= StrideFlags::FROM_REST;
            self.heel_off.wrapping_sub(self.max_stance)
        } else {
            self.stance_start
        };
        flags |= self.stance_flags(start);
        let mut toe_off = self.heel_off.wrapping_add(split.toe_off);
        let mut heel_strike = self.heel_off.wrapping_add(split.heel_strike);
        if let Some((first, last)) = self.filled {
            // An event found inside an interpolated hole was not measured.
            let inside = |e: u32| e.wrapping_sub(first) <= last.wrapping_sub(first);
            if inside(toe_off) {
                toe_off = first;
            }
            if inside(heel_strike) {
                heel_strike = first;
            }
        }
        let d = self.zupt.displacement();
        let index = self.next_index;
        self.next_index = self.next_index.wrapping_add(1);
        let slot = &mut self.stats[(index & 1) as usize];
        slot.0 = index;
        slot.1 = StrideStats::measure(&self.movement, split.toe_off, split.heel_strike);
        let mut held = Stride {
            index,
            events: StrideEvents {
                start,
                heel_off: self.heel_off,
                toe_off,
                heel_strike,
                foot_flat,
                end: foot_flat,
            },
            flags: StrideFlags(flags),
            ..Stride::default()
        };
        d.record_on(&mut held, self.zupt.heading_change_cdeg());
        if self.pending.is_none() {
            self.pending = Some(held);
        } else {
            self.dropped = self.dropped.saturating_add(1);
        }
    }
}

/// Huang's method as a step detector ([`crate::detect::seam::StepDetector`]): the variance + IQR
/// stance detector ([`crate::detect::stance`]) deciding about each sample, and the tracker above
/// turning its decisions into strides, stance to stance.
#[derive(Clone, Debug)]
pub struct StanceStrides<const M: usize = MAX_MOVEMENT_SAMPLES> {
    stance: StanceDetector,
    tracker: StrideTracker<M>,
    /// Decisions made since the last restart (the drain feeds the rest of the delay line
    /// only after one).
    decided: u32,
    last_decision: bool,
    /// A stride released while filling a hole with no call to report it from (the tracker
    /// may hold the next one already).
    held: Option<Stride>,
    dropped: u32,
}

impl<const M: usize> StanceStrides<M> {
    /// The detector and tracker for data described by `config`.
    pub const fn new(config: &DetectConfig) -> Self {
        StanceStrides {
            stance: StanceDetector::new(StanceThresholds::with_limits(
                config.rate,
                config.gyro,
                config.stance,
            )),
            tracker: StrideTracker::sized(config.rate, config.accel, config.gyro, config.phases)
                .with_rails(config.rails)
                .with_gravity_reading(
                    config.rate,
                    config.accel,
                    config.gyro,
                    config.gravity_reading,
                ),
            decided: 0,
            last_decision: false,
            held: None,
            dropped: 0,
        }
    }

    /// Feeds the tracker the samples still in the delay line, with the last stance decision;
    /// returns the stride they let it report, if any.
    fn drain(&mut self, x: &Drain<'_>) -> Option<Stride> {
        let mut closed = None;
        // The tracker has had samples up to `next − 1 − delay`; the foot-frame values reach
        // `next − 1 − filter delay`, so that many more can be drained.
        let fd = x.filter_delay;
        let pending = if self.decided == 0 {
            0
        } else {
            self.stance.delay()
        };
        for k in (0..pending).rev() {
            let at = x.next.wrapping_sub(1 + fd).wrapping_sub(k);
            let foot = x.lines.foot(at.wrapping_add(fd));
            let raw = x.lines.raw(at);
            let origin = x.lines.origin(at);
            if let Some(st) = self
                .tracker
                .process(at, &raw, foot, self.last_decision, origin)
            {
                closed = Some(st);
            }
        }
        // Drained once: a second drain before new samples would feed them again.
        self.decided = 0;
        closed
    }
}

impl<const M: usize> StepDetector for StanceStrides<M> {
    fn delay(&self, filter_delay: u32) -> u32 {
        self.stance.delay() + filter_delay
    }

    fn process(&mut self, x: &Input<'_>, out: &mut Option<Stride>) {
        if out.is_none() {
            *out = self.held.take();
        }
        let Some(decision) = self.stance.process(x.foot, x.newest.gyro) else {
            return;
        };
        self.decided = self.decided.saturating_add(1);
        self.last_decision = decision;
        let delay = self.delay(x.filter_delay);
        if x.since_reset <= delay {
            return;
        }
        let at = x.index.wrapping_sub(delay);
        let foot = x.lines.foot(x.index.wrapping_sub(self.stance.delay()));
        let raw = x.lines.raw(at);
        self.tracker
            .process_into(at, &raw, foot, decision, x.lines.origin(at), out);
    }

    fn restart(&mut self, x: &Drain<'_>) -> Option<Stride> {
        // The drain runs on one stance decision, so it makes one transition at most, and
        // then the tracker holds nothing to hand back; should both ever carry a stride, the
        // later one stays held (reported after the gap), so nothing is lost.
        let drained = self.drain(x);
        self.stance.reset();
        // In the order they closed; the first is handed back, the second waits in the
        // tracker (which `gap` emptied), a third here.
        let mut closed = [self.held.take(), drained, self.tracker.gap()]
            .into_iter()
            .flatten();
        let first = closed.next();
        if let Some(second) = closed.next() {
            self.tracker.hold(second);
        }
        if let Some(third) = closed.next() {
            self.held = Some(third);
        }
        first
    }

    fn hold(&mut self, stride: Stride) {
        if self.held.is_none() {
            self.held = Some(stride);
        } else {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    fn finish(&mut self, x: &Drain<'_>) -> Option<Stride> {
        self.held
            .take()
            .or_else(|| self.drain(x))
            .or_else(|| self.tracker.finish())
    }

    fn stats(&self, index: u32) -> Option<&StrideStats> {
        self.tracker.stats(index)
    }

    fn dropped(&self) -> u32 {
        self.tracker.dropped().saturating_add(self.dropped)
    }
}

#[cfg(test)]
mod tests {
    //! Every transition of the tracker on hand-made stance decisions: 200 Hz, a foot at
    //! rest on a level floor (1 g up, no rotation) during stances.
    use super::*;

    const RATE_HZ: u32 = 200;
    /// 1 g on the ±16 g range's 2048 counts per g.
    const REST: RawSample = RawSample {
        accel: [0, 0, 2048],
        gyro: [0; 3],
        temp: 0,
    };

    fn tracker() -> StrideTracker<MAX_MOVEMENT_SAMPLES> {
        let rate = SampleRate::from_hz(RATE_HZ).unwrap();
        StrideTracker::sized(
            rate,
            crate::sensor::units::AccelScale::from_lsb_per_g(2048),
            crate::sensor::units::GyroScale::from_lsb_per_dps_x10(164),
            PhaseMethod::Augmented,
        )
    }

    /// Feeds runs of `(stance, samples)` from sample `*next`; returns each stride with the
    /// sample whose feeding released it.
    fn feed(t: &mut StrideTracker, next: &mut u32, runs: &[(bool, u32)]) -> Vec<(u32, Stride), 8> {
        let mut out = Vec::new();
        for &(stance, n) in runs {
            for _ in 0..n {
                let foot = FootAccel(if stance { [0; 3] } else { [300, 0, 300] });
                if let Some(s) = t.process(*next, &REST, foot, stance, Origin::Measured) {
                    out.push((*next, s)).unwrap();
                }
                *next += 1;
            }
        }
        out
    }

    #[test]
    fn movement_before_the_first_stance_is_ignored() {
        let (mut t, mut n) = (tracker(), 0);
        assert!(feed(&mut t, &mut n, &[(false, 100), (true, 50)]).is_empty());
        assert_eq!(t.finish(), None);
    }

    #[test]
    fn a_stride_is_released_at_the_next_heel_off_and_the_last_after_a_long_stance() {
        let (mut t, mut n) = (tracker(), 0);
        // Rest 1.5 s, a 300 ms movement, a 200 ms stance, another movement, then rest.
        let out = feed(
            &mut t,
            &mut n,
            &[
                (true, 300),
                (false, 60),
                (true, 40),
                (false, 60),
                (true, 250),
            ],
        );
        assert_eq!(out.len(), 2, "{out:?}");
        let (at, first) = out[0];
        assert_eq!(at, 400, "released by the second heel-off");
        assert_eq!(
            (
                first.events.heel_off,
                first.events.foot_flat,
                first.events.end
            ),
            (300, 360, 360)
        );
        // From a rest longer than MAX_STANCE_IN_STRIDE_MS: the start is that long before
        // heel-off.
        assert_eq!(first.events.start, 300 - 200);
        assert!(first.flags.has(StrideFlags::FROM_REST));
        assert!(!first.flags.has(StrideFlags::TO_REST));
        assert!(
            first.events.heel_off < first.events.toe_off
                && first.events.toe_off < first.events.heel_strike
        );
        assert!(first.events.heel_strike < first.events.foot_flat);
        let (at, second) = out[1];
        // The stance after it ends the walk once it is longer than 1 s (200 samples).
        assert_eq!(at, 460 + 201);
        assert_eq!(
            (
                second.events.start,
                second.events.heel_off,
                second.events.foot_flat
            ),
            (360, 400, 460)
        );
        assert!(second.flags.has(StrideFlags::TO_REST));
        assert!(!second.flags.has(StrideFlags::FROM_REST));
        assert_eq!((first.index, second.index), (0, 1));
        assert_eq!(t.finish(), None);
        assert_eq!(t.dropped(), 0);
    }

    #[test]
    fn a_movement_shorter_than_the_minimum_is_a_wobble_of_the_stance() {
        let (mut t, mut n) = (tracker(), 0);
        // 100 ms of movement (< MIN_MOVEMENT_MS) inside a stance, then a real step.
        let out = feed(
            &mut t,
            &mut n,
            &[
                (true, 50),
                (false, 20),
                (true, 50),
                (false, 60),
                (true, 250),
            ],
        );
        assert_eq!(out.len(), 1, "{out:?}");
        let s = out[0].1;
        // The stance kept its start through the wobble.
        assert_eq!(
            (s.events.start, s.events.heel_off, s.events.foot_flat),
            (0, 120, 180)
        );
    }

    #[test]
    fn the_stride_held_at_the_end_is_finished_towards_rest() {
        let (mut t, mut n) = (tracker(), 0);
        let out = feed(&mut t, &mut n, &[(true, 100), (false, 60), (true, 10)]);
        assert!(out.is_empty());
        let last = t
            .finish()
            .expect("the stride waiting for its stance to end");
        assert_eq!((last.events.heel_off, last.events.foot_flat), (100, 160));
        assert!(last.flags.has(StrideFlags::TO_REST));
        assert_eq!(t.finish(), None);
    }

    #[test]
    fn a_gap_in_a_movement_makes_a_gap_stride_closed_at_the_next_stance() {
        let (mut t, mut n) = (tracker(), 0);
        let before = feed(&mut t, &mut n, &[(true, 100), (false, 30)]);
        assert!(before.is_empty());
        assert_eq!(t.gap(), None);
        n += 10; // the samples lost
        let out = feed(&mut t, &mut n, &[(false, 20), (true, 250)]);
        assert_eq!(out.len(), 1, "{out:?}");
        let s = out[0].1;
        assert!(s.flags.has(StrideFlags::GAP));
        assert_eq!((s.events.heel_off, s.events.end), (100, 160));
    }

    #[test]
    fn a_gap_in_a_stance_makes_a_gap_stride_only_if_the_foot_moved_long_enough() {
        // Moving less than the minimum after the gap: no stride happened.
        let (mut t, mut n) = (tracker(), 0);
        feed(&mut t, &mut n, &[(true, 100)]);
        assert_eq!(t.gap(), None);
        assert!(feed(&mut t, &mut n, &[(false, 10), (true, 250)]).is_empty());
        assert_eq!(t.finish(), None);
        // Moving longer: a gap stride from the stance before the hole.
        let (mut t, mut n) = (tracker(), 0);
        feed(&mut t, &mut n, &[(true, 100)]);
        t.gap();
        let out = feed(&mut t, &mut n, &[(false, 60), (true, 250)]);
        assert_eq!(out.len(), 1, "{out:?}");
        assert!(out[0].1.flags.has(StrideFlags::GAP));
    }

    #[test]
    fn the_stride_complete_before_a_gap_is_handed_back_by_it() {
        let (mut t, mut n) = (tracker(), 0);
        feed(&mut t, &mut n, &[(true, 100), (false, 60), (true, 20)]);
        let held = t.gap().expect("the stride waiting for its stance to end");
        assert_eq!((held.events.heel_off, held.events.foot_flat), (100, 160));
        assert!(!held.flags.has(StrideFlags::GAP));
    }

    #[test]
    fn interpolated_samples_flag_the_stride_they_fall_in() {
        let (mut t, mut n) = (tracker(), 0);
        feed(&mut t, &mut n, &[(true, 100), (false, 30)]);
        t.process(n, &REST, FootAccel([300, 0, 300]), false, Origin::Bridged);
        n += 1;
        feed(&mut t, &mut n, &[(false, 29), (true, 10)]);
        let s = t.finish().unwrap();
        assert!(s.flags.has(StrideFlags::BRIDGED) && s.flags.valid());
        let (mut t, mut n) = (tracker(), 0);
        feed(&mut t, &mut n, &[(true, 100), (false, 30)]);
        t.process(n, &REST, FootAccel([300, 0, 300]), false, Origin::Filled);
        n += 1;
        feed(&mut t, &mut n, &[(false, 29), (true, 10)]);
        let s = t.finish().unwrap();
        assert!(s.flags.has(StrideFlags::GAP) && !s.flags.valid());
    }
}

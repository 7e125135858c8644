//! Nothing lost: a length for every stride the detector finds.
//!
//! A stride whose length could not be measured (a hole in its movement, a clipped
//! accelerometer whose loss nothing bounds, a movement beyond its buffer, a model that said
//! more than a person strides: [`StrideFlags::INVALID`]) still happened, and a foot pod that
//! dropped it from the distance would lose a metre per hole. It gets the length the walker's
//! own recent strides give at the same cadence, flagged [`StrideFlags::ESTIMATED`], and
//! counts in the distance ([`StrideFlags::counts_distance`]).
//!
//! **The estimate.** The mean length of the last [`HISTORY`] measured, valid gait cycles (no
//! stride from or into a rest, no gap): the walker's own strides at the pace of the moment.
//! Measured as a predictor of every measured stride from the ones before it (`gaitclip
//! flags`), the mean of the last two had the smallest bias on all three datasets (−0.2 cm
//! gaitmap, −0.6 pyshoe, +1.2 IPOL) and an RMSE of 21–39 cm that is the strides' own
//! variability on walks full of turns; matching the cadence (the velocity of kept strides
//! within 25 % of the duration, times the duration) or taking the last one, the median of
//! three or the velocity of three were no better on all three (+6.6 cm bias on IPOL for the
//! cadence match).
//!
//! **A stride of more cycles than one.** A cluster of holes that swallowed a stance instant
//! (or a movement beyond its buffer) makes one "stride" of two cycles or more, and one
//! stride's length would drop the others from the distance: the estimate is the mean length
//! times the cycles the stride lasted, its duration over the mean duration of the kept
//! strides with a quarter cycle's slack (`⌊d/d̄ + ¼⌋`: two cycles from 1.75 of them, so that a
//! slow single stride stays one; [`MAX_CYCLES`] at most). A stride from or into a rest holds
//! standing, and counts one; so does a movement longer than its buffer (standing or fiddling
//! inside it, not cycles: a hole cut into the demo walk's stand made one of 4.9 s); and so does
//! a stride across a hole that restarted detection (longer than
//! [`crate::pipeline::config::FILL_MAX_MS`], [`LengthEstimator::restarted_at`]): a stand can
//! hide in it (a 1.9 s hole cut over the demo walk's stop made one stride of 3.8 s, two
//! strides and a stand, which counted four). Any other lasts whole cycles: the holes in it
//! are filled ones, at most 150 ms each, shorter than any stance the foot can rest in, so a
//! stand between them would be seen as a rest. Found on `ipol_gait_events` (`17-2_right`:
//! 2.5 s of a dense hole cluster around the U-turn, two steps, estimated as one; now as two,
//! +1.65 m, the only stride of the four datasets whose estimate changed). Such a stride's
//! length is then up to [`MAX_CYCLES`] × [`MAX_STRIDE_MM`]: it is the distance of the cycles,
//! not one stride's.
//!
//! With no measured stride yet (a hole before the first) there is nothing to estimate from:
//! the stride keeps its flags, no length, and the host counts it as unestimated.
//!
//! What each flag's estimate costs against the stride's measured length is measured by
//! cutting holes into real recordings (`gaitclip flags`, `docs/`).
//!
//! Integer and bounded: [`HISTORY`] pairs of `u32` and a sample number.

use crate::record::stride::{Stride, StrideFlags, MAX_STRIDE_MM};

/// Measured strides the estimate is the mean of.
pub const HISTORY: usize = 2;
/// The most cycles one estimated stride is taken to span (a movement buffer holds 5.12 s,
/// four slow cycles).
pub const MAX_CYCLES: u32 = 4;

/// Flags under which a valid stride is not one gait cycle at the walker's pace, and teaches
/// the estimate nothing.
const NOT_A_CYCLE: u16 = StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::GAP;

/// The last measured strides, and the estimate for those that could not be measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LengthEstimator {
    /// Lengths, mm, of the kept strides (ring, newest at `(next − 1) mod HISTORY`).
    length_mm: [u32; HISTORY],
    /// Their durations, samples.
    duration: [u32; HISTORY],
    kept: u8,
    next: u8,
    /// The first sample of the earliest hole that restarted detection and that no stride
    /// has ended past yet.
    restart_hole: Option<u32>,
}

impl Default for LengthEstimator {
    fn default() -> Self {
        Self::new()
    }
}

impl LengthEstimator {
    /// No stride seen.
    pub const fn new() -> Self {
        LengthEstimator {
            length_mm: [0; HISTORY],
            duration: [0; HISTORY],
            kept: 0,
            next: 0,
            restart_hole: None,
        }
    }

    /// A hole starting at sample `first_missing` restarted detection: a stride across it is
    /// taken for one cycle (a stand can hide in it). Called by the pipeline, in sample order.
    pub fn restarted_at(&mut self, first_missing: u32) {
        if self.restart_hole.is_none() {
            self.restart_hole = Some(first_missing);
        }
    }

    /// Strides kept so far (at most [`HISTORY`]).
    pub const fn kept(&self) -> usize {
        self.kept as usize
    }

    /// Learns from a measured stride, or estimates one that was not: a stride whose flags
    /// make its length invalid gets the estimate (see the [module](self)) and
    /// [`StrideFlags::ESTIMATED`], unless nothing was measured yet. Never panics.
    pub fn process(&mut self, s: &mut Stride) {
        let duration = s.events.end.wrapping_sub(s.events.start);
        let across_restart = match self.restart_hole {
            Some(h) if s.events.end > h => {
                // Passed: strides from here on start after it.
                self.restart_hole = None;
                s.events.start <= h
            }
            _ => false,
        };
        if duration == 0 || duration > u32::MAX / 2 {
            return;
        }
        if s.flags.valid() {
            if s.flags.0 & NOT_A_CYCLE == 0 && s.length_mm > 0 {
                let at = self.next as usize;
                self.length_mm[at] = s.length_mm;
                self.duration[at] = duration;
                self.next = ((at + 1) % HISTORY) as u8;
                if (self.kept as usize) < HISTORY {
                    self.kept += 1;
                }
            }
            return;
        }
        if let Some(mm) = self.estimate_mm() {
            let within = StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::TOO_LONG;
            let k = match s.flags.0 & within {
                0 if !across_restart => self.cycles_in(duration),
                _ => 1,
            };
            s.length_mm = (mm.min(MAX_STRIDE_MM) as u64 * k as u64) as u32;
            s.flags.0 |= StrideFlags::ESTIMATED;
            if k > 1 {
                s.flags.0 |= StrideFlags::SEVERAL_CYCLES;
            }
        }
    }

    /// The cycles a stride of `duration` samples spans: `⌊duration / mean + ¼⌋` over the kept
    /// strides' mean duration, from 1 to [`MAX_CYCLES`] (1 with none kept).
    pub fn cycles_in(&self, duration: u32) -> u32 {
        let n = self.kept as usize;
        let total: u64 = self.duration[..n].iter().map(|&d| d as u64).sum();
        if total == 0 {
            return 1;
        }
        // ⌊duration / (total / n) + ¼⌋ = ⌊(4·duration·n + total) / (4·total)⌋.
        let k = (4 * duration as u64 * n as u64 + total) / (4 * total);
        k.clamp(1, MAX_CYCLES as u64) as u32
    }

    /// The estimated length, mm: the mean of the kept strides; `None` with none kept.
    pub fn estimate_mm(&self) -> Option<u32> {
        let n = self.kept as usize;
        if n == 0 {
            return None;
        }
        let sum: u64 = self.length_mm[..n].iter().map(|&l| l as u64).sum();
        Some(((sum + n as u64 / 2) / n as u64) as u32)
    }
}

//! Lost samples in a recording, found from its timestamps, and the clock that maps the
//! core's sample numbers (which count the lost ones) back to the recording's time.
//!
//! A recorded interval longer than [`GAP_INTERVALS`] nominal intervals may be a hole or
//! only a late timestamp. Loggers stamp samples when they handle them, not when the sensor
//! took them, so a late stamp is followed by an early one and the stamps come back onto the
//! sensor's grid (seven `pyshoe_vicon` traces have intervals of 1.1–8.9 ms around 5 ms, and
//! every one of them is `n × 5 ms` long end to end). A hole stays off the grid. So the
//! decision looks [`LOOK_AHEAD`] samples past the long interval: the samples missing are
//! how far behind the grid the stamps still are there.

use crate::trace::ImuSample;

/// An interval longer than this many nominal intervals is examined as a possible gap.
pub const GAP_INTERVALS: f64 = 1.5;
/// Samples after a long interval over which late stamps must come back onto the grid.
pub const LOOK_AHEAD: usize = 2;

/// `missing` sample periods are lost just before recording sample `before`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Gap {
    /// Index of the first sample after the hole, in the recording.
    pub before: usize,
    /// Sample periods lost.
    pub missing: u32,
}

/// The timestamps cannot be replayed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum TimeError {
    /// A timestamp is not later than the one before it.
    #[error(
        "sample {index} (from 0): time {t_s} s is not after the previous sample's {previous_s} s"
    )]
    NotIncreasing {
        /// Index of the sample in the recording.
        index: usize,
        /// Its time, s.
        t_s: f64,
        /// The previous sample's time, s.
        previous_s: f64,
    },
}

/// Finds the gaps in `samples` recorded at `rate_hz`; see the module comment for the rule.
pub fn find(samples: &[ImuSample], rate_hz: f64) -> Result<Vec<Gap>, TimeError> {
    let dt = 1.0 / rate_hz;
    let t = |i: usize| samples[i].t_s;
    let mut gaps = Vec::new();
    for i in 1..samples.len() {
        let d = t(i) - t(i - 1);
        // A NaN interval is not greater either: rejected too.
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(TimeError::NotIncreasing {
                index: i,
                t_s: t(i),
                previous_s: t(i - 1),
            });
        }
        if d <= GAP_INTERVALS * dt {
            continue;
        }
        let j = (i + LOOK_AHEAD).min(samples.len() - 1);
        let behind = (t(j) - t(i - 1)) / dt - (j - i + 1) as f64;
        let missing = behind.round();
        if missing >= 1.0 {
            gaps.push(Gap {
                before: i,
                missing: missing.min(u32::MAX as f64) as u32,
            });
        }
    }
    Ok(gaps)
}

/// Maps the core's sample numbers (recording index plus the periods lost before it) to the
/// recording's time; a number inside a hole is placed on the grid after the last sample
/// before it.
#[derive(Clone, Debug)]
pub struct GapClock<'a> {
    samples: &'a [ImuSample],
    /// (core number, recording index) of the first sample after each gap, and of sample 0.
    starts: Vec<(u64, usize)>,
    dt_s: f64,
}

impl<'a> GapClock<'a> {
    /// The clock of `samples` at `rate_hz` with `gaps`.
    pub fn new(samples: &'a [ImuSample], gaps: &[Gap], rate_hz: f64) -> Self {
        let mut starts = vec![(0u64, 0usize)];
        let mut lost = 0u64;
        for g in gaps {
            lost += g.missing as u64;
            starts.push((g.before as u64 + lost, g.before));
        }
        GapClock {
            samples,
            starts,
            dt_s: 1.0 / rate_hz,
        }
    }

    /// Index in the recording of core sample number `n`; a number inside a hole maps to the
    /// first sample after it.
    pub fn recording_index(&self, n: u32) -> u32 {
        let n = n as u64;
        let k = self.starts.partition_point(|&(c, _)| c <= n).max(1) - 1;
        let (c0, i0) = self.starts[k];
        let i = i0 as u64 + (n - c0);
        match self.starts.get(k + 1) {
            Some(&(_, next)) if i >= next as u64 => next as u32,
            _ => i.min(u32::MAX as u64) as u32,
        }
    }

    /// Time of core sample number `n`, s.
    pub fn t_s(&self, n: u32) -> f64 {
        let n = n as u64;
        let k = self.starts.partition_point(|&(c, _)| c <= n).max(1) - 1;
        let (c0, i0) = self.starts[k];
        let i = i0 + (n - c0) as usize;
        let last = self
            .starts
            .get(k + 1)
            .map_or(self.samples.len(), |&(_, b)| b);
        if i < last {
            if let Some(s) = self.samples.get(i) {
                return s.t_s;
            }
        }
        // In a hole or past the end: on the grid after the last sample before it.
        let Some(prev) = last.checked_sub(1).and_then(|p| self.samples.get(p)) else {
            return n as f64 * self.dt_s;
        };
        let prev_n = c0 + (last - 1 - i0) as u64;
        prev.t_s + (n - prev_n) as f64 * self.dt_s
    }
}

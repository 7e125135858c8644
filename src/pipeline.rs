//! The per-sample pipeline: mean filter → stance detector → stride tracker (phases, ZUPT
//! length), composed in that order, each stage fed only the output of the one before.

use crate::mean_filter::MeanFilter;
use crate::rate::SampleRate;
use crate::sample::{AccelRange, GyroRange, RawSample};
use crate::stance::{StanceDetector, StanceThresholds};
use crate::stride::{Stride, StrideTracker};

/// Window of the mean filter ahead of the stance detector (4 samples: 20 ms at 200 Hz).
pub const MEAN_FILTER_LEN: usize = 4;
/// Capacity of the delay line that aligns raw samples with the (centred) stance decision.
pub const DELAY_CAPACITY: usize = 64;

/// What the pipeline needs to know about the data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Sample rate.
    pub rate: SampleRate,
    /// Accelerometer range the counts are in.
    pub accel: AccelRange,
    /// Gyroscope range the counts are in.
    pub gyro: GyroRange,
}

/// From raw samples to strides.
#[derive(Clone, Debug)]
pub struct Pipeline {
    filter: MeanFilter<MEAN_FILTER_LEN>,
    stance: StanceDetector,
    tracker: StrideTracker,
    delay_line: [RawSample; DELAY_CAPACITY],
    /// Samples between an input and the sample its stance decision is about.
    delay: u32,
    /// Number of the next input sample.
    next: u32,
    /// Inputs since the last reset (start or gap).
    since_reset: u32,
    last_decision: bool,
}

impl Pipeline {
    /// A pipeline for data described by `config`.
    pub const fn new(config: Config) -> Self {
        let stance = StanceDetector::new(StanceThresholds::new(
            config.rate,
            config.accel,
            config.gyro,
        ));
        // The window is centred on sample n − W/2; the mean filter adds (N − 1)/2, rounded up.
        let delay = stance.delay() + (MEAN_FILTER_LEN as u32) / 2;
        Pipeline {
            filter: MeanFilter::new(),
            stance,
            tracker: StrideTracker::new(config.rate, config.gyro),
            delay_line: [RawSample {
                accel: [0; 3],
                gyro: [0; 3],
                temp: 0,
            }; DELAY_CAPACITY],
            delay,
            next: 0,
            since_reset: 0,
            last_decision: false,
        }
    }

    /// Latency of the pipeline in samples: a stride ending at foot-flat sample `n` is
    /// returned by the call that feeds sample `n + latency`.
    pub const fn latency(&self) -> u32 {
        self.delay
    }

    /// Number of the next sample to be fed.
    pub const fn next_index(&self) -> u32 {
        self.next
    }

    /// Feeds one sample; returns a stride when one has just ended.
    pub fn process(&mut self, s: &RawSample) -> Option<Stride> {
        let index = self.next;
        self.next = self.next.wrapping_add(1);
        self.delay_line[index as usize & (DELAY_CAPACITY - 1)] = *s;
        self.since_reset = self.since_reset.saturating_add(1);
        let f_accel = self.filter.process(s.accel);
        let decision = self.stance.process(f_accel, s.gyro)?;
        self.last_decision = decision;
        if self.since_reset <= self.delay {
            return None;
        }
        let at = index.wrapping_sub(self.delay);
        let aligned = self.delay_line[at as usize & (DELAY_CAPACITY - 1)];
        self.tracker.process(at, &aligned, decision)
    }

    /// Declares `missing` samples lost (FIFO overflow, a jump in timestamps): the stride in
    /// progress is dropped, since no length over a gap can be trusted, and detection
    /// restarts after it.
    pub fn gap(&mut self, missing: u32) {
        self.next = self.next.wrapping_add(missing);
        self.since_reset = 0;
        self.filter = MeanFilter::new();
        self.stance.reset();
        self.tracker.reset();
    }

    /// Drains the samples still in the delay line at the end of a recording, with the last
    /// stance decision; returns the stride they close, if any.
    pub fn finish(&mut self) -> Option<Stride> {
        let pending = self.delay.min(self.since_reset.saturating_sub(1));
        let mut out = None;
        for k in (0..pending).rev() {
            let at = self.next.wrapping_sub(1).wrapping_sub(k);
            let s = self.delay_line[at as usize & (DELAY_CAPACITY - 1)];
            if let Some(st) = self.tracker.process(at, &s, self.last_decision) {
                out = Some(st);
            }
        }
        self.since_reset = 0;
        out
    }
}

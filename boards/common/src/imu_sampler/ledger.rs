//! The sampler's bookkeeping without the bus: what a pulse makes due, what a read's outcome
//! does to the counters and the queue. [`super::blocking`] and [`super::asynch`] perform the
//! transfers and report each outcome here, so the two samplers cannot count differently.

use gaitclip::sensor::sample::RawSample;

use super::{Counters, Item, ReadMode, FIFO_BURST, RESTART_AFTER};

/// What a data-ready pulse asks of the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Due {
    /// Nothing yet (a FIFO batch still filling).
    Nothing,
    /// One 14-byte sample burst.
    Sample,
    /// The FIFO, in at most this many bursts of [`FIFO_BURST`] (more than one when the reads
    /// fell behind; bounded by what was pulsed).
    Fifo { bursts: usize },
}

/// The sampler's state apart from the driver.
pub(crate) struct Ledger<W> {
    mode: ReadMode,
    /// Data-ready pulses whose sample is still in the FIFO (FIFO mode).
    unread: u32,
    /// Sample periods in a row whose read failed.
    failed_periods: u32,
    /// Lost periods not yet handed to the queue.
    pending_gap: u32,
    counters: Counters,
    /// Samples read and handed on so far, not counting those dropped while the gyro
    /// settles (what a sleep request counts).
    read: u32,
    /// Go to the low-power wait once this many samples have been read, with these settings.
    sleep_request: Option<(u32, W)>,
    /// Samples still to drop after waking while the gyro settles.
    settling: u32,
    /// Periods unsampled since the sensor went to sleep, not yet handed over as
    /// [`Item::Woke`].
    pending_woke: u32,
}

impl<W: Copy> Ledger<W> {
    /// Nothing read, nothing lost.
    pub(crate) const fn new(mode: ReadMode) -> Self {
        Ledger {
            mode,
            unread: 0,
            failed_periods: 0,
            pending_gap: 0,
            counters: Counters::ZERO,
            read: 0,
            sleep_request: None,
            settling: 0,
            pending_woke: 0,
        }
    }

    pub(crate) const fn mode(&self) -> ReadMode {
        self.mode
    }

    pub(crate) const fn counters(&self) -> Counters {
        self.counters
    }

    pub(crate) const fn samples_read(&self) -> u32 {
        self.read
    }

    pub(crate) fn request_sleep(&mut self, after: u32, wake: W) {
        self.sleep_request = Some((after, wake));
    }

    /// A data-ready pulse: what to read now.
    pub(crate) fn pulse(&mut self) -> Due {
        match self.mode {
            ReadMode::PerSample => Due::Sample,
            ReadMode::Fifo { batch } => {
                self.unread = self.unread.saturating_add(1);
                if self.unread >= batch.max(1) as u32 || self.failed_periods > 0 {
                    Due::Fifo {
                        bursts: self.unread as usize / FIFO_BURST + 1,
                    }
                } else {
                    Due::Nothing
                }
            }
            ReadMode::Watermark { samples } => {
                self.unread = self.unread.saturating_add(samples.max(1) as u32);
                // Read until the FIFO is empty: INT1 stays high while it holds its
                // watermark, so a FIFO left above it would never pulse again. One burst more
                // than the pulses account for, for what arrived meanwhile.
                Due::Fifo {
                    bursts: self.unread as usize / FIFO_BURST + 2,
                }
            }
        }
    }

    /// After a pulse's reads: the motion-wait settings if the requested sleep is due now
    /// (the request is taken).
    pub(crate) fn sleep_due(&mut self) -> Option<W> {
        match self.sleep_request {
            Some((at, wake)) if self.read >= at => {
                self.sleep_request = None;
                Some(wake)
            }
            _ => None,
        }
    }

    /// One failed bus attempt.
    pub(crate) fn bus_error(&mut self) {
        self.counters.bus_errors = self.counters.bus_errors.saturating_add(1);
    }

    /// A sample burst read.
    pub(crate) fn sample(&mut self, s: RawSample, push: &mut impl FnMut(Item) -> bool) {
        self.failed_periods = 0;
        if self.keep() {
            self.emit(push, Item::Sample(s));
        }
    }

    /// A sample period whose read failed every retry: its sample is gone (the registers
    /// hold only the newest). Whether the sensor is due a restart.
    #[must_use]
    pub(crate) fn sample_missed(&mut self) -> bool {
        self.lost(1);
        self.period_failed()
    }

    /// A FIFO burst read (`samples`, at most [`FIFO_BURST`]); whether more may be waiting.
    #[must_use]
    pub(crate) fn fifo_read(
        &mut self,
        samples: &[RawSample],
        push: &mut impl FnMut(Item) -> bool,
    ) -> bool {
        self.failed_periods = 0;
        self.unread = self.unread.saturating_sub(samples.len() as u32);
        for s in samples {
            if self.keep() {
                self.emit(push, Item::Sample(*s));
            }
        }
        let drained = match self.mode {
            // A watermark read goes on until a read brings nothing (the part may hold back
            // a period it is still assembling, and an error may follow a short burst).
            ReadMode::Watermark { .. } => samples.is_empty(),
            _ => samples.len() < FIFO_BURST,
        };
        if drained {
            // Pulses counted but not in the FIFO: none are waiting any more.
            self.unread = 0;
            return false;
        }
        true
    }

    /// The FIFO overflowed (or its count was misaligned) and was reset: everything pulsed
    /// since the last read is gone.
    pub(crate) fn fifo_overflowed(&mut self) {
        self.counters.fifo_overflows = self.counters.fifo_overflows.saturating_add(1);
        let lost = core::mem::take(&mut self.unread);
        self.lost(lost);
    }

    /// A sample period whose read failed (the FIFO keeps its samples for the next pulse);
    /// whether the sensor is due a restart, which loses what waits in the FIFO.
    #[must_use]
    pub(crate) fn period_failed(&mut self) -> bool {
        self.failed_periods = self.failed_periods.saturating_add(1);
        if self.failed_periods >= RESTART_AFTER {
            // Re-initialising resets the FIFO: samples waiting there are lost too.
            let lost = core::mem::take(&mut self.unread);
            self.lost(lost);
            return true;
        }
        false
    }

    /// A restart: whether the board recovered the bus and whether the set-up worked (on
    /// failure the next failed period tries again).
    pub(crate) fn restarted(&mut self, recovered: bool, set_up: bool) {
        if recovered {
            self.counters.recoveries = self.counters.recoveries.saturating_add(1);
        }
        if set_up {
            self.counters.restarts = self.counters.restarts.saturating_add(1);
            self.failed_periods = 0;
        } else {
            self.bus_error();
        }
    }

    /// The sensor entered its motion wait.
    pub(crate) fn asleep(&mut self, push: &mut impl FnMut(Item) -> bool) {
        self.unread = 0;
        self.counters.sleeps = self.counters.sleeps.saturating_add(1);
        if !push(Item::Asleep) {
            self.counters.overruns = self.counters.overruns.saturating_add(1);
        }
    }

    /// Motion after `slept` periods asleep; the first `settle` samples will be dropped.
    pub(crate) fn motion(&mut self, slept: u32, settle: u32) {
        self.settling = settle;
        self.pending_woke = self.pending_woke.saturating_add(slept);
        self.counters.slept_periods = self.counters.slept_periods.saturating_add(slept);
    }

    /// The sensor samples again: the unsampled periods are handed over now if no settling
    /// samples are still to come (else with the first sample kept).
    pub(crate) fn resumed(&mut self, push: &mut impl FnMut(Item) -> bool) {
        if self.pending_woke > 0 && self.settling == 0 && push(Item::Woke(self.pending_woke)) {
            self.pending_woke = 0;
        }
    }

    /// The watchdog found `periods` without a pulse: they and what waited in the FIFO are
    /// lost (the sensor is restarted next, then [`Ledger::silence_reported`]).
    pub(crate) fn silence(&mut self, periods: u32) {
        self.counters.silences = self.counters.silences.saturating_add(1);
        let lost = periods.saturating_add(core::mem::take(&mut self.unread));
        self.lost(lost);
    }

    /// The silence's gap handed over, if the queue has room (else with the next sample).
    pub(crate) fn silence_reported(&mut self, push: &mut impl FnMut(Item) -> bool) {
        if self.pending_gap > 0 && push(Item::Gap(self.pending_gap)) {
            self.pending_gap = 0;
        }
    }

    /// Counts periods lost: they become part of the next gap.
    fn lost(&mut self, periods: u32) {
        self.pending_gap = self.pending_gap.saturating_add(periods);
        self.counters.lost_samples = self.counters.lost_samples.saturating_add(periods);
    }

    /// Counts a sample read; true if it is kept (not dropped while the gyro settles).
    fn keep(&mut self) -> bool {
        if self.settling > 0 {
            self.settling -= 1;
            self.pending_woke = self.pending_woke.saturating_add(1);
            self.counters.slept_periods = self.counters.slept_periods.saturating_add(1);
            return false;
        }
        self.read = self.read.wrapping_add(1);
        true
    }

    /// Hands `item` to `push` (which returns `false` when the queue is full), reporting any
    /// pending wake or gap first; what does not fit joins them.
    fn emit(&mut self, push: &mut impl FnMut(Item) -> bool, item: Item) {
        if self.pending_woke > 0 {
            if !push(Item::Woke(self.pending_woke)) {
                self.counters.overruns = self.counters.overruns.saturating_add(1);
                if let Item::Sample(_) = item {
                    // Joins the unsampled periods: the pipeline restarts after them anyway.
                    self.pending_woke = self.pending_woke.saturating_add(1);
                    self.counters.slept_periods = self.counters.slept_periods.saturating_add(1);
                }
                return;
            }
            self.pending_woke = 0;
        }
        if self.pending_gap > 0 {
            if !push(Item::Gap(self.pending_gap)) {
                self.counters.overruns = self.counters.overruns.saturating_add(1);
                if let Item::Sample(_) = item {
                    self.lost(1);
                }
                return;
            }
            self.pending_gap = 0;
        }
        if !push(item) {
            self.counters.overruns = self.counters.overruns.saturating_add(1);
            if let Item::Sample(_) = item {
                self.lost(1);
            }
        }
    }
}

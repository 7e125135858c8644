//! The sensor side of every board: what the data-ready interrupt does.
//!
//! Each board calls [`ImuSampler::on_data_ready`] from the interrupt of the sensor's INT
//! pin (the emulated boards from a timer standing in for it). The sampler reads the sensor
//! through its driver crate's source ([`gaitclip_imu::source`]: the MPU6050's, the
//! LSM6DSV320X's), either one sample per data-ready ([`ReadMode::PerSample`]), the FIFO every
//! few pulses ([`ReadMode::Fifo`], fewer bus transactions and wake-ups of the I2C
//! peripheral), or the FIFO at its watermark ([`ReadMode::Watermark`]), and hands [`Item`]s
//! to the board's queue. Nothing is lost silently:
//!
//! - a failed read is counted and retried at once, [`RETRIES`] times;
//! - a sample period whose read still fails becomes part of a [`Item::Gap`] (per-sample
//!   mode; in FIFO mode the samples wait in the FIFO and the next pulse tries again);
//! - after [`RESTART_AFTER`] failed periods in a row the bus is recovered (the board clocks
//!   SCL, [`BusRecovery`]) and the sensor re-initialised; what it lost meanwhile is a gap;
//! - a FIFO overflow, or a queue with no room, is a gap of the samples it cost;
//! - a sensor that stops pulsing altogether is found by the board's watchdog, which calls
//!   [`ImuSampler::on_silence`];
//! - the periods the sensor spent asleep ([`ImuSampler::request_sleep`], [`crate::sleep`])
//!   and the gyro's settling after it are one [`Item::Woke`], declared like a gap.
//!
//! Two samplers, one bookkeeping: [`ImuSampler`] ([`blocking`]) for the bare-metal boards'
//! interrupts and [`asynch::ImuSampler`] for the embassy board's task, which awaits each
//! transfer. Both only perform the transfers; what a pulse makes due and what each outcome
//! does to the counters and the queue is decided once, sans-IO, in `ledger`, so the host
//! tests that drive one with `embedded-hal-mock` hold for the other (tests-host's
//! `bus_faults` runs every scenario through both).
//!
//! Board glue, shared: generic over the part, its bus and the delay.

mod ledger;
mod sampler;

pub use sampler::{asynch, blocking};

pub use blocking::ImuSampler;

use gaitclip::detect::seam::StepDetector;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::sample::RawSample;
/// How the sensor is read: per sample, the FIFO every few pulses, or the FIFO at its
/// watermark (the seam's, so that each part's source can refuse what it cannot do).
pub use gaitclip_imu::source::ReadMode;

/// Immediate retries of a failed read.
pub const RETRIES: u32 = 2;
/// Failed sample periods in a row after which the bus is recovered and the sensor set up
/// again.
pub const RESTART_AFTER: u32 = 3;
/// Most samples read from the FIFO in one burst (the sampler's buffer, 14 B each).
pub const FIFO_BURST: usize = 16;

/// What the sample interrupt hands to the main loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// One sample, in order.
    Sample(RawSample),
    /// This many sample periods were lost here: the pipeline reports the stride in progress
    /// as a gap stride (invalid, no length) instead of measuring across the hole.
    Gap(u32),
    /// The sensor went to its low-power wait for motion after the sample before this
    /// ([`ImuSampler::request_sleep`]): nothing follows until [`Item::Woke`].
    Asleep,
    /// The sensor woke on motion and samples again: this many sample periods went
    /// unsampled (asleep, and the gyro's settling after it). The pipeline takes them as a
    /// hole, which restarts detection: a walk that began while the sensor woke is a gap
    /// stride, flagged, not dropped.
    Woke(u32),
}

impl Item {
    /// Hands the item to the pipeline; the stride it lets the pipeline report, if any (a
    /// gap's was closed before the gap).
    pub fn feed<D: StepDetector>(self, pipeline: &mut Pipeline<D>) -> Option<Stride> {
        match self {
            Item::Sample(s) => pipeline.process(&s),
            Item::Gap(n) | Item::Woke(n) => pipeline.gap(n),
            Item::Asleep => None,
        }
    }
}

/// A board's way to free a stuck I2C bus.
pub trait BusRecovery {
    /// Clocks SCL (nine pulses and a STOP) so that a slave holding SDA low lets go;
    /// returns whether the board could do it.
    fn recover_bus(&mut self) -> bool;
}

/// What went wrong so far, for the summary line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Failed bus transactions (every attempt counts).
    pub bus_errors: u32,
    /// Sensor re-initialisations after repeated failures or silence.
    pub restarts: u32,
    /// Bus recoveries (SCL clocked) that the board performed.
    pub recoveries: u32,
    /// FIFO overflows (or misaligned FIFO counts) found.
    pub fifo_overflows: u32,
    /// Watchdog calls: the sensor stopped pulsing.
    pub silences: u32,
    /// Items the queue had no room for.
    pub overruns: u32,
    /// Sample periods reported as gaps.
    pub lost_samples: u32,
    /// Times the sensor went to its low-power wait for motion.
    pub sleeps: u32,
    /// Sample periods spent there (and settling after it), not counted as lost.
    pub slept_periods: u32,
}

impl Counters {
    /// Nothing went wrong yet (for a `static`, where `Default` is not `const`).
    pub const ZERO: Counters = Counters {
        bus_errors: 0,
        restarts: 0,
        recoveries: 0,
        fifo_overflows: 0,
        silences: 0,
        overruns: 0,
        lost_samples: 0,
        sleeps: 0,
        slept_periods: 0,
    };
}

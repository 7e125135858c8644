//! The low-g and high-g accelerometers merged into one unclipped specific force, in fixed
//! point, and the FIFO's words assembled into the pipeline's samples.
//!
//! **Why per axis, at the rail.** The low-g channel resolves 0.49 mg per count at ±16 g; the
//! high-g one 3.9 mg at ±128 g. Below the low-g rail the low-g value is the better reading;
//! at it, the true value lies beyond and only the high-g channel has it. So each axis takes
//! the low-g value until that axis reaches [`DualRange::rail_counts`] (15.5 g of ±16 g by
//! default: real parts clip a little below their nominal range), and the high-g value from
//! there.
//!
//! **One scale out.** The pipeline takes one scale per stream, so the merged counts are the
//! high-g channel's ([`DualRange::scale`]): a low-g value is rescaled to it, rounded half away
//! from zero. The merge's resolution is therefore the high-g channel's, 1/`H` g per count
//! (3.9 mg at ±128 g), its error against the exact rescaling at most half a count, and its
//! range the high-g channel's full scale.
//!
//! **Aligned in time.** The high-g channel samples at 480 Hz or faster, the low-g one at the
//! pipeline's rate. A low-g sample stands, for the integrator, for its own period
//! `(k − 1, k]`; the high-g value that replaces it is the mean of the high-g samples of that
//! period (the FIFO's time slots say which), rounded half away from zero. A low-g sample at
//! its rail with no high-g sample in its period keeps its clipped value and is counted
//! ([`Assembler::high_g_missing`]).

use crate::fifo::{FifoWord, Tag};
use crate::range::{AccelRange, HighGRange};
use gaitclip_imu::{AccelScale, RawSample};

/// The two accelerometers' ranges and the low-g reading taken as its rail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DualRange {
    low: AccelRange,
    high: HighGRange,
    rail_counts: i32,
}

impl DualRange {
    /// The ranges `low` and `high`, the low-g rail at 31/32 of its full scale (15.5 g of
    /// ±16 g).
    pub const fn new(low: AccelRange, high: HighGRange) -> Self {
        let full = low.full_scale_g() as i32 * low.lsb_per_g() as i32;
        DualRange {
            low,
            high,
            rail_counts: full / 32 * 31,
        }
    }

    /// The same ranges with the low-g rail at `counts` (clamped to 1..=32 767): readings with
    /// |v| at or above it are taken as clipped.
    pub const fn with_rail_counts(self, counts: i32) -> Self {
        DualRange {
            rail_counts: if counts < 1 {
                1
            } else if counts > i16::MAX as i32 {
                i16::MAX as i32
            } else {
                counts
            },
            ..self
        }
    }

    /// The low-g reading taken as its rail, counts.
    pub const fn rail_counts(&self) -> i32 {
        self.rail_counts
    }

    /// The merged counts' scale: the high-g channel's.
    pub const fn scale(&self) -> AccelScale {
        self.high.scale()
    }

    /// A low-g value rescaled to the merged counts: `low · H / L` rounded half away from
    /// zero (|error| ≤ 0.5 count; every ±16 g value fits, since `H < L`).
    pub const fn low_to_merged(&self, low: i16) -> i16 {
        let num = low as i64 * self.high.lsb_per_g() as i64;
        saturate(div_round(num, self.low.lsb_per_g() as i64))
    }

    /// One axis: `low` from the low-g channel, and `high_sum` of `high_n` high-g samples of
    /// the same period. The merged counts, and whether the high-g channel gave them.
    pub const fn merge_axis(&self, low: i16, high_sum: i32, high_n: u32) -> (i16, bool) {
        let clipped = (low as i32).abs() >= self.rail_counts;
        if clipped && high_n > 0 {
            (saturate(div_round(high_sum as i64, high_n as i64)), true)
        } else {
            (self.low_to_merged(low), false)
        }
    }
}

/// `n / d` rounded half away from zero; `d > 0`.
const fn div_round(n: i64, d: i64) -> i64 {
    if n >= 0 {
        (n + d / 2) / d
    } else {
        -((-n + d / 2) / d)
    }
}

const fn saturate(v: i64) -> i16 {
    if v > i16::MAX as i64 {
        i16::MAX
    } else if v < i16::MIN as i64 {
        i16::MIN
    } else {
        v as i16
    }
}

/// Most high-g samples summed into one low-g period: 7 680 Hz over the slowest low-g rate
/// the pipeline takes (25 Hz) is 307; more are ignored (and counted), so the sum cannot
/// overflow (32 768 · 512 < 2³¹).
pub const MAX_HIGH_G_PER_SAMPLE: u32 = 512;

/// Assembles FIFO words into the pipeline's samples at the low-g rate: the low-g
/// accelerometer and the gyroscope of one time slot, the accelerometer merged with the
/// high-g samples of its period ([`DualRange`]).
///
/// A sample is complete when a word of a later time slot arrives (the words of one slot come
/// in any order), or at [`Assembler::flush`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Assembler {
    ranges: DualRange,
    slot: Option<u8>,
    accel: Option<[i16; 3]>,
    gyro: Option<[i16; 3]>,
    temp: i16,
    high_sum: [i32; 3],
    high_n: u32,
    /// Samples that had an axis at the low-g rail and no high-g sample in their period.
    high_g_missing: u32,
    /// Axes the high-g channel gave.
    high_g_axes: u32,
    /// Time slots that closed with only one of the accelerometer and gyroscope.
    unpaired: u32,
    /// High-g samples beyond [`MAX_HIGH_G_PER_SAMPLE`] in one period, not summed.
    high_g_dropped: u32,
}

impl Assembler {
    /// An assembler for `ranges`, before any word.
    pub const fn new(ranges: DualRange) -> Self {
        Assembler {
            ranges,
            slot: None,
            accel: None,
            gyro: None,
            temp: 0,
            high_sum: [0; 3],
            high_n: 0,
            high_g_missing: 0,
            high_g_axes: 0,
            unpaired: 0,
            high_g_dropped: 0,
        }
    }

    /// Takes one word; the sample it completes, if any.
    pub fn push(&mut self, w: FifoWord) -> Option<RawSample> {
        let done = match self.slot {
            Some(s) if s != w.slot => self.close(),
            _ => None,
        };
        self.slot = Some(w.slot);
        match w.tag {
            Tag::Accel => self.accel = Some(w.data),
            Tag::Gyro => self.gyro = Some(w.data),
            Tag::Temperature => self.temp = w.data[0],
            Tag::HighG => {
                if self.high_n < MAX_HIGH_G_PER_SAMPLE {
                    for k in 0..3 {
                        self.high_sum[k] += w.data[k] as i32;
                    }
                    self.high_n += 1;
                } else {
                    self.high_g_dropped = self.high_g_dropped.saturating_add(1);
                }
            }
            Tag::Timestamp | Tag::Other(_) => {}
        }
        done
    }

    /// The same assembler with the period it was assembling dropped (its FIFO was emptied:
    /// the caller's gap covers that period); the counts so far stay.
    pub const fn restarted(self) -> Self {
        Assembler {
            slot: None,
            accel: None,
            gyro: None,
            temp: 0,
            high_sum: [0; 3],
            high_n: 0,
            ..self
        }
    }

    /// Completes the last slot's sample, if it has one.
    pub fn flush(&mut self) -> Option<RawSample> {
        self.slot = None;
        self.close()
    }

    fn close(&mut self) -> Option<RawSample> {
        let (accel, gyro) = match (self.accel.take(), self.gyro.take()) {
            (Some(a), Some(g)) => (a, g),
            (None, None) => return None,
            _ => {
                self.unpaired = self.unpaired.saturating_add(1);
                return None;
            }
        };
        let mut merged = [0i16; 3];
        let mut railed_without_high = false;
        for k in 0..3 {
            let (v, high) = self
                .ranges
                .merge_axis(accel[k], self.high_sum[k], self.high_n);
            merged[k] = v;
            if high {
                self.high_g_axes = self.high_g_axes.saturating_add(1);
            } else if (accel[k] as i32).abs() >= self.ranges.rail_counts() {
                railed_without_high = true;
            }
        }
        if railed_without_high {
            self.high_g_missing = self.high_g_missing.saturating_add(1);
        }
        self.high_sum = [0; 3];
        self.high_n = 0;
        Some(RawSample {
            accel: merged,
            gyro,
            temp: self.temp,
        })
    }

    /// Samples that had an axis at the low-g rail and no high-g sample in their period (that
    /// axis keeps its clipped value).
    pub const fn high_g_missing(&self) -> u32 {
        self.high_g_missing
    }

    /// Axes the high-g channel gave, over all samples.
    pub const fn high_g_axes(&self) -> u32 {
        self.high_g_axes
    }

    /// Time slots that closed with only one of the accelerometer and gyroscope (not a
    /// sample: a lost sample period, which the caller declares as a gap).
    pub const fn unpaired(&self) -> u32 {
        self.unpaired
    }

    /// High-g samples beyond [`MAX_HIGH_G_PER_SAMPLE`] in one period.
    pub const fn high_g_dropped(&self) -> u32 {
        self.high_g_dropped
    }
}

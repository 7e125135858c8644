//! Per-phase features of a stride (Huang §2.4.2, Table 2), in Q16 fixed point.
//!
//! For each of the four segments (push-off, swing, heel-strike, the whole movement) and each
//! of the three signals (vertical, sagittal, magnitude; see [`crate::detect::phase_stats`]):
//!
//! | stat | value | unit |
//! |---|---|---|
//! | `max`, `min`, `range` | extremes and their difference | g |
//! | `mean_abs` | Σ\|a\|/N | g |
//! | `var` | unbiased variance (Zhang eq. 4) | g² |
//! | `weinberg` | range^¼ (Weinberg's term) | g^¼ |
//! | `kim` | mean_abs^⅓ (Kim's term) | g^⅓ |
//! | `scarlett` | (mean_abs − min)/range (Scarlett's term) | 1 |
//!
//! plus each segment's `duration` (s) and `frequency` (1/duration, Hz), and two stride-wide
//! values: the stride frequency (1 / foot-flat-to-foot-flat time, Hz) and the ZUPT
//! displacement (m), so that the learnt models can use the strapdown estimate too.
//!
//! Every value is an `i64` in Q16 of its unit (`1.0 == 65536`). Accelerations are exact
//! (counts · 32); means, variances and ratios are rounded to nearest from the exact sums
//! (error ≤ 0.5 LSB, 7.6e−6); roots are rounded down from exact or Q48 inputs (error < 1 LSB,
//! 1.53e−5). `tests-host/tests/lengths.rs` checks every feature against f64 within 1 LSB.
//! Empty segments give zeros. Work is per stride, not per sample.

use crate::detect::phase_stats::{Channel, ChannelStats, Segment, StrideStats, CHANNELS, SEGMENTS};
use crate::fixed::{div_round_i128, iroot_u128, root_q16, Q16_ONE};
use crate::record::stride::Stride;
use crate::sensor::rate::SampleRate;
use crate::sensor::units::FOOT_LSB_PER_G;

/// Statistics taken of every signal in every segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Stat {
    /// Largest value, g.
    Max = 0,
    /// Smallest value, g.
    Min = 1,
    /// max − min, g.
    Range = 2,
    /// Mean of |a|, g.
    MeanAbs = 3,
    /// Unbiased variance, g².
    Variance = 4,
    /// range^¼, g^¼.
    Weinberg = 5,
    /// mean_abs^⅓, g^⅓.
    Kim = 6,
    /// (mean_abs − min)/range, dimensionless.
    Scarlett = 7,
}

/// Number of [`Stat`]s.
pub const STATS: usize = 8;

impl Stat {
    /// Every stat, in index order.
    pub const ALL: [Stat; STATS] = [
        Stat::Max,
        Stat::Min,
        Stat::Range,
        Stat::MeanAbs,
        Stat::Variance,
        Stat::Weinberg,
        Stat::Kim,
        Stat::Scarlett,
    ];

    /// Short name.
    pub const fn name(self) -> &'static str {
        match self {
            Stat::Max => "max",
            Stat::Min => "min",
            Stat::Range => "range",
            Stat::MeanAbs => "mean_abs",
            Stat::Variance => "var",
            Stat::Weinberg => "weinberg",
            Stat::Kim => "kim",
            Stat::Scarlett => "scarlett",
        }
    }
}

/// Features per segment: every stat of every channel, then duration and frequency.
pub const PER_SEGMENT: usize = CHANNELS * STATS + 2;
/// Total number of features.
pub const COUNT: usize = SEGMENTS * PER_SEGMENT + 2;
/// Index of the stride frequency (Hz).
pub const STRIDE_FREQUENCY: usize = SEGMENTS * PER_SEGMENT;
/// Index of the ZUPT displacement (m).
pub const ZUPT_LENGTH: usize = STRIDE_FREQUENCY + 1;

/// Index of `stat` of `channel` over `segment`.
pub const fn index(segment: Segment, channel: Channel, stat: Stat) -> usize {
    segment as usize * PER_SEGMENT + channel as usize * STATS + stat as usize
}

/// Index of the duration (s) of `segment`.
pub const fn duration_index(segment: Segment) -> usize {
    segment as usize * PER_SEGMENT + CHANNELS * STATS
}

/// Index of the frequency (1/duration, Hz) of `segment`.
pub const fn frequency_index(segment: Segment) -> usize {
    duration_index(segment) + 1
}

/// The name of feature `i`, as `(segment, channel, stat)`; stride-wide features and the
/// per-segment duration and frequency leave the parts they lack empty.
pub const fn name_parts(i: usize) -> (&'static str, &'static str, &'static str) {
    if i == STRIDE_FREQUENCY {
        return ("stride", "", "frequency");
    }
    if i == ZUPT_LENGTH {
        return ("stride", "", "zupt_length");
    }
    if i >= COUNT {
        return ("", "", "");
    }
    let seg = Segment::ALL[i / PER_SEGMENT].name();
    let k = i % PER_SEGMENT;
    if k == CHANNELS * STATS {
        (seg, "", "duration")
    } else if k == CHANNELS * STATS + 1 {
        (seg, "", "frequency")
    } else {
        (
            seg,
            Channel::ALL[k / STATS].name(),
            Stat::ALL[k % STATS].name(),
        )
    }
}

/// Shift from foot-frame counts (g/2048) to Q16 g.
const COUNTS_TO_Q16_SHIFT: u32 = 16 - FOOT_LSB_PER_G.trailing_zeros();
const _: () = assert!((FOOT_LSB_PER_G as u32).is_power_of_two() && FOOT_LSB_PER_G <= 1 << 16);

/// The features of one stride, each in Q16 of its unit (see the module table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Features(pub [i64; COUNT]);

impl Features {
    /// Feature `i` (0 out of range).
    pub fn get(&self, i: usize) -> i64 {
        self.0.get(i).copied().unwrap_or(0)
    }

    /// `stat` of `channel` over `segment`.
    pub fn stat(&self, segment: Segment, channel: Channel, stat: Stat) -> i64 {
        self.get(index(segment, channel, stat))
    }

    /// The features of `stride`, whose movement `stats` summarise
    /// ([`crate::detect::stance_strides::StrideTracker::stats`]), recorded at `rate`.
    pub fn of(stride: &Stride, stats: &StrideStats, rate: SampleRate) -> Features {
        let mut f = [0i64; COUNT];
        for seg in Segment::ALL {
            let s = &stats.segments[seg as usize];
            for ch in Channel::ALL {
                let v = channel_features(&s.channels[ch as usize], s.samples);
                let at = index(seg, ch, Stat::Max);
                f[at..at + STATS].copy_from_slice(&v);
            }
            f[duration_index(seg)] = duration_q16(s.samples, rate);
            f[frequency_index(seg)] = frequency_q16(s.samples, rate);
        }
        f[STRIDE_FREQUENCY] =
            frequency_q16(stride.events.end.wrapping_sub(stride.events.start), rate);
        f[ZUPT_LENGTH] = zupt_length_q16(stride);
        Features(f)
    }

    /// Only the ZUPT displacement ([`ZUPT_LENGTH`]), every other feature zero: all the
    /// `zupt` model reads, for a fraction of [`Features::of`]'s work (its divisions and
    /// roots are ≈ 330 k instructions per stride on the M4).
    pub fn zupt_only(stride: &Stride) -> Features {
        let mut f = [0i64; COUNT];
        f[ZUPT_LENGTH] = zupt_length_q16(stride);
        Features(f)
    }
}

/// The stride's ZUPT displacement in m, Q16.
fn zupt_length_q16(stride: &Stride) -> i64 {
    div_round_i128(stride.zupt_um as i128 * Q16_ONE as i128, 1_000_000) as i64
}

/// Duration of `samples` at `rate`, s, Q16.
pub fn duration_q16(samples: u32, rate: SampleRate) -> i64 {
    div_round_i128(
        samples as i128 * 1000 * Q16_ONE as i128,
        rate.millihertz() as i128,
    ) as i64
}

/// Frequency of something lasting `samples` at `rate`, Hz, Q16; 0 for no samples.
pub fn frequency_q16(samples: u32, rate: SampleRate) -> i64 {
    if samples == 0 {
        return 0;
    }
    div_round_i128(
        rate.millihertz() as i128 * Q16_ONE as i128,
        samples as i128 * 1000,
    ) as i64
}

/// The [`STATS`] values of one channel over `n` samples, Q16.
fn channel_features(c: &ChannelStats, n: u32) -> [i64; STATS] {
    if n == 0 {
        return [0; STATS];
    }
    let q = |counts: i64| counts << COUNTS_TO_Q16_SHIFT;
    let n128 = n as i128;
    let max = q(c.max as i64);
    let min = q(c.min as i64);
    let range = max - min;
    let mean_abs = div_round_i128((c.sum_abs as i128) << COUNTS_TO_Q16_SHIFT, n128) as i64;
    // Unbiased: (n·Σx² − (Σx)²) / (n(n−1)), in counts², → Q16 g²: · 2¹⁶ / 2048².
    let var = if n > 1 {
        let num = n128 * c.sum_sq as i128 - c.sum as i128 * c.sum as i128;
        let lsb2 = (FOOT_LSB_PER_G as i128) * (FOOT_LSB_PER_G as i128);
        div_round_i128(num * Q16_ONE as i128, n128 * (n128 - 1) * lsb2) as i64
    } else {
        0
    };
    let weinberg = root_q16(range.max(0) as u64, 4) as i64;
    // From the exact mean (Q48 before the root), so that only the root's floor is lost.
    let kim = iroot_u128(
        ((c.sum_abs as u128) << (COUNTS_TO_Q16_SHIFT + 32)) / n as u128,
        3,
    ) as i64;
    // From the exact sums, not the rounded mean: (Σ|a|/n − min)/range in one rounding.
    let scarlett = if range > 0 {
        let num = ((c.sum_abs as i128) << COUNTS_TO_Q16_SHIFT) - n128 * min as i128;
        div_round_i128(num * Q16_ONE as i128, n128 * range as i128) as i64
    } else {
        0
    };
    [max, min, range, mean_abs, var, weinberg, kim, scarlett]
}

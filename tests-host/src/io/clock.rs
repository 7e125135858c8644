//! The sensor's sample clock, recovered from a recording's timestamps: where samples were
//! lost, and the time of every sample the core numbers.
//!
//! A recording's stamps are not always the sensor's clock. Three kinds are met in practice:
//!
//! - **The sensor's own clock** (`gaitmap_walk`; `ipol_gait_events`, whose stamps are the
//!   wireless packet counter, so that lost packets are holes): a grid, with holes.
//! - **A logger's clock with jitter** (`pyshoe_vicon`: a stamp late by up to 4 ms, the next
//!   ones early again): the grid, seen through noise that averages out.
//! - **A host computer's clock** (PC logging tools such as MicroStrain SensorConnect stamp a
//!   sample when the computer receives it): bursts of samples microseconds apart, then pauses
//!   of several periods, around a sensor clock that is steady to 0.01 %, and which may drift
//!   against the host's by ±100 ppm.
//!
//! In every case the sensor sampled on a steady grid, `t = t₀ + n·P`, and a stamp is that
//! time plus a delay that is never much below the smallest one (a sample cannot reach the
//! logger before it was taken). So the clock is fitted to the *earliest* stamps, and a hole
//! is where the stamps fall behind that clock and stay behind:
//!
//! 1. **Nominal period** `P₀`: `--rate` or `meta.json` when given; else from the stamps
//!    ([`nominal_period`]: the median advance per row between deliveries, robust to lost
//!    packets and to bursts), then corrected for drift before any hole is known.
//! 2. **Holes, greedily.** With the current clock, row `i` would be sample number
//!    `n = i + L` (`L` periods lost so far). Over the [`LOOK_AHEAD`] rows from `i` on, the
//!    least-delayed stamp's lag behind the clock is measured; when even that lag is at least
//!    `1 − `[`EARLY_ALLOWANCE`] periods, `⌊lag / P + `[`EARLY_ALLOWANCE`]`⌋` samples are
//!    missing before row `i` (the stamps stay behind: no later burst catches up), and `L`
//!    grows by that much. Jitter and bursts are late stamps followed by timely ones within
//!    the look-ahead: no hole. Inside a burst the stamps say nothing about where a hole
//!    lies: it is placed at the burst's first late row (the numbering with the least delay).
//! 3. **Fit.** Each block of [`BLOCK`] rows (more past [`FIT_POINTS`] blocks: a bounded
//!    record of the longest recording) contributes its least-delayed stamp `(n, t)`; the
//!    slope `P` is the median of the slopes between blocks half the recording apart (a
//!    Theil–Sen estimate, robust to blocks whose least delay is unusual), the offset `t₀` a
//!    low quantile ([`OFFSET_QUANTILE`]) of `t − n·P` over the blocks. The fit is global:
//!    the holes are steps in `n`, not breaks in the line, so the clock holds across them.
//! 4. Steps 2–3 repeat until the holes no longer change (at most [`MAX_ROUNDS`]).
//!
//! The result maps the core's sample numbers (rows plus the periods lost before them) to
//! the sensor clock's time, and back to rows for the ground truth of a dataset.

/// Rows after a possible hole over which late stamps must come back onto the clock for it
/// to be jitter, not lost samples: longer than a host's bursts (8 samples in the tests) and
/// the pauses between them.
pub const LOOK_AHEAD: usize = 64;
/// Rows per block of the clock fit (one least-delayed stamp each).
pub const BLOCK: usize = 64;
/// The most blocks the fit keeps: past them the blocks double (a recording longer than
/// `FIT_POINTS · BLOCK` = 4.19 M rows, 11.6 h at 100 Hz, is fitted on blocks of 128 rows
/// or more; every shared recording is shorter).
pub const FIT_POINTS: usize = 1 << 16;
/// Most rounds of hole finding and fitting.
pub const MAX_ROUNDS: usize = 6;
/// How early, in periods, a stamp may be against the clock fitted to the earliest stamps
/// and still be on it (a logger's jitter). Rows late by up to one period less than this
/// are not taken for lost samples.
pub const EARLY_ALLOWANCE: f64 = 0.25;
/// Quantile of the blocks' least delays that the clock's offset is set to: low, so that
/// lags behind the clock are rarely negative, not the least, which an early outlier sets.
pub const OFFSET_QUANTILE: f64 = 0.1;
/// A hole inside a burst moves from its first candidate row only to a place where the
/// angular rate is this much smoother ([`SampleClock::place_holes`]).
pub const MOVE_IF_SMOOTHER: f64 = 0.7;
/// A stamp more than this many periods from the recovered clock is counted as re-timed.
pub const RETIMED_PERIODS: f64 = 0.25;

/// `missing` sample periods are lost just before row `before` of the recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Gap {
    /// Index of the first row after the hole.
    pub before: usize,
    /// Sample periods lost.
    pub missing: u32,
}

/// A stamp goes back by more than a re-sent sample's would: bad input.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("sample {index} (from 0): time {t_s} s is before the previous sample's {previous_s} s by more than half a period")]
pub struct TimeGoesBack {
    /// Index of the sample in the recording (before any was dropped).
    pub index: usize,
    /// Its time, s.
    pub t_s: f64,
    /// The previous sample's time, s.
    pub previous_s: f64,
}

/// Re-sent samples in a recording: a stamp equal to the one before, or earlier than it by
/// less than half a period, repeats a sample already received (a wireless link re-sent a
/// packet). The first is kept. Returns the indices of the samples to keep; a stamp that
/// goes back further is an error.
pub fn drop_repeats(stamps: &[f64], period_s: f64) -> Result<Vec<usize>, TimeGoesBack> {
    let mut keep = Vec::with_capacity(stamps.len());
    let mut f = RepeatFilter::new(period_s);
    for (i, &t) in stamps.iter().enumerate() {
        if f.keeps(i, t)? {
            keep.push(i);
        }
    }
    Ok(keep)
}

/// [`drop_repeats`] one stamp at a time, for a recording read as a stream.
#[derive(Clone, Copy, Debug)]
pub struct RepeatFilter {
    last: Option<f64>,
    period_s: f64,
}

impl RepeatFilter {
    /// No stamp seen yet, repeats judged at `period_s`.
    pub fn new(period_s: f64) -> Self {
        RepeatFilter {
            last: None,
            period_s,
        }
    }

    /// Whether the sample at index `i` with stamp `t` is kept (a re-sent one is not); an
    /// error where it goes back further than a re-sent sample would.
    pub fn keeps(&mut self, i: usize, t: f64) -> Result<bool, TimeGoesBack> {
        match self.last {
            Some(prev) if t <= prev => {
                // NaN never gets here (the readers reject non-finite cells).
                if prev - t < 0.5 * self.period_s {
                    return Ok(false);
                }
                Err(TimeGoesBack {
                    index: i,
                    t_s: t,
                    previous_s: prev,
                })
            }
            _ => {
                self.last = Some(t);
                Ok(true)
            }
        }
    }
}

/// The nominal period of stamps with no rate given (step 1 of the module comment), s;
/// `None` for fewer than two increasing stamps.
///
/// Rows arrive in deliveries: one row each from a sensor's or a logger's clock, bursts of
/// rows microseconds apart from a host's (rows closer than a tenth of the mean interval
/// are one delivery). Between two deliveries the stamps advance by the rows of the later
/// one times the period, plus the periods of any hole and the change of delay. The median
/// of that advance per row, over all deliveries, is near the period: holes and delays touch
/// few deliveries and leave it where it is (the span per row would carry every lost sample,
/// and the median interval of a host's bursts is microseconds). The period is the mean
/// advance per row over the deliveries within a quarter of that median: the median alone is
/// one tick of stamps rounded to a coarse one (4.9 ms for 204.8 Hz at 0.1 ms).
pub fn nominal_period(stamps: &[f64]) -> Option<f64> {
    nominal_period_of(&|| stamps.iter().copied(), stamps.len())
}

/// [`nominal_period`] of the `n` stamps each call of `stamps` yields in order (a recording
/// read as many times as needed, kept nowhere): the same arithmetic in the same order, the
/// median an exact order statistic ([`nth_smallest`]).
pub fn nominal_period_of<I: Iterator<Item = f64>>(
    stamps: &impl Fn() -> I,
    n: usize,
) -> Option<f64> {
    if n < 2 {
        return None;
    }
    let (first, last) = stamps().fold((None, 0.0), |(f, _), t| (f.or(Some(t)), t));
    let mean = (last - first.unwrap_or(last)) / (n - 1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return None;
    }
    // (advance, rows) between the ends of consecutive deliveries (the last row of each).
    let steps = || Deliveries::new(stamps(), mean).filter(|(a, _)| a.is_finite() && *a > 0.0);
    let count = steps().count();
    if count == 0 {
        return Some(mean);
    }
    let median = nth_smallest(&|| steps().map(|(a, k)| a / k as f64), count / 2);
    // Stamps rounded to a tick (0.1 ms is common) make the per-row advances a tick apart
    // (4.8 and 4.9 ms at 204.8 Hz), and the median one of them: the mean over the deliveries
    // near the median (within a quarter: no hole, no late delivery) is the period itself.
    let (mut sum, mut rows) = (0.0, 0usize);
    for (a, k) in steps() {
        if (a / k as f64 - median).abs() <= 0.25 * median {
            sum += a;
            rows += k;
        }
    }
    Some(if rows > 0 { sum / rows as f64 } else { median })
}

/// The steps between deliveries of [`nominal_period`]: rows closer than a tenth of `mean`
/// are one delivery; yields (advance, rows) from each delivery's last row to the next's.
struct Deliveries<I: Iterator<Item = f64>> {
    stamps: std::iter::Peekable<std::iter::Enumerate<I>>,
    mean: f64,
    /// The last delivery end seen: its row and stamp.
    end: Option<(usize, f64)>,
}

impl<I: Iterator<Item = f64>> Deliveries<I> {
    fn new(stamps: I, mean: f64) -> Self {
        Deliveries {
            stamps: stamps.enumerate().peekable(),
            mean,
            end: None,
        }
    }
}

impl<I: Iterator<Item = f64>> Iterator for Deliveries<I> {
    type Item = (f64, usize);

    fn next(&mut self) -> Option<(f64, usize)> {
        while let Some((i, t)) = self.stamps.next() {
            let is_end = match self.stamps.peek() {
                None => true,
                Some(&(_, next)) => next - t >= 0.1 * self.mean,
            };
            if !is_end {
                continue;
            }
            let prev = self.end.replace((i, t));
            if let Some((j, u)) = prev {
                return Some((t - u, i - j));
            }
        }
        None
    }
}

/// The `k`-th smallest (from 0, in [`f64::total_cmp`]'s order) of the values each call of
/// `values` yields, the same every call: what sorting them and taking `[k]` gives, found by
/// four passes of a 16-bit radix select on the order-preserving keys of the values (65 536
/// counters, nothing kept of the values themselves). `k` must be below the count.
pub fn nth_smallest<I: Iterator<Item = f64>>(values: &impl Fn() -> I, k: usize) -> f64 {
    // The total order's key: flip the sign bit of a positive value, every bit of a negative.
    let key = |v: f64| {
        let b = v.to_bits();
        if b >> 63 == 1 {
            !b
        } else {
            b | (1 << 63)
        }
    };
    let (mut prefix, mut rank) = (0u64, k);
    let mut counts = vec![0usize; 1 << 16];
    for pass in 0..4u32 {
        let shift = 48 - 16 * pass;
        counts.iter_mut().for_each(|c| *c = 0);
        for v in values() {
            let kv = key(v);
            // The bits above this pass's must be the prefix found so far.
            if pass > 0 && kv >> (shift + 16) != prefix {
                continue;
            }
            counts[((kv >> shift) & 0xFFFF) as usize] += 1;
        }
        let mut bucket = 0;
        for (b, &c) in counts.iter().enumerate() {
            if rank < c {
                bucket = b;
                break;
            }
            rank -= c;
        }
        prefix = (prefix << 16) | bucket as u64;
    }
    let b = if prefix >> 63 == 1 {
        prefix & !(1 << 63)
    } else {
        !prefix
    };
    f64::from_bits(b)
}

/// The sample clock of a recording.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleClock {
    /// Sample period, s.
    pub period_s: f64,
    /// Time of sample number 0, s.
    pub offset_s: f64,
    /// The nominal period the fit started from, s.
    pub nominal_period_s: f64,
    /// Where samples were lost, in row order.
    pub holes: Vec<Gap>,
    /// Stamps further than [`RETIMED_PERIODS`] from the clock.
    pub retimed: usize,
    /// The largest distance of a stamp from the clock, s.
    pub max_offclock_s: f64,
    /// Rows of the recording (the sample number of each is its row plus the periods lost in
    /// the holes before it: nothing per row is kept).
    rows: usize,
}

impl SampleClock {
    /// Recovers the clock of `stamps` (increasing), starting from `nominal_hz` when given;
    /// see the module comment. `None` for an empty recording.
    pub fn recover(stamps: &[f64], nominal_hz: Option<f64>) -> Option<SampleClock> {
        Self::recover_of(&|| stamps.iter().copied(), stamps.len(), nominal_hz)
    }

    /// [`SampleClock::recover`] of the `n` stamps each call of `stamps` yields in order (a
    /// recording read as a stream, as many times as the rounds need): what it keeps is the
    /// holes, one point per [`BLOCK`] rows for the fit and a window of [`LOOK_AHEAD`] rows.
    pub fn recover_of<I: Iterator<Item = f64>>(
        stamps: &impl Fn() -> I,
        n: usize,
        nominal_hz: Option<f64>,
    ) -> Option<SampleClock> {
        if n == 0 {
            return None;
        }
        let nominal = match nominal_hz {
            Some(hz) if hz.is_finite() && hz > 0.0 => 1.0 / hz,
            _ => nominal_period_of(stamps, n).unwrap_or(1.0),
        };
        let mut period = refine_period(stamps, n, nominal);
        let mut offset = stamps()
            .take(n.min(BLOCK))
            .enumerate()
            .map(|(j, t)| t - j as f64 * period)
            .fold(f64::INFINITY, f64::min);
        let mut holes = Vec::new();
        for round in 0..MAX_ROUNDS {
            let found = find_holes(stamps(), period, offset);
            if round > 0 && found == holes {
                break;
            }
            holes = found;
            (period, offset) = fit(stamps(), &holes, period, offset);
        }
        let (mut retimed, mut max_off) = (0, 0.0f64);
        for (t, k) in stamps().zip(Numbering::new(&holes)) {
            let off = (t - (offset + k as f64 * period)).abs();
            if off > RETIMED_PERIODS * period {
                retimed += 1;
            }
            max_off = max_off.max(off);
        }
        Some(SampleClock {
            period_s: period,
            offset_s: offset,
            nominal_period_s: nominal,
            holes,
            retimed,
            max_offclock_s: max_off,
            rows: n,
        })
    }

    /// Moves each hole to where the samples say it is, among the rows its stamps cannot
    /// tell apart. A host delivers a burst of samples at once, so when a hole falls inside a
    /// burst every row of it looks equally late; a burst that stalls looks late too. The
    /// hole finder puts the hole at the first row that could follow it; it may lie before
    /// any later row of that burst, or of the stalled bursts after it, up to the end of the
    /// first burst that arrives on time. The samples decide between those places: a moving
    /// foot's angular rate (`rate(row)`, any unit) is smooth from one period to the next,
    /// so the hole goes where the rate, with the hole filled by a straight line, is
    /// smoothest (least energy of second differences over the candidate rows). The
    /// acceleration is not used: impacts make it jump from one sample to the next. In a
    /// stance the rate is noise and any place is as good (nothing moves there). Stamps
    /// without bursts (every row its own) leave the holes where they are.
    pub fn place_holes(&mut self, stamps: &[f64], rate: impl Fn(usize) -> [f64; 3]) {
        self.place_holes_of(stamps.iter().enumerate().map(|(i, &t)| (t, rate(i))));
    }

    /// [`SampleClock::place_holes`] reading the rows once, in order, as (stamp, rate) pairs:
    /// a window of [`PLACE_WINDOW`] rows is all it keeps.
    pub fn place_holes_of(&mut self, rows: impl Iterator<Item = (f64, [f64; 3])>) {
        let n = self.rows;
        // Moves are made at the end: the numbering the later holes are judged by is the
        // holes' as found.
        let mut moves: Vec<(usize, usize)> = Vec::new();
        let original = &self.holes;
        let mut ring: Vec<(f64, [f64; 3])> = vec![(0.0, [0.0; 3]); PLACE_WINDOW];
        let mut read = 0usize;
        let mut rows = rows.take(n);
        for k in 0..self.holes.len() {
            let first = self.holes[k].before;
            // Every row this hole can look at: first − 2 ..= first + LOOK_AHEAD + 2.
            let need = (first + LOOK_AHEAD + 3).min(n);
            while read < need {
                match rows.next() {
                    Some(r) => ring[read % PLACE_WINDOW] = r,
                    None => break,
                }
                read += 1;
            }
            let at = |row: usize| ring[row % PLACE_WINDOW];
            let m = self.holes[k].missing as usize;
            let limit = self
                .holes
                .get(k + 1)
                .map_or(n, |g| g.before)
                .min(first + LOOK_AHEAD)
                .min(read);
            // Bursts from `first` on; the range ends with the first burst whose last row is
            // on time under the numbering after the hole (the holes as found: a hole moved
            // does not move the numbering the later ones are judged by).
            let burst_gap = 0.25 * self.period_s;
            let lag =
                |row: usize| (at(row).0 - self.t_s(number_with(original, row))) / self.period_s;
            let mut last = first;
            loop {
                while last + 1 < limit && at(last + 1).0 - at(last).0 < burst_gap {
                    last += 1;
                }
                if lag(last) < 1.0 - EARLY_ALLOWANCE || last + 1 >= limit {
                    break;
                }
                last += 1;
            }
            if last == first {
                continue;
            }
            // Rows first − 2 ..= last + 2 with the hole before row h, as rates on the grid.
            let (lo, hi) = (first.saturating_sub(2), (last + 2).min(n - 1).min(read - 1));
            let roughness = |h: usize| -> f64 {
                let mut seq: Vec<[f64; 3]> = Vec::with_capacity(hi - lo + 1 + m);
                for row in lo..=hi {
                    if row == h && row > lo {
                        let (a, b) = (at(row - 1).1, at(row).1);
                        for j in 1..=m {
                            let f = j as f64 / (m + 1) as f64;
                            seq.push([0, 1, 2].map(|i| a[i] + f * (b[i] - a[i])));
                        }
                    }
                    seq.push(at(row).1);
                }
                seq.windows(3)
                    .map(|w| {
                        (0..3)
                            .map(|i| (w[2][i] - 2.0 * w[1][i] + w[0][i]).powi(2))
                            .sum::<f64>()
                    })
                    .sum()
            };
            let best = (first..=last)
                .min_by(|&a, &b| roughness(a).total_cmp(&roughness(b)).then(a.cmp(&b)))
                .unwrap_or(first);
            // Only a clearly smoother place moves it: where the rate is noise (a stance) the
            // stamps' first candidate stays.
            if best != first && roughness(best) < MOVE_IF_SMOOTHER * roughness(first) {
                moves.push((k, best));
            }
        }
        for (k, best) in moves {
            self.holes[k].before = best;
        }
    }

    /// The clock's rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        1.0 / self.period_s
    }

    /// Samples lost in all the holes.
    pub fn lost(&self) -> u64 {
        self.holes.iter().map(|g| g.missing as u64).sum()
    }

    /// Time of sample number `n`, s.
    pub fn t_s(&self, n: u32) -> f64 {
        self.offset_s + n as f64 * self.period_s
    }

    /// The sample number nearest time `t_s` on this clock (clamped at 0).
    pub fn number_at(&self, t_s: f64) -> u32 {
        ((t_s - self.offset_s) / self.period_s)
            .round()
            .clamp(0.0, u32::MAX as f64) as u32
    }

    /// Sample number of row `row` (rows past the end go on at one per period).
    pub fn number_of_row(&self, row: usize) -> u32 {
        number_with(&self.holes, row)
    }

    /// The row of sample number `n`, or of the first row after it if it was lost (rows past
    /// the end go on at one per period).
    pub fn row_of_number(&self, n: u32) -> u32 {
        let rows = self.rows.max(1);
        // The first row whose number is `n` or more (numbers increase with the rows).
        let (mut lo, mut hi) = (0usize, rows);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if self.number_of_row(mid) < n {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        if lo < rows {
            return lo as u32;
        }
        let last = rows - 1;
        let extra = n.saturating_sub(self.number_of_row(last)) as usize;
        (last + extra).min(u32::MAX as usize) as u32
    }
}

/// Rows [`SampleClock::place_holes_of`] keeps: a hole looks at most [`LOOK_AHEAD`] + 5 rows.
pub const PLACE_WINDOW: usize = 128;

/// The sample number of row `row` with `holes` (in row order): the row plus the periods
/// lost before it, saturated.
fn number_with(holes: &[Gap], row: usize) -> u32 {
    let upto = holes.partition_point(|g| g.before <= row);
    let lost: u64 = holes[..upto].iter().map(|g| g.missing as u64).sum();
    (row as u64 + lost).min(u32::MAX as u64) as u32
}

/// The sample numbers of the rows, in order, with `holes` (in row order): row plus the
/// periods lost so far.
struct Numbering<'a> {
    holes: std::iter::Peekable<std::slice::Iter<'a, Gap>>,
    row: usize,
    lost: u64,
}

impl<'a> Numbering<'a> {
    fn new(holes: &'a [Gap]) -> Self {
        Numbering {
            holes: holes.iter().peekable(),
            row: 0,
            lost: 0,
        }
    }
}

impl Iterator for Numbering<'_> {
    type Item = u32;

    fn next(&mut self) -> Option<u32> {
        let row = self.row;
        while let Some(g) = self.holes.next_if(|g| g.before <= row) {
            self.lost += g.missing as u64;
        }
        self.row += 1;
        Some((row as u64 + self.lost).min(u32::MAX as u64) as u32)
    }
}

/// Step 1½: the period corrected for a clock that drifts against the stamps, before any
/// hole is known (a hole finder on the wrong period takes the drift for lost samples).
/// Between consecutive blocks of `B` rows, the least-delayed stamps differ by `B` periods
/// plus whole periods lost in holes: the difference's fractional part, in periods, is the
/// drift over `B` rows. Its mean over the blocks, taken on the circle (a fractional part
/// near ±½ wraps), corrects the period; blocks of 16 rows first (a period off by up to
/// 3 %), then longer ones refine it (noise shrinks as the drift over a block grows).
fn refine_period<I: Iterator<Item = f64>>(stamps: &impl Fn() -> I, n: usize, nominal: f64) -> f64 {
    let mut period = nominal;
    for b in [16usize, 64, 256, 1024] {
        // The least-delayed stamp of each whole block of `b` rows, against the period.
        let blocks = n / b;
        if blocks < 8 {
            break;
        }
        // The fractional parts as angles, averaged on the circle: a drift near half a period
        // per block wraps around without pulling the mean.
        let (mut sin, mut cos) = (0.0, 0.0);
        let (mut previous, mut least) = (None::<f64>, f64::INFINITY);
        for (i, t) in stamps().take(blocks * b).enumerate() {
            least = f64::min(least, t - i as f64 * period);
            if i % b == b - 1 {
                if let Some(p) = previous {
                    let phase = (least - p) / period * std::f64::consts::TAU;
                    sin += phase.sin();
                    cos += phase.cos();
                }
                previous = Some(least);
                least = f64::INFINITY;
            }
        }
        let frac = f64::atan2(sin, cos) / std::f64::consts::TAU;
        period += frac * period / b as f64;
    }
    period
}

/// Step 2 of the module comment: the holes of `stamps` against the clock `(period, offset)`.
fn find_holes(stamps: impl Iterator<Item = f64>, period: f64, offset: f64) -> Vec<Gap> {
    // u_j = t_j − offset − j·P: a row's lag behind the clock before any hole is counted; the
    // least of u over [i, i + LOOK_AHEAD), by a monotone deque over a window of as many rows.
    // Both are rings of LOOK_AHEAD slots (the window holds at most that many rows, the deque
    // at most the window's), indexed modulo a power of two: a fixed array, not a `VecDeque`.
    const _: () = assert!(LOOK_AHEAD.is_power_of_two());
    let slot = |k: usize| k % LOOK_AHEAD;
    // The window's lags by row; the deque's (row, lag) from `head`, `len` of them.
    let mut window = [0.0f64; LOOK_AHEAD];
    let mut deque = [(0usize, 0.0f64); LOOK_AHEAD];
    let (mut head, mut len) = (0usize, 0usize);
    let mut holes: Vec<Gap> = Vec::new();
    let mut lost = 0u64;
    // Whether a row since the last hole was on time: if none was, a hole found now is the
    // rest of that one (a stalled delivery before it hid part of it), not a new hole.
    let mut on_time_since = true;
    let mut judge = |i: usize, m: f64, u: f64| {
        if i == 0 {
            return;
        }
        // Whole periods the least-delayed stamp ahead lies behind, with a quarter period's
        // allowance for a stamp a little early; a stamp late by less than three quarters of
        // a period just before a hole is not taken for part of it.
        let behind = (m - lost as f64 * period) / period + EARLY_ALLOWANCE;
        if behind >= 1.0 {
            let missing = behind.floor().min(u32::MAX as f64) as u32;
            match holes.last_mut() {
                Some(last) if !on_time_since => last.missing = last.missing.saturating_add(missing),
                _ => holes.push(Gap { before: i, missing }),
            }
            lost += missing as u64;
            on_time_since = false;
        }
        let lag = (u - lost as f64 * period) / period;
        on_time_since |= lag < 1.0 - EARLY_ALLOWANCE;
    };
    let (mut first, mut rows) = (0usize, 0usize);
    for (j, t) in stamps.enumerate() {
        let u = t - offset - j as f64 * period;
        while len > 0 && deque[slot(head + len - 1)].1 >= u {
            len -= 1;
        }
        deque[slot(head + len)] = (j, u);
        len += 1;
        window[slot(j)] = u;
        rows = j + 1;
        if rows - first == LOOK_AHEAD {
            judge(first, deque[head].1, window[slot(first)]);
            if deque[head].0 == first {
                (head, len) = (slot(head + 1), len - 1);
            }
            first += 1;
        }
    }
    // The last rows, their windows cut by the end (the deque holds the last row till then).
    while first < rows {
        judge(first, deque[head].1, window[slot(first)]);
        if deque[head].0 == first {
            (head, len) = (slot(head + 1), len - 1);
        }
        first += 1;
    }
    holes
}

/// Step 3 of the module comment: period and offset from the least-delayed stamp of each
/// block. Falls back to `(period, offset)` when there are too few blocks.
fn fit(stamps: impl Iterator<Item = f64>, holes: &[Gap], period: f64, offset: f64) -> (f64, f64) {
    // The least-delayed (number, stamp) of each block of BLOCK rows (the first of equals);
    // past FIT_POINTS of them, neighbours merge and the blocks double (the least-delayed of a
    // block is that of its halves), so that what is kept does not grow with the recording.
    let delay = |p: (f64, f64)| p.1 - p.0 * period;
    let earlier_least = |a: (f64, f64), b: (f64, f64)| {
        if delay(b).total_cmp(&delay(a)).is_lt() {
            b
        } else {
            a
        }
    };
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut block = BLOCK;
    let mut best: Option<(f64, f64)> = None;
    for (i, (t, k)) in stamps.zip(Numbering::new(holes)).enumerate() {
        let p = (k as f64, t);
        best = Some(best.map_or(p, |b| earlier_least(b, p)));
        if i % block == block - 1 {
            points.extend(best.take());
            if points.len() == FIT_POINTS {
                points = points
                    .chunks(2)
                    .map(|c| c.iter().copied().reduce(earlier_least).unwrap_or(c[0]))
                    .collect();
                block *= 2;
            }
        }
    }
    points.extend(best);
    let m = points.len();
    let slope = if m >= 4 {
        let half = m / 2;
        let mut slopes: Vec<f64> = (0..m - half)
            .filter_map(|a| {
                let (p, q) = (points[a], points[a + half]);
                (q.0 > p.0).then(|| (q.1 - p.1) / (q.0 - p.0))
            })
            .collect();
        slopes.sort_by(f64::total_cmp);
        slopes.get(slopes.len() / 2).copied().unwrap_or(period)
    } else {
        period
    };
    // A slope far from where the fit started means too few samples to trust it.
    let slope = if slope > 0.5 * period && slope < 2.0 * period {
        slope
    } else {
        period
    };
    let mut offsets: Vec<f64> = points.iter().map(|&(k, t)| t - k * slope).collect();
    if offsets.is_empty() {
        return (period, offset);
    }
    offsets.sort_by(f64::total_cmp);
    let k = ((offsets.len() - 1) as f64 * OFFSET_QUANTILE).round() as usize;
    (slope, offsets[k])
}

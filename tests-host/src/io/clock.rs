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
//! 3. **Fit.** Each block of [`BLOCK`] rows contributes its least-delayed stamp `(n, t)`; the
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
    let mut last: Option<f64> = None;
    for (i, &t) in stamps.iter().enumerate() {
        match last {
            Some(prev) if t <= prev => {
                // NaN never gets here (the readers reject non-finite cells).
                if prev - t < 0.5 * period_s {
                    continue;
                }
                return Err(TimeGoesBack {
                    index: i,
                    t_s: t,
                    previous_s: prev,
                });
            }
            _ => {
                keep.push(i);
                last = Some(t);
            }
        }
    }
    Ok(keep)
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
    let n = stamps.len();
    if n < 2 {
        return None;
    }
    let mean = (stamps[n - 1] - stamps[0]) / (n - 1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return None;
    }
    // The last row of each delivery.
    let ends: Vec<usize> = (0..n)
        .filter(|&i| i + 1 == n || stamps[i + 1] - stamps[i] >= 0.1 * mean)
        .collect();
    // (advance, rows) between the ends of consecutive deliveries.
    let steps: Vec<(f64, usize)> = ends
        .windows(2)
        .map(|w| (stamps[w[1]] - stamps[w[0]], w[1] - w[0]))
        .filter(|(a, _)| a.is_finite() && *a > 0.0)
        .collect();
    if steps.is_empty() {
        return Some(mean);
    }
    let mut per_row: Vec<f64> = steps.iter().map(|(a, k)| a / *k as f64).collect();
    per_row.sort_by(f64::total_cmp);
    let median = per_row[per_row.len() / 2];
    // Stamps rounded to a tick (0.1 ms is common) make the per-row advances a tick apart
    // (4.8 and 4.9 ms at 204.8 Hz), and the median one of them: the mean over the deliveries
    // near the median (within a quarter: no hole, no late delivery) is the period itself.
    let (mut sum, mut rows) = (0.0, 0usize);
    for &(a, k) in &steps {
        if (a / k as f64 - median).abs() <= 0.25 * median {
            sum += a;
            rows += k;
        }
    }
    Some(if rows > 0 { sum / rows as f64 } else { median })
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
    /// Sample number of each row.
    numbers: Vec<u32>,
}

impl SampleClock {
    /// Recovers the clock of `stamps` (increasing), starting from `nominal_hz` when given;
    /// see the module comment. `None` for an empty recording.
    pub fn recover(stamps: &[f64], nominal_hz: Option<f64>) -> Option<SampleClock> {
        let n = stamps.len();
        if n == 0 {
            return None;
        }
        let nominal = match nominal_hz {
            Some(hz) if hz.is_finite() && hz > 0.0 => 1.0 / hz,
            _ => nominal_period(stamps).unwrap_or(1.0),
        };
        let mut period = refine_period(stamps, nominal);
        let mut offset = (0..n.min(BLOCK))
            .map(|j| stamps[j] - j as f64 * period)
            .fold(f64::INFINITY, f64::min);
        let mut holes = Vec::new();
        for round in 0..MAX_ROUNDS {
            let found = find_holes(stamps, period, offset);
            if round > 0 && found == holes {
                break;
            }
            holes = found;
            let numbers = numbering(n, &holes);
            (period, offset) = fit(stamps, &numbers, period, offset);
        }
        let numbers = numbering(n, &holes);
        let (mut retimed, mut max_off) = (0, 0.0f64);
        for (&t, &k) in stamps.iter().zip(&numbers) {
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
            numbers,
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
        let burst_gap = 0.25 * self.period_s;
        let n = stamps.len();
        let mut moved = false;
        for k in 0..self.holes.len() {
            let first = self.holes[k].before;
            let m = self.holes[k].missing as usize;
            let limit = self
                .holes
                .get(k + 1)
                .map_or(n, |g| g.before)
                .min(first + LOOK_AHEAD);
            // Bursts from `first` on; the range ends with the first burst whose last row is
            // on time under the numbering after the hole.
            let lag = |row: usize| (stamps[row] - self.t_s(self.numbers[row])) / self.period_s;
            let mut last = first;
            loop {
                while last + 1 < limit && stamps[last + 1] - stamps[last] < burst_gap {
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
            let (lo, hi) = (first.saturating_sub(2), (last + 2).min(n - 1));
            let roughness = |h: usize| -> f64 {
                let mut seq: Vec<[f64; 3]> = Vec::with_capacity(hi - lo + 1 + m);
                for row in lo..=hi {
                    if row == h && row > lo {
                        let (a, b) = (rate(row - 1), rate(row));
                        for j in 1..=m {
                            let f = j as f64 / (m + 1) as f64;
                            seq.push([0, 1, 2].map(|i| a[i] + f * (b[i] - a[i])));
                        }
                    }
                    seq.push(rate(row));
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
                self.holes[k].before = best;
                moved = true;
            }
        }
        if moved {
            self.numbers = numbering(self.numbers.len(), &self.holes);
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
        match self.numbers.get(row) {
            Some(&k) => k,
            None => {
                let last = self.numbers.len() - 1;
                let extra = (row - last).min(u32::MAX as usize) as u32;
                self.numbers[last].saturating_add(extra)
            }
        }
    }

    /// The row of sample number `n`, or of the first row after it if it was lost (rows past
    /// the end go on at one per period).
    pub fn row_of_number(&self, n: u32) -> u32 {
        let row = self.numbers.partition_point(|&k| k < n);
        if row < self.numbers.len() {
            return row as u32;
        }
        let last = self.numbers.len() - 1;
        let extra = n.saturating_sub(self.numbers[last]) as usize;
        (last + extra).min(u32::MAX as usize) as u32
    }
}

/// The sample number of each of `n` rows with `holes`.
fn numbering(n: usize, holes: &[Gap]) -> Vec<u32> {
    let mut out = Vec::with_capacity(n);
    let mut lost = 0u64;
    let mut next = holes.iter().peekable();
    for row in 0..n {
        while let Some(g) = next.next_if(|g| g.before <= row) {
            lost += g.missing as u64;
        }
        out.push((row as u64 + lost).min(u32::MAX as u64) as u32);
    }
    out
}

/// Step 1½: the period corrected for a clock that drifts against the stamps, before any
/// hole is known (a hole finder on the wrong period takes the drift for lost samples).
/// Between consecutive blocks of `B` rows, the least-delayed stamps differ by `B` periods
/// plus whole periods lost in holes: the difference's fractional part, in periods, is the
/// drift over `B` rows. Its mean over the blocks, taken on the circle (a fractional part
/// near ±½ wraps), corrects the period; blocks of 16 rows first (a period off by up to
/// 3 %), then longer ones refine it (noise shrinks as the drift over a block grows).
fn refine_period(stamps: &[f64], nominal: f64) -> f64 {
    let mut period = nominal;
    for b in [16usize, 64, 256, 1024] {
        let minima: Vec<f64> = stamps
            .chunks_exact(b)
            .enumerate()
            .map(|(k, c)| {
                c.iter()
                    .enumerate()
                    .map(|(j, &t)| t - (k * b + j) as f64 * period)
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        if minima.len() < 8 {
            break;
        }
        // The fractional parts as angles, averaged on the circle: a drift near half a period
        // per block wraps around without pulling the mean.
        let (mut sin, mut cos) = (0.0, 0.0);
        for w in minima.windows(2) {
            let phase = (w[1] - w[0]) / period * std::f64::consts::TAU;
            sin += phase.sin();
            cos += phase.cos();
        }
        let frac = sin.atan2(cos) / std::f64::consts::TAU;
        period += frac * period / b as f64;
    }
    period
}

/// Step 2 of the module comment: the holes of `stamps` against the clock `(period, offset)`.
fn find_holes(stamps: &[f64], period: f64, offset: f64) -> Vec<Gap> {
    let n = stamps.len();
    // u_j = t_j − offset − j·P: a row's lag behind the clock before any hole is counted.
    let u: Vec<f64> = (0..n)
        .map(|j| stamps[j] - offset - j as f64 * period)
        .collect();
    // Minimum of u over [i, i + LOOK_AHEAD), by a monotone deque from the right.
    let mut ahead_min = vec![0.0; n];
    let mut deque: std::collections::VecDeque<usize> = std::collections::VecDeque::new();
    for i in (0..n).rev() {
        while deque.back().is_some_and(|&j| u[j] >= u[i]) {
            deque.pop_back();
        }
        deque.push_back(i);
        while deque.front().is_some_and(|&j| j >= i + LOOK_AHEAD) {
            deque.pop_front();
        }
        ahead_min[i] = u[deque[0]];
    }
    let mut holes: Vec<Gap> = Vec::new();
    let mut lost = 0u64;
    // Whether a row since the last hole was on time: if none was, a hole found now is the
    // rest of that one (a stalled delivery before it hid part of it), not a new hole.
    let mut on_time_since = true;
    for (i, &m) in ahead_min.iter().enumerate().skip(1) {
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
        let lag = (u[i] - lost as f64 * period) / period;
        on_time_since |= lag < 1.0 - EARLY_ALLOWANCE;
    }
    holes
}

/// Step 3 of the module comment: period and offset from the least-delayed stamp of each
/// block. Falls back to `(period, offset)` when there are too few blocks.
fn fit(stamps: &[f64], numbers: &[u32], period: f64, offset: f64) -> (f64, f64) {
    let points: Vec<(f64, f64)> = stamps
        .chunks(BLOCK)
        .zip(numbers.chunks(BLOCK))
        .filter_map(|(t, k)| {
            t.iter()
                .zip(k)
                .map(|(&t, &k)| (k as f64, t))
                .min_by(|a, b| (a.1 - a.0 * period).total_cmp(&(b.1 - b.0 * period)))
        })
        .collect();
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

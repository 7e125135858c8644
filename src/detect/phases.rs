//! Phase splitter after Huang et al. 2022, §2.3.2: where the push-off ends (toe-off) and
//! where the heel strikes, inside one movement between two stances.
//!
//! Input: the movement (heel-off to foot-flat) as foot-frame vertical (gravity removed) and
//! sagittal acceleration, mean-filtered, in g/2048.
//!
//! 1. **Peaks and valleys** of both signals: local maxima above [`MIN_EXTREME_MG`] and local
//!    minima below its negative (smaller wiggles are sensor noise); a flat top counts once,
//!    at its middle.
//! 2. **Two clusters** (Algorithm 1): 1-D k-means, k = 2, on the sample positions of all
//!    extremes, centres started at the movement's first and last sample, at most 50
//!    iterations. The left cluster holds the push-off's force changes, the right one the
//!    heel-strike's.
//! 3. **Major peak-valley pair** per cluster and signal: each peak is paired with the
//!    nearest valley before it ("found backward", as the paper says; searching both ways
//!    put the heel-strike 10 ms nearer on `gaitmap_walk` but 10 ms further on
//!    `ipol_gait_events`, and swing IoU fell from 0.844 to 0.822 overall); (1) a zero crossing lies between them
//!    (always, since peaks are positive and valleys negative), (2) the major pair has the
//!    largest peak-to-valley magnitude, (3) a pair whose magnitude exceeds half the major's
//!    and whose peak lies within [`MERGE_MS`] of the major valley is merged into it (the
//!    merged pair keeps the higher peak and the lower valley).
//! 4. **Boundaries.** Toe-off = mean of the sagittal major peak and the vertical major
//!    valley in the left cluster; heel-strike = mean of the sagittal and vertical major peaks
//!    in the right cluster.
//! 5. **Augmented** ([`PhaseMethod::Augmented`]): two more references per boundary, the zero
//!    crossings of the derivatives nearest each major pair (downward crossings, i.e. peaks,
//!    except the vertical push-off reference, an upward crossing); each reference more than
//!    3σ from the mean of the others (leave-one-out) is dropped and the rest averaged.
//!
//! Integer throughout: positions are sample offsets, the k-means centres are kept ×16, the
//! outlier test is done on squared integers without a root.

use heapless::Vec;

/// Extremes smaller than this (mg) are ignored.
pub const MIN_EXTREME_MG: i32 = 100;
/// Condition (3): a second pair's peak within this many ms of the major valley merges
/// (5 samples at Huang's 100 Hz).
pub const MERGE_MS: u32 = 50;
/// At most this many extremes per movement are considered (vertical first, then sagittal);
/// later ones are ignored.
pub const MAX_EXTREMES: usize = 256;
/// Iteration cap of the k-means (Algorithm 1).
pub const KMEANS_MAX_ITERATIONS: u32 = 50;

/// Which version of Huang's splitter to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhaseMethod {
    /// Major peak-valley pairs of the two signals, two references per boundary.
    MajorPairs,
    /// Plus derivative zero crossings and leave-one-out 3σ rejection, four references.
    Augmented,
}

/// The two inner boundaries of a movement, as offsets from its first sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhaseSplit {
    /// Push-off/swing boundary.
    pub toe_off: u32,
    /// Swing/heel-strike boundary.
    pub heel_strike: u32,
    /// Both boundaries came from major pairs; `false` means they are cluster centres.
    pub found: bool,
}

#[derive(Clone, Copy, Debug)]
struct Extreme {
    /// Sample in the movement (movements are capped below 2¹⁶ samples in [`split`]).
    at: u16,
    /// g/2048, as in the movement.
    value: i16,
    axis: u8,
    peak: bool,
}

#[derive(Clone, Copy, Debug)]
struct Pair {
    peak: Extreme,
    valley: Extreme,
}

impl Pair {
    fn magnitude(&self) -> i32 {
        self.peak.value as i32 - self.valley.value as i32
    }

    /// Centre ×2, for the nearest-crossing search.
    fn centre_x2(&self) -> u32 {
        self.peak.at as u32 + self.valley.at as u32
    }
}

/// Axis numbers in the input pairs.
const VERTICAL: u8 = 0;
const SAGITTAL: u8 = 1;

/// Splits one movement. `movement[i] = [vertical, sagittal, …]` (g/2048; columns after
/// the second are ignored); `merge_samples` is
/// [`MERGE_MS`] at the sample rate. Never panics; a movement of fewer than 3 samples or
/// without extremes gives its quarter and three-quarter points with `found = false`.
#[inline(never)] // see StrideStats::measure
pub fn split<const N: usize>(
    movement: &[[i16; N]],
    method: PhaseMethod,
    merge_samples: u32,
) -> PhaseSplit {
    const { assert!(N >= 2, "a movement has vertical and sagittal columns") };
    // Sample numbers of extremes are kept in 16 bits (6-byte extremes keep the list at
    // 1.5 KiB, which small boards need); no movement buffer comes near 2¹⁶ samples.
    let movement = &movement[..movement.len().min(u16::MAX as usize)];
    let len = movement.len() as u32;
    let fallback = PhaseSplit {
        toe_off: len / 4,
        heel_strike: (3 * len / 4).min(len.saturating_sub(1)),
        found: false,
    };
    if len < 3 {
        return fallback;
    }
    // Filled in place: returned by value it was copied, twice the 1.5 KiB on the stack.
    let mut extremes = Vec::new();
    find_extremes(movement, &mut extremes);
    if extremes.is_empty() {
        return fallback;
    }
    let (c_left, c_right) = kmeans(&extremes, len);
    let in_left =
        |e: &Extreme| (e.at as u32 * 16).abs_diff(c_left) < (e.at as u32 * 16).abs_diff(c_right);
    let major = |axis: u8, left: bool| {
        major_pair(
            extremes
                .iter()
                .filter(|e| e.axis == axis && in_left(e) == left),
            merge_samples,
        )
    };
    let (sag_l, vert_l) = (major(SAGITTAL, true), major(VERTICAL, true));
    let (sag_r, vert_r) = (major(SAGITTAL, false), major(VERTICAL, false));

    let mut to_refs: Vec<u32, 4> = Vec::new();
    let mut hs_refs: Vec<u32, 4> = Vec::new();
    if let Some(p) = sag_l {
        let _ = to_refs.push(p.peak.at as u32);
    }
    if let Some(p) = vert_l {
        let _ = to_refs.push(p.valley.at as u32);
    }
    if let Some(p) = sag_r {
        let _ = hs_refs.push(p.peak.at as u32);
    }
    if let Some(p) = vert_r {
        let _ = hs_refs.push(p.peak.at as u32);
    }
    if method == PhaseMethod::Augmented {
        let crossing = |pair: Option<Pair>, axis: u8, downward: bool| {
            pair.and_then(|p| nearest_derivative_crossing(movement, axis, downward, p))
        };
        for r in [
            crossing(sag_l, SAGITTAL, true),
            crossing(vert_l, VERTICAL, false),
        ]
        .into_iter()
        .flatten()
        {
            let _ = to_refs.push(r);
        }
        for r in [
            crossing(sag_r, SAGITTAL, true),
            crossing(vert_r, VERTICAL, true),
        ]
        .into_iter()
        .flatten()
        {
            let _ = hs_refs.push(r);
        }
    }
    let to = fuse(&to_refs);
    let hs = fuse(&hs_refs);
    match (to, hs) {
        (Some(to), Some(hs)) if to < hs && hs < len => PhaseSplit {
            toe_off: to,
            heel_strike: hs,
            found: true,
        },
        _ => PhaseSplit {
            toe_off: (c_left / 16).min(len - 1),
            heel_strike: (c_right / 16).min(len - 1),
            found: false,
        },
    }
}

fn find_extremes<const N: usize>(movement: &[[i16; N]], out: &mut Vec<Extreme, MAX_EXTREMES>) {
    let min = MIN_EXTREME_MG * crate::sensor::units::FOOT_LSB_PER_G / 1000;
    let len = movement.len();
    for axis in [VERTICAL, SAGITTAL] {
        let a = axis as usize;
        let x = |i: usize| movement[i][a] as i32;
        let mut i = 1;
        while i + 1 < len {
            // A plateau of equal values counts once, at its middle (integer signals of slow
            // peaks are flat for several samples).
            let mut j = i;
            while j + 1 < len && x(j + 1) == x(i) {
                j += 1;
            }
            if j + 1 >= len {
                break;
            }
            let (prev, v, next) = (x(i - 1), x(i), x(j + 1));
            let peak = v > prev && v > next && v > min;
            let valley = v < prev && v < next && v < -min;
            if (peak || valley)
                && out
                    .push(Extreme {
                        at: ((i + j) / 2) as u16,
                        value: v as i16,
                        axis,
                        peak,
                    })
                    .is_err()
            {
                break;
            }
            i = j + 1;
        }
    }
}

/// Algorithm 1: returns the left and right centres, ×16.
fn kmeans(extremes: &[Extreme], len: u32) -> (u32, u32) {
    let mut c = [0u32, (len - 1) * 16];
    for _ in 0..KMEANS_MAX_ITERATIONS {
        let mut sum = [0u64; 2];
        let mut count = [0u64; 2];
        for e in extremes {
            let x = e.at as u32 * 16;
            let k = if x.abs_diff(c[0]) < x.abs_diff(c[1]) {
                0
            } else {
                1
            };
            sum[k] += x as u64;
            count[k] += 1;
        }
        let mut next = c;
        for k in 0..2 {
            if let Some(mean) = (sum[k] + count[k] / 2).checked_div(count[k]) {
                next[k] = mean as u32;
            }
        }
        if next == c {
            break;
        }
        c = next;
    }
    (c[0], c[1])
}

/// `extremes` are one axis's, in order ([`find_extremes`] gives them so): each peak pairs with
/// the valley nearest before it, which is the last valley seen, so one pass pairs them all
/// (a search of every valley per peak was half the phase split: M4 62 672 → 31 516
/// instructions per stride, docs/cost.md).
fn major_pair<'a>(extremes: impl Iterator<Item = &'a Extreme> + Clone, merge: u32) -> Option<Pair> {
    let pairs = extremes.scan(None::<Extreme>, |last_valley, e| {
        Some(if e.peak {
            last_valley.map(|v| Pair {
                peak: *e,
                valley: v,
            })
        } else {
            *last_valley = Some(*e);
            None
        })
    });
    let pairs = pairs.flatten();
    let mut major: Option<Pair> = None;
    for pair in pairs.clone() {
        if major.is_none_or(|m| pair.magnitude() > m.magnitude()) {
            major = Some(pair);
        }
    }
    let mut major = major?;
    let first = major;
    for pair in pairs {
        let close = pair.peak.at.abs_diff(first.valley.at) as u32 <= merge;
        let distinct = pair.peak.at != first.peak.at;
        if distinct && close && 2 * pair.magnitude() > first.magnitude() {
            if pair.peak.value > major.peak.value {
                major.peak = pair.peak;
            }
            if pair.valley.value < major.valley.value {
                major.valley = pair.valley;
            }
        }
    }
    Some(major)
}

/// The sample where the derivative of `axis` crosses zero downward (a peak) or upward
/// (a valley), nearest the centre of `pair`. The derivative is the central difference.
fn nearest_derivative_crossing<const N: usize>(
    movement: &[[i16; N]],
    axis: u8,
    downward: bool,
    pair: Pair,
) -> Option<u32> {
    let a = axis as usize;
    let d = |i: usize| movement[i + 1][a] as i32 - movement[i - 1][a] as i32;
    let centre_x2 = pair.centre_x2();
    let mut best: Option<u32> = None;
    for i in 2..movement.len().saturating_sub(1) {
        let (before, now) = (d(i - 1), d(i));
        let crossed = if downward {
            before > 0 && now <= 0
        } else {
            before < 0 && now >= 0
        };
        if crossed {
            let at = i as u32;
            if best.is_none_or(|b| (2 * at).abs_diff(centre_x2) < (2 * b).abs_diff(centre_x2)) {
                best = Some(at);
            }
        }
    }
    best
}

/// Leave-one-out 3σ rejection (with three or more references), then the mean, rounded.
fn fuse(refs: &[u32]) -> Option<u32> {
    if refs.is_empty() {
        return None;
    }
    let mut kept_sum = 0u64;
    let mut kept = 0u64;
    for (i, &r) in refs.iter().enumerate() {
        let others = refs.len() as i64 - 1;
        let outlier = others >= 2 && {
            let (mut s, mut q) = (0i64, 0i64);
            for (j, &o) in refs.iter().enumerate() {
                if j != i {
                    s += o as i64;
                    q += o as i64 * o as i64;
                }
            }
            // (r − mean)² > 9σ² ⇔ (m·r − s)² > 9·(m·q − s²) for m others (population σ).
            let dev = others * r as i64 - s;
            dev * dev > 9 * (others * q - s * s)
        };
        if !outlier {
            kept_sum += r as u64;
            kept += 1;
        }
    }
    if kept == 0 {
        return None;
    }
    Some(((kept_sum + kept / 2) / kept) as u32)
}

#[cfg(test)]
mod tests {
    //! The splitter's rules on hand-made movements (g/2048; extremes need 100 mg = 204).
    use super::*;

    const MERGE: u32 = 10;

    /// A movement of 100 samples, zero but for triangular bumps `(axis, at, height)`, five
    /// samples wide, their extreme at `at`.
    fn movement(bumps: &[(usize, usize, i16)]) -> [[i16; 2]; 100] {
        let mut m = [[0i16; 2]; 100];
        for &(axis, at, h) in bumps {
            for (k, w) in [(0usize, 1i16), (1, 2), (2, 3), (3, 2), (4, 1)] {
                m[at + k - 2][axis] += h / 3 * w;
            }
        }
        m
    }

    fn extreme(at: u16, value: i16, peak: bool) -> Extreme {
        Extreme {
            at,
            value,
            axis: VERTICAL,
            peak,
        }
    }

    #[test]
    fn extremes_are_above_the_noise_floor_and_a_plateau_counts_once() {
        let mut m = [[0i16; 2]; 20];
        // A flat top of 1000 over samples 4..=6, a 150 (< 204) bump, a valley at 14.
        for (i, v) in [
            (3, 500),
            (4, 1000),
            (5, 1000),
            (6, 1000),
            (7, 500),
            (10, 150),
            (14, -900),
        ] {
            m[i][0] = v;
        }
        let mut found = Vec::new();
        find_extremes(&m, &mut found);
        let got: [(u16, bool); 2] = [(found[0].at, found[0].peak), (found[1].at, found[1].peak)];
        assert_eq!(found.len(), 2);
        assert_eq!(got, [(5, true), (14, false)]);
    }

    #[test]
    fn a_peak_pairs_with_the_nearest_valley_before_it() {
        // Valleys at 10 and 30, peak at 25, valley after it at 27 (nearer, but after).
        let e = [
            extreme(10, -500, false),
            extreme(25, 800, true),
            extreme(27, -900, false),
            extreme(30, -600, false),
        ];
        let p = major_pair(e.iter(), MERGE).unwrap();
        assert_eq!((p.peak.at, p.valley.at), (25, 10));
        // No valley before any peak: no pair.
        assert!(major_pair(
            [extreme(5, 800, true), extreme(9, -800, false)].iter(),
            MERGE
        )
        .is_none());
    }

    /// The pairing by one pass is the definition's (every peak's nearest valley before it,
    /// searched among all of them) on 5 000 lists of extremes in order, as
    /// `find_extremes` gives them.
    #[test]
    fn one_pass_pairs_as_the_search_of_every_valley_does() {
        fn searched(e: &[Extreme], merge: u32) -> Option<Pair> {
            let pairs = e.iter().filter(|e| e.peak).filter_map(|p| {
                e.iter()
                    .filter(|v| !v.peak && v.at < p.at)
                    .min_by_key(|v| v.at.abs_diff(p.at))
                    .map(|v| Pair {
                        peak: *p,
                        valley: *v,
                    })
            });
            let first = pairs.clone().fold(None::<Pair>, |m, p| match m {
                Some(m) if p.magnitude() <= m.magnitude() => Some(m),
                _ => Some(p),
            })?;
            let mut major = first;
            for pair in pairs {
                let close = pair.peak.at.abs_diff(first.valley.at) as u32 <= merge;
                if pair.peak.at != first.peak.at
                    && close
                    && 2 * pair.magnitude() > first.magnitude()
                {
                    if pair.peak.value > major.peak.value {
                        major.peak = pair.peak;
                    }
                    if pair.valley.value < major.valley.value {
                        major.valley = pair.valley;
                    }
                }
            }
            Some(major)
        }
        let mut seed = 0x9e37_79b9_u32;
        let mut next = move |n: u32| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) % n
        };
        let key =
            |p: Option<Pair>| p.map(|p| (p.peak.at, p.peak.value, p.valley.at, p.valley.value));
        for _ in 0..5000 {
            let mut e: heapless::Vec<Extreme, 40> = heapless::Vec::new();
            let mut at = 0u16;
            for _ in 0..next(40) {
                at += 1 + next(12) as u16;
                let peak = next(2) == 0;
                let size = 200 + next(3000) as i16;
                let _ = e.push(extreme(at, if peak { size } else { -size }, peak));
            }
            assert_eq!(
                key(major_pair(e.iter(), MERGE)),
                key(searched(&e, MERGE)),
                "{e:?}"
            );
        }
    }

    #[test]
    fn the_largest_pair_is_major_and_a_close_strong_one_merges_into_it() {
        // Major: valley 10 (−1000), peak 20 (1000). Second: valley 15 (−700) … peak 18
        // (900)? No: its nearest valley before 18 is 15. Its peak is within MERGE of the
        // major valley and its magnitude (1600) over half the major's (2000): merged, the
        // major keeping its own higher peak and lower valley.
        let e = [
            extreme(10, -1000, false),
            extreme(15, -700, false),
            extreme(18, 900, true),
            extreme(30, -200, false),
            extreme(40, 1100, true),
        ];
        // Pairs: (18, 15) magnitude 1600, (40, 30) magnitude 1300: (18, 15) is major.
        let p = major_pair(e.iter(), MERGE).unwrap();
        assert_eq!((p.peak.at, p.valley.at), (18, 15));
        // A pair whose peak is within MERGE of the major valley and more than half as large
        // lends its higher peak and lower valley.
        let e = [
            extreme(10, -1000, false),
            extreme(14, 1000, true),
            extreme(16, -1200, false),
            extreme(20, 1200, true),
        ];
        // (14, 10): 2000; (20, 16): 2400 is major; (14, 10)'s peak is 2 from valley 16 and
        // 2000 > 1200: merged, keeping the higher peak (1200 at 20) and the lower valley
        // (−1200 at 16).
        let p = major_pair(e.iter(), MERGE).unwrap();
        assert_eq!((p.peak.at, p.valley.at), (20, 16));
        // A weak close pair (under half) does not merge; neither does a far one.
        let e = [
            extreme(10, -2000, false),
            extreme(12, 2000, true),
            extreme(30, -300, false),
            extreme(33, 300, true),
        ];
        let p = major_pair(e.iter(), MERGE).unwrap();
        assert_eq!((p.peak.at, p.valley.at, p.peak.value), (12, 10, 2000));
    }

    #[test]
    fn fuse_drops_a_reference_far_from_the_others() {
        assert_eq!(fuse(&[]), None);
        assert_eq!(
            fuse(&[10, 13]),
            Some(12),
            "two references: their mean, rounded"
        );
        assert_eq!(
            fuse(&[20, 21, 19, 60]),
            Some(20),
            "60 is > 3σ from the others"
        );
        assert_eq!(fuse(&[20, 24, 28]), Some(24), "nothing is an outlier");
    }

    #[test]
    fn short_or_flat_movements_fall_back_to_the_quarter_points() {
        let flat = [[0i16; 2]; 40];
        let s = split(&flat, PhaseMethod::Augmented, MERGE);
        assert_eq!((s.toe_off, s.heel_strike, s.found), (10, 30, false));
        let s = split(&flat[..2], PhaseMethod::MajorPairs, MERGE);
        assert!(!s.found && s.toe_off <= s.heel_strike);
        let s = split::<2>(&[], PhaseMethod::MajorPairs, MERGE);
        assert_eq!((s.toe_off, s.heel_strike, s.found), (0, 0, false));
    }

    #[test]
    fn push_off_and_heel_strike_come_from_the_two_clusters() {
        // Push-off (left): sagittal valley 10 → peak 20, vertical valley 20 → peak 30.
        // Heel-strike (right): sagittal valley 70 → peak 80, vertical valley 72 → peak 80.
        let m = movement(&[
            (SAGITTAL as usize, 10, -900),
            (SAGITTAL as usize, 20, 900),
            (VERTICAL as usize, 20, -900),
            (VERTICAL as usize, 30, 900),
            (SAGITTAL as usize, 70, -900),
            (SAGITTAL as usize, 80, 900),
            (VERTICAL as usize, 72, -900),
            (VERTICAL as usize, 80, 900),
        ]);
        let s = split(&m, PhaseMethod::MajorPairs, MERGE);
        // Toe-off: mean of the sagittal peak (20) and the vertical valley (20); heel-strike:
        // of the two peaks (80, 80).
        assert_eq!((s.toe_off, s.heel_strike, s.found), (20, 80, true));
        // The augmented splitter adds the derivatives' zero crossings near each pair; on
        // these bumps they stay within two samples of the pairs' answer.
        let a = split(&m, PhaseMethod::Augmented, MERGE);
        assert!(a.found);
        assert!(
            a.toe_off.abs_diff(20) <= 2 && a.heel_strike.abs_diff(80) <= 2,
            "{a:?}"
        );
    }
}

//! Lu et al. 2020's fuzzy-logic Weinberg coefficient, in Q16 fixed point.
//!
//! Inputs: the step frequency `f` and the peak-to-valley difference `D` of vertical
//! acceleration. Each is mapped linearly from its universe onto seven levels
//! `−3 … 3` (NB, NM, NS, ZE, PS, PM, PB) with unit-spaced triangular memberships; the
//! Mamdani rule base of the paper's Table 2 (min for AND and implication, max for
//! aggregation) gives a fuzzy output on the same seven levels, and its centre of gravity,
//! mapped onto `[K_MIN, K_MAX] = [0.55, 1.0]`, is `k` in `SL = k·(a_max − a_min)^¼`.
//!
//! Table 2 is printed with `f` and `D` in its corner; its rows are `D` and its columns `f`:
//! that is the reading in which, as the paper's text says, `k` falls as `f` rises at a fixed
//! `D` and rises with `D` at a fixed `f`.
//!
//! The centre of gravity is taken over the output universe sampled every 1/32 level (193
//! points), integer sums throughout. Error against the continuous centre of gravity: at
//! most 0.002 in `k` (asserted by the host test against an f64 reference with 10⁴ samples
//! per level; measured 0.0015).

use crate::fixed::Q16_ONE;

/// Lower end of the output universe, Q16 (0.55).
pub const K_MIN_Q16: i64 = 36_045;
/// Upper end of the output universe, Q16 (1.0).
pub const K_MAX_Q16: i64 = Q16_ONE;
/// The paper's step-frequency universe, Hz, Q16: [1, 2.8].
pub const F_UNIVERSE_Q16: (i64, i64) = (Q16_ONE, 183_501);
/// The paper's peak-to-valley universe for hand-held user acceleration, g, Q16: [0.12, 0.9].
pub const D_UNIVERSE_Q16: (i64, i64) = (7_864, 58_982);

/// Output level per rule: `RULES[d][f]`, levels −3 (NB) … 3 (PB), Table 2.
pub const RULES: [[i8; 7]; 7] = [
    [-1, -1, -1, -2, -3, -3, -3],
    [1, 1, 1, 0, 0, -1, -2],
    [2, 2, 1, 1, 0, 0, -1],
    [3, 2, 1, 1, 1, 0, 0],
    [3, 2, 1, 1, 1, 0, 0],
    [3, 2, 1, 1, 1, 1, 1],
    [3, 2, 2, 1, 1, 1, 1],
];

/// Output-universe samples per level of the centre-of-gravity sum.
pub const STEPS_PER_LEVEL: i64 = 32;

/// Position of `v` on the level axis, Q16 in [−3, 3], for the universe `(lo, hi)`.
fn level_q16(v: i64, (lo, hi): (i64, i64)) -> i64 {
    if hi <= lo {
        return 0;
    }
    let v = v.clamp(lo, hi);
    ((v - lo) as i128 * 6 * Q16_ONE as i128 / (hi - lo) as i128) as i64 - 3 * Q16_ONE
}

/// Membership, Q16, of a level-axis position `x` (Q16) in the triangle centred on `level`.
fn membership_q16(x: i64, level: i64) -> i64 {
    (Q16_ONE - (x - level * Q16_ONE).abs()).max(0)
}

/// Lu's `k`, Q16 in [0.55, 1.0], for step frequency `f_q16` (Hz) in universe `f_universe`
/// and peak-to-valley difference `d_q16` in `d_universe` (both Q16, same unit as the
/// value). Inputs outside a universe are clamped to it.
pub fn lu_k_q16(f_q16: i64, f_universe: (i64, i64), d_q16: i64, d_universe: (i64, i64)) -> i64 {
    let xf = level_q16(f_q16, f_universe);
    let xd = level_q16(d_q16, d_universe);
    // At most two levels per input have a non-zero membership: at most four rules fire.
    let mut fired: [(i64, i64); 4] = [(0, 0); 4];
    let mut count = 0;
    for (di, row) in RULES.iter().enumerate() {
        let md = membership_q16(xd, di as i64 - 3);
        if md == 0 {
            continue;
        }
        for (fi, &out) in row.iter().enumerate() {
            let mf = membership_q16(xf, fi as i64 - 3);
            if mf == 0 || count == fired.len() {
                continue;
            }
            fired[count] = (md.min(mf), out as i64);
            count += 1;
        }
    }
    let (mut num, mut den) = (0i64, 0i64);
    for step in -3 * STEPS_PER_LEVEL..=3 * STEPS_PER_LEVEL {
        let y = step * Q16_ONE / STEPS_PER_LEVEL;
        let mu = fired[..count]
            .iter()
            .map(|&(w, level)| w.min(membership_q16(y, level)))
            .max()
            .unwrap_or(0);
        num += mu * step;
        den += mu;
    }
    // Centre of gravity in level units (Q16), then onto [K_MIN, K_MAX].
    let c = if den == 0 {
        0
    } else {
        num * Q16_ONE / (den * STEPS_PER_LEVEL)
    };
    K_MIN_Q16 + (c + 3 * Q16_ONE) * (K_MAX_Q16 - K_MIN_Q16) / (6 * Q16_ONE)
}

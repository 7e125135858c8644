//! Samples for a hole: what the pipeline feeds in place of the samples a lost packet or a
//! FIFO overflow took ([`crate::pipeline::Pipeline::gap`]).
//!
//! A short hole in a walk is bridged by the cubic through the two samples either side of it:
//! the foot's angular rate and acceleration are smooth over a few sample periods between
//! impacts, and a cubic follows the curvature that a straight line cuts off (over 30 ms of a
//! swing at 10 rad/s and 2.5 Hz, a straight line misses the rate by ≈ 0.3 rad/s in the
//! middle, a cubic by ≈ 0.001 rad/s). Longer holes, which are filled only so that detection
//! and the events outside them go on, use the straight line, which cannot overshoot.

use crate::sensor::sample::RawSample;

/// Sample `k` of the `n` periods from `a` (k = 0) to `b` (k = n), each axis on the straight
/// line between them, rounded to the nearest count (halves up): within ½ count of the exact
/// value (`tests/fixed_point.rs`). Range: `0 ≤ k ≤ n`, `1 ≤ n ≤ 2¹⁴` (larger `n` and `k`
/// are clamped to it), where `|a·(n − k) + b·k| < 2¹⁵·n` fits an `i32`.
pub fn linear(a: &RawSample, b: &RawSample, k: u32, n: u32) -> RawSample {
    let n = n.clamp(1, 1 << 14) as i32;
    let k = (k as i32).min(n);
    let at = |x: i16, y: i16| -> i16 {
        let v = x as i32 * (n - k) + y as i32 * k;
        (2 * v + n).div_euclid(2 * n) as i16
    };
    let axes = |x: [i16; 3], y: [i16; 3]| [at(x[0], y[0]), at(x[1], y[1]), at(x[2], y[2])];
    RawSample {
        accel: axes(a.accel, b.accel),
        gyro: axes(a.gyro, b.gyro),
        temp: at(a.temp, b.temp),
    }
}

/// Sample `k` (1..=m) of a hole of `m` samples on the cubic through the four samples `p`:
/// two before the hole (at −1 and 0) and two after it (at m + 1 and m + 2), each axis
/// separately (Lagrange form), rounded to the nearest count and saturated to `i16`: within
/// ½ count of the exact cubic wherever it lies inside the `i16` range, and a cubic in time
/// comes back to the count (`tests/fixed_point.rs`). Range: `m ≤ 1 000`, `k ≤ m` (larger
/// values are clamped to it); the weights, over the common denominator
/// `(m + 1)(m + 2)(m + 3)`, are then below `(m + 3)⁴` in magnitude, so with samples below
/// 2¹⁵ every product and sum fits an `i64`.
pub fn cubic(p: &[RawSample; 4], k: u32, m: u32) -> RawSample {
    let m = m.min(1000) as i64;
    let k = (k as i64).min(m);
    // Numerators of the four Lagrange weights at x = k over their node products, scaled to
    // the common denominator D = (m + 1)(m + 2)(m + 3).
    let d = (m + 1) * (m + 2) * (m + 3);
    let w = [
        -(m + 1) * k * (k - m - 1) * (k - m - 2),
        (m + 3) * (k + 1) * (k - m - 1) * (k - m - 2),
        -(m + 3) * (k + 1) * k * (k - m - 2),
        (m + 1) * (k + 1) * k * (k - m - 1),
    ];
    let at = |v: [i16; 4]| -> i16 {
        let sum: i64 = v.iter().zip(&w).map(|(&x, &w)| x as i64 * w).sum();
        (2 * sum + d)
            .div_euclid(2 * d)
            .clamp(i16::MIN as i64, i16::MAX as i64) as i16
    };
    let axis = |f: &dyn Fn(&RawSample) -> i16| at([f(&p[0]), f(&p[1]), f(&p[2]), f(&p[3])]);
    RawSample {
        accel: [0, 1, 2].map(|i| axis(&|s: &RawSample| s.accel[i])),
        gyro: [0, 1, 2].map(|i| axis(&|s: &RawSample| s.gyro[i])),
        temp: axis(&|s: &RawSample| s.temp),
    }
}

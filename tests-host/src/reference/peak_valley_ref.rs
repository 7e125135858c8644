//! An `f64` reference of Lu's peak-valley detection, written as the paper writes it: each
//! rule applied in turn to the whole list of extremes the rule before it left, in g.
//!
//! Shared with the core are only the definitions: the thresholds (converted to g here), the
//! look-ahead limits in ms and the samples they round to, the filter's `α` and delay. The
//! filtering, the comparisons and the means are done here in `f64` on the physical values.
//! The core streams the same rules ([`gaitclip::detect::peak_valley`]); a test checks both find the
//! same steps.

use gaitclip::detect::peak_valley::{
    C_DEN, C_NUM, DYNAMIC_LOOKAHEAD_MS, DYNAMIC_WINDOW, MIN_INTERVAL_MS, NEIGHBOUR_PEAK_G,
    NEIGHBOUR_VALLEY_G, STATIC_G, STATIC_WINDOW, TH1_G, TH2_G, WALK_GAP_MS,
};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::signal::low_pass::{alpha_q16, LowPass, LOW_PASS_LSB_PER_G};

/// An extreme: sample number, value in g, peak or not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extreme {
    /// Sample number.
    pub index: u32,
    /// g.
    pub value: f64,
    /// Peak (else valley).
    pub peak: bool,
}

/// A step: peak, valley, samples since the walk's previous step's peak (0 for the first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// The peak (sample number with the filter delay taken off).
    pub peak: Extreme,
    /// The valley after it.
    pub valley: Extreme,
    /// Samples from the previous step's peak, 0 for a walk's first step.
    pub period: u32,
}

fn g(units: i32) -> f64 {
    units as f64 / LOW_PASS_LSB_PER_G as f64
}

/// The cascade of two backward-Euler one-pole sections, in g, on inputs in g.
pub fn low_pass(rate: SampleRate, x: &[f64]) -> Vec<f64> {
    let a = alpha_q16(rate) as f64 / 65_536.0;
    let settled = x.first().copied().unwrap_or(0.0);
    let (mut y1, mut y2) = (settled, settled);
    x.iter()
        .map(|&v| {
            y1 += a * (v - y1);
            y2 += a * (y1 - y2);
            y2
        })
        .collect()
}

/// Peaks (maxima above zero) and valleys (minima below zero) of `y`; a plateau's extreme is
/// its last sample; none in the first `settle` samples.
pub fn extremes(y: &[f64], settle: u32) -> Vec<Extreme> {
    let mut out = Vec::new();
    let mut dir = 0i8;
    for i in 1..y.len() {
        let (prev, cur) = (y[i - 1], y[i]);
        if cur > prev {
            if dir < 0 && prev < 0.0 {
                out.push(Extreme {
                    index: i as u32 - 1,
                    value: prev,
                    peak: false,
                });
            }
            dir = 1;
        } else if cur < prev {
            if dir > 0 && prev > 0.0 {
                out.push(Extreme {
                    index: i as u32 - 1,
                    value: prev,
                    peak: true,
                });
            }
            dir = -1;
        }
    }
    out.retain(|e| e.index >= settle);
    out
}

/// Mean of the window of `width` that starts at `list[i]` when `width − 1` successors lie
/// within `horizon` samples; else of the last `width` values up to the last successor
/// within it.
fn window_mean(list: &[Extreme], i: usize, width: usize, horizon: u32) -> f64 {
    let e = list[i];
    let mut end = i + 1;
    while end < list.len() && end - i < width && list[end].index - e.index < horizon {
        end += 1;
    }
    let start = end.saturating_sub(width);
    let w = &list[start..end];
    w.iter().map(|x| x.value).sum::<f64>() / w.len() as f64
}

/// One kind's extremes through the static rule, the dynamic threshold, the minimum
/// interval and the neighbouring difference.
fn rules(list: &[Extreme], rate: SampleRate, peak: bool) -> Vec<Extreme> {
    let walk_gap = rate.samples_in_ms(WALK_GAP_MS);
    let sign = if peak { 1.0 } else { -1.0 };
    // Eq. 2.
    let not_static: Vec<Extreme> = (0..list.len())
        .filter(|&i| sign * window_mean(list, i, STATIC_WINDOW, walk_gap) >= g(STATIC_G))
        .map(|i| list[i])
        .collect();
    // Eq. 3, 4.
    let c = C_NUM as f64 / C_DEN as f64;
    let lookahead = rate.samples_in_ms(DYNAMIC_LOOKAHEAD_MS);
    let th = if peak { g(TH1_G) } else { g(TH2_G) };
    let above: Vec<Extreme> = (0..not_static.len())
        .filter(|&i| {
            let v = not_static[i].value;
            let m = window_mean(&not_static, i, DYNAMIC_WINDOW, lookahead);
            sign * v >= sign * c * m && sign * v >= sign * th
        })
        .map(|i| not_static[i])
        .collect();
    // Minimum interval: the one nearer zero goes, the survivor meets the next.
    let min_interval = rate.samples_in_ms(MIN_INTERVAL_MS);
    let mut spaced: Vec<Extreme> = Vec::new();
    let mut cur: Option<Extreme> = None;
    for &x in &above {
        cur = Some(match cur {
            Some(c) if x.index - c.index < min_interval => {
                if x.value.abs() > c.value.abs() {
                    x
                } else {
                    c
                }
            }
            Some(c) => {
                spaced.push(c);
                x
            }
            None => x,
        });
    }
    spaced.extend(cur);
    // Eq. 5.
    let t = if peak {
        g(NEIGHBOUR_PEAK_G)
    } else {
        g(NEIGHBOUR_VALLEY_G)
    };
    let mut kept: Vec<Extreme> = Vec::new();
    for (i, &e) in spaced.iter().enumerate() {
        let prev = kept.last().filter(|p| e.index - p.index < walk_gap);
        let next = spaced.get(i + 1).filter(|n| n.index - e.index < walk_gap);
        let outlier = match (prev, next) {
            (Some(p), Some(n)) => {
                let (d1, d2) = (p.value - e.value, n.value - e.value);
                if peak {
                    e.value < d1 && e.value < d2 && d1 > t && d2 > t
                } else {
                    e.value > d1 && e.value > d2 && d1 < t && d2 < t
                }
            }
            _ => false,
        };
        if !outlier {
            kept.push(e);
        }
    }
    kept
}

/// Lu's steps in `vertical` (g, gravity removed) sampled at `rate`, from a recording
/// without gaps.
pub fn steps(rate: SampleRate, vertical: &[f64]) -> Vec<Step> {
    let y = low_pass(rate, vertical);
    // The delay is a definition shared with the core, like α.
    let d = LowPass::new(rate).delay();
    let all = extremes(&y, d);
    let peaks: Vec<Extreme> = all.iter().copied().filter(|e| e.peak).collect();
    let valleys: Vec<Extreme> = all.iter().copied().filter(|e| !e.peak).collect();
    let mut seq = rules(&peaks, rate, true);
    seq.extend(rules(&valleys, rate, false));
    seq.sort_by_key(|e| e.index);
    // The sequence: walks split where extremes are a walk gap apart; in a walk, runs of one
    // kind keep their extreme farthest from zero; a peak pairs with the valley after it.
    let walk_gap = rate.samples_in_ms(WALK_GAP_MS);
    let mut out = Vec::new();
    let mut w = 0;
    while w < seq.len() {
        let mut end = w + 1;
        while end < seq.len() && seq[end].index - seq[end - 1].index < walk_gap {
            end += 1;
        }
        let mut runs: Vec<Extreme> = Vec::new();
        for &x in &seq[w..end] {
            match runs.last_mut() {
                Some(r) if r.peak == x.peak => {
                    if x.value.abs() > r.value.abs() {
                        *r = x;
                    }
                }
                _ => runs.push(x),
            }
        }
        let mut last_peak: Option<u32> = None;
        for pair in runs.windows(2) {
            if pair[0].peak && !pair[1].peak {
                let period = last_peak.map_or(0, |q| pair[0].index - q);
                last_peak = Some(pair[0].index);
                let undo = |mut x: Extreme| {
                    x.index -= d;
                    x
                };
                out.push(Step {
                    peak: undo(pair[0]),
                    valley: undo(pair[1]),
                    period,
                });
            }
        }
        w = end;
    }
    out
}

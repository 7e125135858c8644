//! f64 reference of the length stage: the features of [`gaitclip::length::features`], the basis
//! terms of [`gaitclip::length::models`], Lu's fuzzy `k` with a fine centre of gravity, and the
//! RBF SVR as trained. The fixed-point code is checked against these, and the models are
//! trained on these features.

use gaitclip::detect::phase_stats::{Channel, ChannelStats, Segment, StrideStats};
use gaitclip::length::features::{self, Stat, COUNT, STATS, STRIDE_FREQUENCY, ZUPT_LENGTH};
use gaitclip::length::fuzzy::RULES;
use gaitclip::length::models::{Model, Settings, MAX_TERMS};
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::units::FOOT_LSB_PER_G;

/// The features of a stride in f64, in the units of [`gaitclip::length::features`] (not Q16), from
/// its phase statistics `stats`.
pub fn features(stride: &Stride, stats: &StrideStats, rate: SampleRate) -> [f64; COUNT] {
    let hz = rate.millihertz() as f64 / 1000.0;
    let mut f = [0.0; COUNT];
    for seg in Segment::ALL {
        let s = &stats.segments[seg as usize];
        for ch in Channel::ALL {
            let v = channel(&s.channels[ch as usize], s.samples);
            let at = features::index(seg, ch, Stat::Max);
            f[at..at + STATS].copy_from_slice(&v);
        }
        f[features::duration_index(seg)] = s.samples as f64 / hz;
        f[features::frequency_index(seg)] = if s.samples == 0 {
            0.0
        } else {
            hz / s.samples as f64
        };
    }
    let period = stride.events.end.wrapping_sub(stride.events.start);
    f[STRIDE_FREQUENCY] = if period == 0 { 0.0 } else { hz / period as f64 };
    f[ZUPT_LENGTH] = stride.zupt_um as f64 / 1e6;
    f
}

fn channel(c: &ChannelStats, n: u32) -> [f64; STATS] {
    if n == 0 {
        return [0.0; STATS];
    }
    let g = FOOT_LSB_PER_G as f64;
    let nf = n as f64;
    let (max, min) = (c.max as f64 / g, c.min as f64 / g);
    let range = max - min;
    let mean_abs = c.sum_abs as f64 / g / nf;
    let var = if n > 1 {
        let (s, s2) = (c.sum as f64, c.sum_sq as f64);
        (nf * s2 - s * s) / (nf * (nf - 1.0)) / (g * g)
    } else {
        0.0
    };
    let scarlett = if range > 0.0 {
        (mean_abs - min) / range
    } else {
        0.0
    };
    [
        max,
        min,
        range,
        mean_abs,
        var,
        range.powf(0.25),
        mean_abs.cbrt(),
        scarlett,
    ]
}

/// Lu's `k` with the centre of gravity integrated on `steps` points per level.
pub fn lu_k(f: f64, f_universe: (f64, f64), d: f64, d_universe: (f64, f64), steps: usize) -> f64 {
    let level = |v: f64, (lo, hi): (f64, f64)| {
        if hi <= lo {
            0.0
        } else {
            (v.clamp(lo, hi) - lo) / (hi - lo) * 6.0 - 3.0
        }
    };
    let tri = |x: f64, l: f64| (1.0 - (x - l).abs()).max(0.0);
    let (xf, xd) = (level(f, f_universe), level(d, d_universe));
    let mut fired = Vec::new();
    for (di, row) in RULES.iter().enumerate() {
        for (fi, &out) in row.iter().enumerate() {
            let w = tri(xd, di as f64 - 3.0).min(tri(xf, fi as f64 - 3.0));
            if w > 0.0 {
                fired.push((w, out as f64));
            }
        }
    }
    let (mut num, mut den) = (0.0, 0.0);
    let n = 6 * steps;
    for i in 0..=n {
        let y = -3.0 + 6.0 * i as f64 / n as f64;
        let mu = fired
            .iter()
            .map(|&(w, l)| w.min(tri(y, l)))
            .fold(0.0, f64::max);
        num += mu * y;
        den += mu;
    }
    let c = if den == 0.0 { 0.0 } else { num / den };
    0.55 + (c + 3.0) / 6.0 * 0.45
}

/// The basis terms of a closed-form model in f64 (see [`gaitclip::length::models::basis`]);
/// `lu_d_range` is the foot range mapped onto Lu's D universe, g.
pub fn basis(
    model: Model,
    f: &[f64; COUNT],
    settings: Settings,
    lu_d_range: (f64, f64),
) -> Option<[f64; MAX_TERMS]> {
    let mv = Segment::Movement;
    let st = |c: Channel, s: Stat| f[features::index(mv, c, s)];
    let weinberg = st(Channel::Vertical, Stat::Weinberg);
    let sf = f[STRIDE_FREQUENCY];
    let var = st(Channel::Vertical, Stat::Variance);
    let h = settings.height_mm as f64 / 1000.0;
    Some(match model {
        Model::Zupt | Model::HuangSvrFusion | Model::HuangSvrWhole | Model::HuangSvrAdaBoost => {
            return None
        }
        Model::Weinberg => [weinberg, 0.0, 0.0, 0.0],
        Model::Kim => [st(Channel::Magnitude, Stat::Kim), 0.0, 0.0, 0.0],
        Model::Scarlett => [st(Channel::Vertical, Stat::Scarlett), 0.0, 0.0, 0.0],
        Model::Ladetto => [sf, var, 1.0, 0.0],
        Model::Zhang => [h * sf, h * var, h, 1.0],
        Model::LuFuzzy => {
            // The model's centre of gravity is the firmware's discrete one (its distance to
            // the continuous integral is tested on its own in tests/lengths.rs).
            let steps = gaitclip::length::fuzzy::STEPS_PER_LEVEL as usize;
            let range = st(Channel::Vertical, Stat::Range);
            let k = lu_k(2.0 * sf, (1.0, 2.8), range, lu_d_range, steps);
            [k * weinberg, 0.0, 0.0, 0.0]
        }
        Model::Ho => {
            let v = f[ZUPT_LENGTH] * sf;
            [(0.68 - 0.37 * v + 0.15 * v * v) * weinberg, 0.0, 0.0, 0.0]
        }
        Model::Strozzi => {
            let a_max = st(Channel::Magnitude, Stat::Max).max(1.0 / 16.0);
            [weinberg / a_max.cbrt(), 0.0, 0.0, 0.0]
        }
        Model::Vezocnik => [
            st(Channel::Magnitude, Stat::Range).max(0.0).powf(0.1),
            0.0,
            0.0,
            0.0,
        ],
        Model::Tian => [h * (2.0 * sf).max(0.0).sqrt(), 0.0, 0.0, 0.0],
    })
}

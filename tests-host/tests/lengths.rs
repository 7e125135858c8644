//! The fixed-point length stage against its f64 reference (roots, exp, Lu's fuzzy k,
//! features, basis terms), and Zhang's model fitted on the paper's own Table 1.

use gaitclip::detect::phase_stats::StrideStats;
use gaitclip::fixed::{exp_neg_q32, root_q16, tenth_root_q16};
use gaitclip::length::features::{self, Features, COUNT};
use gaitclip::length::fuzzy::{lu_k_q16, D_UNIVERSE_Q16, F_UNIVERSE_Q16};
use gaitclip::length::models::{self, Model, Settings, MAX_TERMS};
use gaitclip::record::stride::{Stride, StrideEvents};
use gaitclip::sensor::rate::SampleRate;
use gaitclip_host::reference::length_ref;
use gaitclip_host::train::fit::least_squares;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const Q16: f64 = 65536.0;

fn rng() -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(11)
}

#[test]
fn roots_are_floor_within_one_lsb() {
    let mut r = rng();
    for n in 1..=5u32 {
        let mut max = 0f64;
        for _ in 0..20_000 {
            let bits = r.random_range(1..48);
            let x: u64 = r.random_range(0..(1u64 << bits));
            let exact = (x as f64 / Q16).powf(1.0 / n as f64) * Q16;
            let got = root_q16(x, n) as f64;
            let err = exact - got;
            assert!(
                (-1e-9 * exact..1.0 + 1e-9 * exact).contains(&err),
                "n={n} x={x}: {got} vs {exact}"
            );
            max = max.max(err);
        }
        eprintln!("root {n}: max error {max:.3} LSB");
    }
}

#[test]
fn tenth_root_within_two_lsb() {
    let mut r = rng();
    let mut max = 0f64;
    for _ in 0..20_000 {
        let bits = r.random_range(7..48);
        let x: u64 = r.random_range(64..(1u64 << bits));
        let exact = (x as f64 / Q16).powf(0.1) * Q16;
        let err = exact - tenth_root_q16(x) as f64;
        assert!((-1e-6..2.0).contains(&err), "x={x}: error {err} LSB");
        max = max.max(err);
    }
    eprintln!("tenth root: max error {max:.3} LSB");
}

#[test]
fn exp_neg_within_stated_bound() {
    let mut r = rng();
    let mut max_rel = 0f64;
    for i in 0..200_000u64 {
        let t: u64 = if i < 1000 {
            i << 26 // every table boundary region near 0..16
        } else {
            r.random_range(0..50u64 << 32)
        };
        let tf = t as f64 / 4_294_967_296.0;
        let exact = (-tf).exp();
        let got = exp_neg_q32(t) as f64 / (1u64 << 62) as f64;
        let bound = 8e-12 * exact + 3.0 / (1u64 << 62) as f64;
        // f64's own exp is within 1 ulp (1.1e−16 relative), far inside the bound.
        assert!(
            (got - exact).abs() <= bound + 2.3e-16 * exact,
            "t={tf}: {got} vs {exact}"
        );
        if exact > 1e-6 {
            max_rel = max_rel.max((got - exact).abs() / exact);
        }
    }
    eprintln!("exp: max relative error {max_rel:e} (for e^-t > 1e-6)");
}

#[test]
fn lu_fuzzy_k_matches_continuous_centre_of_gravity() {
    let to = |v: (i64, i64)| (v.0 as f64 / Q16, v.1 as f64 / Q16);
    let (fu, du) = (to(F_UNIVERSE_Q16), to(D_UNIVERSE_Q16));
    let mut r = rng();
    let mut max = 0f64;
    for i in 0..3000 {
        // A grid over both universes (rule corners included), then random points.
        let (f, d) = if i < 900 {
            (
                fu.0 - 0.1 + (fu.1 - fu.0 + 0.2) * (i % 30) as f64 / 29.0,
                du.0 - 0.1 + (du.1 - du.0 + 0.2) * (i / 30) as f64 / 29.0,
            )
        } else {
            (r.random_range(0.5..3.2), r.random_range(0.0..1.1))
        };
        let got = lu_k_q16(
            (f * Q16) as i64,
            F_UNIVERSE_Q16,
            (d * Q16) as i64,
            D_UNIVERSE_Q16,
        ) as f64
            / Q16;
        let want = length_ref::lu_k(f, fu, d, du, 10_000);
        assert!(
            (0.55 - 1e-4..=1.0 + 1e-4).contains(&got),
            "k {got} out of [0.55, 1]"
        );
        max = max.max((got - want).abs());
    }
    eprintln!("lu k: max error {max:.5}");
    assert!(max <= 0.002, "max error {max}");
}

#[test]
fn lu_rule_base_reads_as_the_paper_says() {
    // At a fixed D, k falls as f rises; at a fixed f, k rises with D.
    let k = |f: f64, d: f64| {
        lu_k_q16(
            (f * Q16) as i64,
            F_UNIVERSE_Q16,
            (d * Q16) as i64,
            D_UNIVERSE_Q16,
        )
    };
    assert!(k(1.0, 0.3) > k(2.8, 0.3));
    assert!(k(1.5, 0.9) > k(1.5, 0.12));
}

/// Random strides: a random movement buffer split at random phases.
fn random_strides(n: usize) -> Vec<(Stride, StrideStats)> {
    let mut r = rng();
    (0..n)
        .map(|_| {
            let len = r.random_range(1..700usize);
            let scale = r.random_range(100..16_000i32);
            let m: Vec<[i16; 3]> = (0..len)
                .map(|_| [0; 3].map(|_| r.random_range(-scale..=scale).clamp(-32768, 32767) as i16))
                .collect();
            let to = r.random_range(0..=len as u32);
            let hs = r.random_range(to..=len as u32);
            let stance = r.random_range(0..300u32);
            (
                Stride {
                    events: StrideEvents {
                        start: 1000,
                        heel_off: 1000 + stance,
                        end: 1000 + stance + len as u32,
                        ..StrideEvents::default()
                    },
                    zupt_um: r.random_range(0..3_000_000),
                    ..Stride::default()
                },
                StrideStats::measure(&m, to, hs),
            )
        })
        .collect()
}

#[test]
fn features_match_f64_reference() {
    let rate = SampleRate::from_millihertz(204_800).unwrap();
    let mut max = [0f64; COUNT];
    for (s, stats) in random_strides(2000) {
        let fixed = Features::of(&s, &stats, rate);
        let want = length_ref::features(&s, &stats, rate);
        for i in 0..COUNT {
            let got = fixed.0[i] as f64 / Q16;
            let (seg, ch, stat) = features::name_parts(i);
            // Rounded values: half an LSB; roots: below by less than one LSB.
            let tol = 1.0 / Q16 + 1e-9 * want[i].abs();
            let err = (got - want[i]).abs();
            assert!(err <= tol, "{seg}.{ch}.{stat}: {got} vs {}", want[i]);
            max[i] = max[i].max(err);
        }
    }
    let worst = max.iter().cloned().fold(0.0, f64::max);
    eprintln!("features: worst error {:.2} LSB", worst * Q16);
}

#[test]
fn basis_terms_match_f64_reference() {
    let rate = SampleRate::from_millihertz(200_000).unwrap();
    let params = &gaitclip::length::trained::PARAMS;
    let lu = (
        params.lu_d_range_q16.0 as f64 / Q16,
        params.lu_d_range_q16.1 as f64 / Q16,
    );
    let settings = Settings { height_mm: 1712 };
    for (s, stats) in random_strides(500) {
        let fixed = Features::of(&s, &stats, rate);
        let want = length_ref::features(&s, &stats, rate);
        for m in Model::ALL {
            let (Some(b), Some(w)) = (
                models::basis(m, &fixed, settings, params),
                length_ref::basis(m, &want, settings, lu),
            ) else {
                continue;
            };
            for k in 0..MAX_TERMS {
                let got = b[k] as f64 / Q16;
                // Terms are products of at most three Q16 roundings of values of order 1;
                // Lu's k adds its own 0.002 (in k ≥ 0.55: 0.4 % of the term).
                let tol = if m == Model::LuFuzzy {
                    0.004 * w[k].abs() + 1e-4
                } else {
                    2e-4 + 1e-4 * w[k].abs()
                };
                assert!(
                    (got - w[k]).abs() <= tol,
                    "{} term {k}: {got} vs {}",
                    m.name(),
                    w[k]
                );
            }
        }
    }
}

/// Zhang et al. 2018, Table 1: height (m), stride frequency (Hz), vertical acceleration
/// variance, step length (m), 30 calibration walks.
const ZHANG_TABLE_1: [[f64; 4]; 30] = [
    [1.60, 1.6418, 0.1662, 0.5455],
    [1.60, 1.5842, 0.1253, 0.5217],
    [1.60, 1.8242, 0.4685, 0.6154],
    [1.60, 1.8470, 0.3424, 0.6000],
    [1.60, 1.8377, 0.5645, 0.6316],
    [1.60, 1.9035, 0.8991, 0.6857],
    [1.63, 1.5820, 0.2578, 0.6154],
    [1.63, 1.5016, 0.2138, 0.6000],
    [1.63, 1.7242, 0.6021, 0.7102],
    [1.63, 1.7566, 0.5718, 0.7059],
    [1.63, 1.8346, 1.2402, 0.8000],
    [1.63, 1.8831, 1.1853, 0.8000],
    [1.71, 1.7640, 0.5182, 0.6667],
    [1.71, 1.7624, 0.3912, 0.6667],
    [1.71, 1.8278, 0.9619, 0.7273],
    [1.71, 1.8471, 0.8618, 0.7273],
    [1.71, 1.9942, 1.4286, 0.8000],
    [1.71, 2.0901, 1.8048, 0.8276],
    [1.78, 1.4914, 0.2503, 0.6667],
    [1.78, 1.6307, 0.3343, 0.7059],
    [1.78, 1.7328, 0.5587, 0.7500],
    [1.78, 1.7476, 0.5065, 0.7500],
    [1.78, 1.9508, 1.2965, 0.8889],
    [1.78, 1.9738, 1.2014, 0.8571],
    [1.83, 1.4564, 0.2006, 0.6486],
    [1.83, 1.6707, 0.2367, 0.6857],
    [1.83, 1.7334, 0.4753, 0.7500],
    [1.83, 1.7614, 0.5075, 0.7500],
    [1.83, 2.0869, 1.2029, 1.0000],
    [1.83, 2.0604, 1.2742, 0.9600],
];

fn rms_residual(rows: &[[f64; MAX_TERMS]], y: &[f64], c: &[f64; MAX_TERMS]) -> f64 {
    let se: f64 = rows
        .iter()
        .zip(y)
        .map(|(r, y)| (r.iter().zip(c).map(|(a, b)| a * b).sum::<f64>() - y).powi(2))
        .sum();
    (se / y.len() as f64).sqrt()
}

#[test]
fn zhang_fit_on_the_papers_table_1() {
    let y: Vec<f64> = ZHANG_TABLE_1.iter().map(|r| r[3]).collect();
    // Zhang eq. 2: SL = h·(A·f + B·var + C) + D, the basis gaitclip's `zhang` model uses.
    let zhang: Vec<[f64; MAX_TERMS]> = ZHANG_TABLE_1
        .iter()
        .map(|&[h, f, v, _]| [h * f, h * v, h, 1.0])
        .collect();
    let ladetto: Vec<[f64; MAX_TERMS]> = ZHANG_TABLE_1
        .iter()
        .map(|&[_, f, v, _]| [f, v, 1.0, 0.0])
        .collect();
    let cz = least_squares(&zhang, &y, 4).unwrap();
    let cl = least_squares(&ladetto, &y, 3).unwrap();
    let (rz, rl) = (
        rms_residual(&zhang, &y, &cz),
        rms_residual(&ladetto, &y, &cl),
    );
    eprintln!(
        "Zhang A B C D = {cz:?}, RMS residual {rz:.4} m; Ladetto A B C = {cl:?}, RMS {rl:.4} m"
    );
    // Longer steps with a faster cadence and a livelier trunk: A and B positive.
    assert!(cz[0] > 0.0 && cz[1] > 0.0, "{cz:?}");
    assert!(cl[0] > 0.0 && cl[1] > 0.0, "{cl:?}");
    // The height term explains what frequency and variance cannot (the paper's claim).
    assert!(rz < 0.8 * rl, "Zhang {rz} vs Ladetto {rl}");
    assert!(rz < 0.05, "Zhang residual {rz} m");
    // The same coefficients, through the firmware's fixed-point model, give the same
    // step lengths (within 1 mm) from features made to carry the table's f and var.
    let mut params = gaitclip::length::trained::PARAMS;
    params.linear[Model::Zhang.linear_index().unwrap()] =
        cz.map(|c| (c * 1e6 * Q16).round() as i64);
    for (row, want) in ZHANG_TABLE_1.iter().zip(&zhang) {
        let mut f = Features([0; COUNT]);
        f.0[features::STRIDE_FREQUENCY] = (row[1] * Q16).round() as i64;
        let var = features::index(
            gaitclip::detect::phase_stats::Segment::Movement,
            gaitclip::detect::phase_stats::Channel::Vertical,
            features::Stat::Variance,
        );
        f.0[var] = (row[2] * Q16).round() as i64;
        let s = Settings {
            height_mm: (row[0] * 1000.0).round() as u16,
        };
        let got = models::predict_um(Model::Zhang, &f, s, &params).unwrap() as f64 / 1e6;
        let exact: f64 = want.iter().zip(&cz).map(|(a, b)| a * b).sum();
        assert!((got - exact).abs() < 1e-3, "{got} vs {exact}");
    }
}

/// The pipeline's shortcut for the `zupt` model (`Features::zupt_only`, which skips the
/// other 105 features) gives the length the full features give, on every demo stride.
#[test]
fn the_zupt_shortcut_gives_the_full_features_length() {
    use gaitclip::length::features::Features;
    use gaitclip::length::models::{predict_mm, Model, Settings};
    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    let rate = gaitclip::sensor::rate::SampleRate::from_hz(200).unwrap();
    let ranges = gaitclip_host::io::trace::Ranges::default();
    let config =
        gaitclip::pipeline::config::Config::new(rate, ranges.accel.scale(), ranges.gyro.scale());
    let (strides, _) = gaitclip_host::replay::core_run_with_stats(&counts, &[], config);
    assert!(strides.len() >= 20);
    let p = &gaitclip::length::trained::PARAMS;
    for (s, stats) in &strides {
        let full = predict_mm(
            Model::Zupt,
            &Features::of(s, stats, rate),
            Settings::DEFAULT,
            p,
        );
        let short = predict_mm(Model::Zupt, &Features::zupt_only(s), Settings::DEFAULT, p);
        assert_eq!(full, short, "{s:?}");
        if s.flags.valid() {
            assert_eq!(short, Some(s.length_mm), "{s:?}");
        }
    }
}

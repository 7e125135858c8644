//! Every fixed-point routine of the core against an f64 reference, with the error bound its
//! doc comment states.

use gaitclip::detect::rest::{RestSums, RestThresholds, ACCEL_STD_MAX_MMPS2, GYRO_RMS_MAX_MRADPS};
use gaitclip::detect::stance::{deflate, StanceThresholds, DEFLATED_IQR_MAX, DEFLATED_STD_MAX};
use gaitclip::detect::zupt::ZuptIntegrator;
use gaitclip::fixed::{isqrt_u128, isqrt_u64, mul_q30, QuatQ30, Q30_ONE};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip::sensor::units::{AccelScale, GyroScale};
use gaitclip::signal::mean_filter::MeanFilter;
use gaitclip_host::sim::fixtures::FIRMWARE_TRACE;
use gaitclip_mpu6050::{AccelRange, GyroRange};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const LSB: f64 = 1.0 / (1u64 << 30) as f64;

fn q(v: f64) -> i32 {
    (v * Q30_ONE as f64).round() as i32
}
fn f(v: i32) -> f64 {
    v as f64 * LSB
}
fn rng() -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(7)
}

#[test]
fn mul_q30_within_half_lsb() {
    let mut r = rng();
    let mut max = 0f64;
    for _ in 0..100_000 {
        let (a, b) = (
            r.random_range(-Q30_ONE..=Q30_ONE),
            r.random_range(-Q30_ONE..=Q30_ONE),
        );
        let err = (f(mul_q30(a, b)) - f(a) * f(b)).abs();
        max = max.max(err);
    }
    assert!(max <= 0.5 * LSB + 1e-18, "max error {max:e}");
}

#[test]
fn isqrt_is_exact() {
    let mut r = rng();
    for _ in 0..100_000 {
        let x: u64 = r.random::<u64>() >> r.random_range(0..64);
        let s = isqrt_u64(x) as u128;
        assert!(s * s <= x as u128 && (s + 1) * (s + 1) > x as u128, "{x}");
        assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
    }
    // Where a root computed in f64 is most likely off: either side of a square, for every
    // root below 2²⁰ and random ones up to 2³², and the ends of the range.
    let roots = (0..1u64 << 20).chain((0..200_000).map(|_| r.random_range(0..=u32::MAX as u64)));
    for k in roots.chain([u32::MAX as u64 - 1, u32::MAX as u64]) {
        let sq = k * k;
        for x in [sq.saturating_sub(1), sq, sq.saturating_add(1), sq + 2 * k] {
            assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
        }
    }
    for x in [0, 1, 2, 3, u64::MAX - 1, u64::MAX] {
        assert_eq!(isqrt_u64(x), x.isqrt(), "{x}");
    }
}

#[test]
fn isqrt_u128_is_exact() {
    let mut r = rng();
    for _ in 0..200_000 {
        let x: u128 = r.random::<u128>() >> r.random_range(0..128);
        assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
    }
    // Either side of a square, for roots of every size up to 2⁶⁴ − 1 (the f64 root is
    // rounded, and above 2¹⁰⁴ corrected by a Newton step), and the ends of the range.
    let roots = (0..100_000u128)
        .chain((1..=64).flat_map(|bits: u32| {
            let top = if bits == 64 {
                u64::MAX as u128
            } else {
                (1u128 << bits) - 1
            };
            [top, top - top / 3, top / 2 + 1]
        }))
        .chain((0..200_000).map(|_| (r.random::<u64>() >> r.random_range(0..40)) as u128));
    for k in roots {
        let sq = k * k;
        for x in [sq.saturating_sub(1), sq, sq + 1, sq + 2 * k] {
            assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
        }
    }
    for x in [
        0,
        1,
        2,
        3,
        u64::MAX as u128,
        1 << 104,
        (1 << 104) - 1,
        u128::MAX - 1,
        u128::MAX,
    ] {
        assert_eq!(isqrt_u128(x), x.isqrt(), "{x}");
    }
}

/// A uniformly random unit quaternion in Q30.
fn random_unit(r: &mut ChaCha8Rng) -> QuatQ30 {
    let c: [f64; 4] = [0; 4].map(|_| r.random_range(-1.0..1.0));
    let n = c.iter().map(|v| v * v).sum::<f64>().sqrt();
    QuatQ30 {
        w: q(c[0] / n),
        x: q(c[1] / n),
        y: q(c[2] / n),
        z: q(c[3] / n),
    }
}

fn quat_f64(q: QuatQ30) -> [f64; 4] {
    [f(q.w), f(q.x), f(q.y), f(q.z)]
}

fn rotate_f64(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let m = gaitclip_host::eval::scoring::rotation_matrix(q);
    [0, 1, 2].map(|i| (0..3).map(|k| m[i][k] * v[k]).sum())
}

#[test]
fn matrix_matches_f64_within_2_lsb() {
    let mut r = rng();
    for _ in 0..10_000 {
        let qq = random_unit(&mut r);
        let m = qq.matrix();
        for (j, e) in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
            .iter()
            .enumerate()
        {
            let col = rotate_f64(quat_f64(qq), *e);
            for i in 0..3 {
                assert!((f(m[i][j]) - col[i]).abs() <= 2.0 * LSB, "{:?}", qq);
            }
        }
    }
}

#[test]
fn hamilton_product_within_2_lsb() {
    let mut r = rng();
    for _ in 0..10_000 {
        let (a, b) = (random_unit(&mut r), random_unit(&mut r));
        let [aw, ax, ay, az] = quat_f64(a);
        let [bw, bx, by, bz] = quat_f64(b);
        let exact = [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ];
        let got = quat_f64(a * b);
        for k in 0..4 {
            assert!((got[k] - exact[k]).abs() <= 2.0 * LSB);
        }
    }
}

/// Constant rotation at 5 rad/s about a random axis for one second at 200 Hz (0.025 rad a
/// step), and at the ±2000 °/s rail at 100, 50 and 25 Hz: the integrated attitude stays
/// within the per-step error the doc comment of `integrate_half_angle` states, times the
/// steps, and unit norm within 1e−8.
#[test]
fn quaternion_integration_tracks_exact_rotation() {
    let mut r = rng();
    for _ in 0..50 {
        let a: [f64; 3] = [0; 3].map(|_| r.random_range(-1.0..1.0));
        let n = a.iter().map(|v| v * v).sum::<f64>().sqrt();
        let axis = a.map(|v| v / n);
        // At the rail at 50 Hz a step turns 0.7 rad: θ⁵/120 = 1.4e−3 rad per step; at 25 Hz
        // 1.4 rad: 4.5e−2 per step.
        for (rate, hz, steps, bound) in [
            (5.0, 200.0, 200, 2e-6),
            (34.9, 100.0, 10, 5e-4),
            (34.9, 50.0, 5, 8e-3),
            (34.9, 25.0, 3, 1.5e-1),
        ] {
            let h = axis.map(|v| q(v * rate / hz / 2.0));
            let mut att = QuatQ30::IDENTITY;
            for _ in 0..steps {
                att = att.integrate_half_angle(h);
            }
            let got = quat_f64(att);
            let norm = got.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((norm - 1.0).abs() < 1e-8, "norm {norm}");
            let half = rate * steps as f64 / hz / 2.0;
            let exact = [
                half.cos(),
                axis[0] * half.sin(),
                axis[1] * half.sin(),
                axis[2] * half.sin(),
            ];
            let dot: f64 = got.iter().zip(exact).map(|(a, b)| a * b).sum::<f64>() / norm;
            let angle = 2.0 * dot.abs().min(1.0).acos();
            assert!(
                angle < bound,
                "angle error {angle:e} rad at {rate} rad/s, {hz} Hz"
            );
        }
    }
}

#[test]
fn level_from_up_takes_gravity_to_plus_z_any_mounting() {
    let mut r = rng();
    let mut cases: Vec<[i64; 3]> = vec![
        [0, 0, 2048],
        [0, 0, -2048],
        [2048, 0, 0],
        [0, -5, -2048],
        [1, 1, -2048],
    ];
    for _ in 0..10_000 {
        cases.push([0; 3].map(|_| r.random_range(-(1i64 << 23)..(1i64 << 23))));
    }
    for up in cases {
        let qq = QuatQ30::level_from_up(up).unwrap();
        let n = up.iter().map(|&v| (v as f64).powi(2)).sum::<f64>().sqrt();
        if n < 100.0 {
            continue; // integer direction too coarse to judge
        }
        let v = rotate_f64(quat_f64(qq), up.map(|v| v as f64 / n));
        assert!(
            v[0].abs() < 1e-7 && v[1].abs() < 1e-7 && (v[2] - 1.0).abs() < 1e-7,
            "{up:?} → {v:?}"
        );
        // Never a rotation about the vertical beyond what leveling needs: yaw of x stays put
        // up to the tilt (checked loosely by unit norm).
        let norm: f64 = quat_f64(qq).iter().map(|c| c * c).sum();
        assert!((norm - 1.0).abs() < 1e-8);
    }
    assert!(QuatQ30::level_from_up([0, 0, 0]).is_none());
}

#[test]
fn mean_filter_is_floor_of_exact_mean() {
    let mut r = rng();
    let mut filt = MeanFilter::<8>::new();
    let mut hist: Vec<[i16; 3]> = Vec::new();
    for _ in 0..10_000 {
        let x = [0; 3].map(|_| r.random::<i16>());
        hist.push(x);
        let y = filt.process(x);
        let win = &hist[hist.len().saturating_sub(8)..];
        for k in 0..3 {
            let mean = win.iter().map(|v| v[k] as f64).sum::<f64>() / win.len() as f64;
            let err = mean - y[k] as f64;
            assert!((0.0..1.0).contains(&err), "mean {mean} got {}", y[k]);
        }
    }
}

#[test]
fn sample_rate_conversions() {
    let r = SampleRate::from_millihertz(204_800).unwrap();
    assert_eq!(r.samples_in_ms(50), 10); // 10.24
    assert_eq!(r.ms_of_samples(2048), 10_000);
    assert!(SampleRate::from_hz(24).is_none() && SampleRate::from_hz(1001).is_none());
    assert!(SampleRate::from_hz(25).is_some());
    assert!(SampleRate::from_hz(50).is_some());
    assert!(SampleRate::from_hz(u32::MAX).is_none());
}

#[test]
fn rest_thresholds_match_physical_units_within_one_count() {
    for (accel, gyro) in [
        (AccelRange::G16.scale(), GyroRange::Dps2000.scale()),
        (AccelRange::G2.scale(), GyroRange::Dps250.scale()),
        // ST's ±16 g and ±4 000 °/s (0.488 mg and 140 mdps per count).
        (
            AccelScale::from_lsb_per_g(2048),
            GyroScale::from_mdps_per_lsb(140),
        ),
    ] {
        let t = RestThresholds::new(SampleRate::from_hz(200).unwrap(), accel, gyro);
        let a = ACCEL_STD_MAX_MMPS2 as f64 / 1000.0 * accel.lsb_per_g() as f64 / 9.80665;
        let g =
            GYRO_RMS_MAX_MRADPS as f64 / 1000.0 * 180.0 / std::f64::consts::PI * gyro.lsb_per_dps();
        assert!(((t.accel_var_counts2 as f64).sqrt() - a).abs() <= 1.0);
        assert!(((t.gyro_energy_counts2 as f64).sqrt() - g).abs() <= 1.0);
        assert_eq!(t.window, 10);
    }
}

#[test]
fn stance_thresholds_match_physical_units() {
    // Deflated units per (m/s²)²: 2048 · 8 / 9.80665².
    let per = 2048.0 * 8.0 / (9.80665 * 9.80665);
    for (hz, half) in [(100, [2, 3, 6]), (200, [3, 6, 12]), (1000, [15, 30, 60])] {
        let t = StanceThresholds::new(SampleRate::from_hz(hz).unwrap(), GyroRange::Dps2000.scale());
        assert_eq!(t.half, half, "{hz} Hz");
        let std = DEFLATED_STD_MAX as f64 / 1000.0 * per;
        assert!(((t.variance as f64).sqrt() - std).abs() <= 1.0);
        assert!((t.iqr as f64 - DEFLATED_IQR_MAX as f64 / 1000.0 * per).abs() <= 1.0);
    }
}

#[test]
fn deflate_is_the_signed_square_within_one_unit() {
    for x in (i16::MIN..=i16::MAX)
        .step_by(7)
        .chain([i16::MIN, i16::MAX, 0, 1, -1])
    {
        let exact = x as f64 * (x as f64).abs() * 8.0 / 2048.0;
        let got = deflate(x) as f64;
        // Floor: error in [0, 1).
        assert!((0.0..1.0).contains(&(exact - got)), "{x}: {exact} vs {got}");
    }
}

#[test]
fn foot_frame_rotation_matches_f64_within_one_unit() {
    use gaitclip::detect::foot_frame::FootFrameEstimator;
    use gaitclip::sensor::sample::RawSample;
    let mut r = rng();
    for range in [AccelRange::G16, AccelRange::G2] {
        for _ in 0..20 {
            // A frame learnt from a rest in a random attitude.
            let q = random_unit(&mut r);
            let m = q
                .matrix()
                .map(|row| row.map(|v| v as f64 / (1u64 << 30) as f64));
            let lsb = range.lsb_per_g() as f64;
            let up_sensor = [m[2][0] * lsb, m[2][1] * lsb, m[2][2] * lsb];
            let mut est = FootFrameEstimator::new(
                SampleRate::from_hz(200).unwrap(),
                range.scale(),
                GyroRange::Dps2000.scale(),
            );
            let rest = RawSample {
                accel: up_sensor.map(|v| v.round() as i16),
                gyro: [0; 3],
                temp: 0,
            };
            for _ in 0..50 {
                est.process(&rest, true);
            }
            est.process(&rest, false);
            let f = est.frame().expect("frame after a rest");
            let axes = f.axes(range.scale());
            for _ in 0..500 {
                let a = [0; 3].map(|_| r.random::<i16>());
                let got = f.apply(a).0;
                for k in 0..3 {
                    let dot: f64 = (0..3).map(|j| axes[k][j] as f64 * a[j] as f64).sum();
                    let mut exact = dot * 2048.0 / lsb;
                    if k == 2 {
                        exact -= f.gravity() as f64;
                    }
                    let exact = exact.clamp(-32767.0, 32767.0);
                    assert!(
                        (got[k] as f64 - exact).abs() <= 1.0,
                        "{range:?} axis {k}: {} vs {exact}",
                        got[k]
                    );
                }
            }
            // Up is the rest's gravity direction; gravity is 1 g in foot units.
            for j in 0..3 {
                assert!((axes[2][j] as f64 - up_sensor[j] / lsb).abs() < 1e-3);
            }
            assert!((f.gravity() - 2048).abs() <= 1);
        }
    }
}

#[test]
fn mean_filter_with_shorter_window() {
    let mut r = rng();
    let mut filt = MeanFilter::<16>::with_len_log2(2);
    assert_eq!(filt.window(), 4);
    assert_eq!(filt.delay(), 1);
    let mut hist: Vec<[i16; 3]> = Vec::new();
    for _ in 0..5_000 {
        let x = [0; 3].map(|_| r.random::<i16>());
        hist.push(x);
        let y = filt.process(x);
        let win = &hist[hist.len().saturating_sub(4)..];
        for k in 0..3 {
            let mean = win.iter().map(|v| v[k] as f64).sum::<f64>() / win.len() as f64;
            assert!((0.0..1.0).contains(&(mean - y[k] as f64)));
        }
    }
}

/// f64 reference of the ZUPT integrator: same algorithm (level from the stance's mean
/// specific force, gyro bias from its mean rate, exact-normalised first-order attitude with
/// the same |h|²/3 step correction,
/// trapezoidal double integration, linear de-drift), in floating point and SI units.
fn zupt_f64(stance: &[RawSample], movement: &[RawSample], rate_hz: f64) -> ZuptF64 {
    let (acc_lsb, gyr_lsb) = (2048.0 / 9.80665, 16.4 * 180.0 / std::f64::consts::PI);
    let n = stance.len() as f64;
    let mean_a = [0, 1, 2].map(|k| stance.iter().map(|s| s.accel[k] as f64).sum::<f64>() / n);
    let bias = [0, 1, 2].map(|k| stance.iter().map(|s| s.gyro[k] as f64).sum::<f64>() / n);
    let g = mean_a.iter().map(|v| v * v).sum::<f64>().sqrt();
    let u = mean_a.map(|v| v / g);
    let mut att = if u[2] >= 0.0 {
        let c = [1.0 + u[2], u[1], -u[0], 0.0];
        let m = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        c.map(|v| v / m)
    } else {
        let c = [1.0 - u[2], -u[1], -u[0], 0.0];
        let m = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        let q1 = c.map(|v| v / m);
        // q1 ⊗ (0, 1, 0, 0)
        [-q1[1], q1[0], q1[3], -q1[2]]
    };
    let dt = 1.0 / rate_hz;
    let att0 = att;
    let (mut v, mut p2) = ([0f64; 3], [0f64; 3]);
    let mut heights = Vec::new();
    for s in movement {
        let h = [0, 1, 2].map(|k| (s.gyro[k] as f64 - bias[k]) / gyr_lsb * dt / 2.0);
        let h2: f64 = h.iter().map(|v| v * v).sum();
        let h = h.map(|v| v * (1.0 + h2 / 3.0));
        let [w, x, y, z] = att;
        let d = [
            -x * h[0] - y * h[1] - z * h[2],
            w * h[0] + y * h[2] - z * h[1],
            w * h[1] - x * h[2] + z * h[0],
            w * h[2] + x * h[1] - y * h[0],
        ];
        let c = [w + d[0], x + d[1], y + d[2], z + d[3]];
        let m = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        att = c.map(|v| v / m);
        // The rest's departure from 1 g (2048 counts), bounded, removed as an offset along
        // its up (`GravityReading::Offset`).
        let d = (g - 2048.0).clamp(-204.8, 204.8);
        let mut a = rotate_f64(att, [0, 1, 2].map(|k| s.accel[k] as f64 - d * u[k]));
        a[2] -= g - d;
        for k in 0..3 {
            let prev = v[k];
            v[k] += a[k];
            p2[k] += prev + v[k];
        }
        heights.push(p2[2]);
    }
    let nm = movement.len() as f64;
    // Metres at the sensor's scale (2048 counts per g), as the core's default LengthScale.
    let si = dt * dt * 9.80665 / 2048.0 / 2.0;
    let disp = [0, 1, 2].map(|k| (p2[k] - v[k] * nm) * si);
    // De-drifted height at every sample: the linear velocity error leaves v_N·c²/N.
    let max_lift = heights
        .iter()
        .enumerate()
        .map(|(i, &z2)| {
            let c = (i + 1) as f64;
            (z2 - v[2] * c * c / nm) * si
        })
        .fold(0.0f64, f64::max);
    // The heading the x axis turned to under att ⊗ att0*.
    let [w0, x0, y0, z0] = att0;
    let r = quat_mul(att, [w0, -x0, -y0, -z0]);
    let x_axis = rotate_f64(r, [1.0, 0.0, 0.0]);
    let _ = acc_lsb;
    ZuptF64 {
        horizontal: (disp[0].powi(2) + disp[1].powi(2)).sqrt(),
        vertical: disp[2],
        max_lift,
        heading_deg: x_axis[1].atan2(x_axis[0]).to_degrees(),
    }
}

/// What [`zupt_f64`] integrates, m and degrees.
struct ZuptF64 {
    horizontal: f64,
    vertical: f64,
    max_lift: f64,
    heading_deg: f64,
}

fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [w1, x1, y1, z1] = a;
    let [w2, x2, y2, z2] = b;
    [
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ]
}

/// The fixed-point integrator agrees with the f64 reference within 1 mm on every stride of
/// the demo fixture, as recorded and with an accelerometer offset of 60 counts (29 mg) on
/// each axis, which the integrator removes along the rest's up
/// (`GravityReading::Offset`).
#[test]
fn zupt_displacement_matches_f64_reference_within_1mm() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures");
    let recorded = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    let truth = std::fs::read_to_string(dir.join(format!("{FIRMWARE_TRACE}.truth.csv"))).unwrap();
    let rate = SampleRate::from_hz(200).unwrap();
    let mut checked = 0;
    for offset in [0i16, 60] {
        let counts: Vec<RawSample> = recorded
            .iter()
            .map(|s| RawSample {
                accel: s.accel.map(|a| a.saturating_add(offset)),
                ..*s
            })
            .collect();
        for line in truth.lines().skip(1) {
            let c: Vec<&str> = line.split(',').collect();
            let (heel_off, end): (usize, usize) = (c[2].parse().unwrap(), c[5].parse().unwrap());
            let stance = &counts[heel_off - 20..heel_off];
            let movement = &counts[heel_off..end];
            let mut z = ZuptIntegrator::new(
                rate,
                gaitclip_mpu6050::AccelRange::G16.scale(),
                GyroRange::Dps2000.scale(),
            );
            let mut sums = RestSums::new();
            stance.iter().for_each(|s| sums.add(s));
            assert_eq!(sums.count as usize, stance.len());
            assert!(z.start(&sums));
            movement
                .iter()
                .for_each(|s| z.process(s, &gaitclip::sensor::sample::Rails::FULL_SCALE));
            let d = z.displacement();
            let ZuptF64 {
                horizontal: h,
                vertical: v,
                max_lift,
                heading_deg,
            } = zupt_f64(stance, movement, 200.0);
            // The lift over the kept points (every 2nd–8th sample here) against every sample:
            // within the bound `LIFT_POINTS` documents.
            assert!(
                (d.max_lift_um as f64 * 1e-6 - max_lift).abs() < 2.5e-3,
                "lift {} vs {max_lift}",
                d.max_lift_um
            );
            assert!(max_lift > 0.02, "a stride lifts the foot: {max_lift}");
            let turn = z.heading_change_cdeg() as f64 / 100.0;
            // The heading of the integrated attitude: the Q30 integration differs from the f64
            // one by up to 0.03° over the fixture's 90° turn (3·10⁻⁴ relative), the CORDIC by
            // at most 0.01°.
            assert!(
                (turn - heading_deg).abs() <= 0.05,
                "turn {turn} vs {heading_deg}"
            );
            assert!(
                (d.horizontal_um as f64 * 1e-6 - h).abs() < 1e-3,
                "{} vs {h}",
                d.horizontal_um
            );
            assert!(
                (d.vertical_um as f64 * 1e-6 - v).abs() < 1e-3,
                "{} vs {v}",
                d.vertical_um
            );
            checked += 1;
        }
    }
    assert!(checked >= 40);
}

/// `atan2_cdeg` is within 1 centidegree of `atan2` in every quadrant, at the axes and for
/// vectors from a few counts to 2⁶⁰.
#[test]
fn atan2_cdeg_within_one_centidegree() {
    use gaitclip::fixed::atan2_cdeg;
    let exact = |x: i64, y: i64| (y as f64).atan2(x as f64).to_degrees() * 100.0;
    let check = |x: i64, y: i64| {
        let got = atan2_cdeg(x, y);
        let want = exact(x, y);
        // Compared around the circle: −179.997° may round to the cut, +180.00°.
        let diff = (got as f64 - want).rem_euclid(36_000.0);
        assert!(
            diff.min(36_000.0 - diff) <= 1.0,
            "atan2({y}, {x}) = {got} cdeg, want {want}"
        );
        assert!((-18_000..=18_000).contains(&got) && got != -18_000);
    };
    for (x, y) in [
        (1, 0),
        (0, 1),
        (-1, 0),
        (0, -1),
        (-5, -1),
        (-5, 1),
        (1 << 30, 1 << 30),
        ((1 << 60) - 1, -(1 << 60) + 1),
        (-(1 << 60) + 1, 0),
        (3, 4),
    ] {
        check(x, y);
    }
    assert_eq!(atan2_cdeg(0, 0), 0);
    assert_eq!(atan2_cdeg(-7, 0), 18_000);
    let mut r = rng();
    for _ in 0..100_000 {
        let bits = r.random_range(4..60);
        let m = 1i64 << bits;
        check(r.random_range(-m..m), r.random_range(-m..m));
    }
}

fn raw(v: [i16; 7]) -> RawSample {
    RawSample {
        accel: [v[0], v[1], v[2]],
        gyro: [v[3], v[4], v[5]],
        temp: v[6],
    }
}

fn axes(s: &RawSample) -> [i16; 7] {
    [
        s.accel[0], s.accel[1], s.accel[2], s.gyro[0], s.gyro[1], s.gyro[2], s.temp,
    ]
}

/// `bridge::linear` is the straight line between its ends rounded to the nearest count
/// (within ½ count of f64), for any samples and hole lengths up to the fill limit.
#[test]
fn bridge_line_is_the_rounded_straight_line() {
    use gaitclip::signal::bridge::linear;
    let mut r = rng();
    let mut worst = 0f64;
    for _ in 0..20_000 {
        let a: [i16; 7] = std::array::from_fn(|_| r.random());
        let b: [i16; 7] = std::array::from_fn(|_| r.random());
        let n = r.random_range(2..=151u32);
        let k = r.random_range(1..n);
        let got = axes(&linear(&raw(a), &raw(b), k, n));
        for i in 0..7 {
            let exact = a[i] as f64 + (b[i] as f64 - a[i] as f64) * k as f64 / n as f64;
            worst = worst.max((got[i] as f64 - exact).abs());
        }
    }
    eprintln!("linear: worst {worst} counts");
    assert!(worst <= 0.5, "{worst}");
}

/// `bridge::cubic` is the Lagrange cubic through two samples either side of the hole,
/// rounded to the nearest count and saturated: within ½ count of f64 wherever f64 is in
/// range, the rail where it is not; and a cubic in time comes back to the count.
#[test]
fn bridge_cubic_is_the_rounded_lagrange_cubic() {
    use gaitclip::signal::bridge::cubic;
    let mut r = rng();
    let mut worst = 0f64;
    for _ in 0..20_000 {
        let p: [[i16; 7]; 4] = std::array::from_fn(|_| std::array::from_fn(|_| r.random()));
        let m = r.random_range(1..=150u32);
        let k = r.random_range(1..=m);
        let got = axes(&cubic(&p.map(raw), k, m));
        let xs = [-1.0, 0.0, m as f64 + 1.0, m as f64 + 2.0];
        for i in 0..7 {
            let x = k as f64;
            let exact: f64 = (0..4)
                .map(|j| {
                    let w: f64 = (0..4)
                        .filter(|&l| l != j)
                        .map(|l| (x - xs[l]) / (xs[j] - xs[l]))
                        .product();
                    p[j][i] as f64 * w
                })
                .sum();
            let clamped = exact.clamp(i16::MIN as f64, i16::MAX as f64);
            worst = worst.max((got[i] as f64 - clamped).abs());
        }
    }
    eprintln!("cubic: worst {worst} counts (f64 clamped to the rails)");
    assert!(worst <= 0.5 + 1e-6, "{worst}");
    // A cubic in time, sampled at -1, 0, m+1, m+2, is recovered at every sample of the hole.
    let f = |t: f64| 100.0 + 30.0 * t - 2.0 * t * t + 0.05 * t * t * t;
    for m in 1..=12u32 {
        let at = |t: f64| raw([f(t).round() as i16; 7]);
        let ends = [at(-1.0), at(0.0), at(m as f64 + 1.0), at(m as f64 + 2.0)];
        for k in 1..=m {
            let got = cubic(&ends, k, m).accel[0] as f64;
            assert!(
                (got - f(k as f64)).abs() <= 2.0,
                "m {m} k {k}: {got} vs {}",
                f(k as f64)
            );
        }
    }
}

/// Every gyroscope scale the drivers give: the MPU6050's four (counts per °/s with one
/// decimal) and ST's (mdps per count: 4.375 at ±125 °/s, 70 at ±2 000, 140 at ±4 000).
fn gyro_scales() -> Vec<GyroScale> {
    let mut v: Vec<GyroScale> = [
        GyroRange::Dps250,
        GyroRange::Dps500,
        GyroRange::Dps1000,
        GyroRange::Dps2000,
    ]
    .map(|r| r.scale())
    .to_vec();
    v.extend([
        GyroScale::from_ratio(8_000, 35),
        GyroScale::from_mdps_per_lsb(70),
        GyroScale::from_mdps_per_lsb(140),
    ]);
    v
}

#[test]
fn gyro_counts_of_mrad_per_s_within_half_a_count() {
    for gyro in gyro_scales() {
        for mrad in [0u32, 1, 20, 50, 999, 1000, 34_906, 1_000_000] {
            let exact = mrad as f64 / 1000.0 * 180.0 / std::f64::consts::PI * gyro.lsb_per_dps();
            let got = gyro.counts_of_mrad_per_s(mrad) as f64;
            assert!(
                (got - exact).abs() <= 0.5 + exact * 1e-6,
                "{gyro:?} {mrad}: {got} vs {exact}"
            );
        }
    }
}

/// The cycle detector's energy: the Q16 value against the formula in f64, within two Q16
/// units, 10⁻⁵ relative, and what the integer |f| (floored, ≤ 1 count low) can change.
#[test]
fn cycle_energy_matches_f64_within_its_bound() {
    use gaitclip::detect::cycle::CycleConfig;
    use gaitclip::detect::phases::PhaseMethod;
    use gaitclip::pipeline::config::Config;
    let mut r = rng();
    let rate = SampleRate::from_hz(200).unwrap();
    for (accel, gyro) in [
        (AccelRange::G16, GyroRange::Dps2000),
        (AccelRange::G2, GyroRange::Dps250),
        (AccelRange::G8, GyroRange::Dps500),
    ] {
        let cfg = CycleConfig::new(
            rate,
            accel.scale(),
            gyro.scale(),
            gaitclip::sensor::sample::Rails::FULL_SCALE,
            PhaseMethod::MajorPairs,
            80_000,
        );
        let config = Config::new(rate, accel.scale(), gyro.scale());
        let lsb_g = accel.lsb_per_g() as f64;
        let per_count2 = (9.80665 / lsb_g).powi(2) * 65536.0;
        let mut worst = 0f64;
        for _ in 0..20_000 {
            let s = RawSample {
                accel: [0; 3].map(|_| r.random_range(-4000i16..4000)),
                gyro: [0; 3].map(|_| r.random_range(-3000i16..3000)),
                temp: 0,
            };
            let bias = [0; 3].map(|_| r.random_range(-200..200));
            let g = lsb_g as i32 + r.random_range(-50..50);
            let e = cfg.energy_q16(&s, bias, g) as f64;
            let exact = gaitclip_host::reference::cycle_ref::energy(&config, &s, bias, g) * 65536.0;
            if exact >= (1u64 << 26) as f64 {
                assert_eq!(e, (1u64 << 26) as f64, "saturates at 2²⁶");
                continue;
            }
            let f: f64 = s
                .accel
                .iter()
                .map(|&a| (a as f64).powi(2))
                .sum::<f64>()
                .sqrt();
            let d = (f - g as f64).abs();
            let bound = 2.0 + exact * 1e-5 + (2.0 * d + 1.0) * per_count2;
            assert!(
                (e - exact).abs() <= bound,
                "{accel:?} {gyro:?}: {e} vs {exact}"
            );
            worst = worst.max((e - exact).abs() / bound);
        }
        eprintln!("{accel:?} {gyro:?}: worst error {worst:.3} of its bound");
    }
}

/// The rolling contact's velocity `ω × (h·up)` against f64: 10⁻⁴ relative, 10 µm/s absolute.
#[test]
fn rolling_contact_velocity_matches_f64() {
    use gaitclip::detect::zupt::RollingContact;
    let mut r = rng();
    for (hz, gyro) in [
        (100, GyroRange::Dps2000.scale()),
        (200, GyroRange::Dps500.scale()),
        (1000, GyroRange::Dps250.scale()),
        (800, GyroScale::from_mdps_per_lsb(140)),
        (100, GyroScale::from_ratio(8_000, 35)),
    ] {
        let rate = SampleRate::from_hz(hz).unwrap();
        for h_um in [0u32, 40_000, 80_000, 120_000] {
            let rc = RollingContact::new(h_um, rate, gyro);
            for _ in 0..2_000 {
                let q = random_unit(&mut r);
                let w = [0; 3].map(|_| r.random_range(-20_000i32..20_000));
                let gravity_q8 = (2048i64 + r.random_range(-40..40)) << 8;
                let v = rc.velocity_q8(q, w, gravity_q8);
                // Integrator velocity units: v [m/s] = v_q8 · g / (unit_q8 · rate).
                let to_mps = |x: i64| x as f64 * 9.80665 / (gravity_q8 as f64 * hz as f64);
                let rad = std::f64::consts::PI / 180.0 / gyro.lsb_per_dps();
                let wl = rotate_f64(quat_f64(q), w.map(|x| x as f64 * rad));
                let h = h_um as f64 / 1e6;
                let exact = [h * wl[1], -h * wl[0], 0.0];
                for k in 0..3 {
                    let got = to_mps(v[k]);
                    assert!(
                        (got - exact[k]).abs() <= 1e-4 * exact[k].abs() + 1e-5,
                        "{hz} Hz {gyro:?} h {h_um}: axis {k} {got} vs {}",
                        exact[k]
                    );
                }
            }
        }
    }
}

/// The rotation a rail loses, reconstructed from the rate's slopes either side of the clipped
/// run, against the exact area of a parabolic peak cut at the rail (the shape it assumes),
/// for peaks 6–40 samples wide at several sub-sample phases: within −10 %/+30 % (measured:
/// 0.999–1.002, and 1.03–1.27 where a sample falls exactly on the rail and the run counts
/// one sample more than the peak spends above it).
#[test]
fn rail_run_reconstructs_a_clipped_peak() {
    use gaitclip::detect::clipping::RailRun;
    use gaitclip::sensor::sample::AxisRails;
    let mut ratios = Vec::new();
    for (peak, half_width) in [
        (40_000.0, 6.0),
        (60_000.0, 10.0),
        (50_000.0, 25.0),
        (36_000.0, 40.0),
    ] {
        for offset in [0.0, 0.2, 0.4, 0.5, 0.6, 0.8] {
            let rail = i16::MAX as f64;
            // A parabola with its top `peak` at t0, `half_width` samples either side above
            // the rail, and no lower than zero (no second rail).
            let a = (peak - rail) / (half_width * half_width);
            let t0 = 100.0 + offset;
            let mut run = RailRun::NEW;
            for t in 0..200 {
                let x = (peak - a * (t as f64 - t0).powi(2)).max(0.0);
                run.process(
                    x.round().clamp(i16::MIN as f64, i16::MAX as f64) as i16,
                    AxisRails::FULL_SCALE,
                );
            }
            let exact = 4.0 / 3.0 * (peak - rail) * half_width;
            ratios.push((
                run.lost_counts_samples(AxisRails::FULL_SCALE) as f64 / exact,
                half_width,
                offset,
            ));
        }
    }
    eprintln!("reconstructed / exact: {ratios:.3?}");
    for (r, w, o) in ratios {
        assert!(
            (0.9..=1.3).contains(&r),
            "width {w} offset {o}: {r:.3} of the exact area"
        );
    }
}

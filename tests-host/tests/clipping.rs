//! The clipped accelerometer put back ([`gaitclip::detect::clipping`]), measured on real recordings
//! clipped on purpose (`gaitclip clipping`), and the rails learnt from the data
//! ([`gaitclip_host::io::rails`]). Bounds just above the figures measured on 2026-12-03.

use gaitclip::sensor::sample::{AxisRails, Rails};
use gaitclip_host::eval::clip_sweep::{sweep, CLIPPINGS};
use gaitclip_host::eval::markdown::ErrorStats;
use gaitclip_host::io::datasets::{self, root_or_skip};
use gaitclip_host::io::rails::{learn, RailSource};
use gaitclip_host::io::trace::GivenRanges;
use gaitclip_host::io::trace::{ImuSample, Ranges, G_MPS2};
use gaitclip_mpu6050::AccelRange;

#[test]
fn clipped_strides_are_put_back_within_2_cm_at_8_g_and_nearer_at_4_g() {
    let Some(root) = root_or_skip("clipped_strides_are_put_back") else {
        return;
    };
    let gaitmap = datasets::load(&root.join("gaitmap_walk")).unwrap();
    let pyshoe = datasets::load(&root.join("pyshoe_vicon")).unwrap();
    let stats = |d: &datasets::Dataset, k: usize| {
        let r = sweep(d, &CLIPPINGS[k]).unwrap();
        let put: Vec<f64> = r.strides.iter().map(|s| s.restored_m).collect();
        let left: Vec<f64> = r.strides.iter().map(|s| s.left_m).collect();
        (ErrorStats::of(&put), ErrorStats::of(&left))
    };
    // ±8 g, gaitmap_walk (35 clipped strides; measured 1.9 / −0.6 cm, left in 2.9 / −2.3).
    let (put, left) = stats(&gaitmap, 0);
    eprintln!("±8 g gaitmap: put back {put:?}, left in {left:?}");
    assert!(put.n >= 30, "{put:?}");
    assert!(put.rmse <= 0.020 && put.bias.abs() <= 0.008, "{put:?}");
    assert!(put.rmse < left.rmse && put.bias.abs() < left.bias.abs());
    // ±4 g: nearer than the loss left in, on both (measured 3.1 / −1.6 vs 3.8 / −3.0 and
    // 4.2 / −0.7 vs 7.8 / −4.9 cm).
    for d in [&gaitmap, &pyshoe] {
        let (put, left) = stats(d, 1);
        eprintln!("±4 g {}: put back {put:?}, left in {left:?}", d.name);
        assert!(
            put.rmse < left.rmse && put.bias.abs() < left.bias.abs(),
            "{}",
            d.name
        );
        assert!(
            put.rmse
                <= if d.name == "gaitmap_walk" {
                    0.033
                } else {
                    0.053
                }
        );
    }
}

#[test]
fn a_rail_below_the_nominal_range_is_learnt_from_the_recording() {
    let Some(root) = root_or_skip("a_rail_below_the_nominal_range_is_learnt") else {
        return;
    };
    // esangeni_run's z axis clips at −15.65 g, under the ±16 g its counts reach.
    let t =
        gaitclip_host::io::csv_trace::read(&root.join("esangeni_run/course_run_800hz.csv"), None)
            .unwrap();
    let r = learn(&t.samples, Ranges::default(), GivenRanges::default());
    let z = &r.axes[2];
    eprintln!("{}", r.clipped_line());
    assert_eq!(z.low.source, RailSource::Learnt);
    assert!((z.low.value / G_MPS2 + 15.6).abs() < 0.1, "{z:?}");
    assert!(z.clipped >= 20, "{z:?}");
    // The gyro's peaks (1 754 °/s at most) are smooth: no rail.
    assert!(r.axes[3..].iter().all(|a| a.clipped == 0), "{r:?}");
}

fn samples(f: impl Fn(usize) -> f64) -> Vec<ImuSample> {
    (0..4000)
        .map(|i| ImuSample {
            t_s: i as f64 / 200.0,
            acc_mps2: [f(i), 0.0, 9.8],
            gyr_radps: [0.0; 3],
        })
        .collect()
}

#[test]
fn flat_runs_at_an_extreme_are_a_rail_and_smooth_peaks_are_not() {
    // Spikes to 10 g every 200 samples, clipped at 7 g: the same flat top every time.
    let spike = |i: usize| {
        let k = (i % 200) as f64;
        let v = 10.0 * (-(k - 100.0).powi(2) / 4.0).exp() * G_MPS2;
        v.min(7.0 * G_MPS2)
    };
    let r = learn(
        &samples(spike),
        Ranges::default(),
        GivenRanges {
            acc_g: Some(8.0),
            gyro_dps: None,
        },
    );
    let x = &r.axes[0];
    assert_eq!(x.high.source, RailSource::Learnt, "{x:?}");
    assert!((x.high.value / G_MPS2 - 7.0).abs() < 0.04, "{x:?}");
    assert!(x.clipped >= 20);
    assert_eq!(
        r.rails.accel[0].high,
        ((x.high.value * 2048.0 / G_MPS2).floor()) as i16
    );
    // Peaks of different heights, none repeated: no rail, the nominal range stands.
    let smooth = |i: usize| {
        let k = (i % 200) as f64;
        (5.0 + (i / 200) as f64 * 0.1) * (-(k - 100.0).powi(2) / 50.0).exp() * G_MPS2
    };
    let r = learn(
        &samples(smooth),
        Ranges::default(),
        GivenRanges {
            acc_g: Some(8.0),
            gyro_dps: None,
        },
    );
    assert_eq!(
        r.axes[0].high.source,
        RailSource::Nominal,
        "{:?}",
        r.axes[0]
    );
    assert_eq!(r.axes[0].clipped, 0);
    // Without a given range the counts' own ±16 g is the rail.
    let r = learn(&samples(smooth), Ranges::default(), GivenRanges::default());
    assert_eq!(r.rails.accel[0], AxisRails::FULL_SCALE);
    assert_eq!(
        Rails::FULL_SCALE.accel[0],
        AxisRails::new(i16::MIN, i16::MAX).unwrap()
    );
    let _ = AccelRange::G16;
}

#[test]
fn a_sprints_two_rails_cost_running_strides_under_a_centimetre() {
    let Some(root) = root_or_skip("a_sprints_two_rails_cost_running_strides") else {
        return;
    };
    use gaitclip_host::eval::clip_sweep::{sweep_of, Clipped, SPRINT_CLIPPINGS, SPRINT_DATASETS};
    // Both sensors at half their range (measured 2026-12-07: 2.3 / −0.2 cm on esangeni_run's
    // 12 strides, 2.8 / −0.6 on esangeni_course's 160; the accelerometer's loss left in
    // 7.4 / −3.1 and 5.0 / −2.4).
    let both = &SPRINT_CLIPPINGS[2];
    for name in SPRINT_DATASETS {
        let d = datasets::load(&root.join(name)).unwrap();
        let r = sweep_of(&d, both, Clipped::Newly).unwrap();
        let put = ErrorStats::of(&r.strides.iter().map(|s| s.restored_m).collect::<Vec<_>>());
        let left = ErrorStats::of(&r.strides.iter().map(|s| s.left_m).collect::<Vec<_>>());
        eprintln!("{name}: put back {put:?}, left in {left:?}");
        assert!(put.n >= 10, "{name}: {put:?}");
        assert!(
            put.bias.abs() <= 0.01 && put.rmse <= 0.035,
            "{name}: {put:?}"
        );
        assert!(
            put.rmse < left.rmse && put.bias.abs() < left.bias.abs(),
            "{name}"
        );
    }
}

//! The cycle detector's fixed-point strides against their `f64` twin
//! ([`gaitclip_host::reference::cycle_ref`]): every stride of every trial of the three datasets, at the
//! MPU6050's widest ranges, at ±250 °/s (where nearly every stride clips and the tilt
//! is put back on the clipped samples) and at ±8 g and ±4 g (where the accelerometer's heel
//! strikes and push-offs clip and their loss is put back), within 1 mm of the twin, and their
//! direction of travel within what 1 mm allows.

use gaitclip_host::io::datasets::root_or_skip;
use gaitclip_host::io::trace::Ranges;
use gaitclip_host::reference::cycle_ref::{self, Skipped};
use gaitclip_host::{io::csv_trace, io::datasets, replay};
use gaitclip_mpu6050::{AccelRange, GyroRange};

#[test]
fn cycle_strides_match_the_f64_twin_within_1_mm() {
    let Some(root) = root_or_skip("cycle_strides_match_the_f64_twin_within_1_mm") else {
        return;
    };
    let widest = Ranges::default();
    let clipping = Ranges {
        accel: AccelRange::G16,
        gyro: GyroRange::Dps250,
    };
    let accel = |accel| Ranges {
        accel,
        gyro: GyroRange::Dps2000,
    };
    for (name, ranges) in [
        ("gaitmap_walk", widest),
        ("pyshoe_vicon", widest),
        ("ipol_gait_events", widest),
        ("gaitmap_walk", clipping),
        ("pyshoe_vicon", clipping),
        ("gaitmap_walk", accel(AccelRange::G8)),
        ("pyshoe_vicon", accel(AccelRange::G4)),
    ] {
        let d = datasets::load(&root.join(name)).unwrap();
        let (mut measured, mut valid, mut worst, mut clipped) = (0usize, 0usize, 0f64, 0usize);
        let mut accel_clipped = 0usize;
        let mut skipped = [0usize; 4];
        for trial in &d.trials {
            let t = csv_trace::read(&trial.csv, Some(d.rate_hz)).unwrap();
            let p = replay::prepare(&t, ranges).unwrap();
            let run = cycle_ref::run(&p.counts, &p.clock.holes, p.config(ranges));
            for (k, s) in run.strides.iter().enumerate() {
                if s.flags.valid() {
                    valid += 1;
                }
                match cycle_ref::horizontal(&run, k) {
                    Ok(h) => {
                        let m = h.norm();
                        // The direction of travel agrees as far as 1 mm allows, plus the
                        // CORDIC's centidegree.
                        if m >= 0.1 {
                            let twin = h.y.atan2(h.x).to_degrees();
                            let core = s.travel_cdeg as f64 / 100.0;
                            let d = (core - twin + 540.0).rem_euclid(360.0) - 180.0;
                            let bound = (1e-3 / m).to_degrees() + 0.01;
                            assert!(
                                d.abs() <= bound,
                                "{name} {} stride {k}: travel core {core}°, f64 {twin:.3}°",
                                trial.name
                            );
                        }
                        let e = (s.zupt_um as f64 / 1e6 - m).abs();
                        assert!(
                            e <= 1e-3,
                            "{name} {} stride {k} ({}..{}): core {} µm, f64 {:.0} µm",
                            trial.name,
                            s.events.start,
                            s.events.end,
                            s.zupt_um,
                            m * 1e6
                        );
                        worst = worst.max(e);
                        measured += 1;
                        if s.flags
                            .has(gaitclip::record::stride::StrideFlags::GYRO_CLIPPED)
                        {
                            clipped += 1;
                        }
                        if s.flags
                            .has(gaitclip::record::stride::StrideFlags::ACCEL_CLIPPED)
                        {
                            accel_clipped += 1;
                        }
                    }
                    Err(why) => {
                        skipped[match why {
                            Skipped::Flagged => 0,
                            Skipped::NoPrevious => 1,
                            Skipped::Missing => 2,
                            Skipped::LongRest => 3,
                        }] += 1
                    }
                }
            }
        }
        eprintln!(
            "{name} at {:?}/{:?}: {measured} of {valid} valid strides measured ({clipped} gyro \
             clipped, {accel_clipped} accelerometer clipped), \
             worst {:.3} mm; skipped: flagged {}, first after a rest {}, missing {}, long rest {}",
            ranges.gyro,
            ranges.accel,
            worst * 1e3,
            skipped[0],
            skipped[1],
            skipped[2],
            skipped[3]
        );
        // The twin measures the strides that matter: every stride but the first of a walk
        // (at least 84 % of them: 84.4 % in `pyshoe_vicon` at ±250 °/s, 126 of its 808
        // valid strides the first after a rest).
        assert!(
            measured as f64 >= 0.84 * valid as f64,
            "{name}: only {measured} of {valid} valid strides measured"
        );
        if ranges.gyro == GyroRange::Dps250 {
            assert!(clipped * 2 >= measured, "{name}: {clipped} clipped strides");
        }
        if ranges.accel != AccelRange::G16 {
            assert!(
                accel_clipped * 4 >= measured,
                "{name}: {accel_clipped} accelerometer-clipped strides"
            );
        }
    }
}

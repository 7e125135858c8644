//! The simulated sprints (`gaitclip sprint`, docs/sensors.md), and one of them as the
//! LSM6DSV320X's FIFO delivers it: the trace the emulated board replays with that part.

use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag};
use gaitclip_lsm6dsv320x::{AccelRange, GyroRange, HighGRange};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::io::trace::{quantize, G_MPS2};
use crate::sim::gait_sim::{Scenario, Segment, Trajectory, Vigour};

/// A sprinting stride: 3.8 m in 0.54 s (7 m/s), 0.12 s of it on the ground.
pub const SPRINT_LENGTH_M: f64 = 3.8;
/// Its stance, s.
pub const SPRINT_STANCE_S: f64 = 0.12;
/// Its movement, heel-off to foot-flat, s.
pub const SPRINT_MOVEMENT_S: f64 = 0.42;

/// A sprint's vigour with touch-down at `touch_down_g` (the dip's peak specific force above
/// the motion's own): a 25 ms dip, and a 35 ms toe-off snap of 26° (±2 300 °/s on top of
/// the swing's own rotation).
pub fn sprint_vigour(touch_down_g: f64) -> Vigour {
    let dip_s = 0.025;
    let k = (std::f64::consts::PI / dip_s).powi(2);
    Vigour {
        impact_g: 0.0,
        clearance_m: 0.30,
        pitch_rad: 0.9,
        dip_m: touch_down_g * G_MPS2 / (4.0 * k),
        dip_s,
        snap_rad: 26f64.to_radians(),
        snap_s: 0.035,
    }
}

/// The simulated sprints: stand, two strides to speed, twelve sprint strides, two to stop,
/// stand; touch-down at 40 g and at 70 g.
pub fn scenarios() -> Vec<Scenario> {
    let stride = |strides, length_m, stance_s, movement_s, flag| Segment::Walk {
        strides,
        length_m,
        stance_s,
        movement_s,
        turn_deg: 0.0,
        flag,
    };
    [(40.0, "sprint_40g", 11), (70.0, "sprint_70g", 12)]
        .into_iter()
        .map(|(g, name, seed)| Scenario {
            name,
            description:
                "a sprint: clip on the laces, two strides to speed, twelve at 7 m/s, two to stop",
            rate_hz: 960.0,
            mounting_deg: [5.0, -10.0, 0.0],
            seed,
            vigour: sprint_vigour(g),
            segments: vec![
                Segment::Stand(2.0),
                stride(1, 1.6, 0.3, 0.5, "first"),
                stride(1, 2.8, 0.18, 0.45, "speeding"),
                stride(12, SPRINT_LENGTH_M, SPRINT_STANCE_S, SPRINT_MOVEMENT_S, ""),
                stride(1, 2.4, 0.18, 0.45, "slowing"),
                stride(1, 1.0, 0.3, 0.5, "last"),
                Segment::Stand(2.0),
            ],
        })
        .collect()
}

/// The LSM6DSV320X's low-g and gyroscope rate in the sprint recordings, Hz.
pub const LSM_RATE_HZ: u32 = 240;
/// Its high-g rate, Hz: four high-g samples per low-g period.
pub const LSM_HIGH_G_RATE_HZ: u32 = 960;
/// FIFO words per low-g period: four high-g, one low-g, one gyroscope.
pub const LSM_WORDS_PER_SAMPLE: usize = 6;
/// The LSM6DSV320X's ranges in the sprint recordings.
pub const LSM_ACCEL: AccelRange = AccelRange::G16;
/// The high-g range.
pub const LSM_HIGH_G: HighGRange = HighGRange::G128;
/// The gyroscope's range.
pub const LSM_GYRO: GyroRange = GyroRange::Dps4000;

/// Records `sc` as the LSM6DSV320X's FIFO would hold it at [`LSM_RATE_HZ`] with the high-g
/// channel at [`LSM_HIGH_G_RATE_HZ`]: the trajectory sampled at each channel's instants with
/// the scenario's biases and noise (seeded by the scenario), quantised and saturated at the
/// channel's scale. The words in FIFO order: per low-g period, its four high-g words (oldest
/// first), the low-g word and the gyroscope word, all with the period's time slot.
pub fn lsm_fifo(sc: &Scenario) -> Vec<FifoWord> {
    let mut rng = ChaCha8Rng::seed_from_u64(sc.seed);
    let tr = Trajectory::new(sc, &mut rng);
    let rate = LSM_RATE_HZ as f64;
    let per = (LSM_HIGH_G_RATE_HZ / LSM_RATE_HZ) as usize;
    let n = (tr.duration_s * rate).floor() as usize + 1;
    let k = |lsb_per_g: u32| lsb_per_g as f64 / G_MPS2;
    let (low_k, high_k) = (k(LSM_ACCEL.lsb_per_g()), k(LSM_HIGH_G.lsb_per_g()));
    let gyro_k = LSM_GYRO.scale().lsb_per_dps() * 180.0 / std::f64::consts::PI;
    let counts = |v: [f64; 3], k: f64| v.map(|x| quantize(x * k));
    let mut out = Vec::with_capacity(n * LSM_WORDS_PER_SAMPLE);
    for i in 0..n {
        let t = i as f64 / rate;
        let slot = (i % 4) as u8;
        // The high-g samples of the period (t − 1/rate, t], oldest first.
        for j in (0..per).rev() {
            let h = tr.sample(t - j as f64 / (rate * per as f64), &mut rng);
            out.push(FifoWord {
                tag: Tag::HighG,
                slot,
                data: counts(h.acc_mps2, high_k),
            });
        }
        let low = tr.sample(t, &mut rng);
        out.push(FifoWord {
            tag: Tag::Accel,
            slot,
            data: counts(low.acc_mps2, low_k),
        });
        out.push(FifoWord {
            tag: Tag::Gyro,
            slot,
            data: counts(low.gyr_radps, gyro_k),
        });
    }
    out
}

//! `gaitclip eval`: strides, gait events, phases and stance against the ground truth of the
//! recordings in `../shared/datasets`.
//!
//! **Clock.** Everything is compared in the sensor clock's sample numbers, which the core
//! counts (rows plus the periods lost in holes, [`crate::io::clock`]): a reference given as a
//! row is mapped to its number, a reference given as a time (`ipol_gait_events`'
//! `toe_off_s`/`heel_strike_s`, the walk bounds `walk_*_s`) to the number nearest it on the
//! recovered clock. Event errors are then whole periods of the sensor, unaffected by holes.
//!
//! **Matching.** A detected stride is its movement, heel-off to foot-flat. A reference stride
//! is the interval its dataset defines (`gaitmap_walk`: mid-stance to mid-stance;
//! `pyshoe_vicon`: end of stance to end of stance; `ipol_gait_events`: the footstep, toe-off
//! to heel-strike). Each contains the foot's one movement, so a detection matches a
//! reference when their overlap is at least half the shorter of the two; pairs are taken
//! greedily by overlap, one to one. Only detections overlapping the labelled part of a
//! recording count (from the first to the last reference stride; `ipol_gait_events`: its
//! walk bounds). Flagged references (first/last strides, turns, shuffles, U-turn steps) and
//! the detections matched to them or lying mostly (half their movement or more) inside one
//! count neither as found nor as missed nor as extra (*not scored*); so do detections mostly
//! inside `ipol_gait_events`' U-turn, whose steps are labelled only in part. A detection
//! matched to nothing that `pyshoe_vicon`'s Vicon stance label shows to be a movement of the
//! foot (moving over half of it or more: a shuffle, or a stride inside borders that merged
//! two) is counted apart as an *unbordered movement*, not as extra: the stride borders of
//! that dataset were drawn in part by an automatic detector.
//!
//! **Events.** Toe-off and heel-strike errors are detected minus reference, over clean
//! matched strides, reported as the median and 95th percentile of their absolute value.
//!
//! **Phases** (Huang eq. 7–13). Swing is toe-off → heel-strike; contact is the previous
//! heel-strike → toe-off (heel-strike phase, stance and push-off together, which is what the
//! labels bound). A detected phase is a true positive when its IoU with the reference phase
//! of the matched stride is at least 0.5; the IoU column is the mean over true positives.
//!
//! **Stance** (`pyshoe_vicon`): sample-wise F1 of "not inside a detected movement" against
//! the Vicon stance label, over the labelled part of each trial.
//!
//! The datasets and their references are loaded by [`crate::io::datasets`], matched and scored by
//! [`crate::eval::matching`], and written as tables by [`crate::eval::tables`].

use anyhow::Result;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::io::csv_trace;
use crate::io::trace::{ImuSample, Ranges, Trace};

use crate::eval::matching::{score, Detected, Detections, Tally};
use crate::io::datasets::Dataset;

/// A rotation matrix drawn uniformly (from a random unit quaternion).
pub fn random_rotation(rng: &mut impl Rng) -> [[f64; 3]; 3] {
    let q: [f64; 4] = loop {
        let v = [0; 4].map(|_| rng.random_range(-1.0..1.0f64));
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 0.1 && n <= 1.0 {
            break v.map(|x| x / n);
        }
    };
    rotation_matrix(q)
}

/// The rotation matrix of a unit quaternion `[w, x, y, z]` (`v' = M·v`).
pub fn rotation_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The trace as a clip mounted at rotation `r` would have recorded it.
pub fn rotate(samples: &[ImuSample], r: &[[f64; 3]; 3]) -> Vec<ImuSample> {
    let mul = |v: [f64; 3]| r.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2]);
    samples
        .iter()
        .map(|s| ImuSample {
            t_s: s.t_s,
            acc_mps2: mul(s.acc_mps2),
            gyr_radps: mul(s.gyr_radps),
        })
        .collect()
}

/// A detector under evaluation: from a trace (counts at `ranges`) to strides.
pub type Detector<'a> = &'a dyn Fn(&Trace, Ranges) -> Result<Detections>;

/// The core's detector with `config` adjusted by `setup`, as `gaitclip eval` runs it: the
/// trace is prepared ([`crate::replay::prepare`]: counts, recovered clock, holes) and its
/// strides reported in sample numbers.
pub fn core_detector(
    setup: impl Fn(&mut gaitclip::pipeline::config::Config),
) -> impl Fn(&Trace, Ranges) -> Result<Detections> {
    move |t: &Trace, r: Ranges| {
        let prepared = crate::replay::prepare(t, r)?;
        let mut config = prepared.config(r);
        setup(&mut config);
        Ok(Detections {
            strides: prepared
                .strides(config)
                .iter()
                .map(Detected::from)
                .collect(),
            clock: prepared.clock,
        })
    }
}

/// Results of one dataset: the tally of the unrotated traces, and one per rotation.
pub struct DatasetResult {
    /// Dataset name.
    pub name: String,
    /// As recorded.
    pub tally: Tally,
    /// After each random rotation.
    pub rotated: Vec<Tally>,
}

/// Runs `detector` on every trial of `dataset`, as recorded and after `rotations` random
/// rotations (seeded by `seed`, one sequence per trial).
pub fn evaluate(
    dataset: &Dataset,
    detector: Detector,
    rotations: usize,
    seed: u64,
) -> Result<DatasetResult> {
    let ranges = Ranges::default();
    let mut tally = Tally::default();
    let mut rotated = vec![Tally::default(); rotations];
    for (k, trial) in dataset.trials.iter().enumerate() {
        let trace = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        tally.add(&score(trial, &detector(&trace, ranges)?));
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (k as u64).wrapping_mul(0x9E37_79B9));
        for r in rotated.iter_mut() {
            let m = random_rotation(&mut rng);
            let t = Trace {
                samples: rotate(&trace.samples, &m),
                ..trace.clone()
            };
            r.add(&score(trial, &detector(&t, ranges)?));
        }
    }
    Ok(DatasetResult {
        name: dataset.name.clone(),
        tally,
        rotated,
    })
}

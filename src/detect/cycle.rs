//! The every-pace stance detector: one zero-velocity instant per gait cycle, from slow
//! walking to running, and the stride between two of them measured by strapdown
//! integration with the rolling foot's velocity imposed at both ends.
//!
//! **Why not a threshold.** A walking foot at rest reads almost nothing; a jogging foot never
//! drops below ≈ 0.5–1 rad/s on the ground. No fixed threshold on a stance statistic serves
//! both (Huang's [`crate::detect::stance`] detector merges strides at speed; SHOE's own thresholds
//! fail one pace or the other). What every pace shares is the shape of the cycle: each
//! cycle's stillest moment lies far below the swings either side of it.
//!
//! **The energy.** Per sample, `e = |ω − b|² / σω² + (|f| − g)² / σa²` (angular rate minus
//! the rest's gyro bias, specific force against the rest's gravity; σω = 1 rad/s,
//! σa = 1 m/s²), averaged over a centred window of [`ENERGY_WINDOW_MS`]: a SHOE-type
//! statistic, in Q16 of (rad/s)².
//!
//! **One instant per cycle.** After a stance, the energy rises into a swing. A sample is a
//! *candidate* stance when the swing since the last stance has risen at least
//! [`PROMINENCE_MILLIDECADES`] above it (and reached [`SWING_MIN_Q16`]: a step, not a
//! fidget), the gyro's up, integrated from the last stance, agrees with the accelerometer's
//! gravity within [`ATTITUDE_MAX_DEG`] (early in a swing the pitch rate crosses zero and
//! looks like a stance for 20–30 ms: there the two differ by 60–90°), and gravity is within
//! [`FLAT_MAX_DEG`] of the foot's standing up. The stillest candidate wins; it is confirmed
//! once the energy after it has risen by the prominence again (the next push-off) and
//! [`CONFIRM_MS`] have passed without a candidate [`SUPERSEDE_MILLIDECADES`] deeper (a slow
//! swing dips in the middle; the stance after it is far stiller). At rest (energy under
//! [`REST_Q16`]) a later instant is as good as a stiller one: the stance instant follows the
//! rest, and a stance that lasts [`MAX_STANCE_IN_STRIDE_MS`] ends the stride before it (the last step
//! before standing).
//!
//! **Not where the foot cannot have landed.** Inside a walk (the stride starts where a step
//! that counted landed), a candidate is passed over when the step check
//! ([`crate::detect::step_check`]) would surely refuse the stride ending there: the rest test
//! found no rest from the stride's heel-off to [`step_check::REST_NEAR_MS`] after the
//! candidate (nor before the next heel-off; a blip of movement inside a rest does not end it,
//! as in the check's ledger), and either the foot swung slower than a run starts
//! ([`step_check::RUN_START_SWING_MRADPS`]) or less than a step ([`step_check::SWING_MIN_DEG`]),
//! or, swung as a run starts but slower than a runner's ([`step_check::RUN_SWING_MRADPS`]), the
//! stride's own integration to the candidate did not land it on the level a step away
//! ([`step_check::lands_a_step_away`], what the check asks of a run's first stride). A slow
//! stride whose swing dips, a crawl's drag, or a stride out of a stand that stops short and
//! goes on, was cut there into two halves that both counted nowhere; passed over, the stride
//! goes on to the next stance instant and is judged whole. The candidate ends the stride
//! after all if the stride would outlast a step ([`step_check::STEP_MAX_MS`]).
//!
//! **The stride.** A strapdown integrator ([`ZuptIntegrator`]) starts at each candidate:
//! levelled from the mean specific force of the stance so far (the stretch where the energy
//! lies the prominence below the swing), gyro bias and gravity from the last rest, and the
//! velocity of a sensor [`SENSOR_HEIGHT_UM`] above the foot's rolling contact
//! ([`RollingContact`]): the foot rolls at its stillest instant, and imposing zero there
//! makes strides short, the more so the faster. At the next confirmed instant the same
//! velocity is imposed at the end, the difference removed as linear drift. Per stride, no
//! state carries over but the rest's calibration.
//!
//! **The record.** A stride runs from one stance instant to the next (mid-stance to
//! mid-stance); its movement from heel-off (the energy [`EDGE_MILLIDECADES`] above the
//! instant's) to foot-flat (the energy back under the swing by the prominence), where
//! Huang's phase splitter finds toe-off and heel-strike and the phase statistics are taken.
//!
//! Streaming, integer and bounded: a ring of [`ENERGY_CAPACITY`] energies, three
//! integrators (the stride, its state at the candidate, the next stride's from the
//! candidate), and the movement buffer of the stride tracker.

use heapless::Vec;

use crate::detect::foot_frame::{sagittal_rate, FootFrameEstimator};
use crate::detect::gyro_events;
use crate::detect::phase_stats::{StrideStats, CHANNELS};
use crate::detect::phases::{self, PhaseMethod};
use crate::detect::seam::MAX_STANCE_IN_STRIDE_MS;
use crate::detect::seam::{DetectConfig, Drain, Input, StepDetector};
use crate::detect::step_check::{self, StepLedger};
use crate::detect::zupt::{Displacement, RollingContact, ZuptIntegrator};
use crate::fixed::{isqrt_u64, QuatQ30};
use crate::record::stride::{Stride, StrideEvents, StrideFlags};
use crate::sensor::rate::SampleRate;
use crate::sensor::sample::Origin;
use crate::sensor::sample::{Rails, RawSample};
use crate::sensor::units::FOOT_LSB_PER_G;
use crate::sensor::units::{AccelScale, FootAccel, GyroScale};

/// Energy window, ms (5 samples at 100 Hz, as SHOE's; 11 at 200 Hz).
pub const ENERGY_WINDOW_MS: u32 = 50;
/// Ring capacity of the energies: a power of two above the window at 1 kHz (51).
pub const ENERGY_CAPACITY: usize = 64;
/// σω of the energy, mrad/s.
pub const SIGMA_W_MRADPS: u32 = 1000;
/// σa of the energy, mm/s².
pub const SIGMA_A_MMPS2: u32 = 1000;
/// A stance lies at least this far below the swing either side, millidecades (1.25 decades,
/// × 17.8).
pub const PROMINENCE_MILLIDECADES: u32 = 1250;
/// A confirmed candidate gives way to one at least this much deeper, millidecades (× 10).
pub const SUPERSEDE_MILLIDECADES: u32 = 1000;
/// Heel-off: the energy this far above the stance instant's, millidecades (× 3.2).
pub const EDGE_MILLIDECADES: u32 = 500;
/// A candidate is confirmed this long after it, ms.
pub const CONFIRM_MS: u32 = 500;
/// Stances at least this far apart, ms.
pub const MIN_SPACING_MS: u32 = 300;
/// A swing reaches at least this energy, Q16 of (rad/s)² (1 (rad/s)²: a step, not a fidget).
pub const SWING_MIN_Q16: u64 = 1 << 16;
/// At rest the energy is under this, Q16 of (rad/s)² (0.01 (rad/s)², ≈ 6 °/s).
pub const REST_Q16: u64 = 655;
/// Gyro's up against the accelerometer's gravity at a stance, at most, degrees.
pub const ATTITUDE_MAX_DEG: u32 = 45;
/// Gravity against the foot's standing up at a stance, at most, degrees.
pub const FLAT_MAX_DEG: u32 = 60;
/// At a zero-velocity instant the foot on the ground turns at most this fast, mrad/s: a
/// walking foot at its stillest under 0.3 rad/s, a running one rolling over at 0.5–1.5
/// (`esangeni_run`, `pyshoe_vicon`'s runs). A slow stride's swing holds a steady 3–4 rad/s
/// through its middle while its energy dips (`esangeni_course`'s slow walks at 800 Hz): an
/// instant faster than this is a stance only at the walker's own cadence
/// ([`CADENCE_MIN_PERMILLE`]).
pub const STANCE_RATE_MAX_MRADPS: u32 = 1500;
/// A stride that ends at a fast instant ([`STANCE_RATE_MAX_MRADPS`]) lasts at least this share
/// of the stride before it, ‰: a runner's strides follow one another at one cadence, a split
/// slow stride's halves last 0.3–0.5 of it.
pub const CADENCE_MIN_PERMILLE: u32 = 600;
/// The sensor's height above the foot's rolling contact, µm. A clip on the side of the shoe
/// sits ≈ 4–6 cm above it, one on the laces ≈ 8–10 cm; measured: docs/accuracy.md (`gaitclip zupt-sweep`).
pub const SENSOR_HEIGHT_UM: u32 = 80_000;

/// Columns of the movement buffer: Huang's [`CHANNELS`] and the sagittal rate
/// ([`SAGITTAL_RATE_COLUMN`]).
pub const MOVEMENT_COLUMNS: usize = CHANNELS + 1;
/// The movement buffer's column of the sagittal angular rate (gyro counts about the foot's
/// pitch axis, either sign), for [`gyro_events`].
pub const SAGITTAL_RATE_COLUMN: usize = CHANNELS;

/// cos²(45°) and cos²(60°) in Q30.
const COS2_45_Q30: i128 = 1 << 29;
const COS2_60_Q30: i128 = 1 << 28;

/// `10^(millidecades/1000)` as a ratio `num/den` (to 0.01 %), for the three constants above.
const fn ratio(millidecades: u32) -> (u64, u64) {
    match millidecades {
        1250 => (177_828, 10_000),
        1000 => (100_000, 10_000),
        500 => (31_623, 10_000),
        _ => (10_000, 10_000),
    }
}

/// The detector's constants at one rate and range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CycleConfig {
    /// Half the energy window, samples (the window is 2·half + 1).
    pub half: u32,
    /// Samples of [`CONFIRM_MS`], [`MIN_SPACING_MS`], [`MAX_STANCE_IN_STRIDE_MS`].
    pub confirm: u32,
    /// See [`MIN_SPACING_MS`].
    pub spacing: u32,
    /// See [`MAX_STANCE_IN_STRIDE_MS`].
    pub max_stance: u32,
    /// Samples of [`crate::detect::seam::MAX_MOVEMENT_MS`].
    pub max_movement: u32,
    /// Gyro counts² → Q40 of (rad/s)²/σω².
    k_w: u64,
    /// Accelerometer counts² → Q40 of (m/s²)²/σa².
    k_a: u64,
    /// The rolling contact's velocity.
    rolling: RollingContact,
    /// Phase splitter.
    pub phases: PhaseMethod,
    merge: u32,
    integrator: ZuptIntegrator,
    /// Where each axis clips.
    pub rails: Rails,
    /// Whether the accelerometer's loss at its rails is put back ([`Config::restore_accel`](crate::pipeline::config::Config::restore_accel)).
    pub restore_accel: bool,
    /// [`gyro_events::SWING_MIN_MRADPS`] in gyro counts.
    swing_min: i16,
    /// [`STANCE_RATE_MAX_MRADPS`] in gyro counts, squared.
    stance_rate_max_sq: i64,
    /// Samples of [`step_check::REST_NEAR_MS`].
    rest_near: u32,
    /// Samples of [`step_check::REST_BLIP_MS`].
    rest_blip: u32,
    /// Samples of [`step_check::STEP_MAX_MS`].
    step_max: u32,
}

impl CycleConfig {
    /// The constants for `rate`, the ranges and their `rails`, Huang's splitter `phases`
    /// and a sensor `sensor_height_um` above the foot's rolling contact
    /// ([`SENSOR_HEIGHT_UM`]).
    pub const fn new(
        rate: SampleRate,
        accel: AccelScale,
        gyro: GyroScale,
        rails: Rails,
        phases: PhaseMethod,
        sensor_height_um: u32,
    ) -> Self {
        let w = rate.samples_in_ms(ENERGY_WINDOW_MS);
        let mut half = w / 2;
        if half < 1 {
            half = 1;
        }
        if half as usize > (ENERGY_CAPACITY - 1) / 2 {
            half = ((ENERGY_CAPACITY - 1) / 2) as u32;
        }
        // (rad/s per count)² = (π·dps / (180·lsb))²; ÷ σω²; × 2⁴⁰ (the scale is lsb counts per
        // dps °/s).
        let (lsb, dps) = (gyro.lsb() as u128, gyro.dps() as u128);
        let pi_q32 = 13_493_037_705u128;
        let sw = SIGMA_W_MRADPS as u128;
        // π²·dps²·10⁶ / (180²·lsb²·σω²[mrad²]) · 2⁴⁰ = (π·2³²)²·dps²·10⁶·2⁴⁰ / (2⁶⁴·180²·lsb²·σ²):
        // below 2¹²⁸ for dps up to 10³ (π²·2⁶⁴ < 2⁶⁸, 10⁶·10⁶ < 2⁴⁰).
        let k_w =
            ((pi_q32 * pi_q32 * dps * dps * 1_000_000) / (180 * 180 * lsb * lsb * sw * sw)) >> 24;
        // (m/s² per count)² = (9.80665 / lsb_g)²; ÷ σa²; × 2⁴⁰.
        let lsb_g = accel.lsb_per_g() as u128;
        let sa = SIGMA_A_MMPS2 as u128;
        // 9806.65² mm²/s⁴ per g² → (9806.65 / (lsb·σa[mm]))² · 2⁴⁰, with 9806.65 = 980665/100.
        let k_a = ((980_665u128 * 980_665u128) << 40) / (lsb_g * lsb_g * sa * sa * 10_000);
        CycleConfig {
            half,
            confirm: rate.samples_in_ms(CONFIRM_MS),
            spacing: rate.samples_in_ms(MIN_SPACING_MS),
            max_stance: rate.samples_in_ms(MAX_STANCE_IN_STRIDE_MS),
            max_movement: rate.samples_in_ms(crate::detect::seam::MAX_MOVEMENT_MS),
            k_w: k_w as u64,
            k_a: k_a as u64,
            rolling: RollingContact::new(sensor_height_um, rate, gyro),
            phases,
            merge: rate.samples_in_ms(phases::MERGE_MS),
            integrator: ZuptIntegrator::new(rate, accel, gyro),
            rails,
            restore_accel: true,
            stance_rate_max_sq: {
                let c = gyro.counts_of_mrad_per_s(STANCE_RATE_MAX_MRADPS) as i64;
                c * c
            },
            rest_near: rate.samples_in_ms(step_check::REST_NEAR_MS),
            rest_blip: rate.samples_in_ms(step_check::REST_BLIP_MS),
            step_max: rate.samples_in_ms(step_check::STEP_MAX_MS),
            swing_min: {
                let c = gyro.counts_of_mrad_per_s(gyro_events::SWING_MIN_MRADPS);
                if c > i16::MAX as u32 {
                    i16::MAX
                } else {
                    c as i16
                }
            },
        }
    }

    /// Samples between the newest input and the sample a decision is about.
    pub const fn delay(&self) -> u32 {
        self.half
    }

    /// The energy of one sample, Q16 of (rad/s)² (saturated at 2²⁶, 1 024 (rad/s)²: a
    /// swing's peak, far above any stance), for the rest's gyro bias and gravity (counts).
    pub fn energy_q16(&self, s: &RawSample, bias: [i32; 3], gravity_counts: i32) -> u32 {
        let w2: u64 = (0..3)
            .map(|k| {
                let d = s.gyro[k] as i64 - bias[k] as i64;
                (d * d) as u64
            })
            .sum();
        let a2: u64 = s.accel.iter().map(|&a| (a as i64 * a as i64) as u64).sum();
        let d = isqrt_u64(a2) as i64 - gravity_counts as i64;
        let e = (w2 as u128 * self.k_w as u128 + (d * d) as u128 * self.k_a as u128) >> 24;
        e.min(1 << 26) as u32
    }
}

/// Calibration from the last rest, which the detector needs before it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Calibration {
    /// Gyro bias, counts.
    pub gyro_bias: [i32; 3],
    /// Gravity magnitude, accelerometer counts.
    pub gravity_counts: i32,
    /// The foot's standing up, any scale, sensor axes (counts of the rest's mean force).
    pub up: [i32; 3],
    /// The axis the foot pitches about in its steps, a unit row in sensor axes, Q14, any sign
    /// ([`crate::detect::foot_frame::FootFrame::pitch_axis_q14`]); `None` before the first
    /// step was learnt from.
    pub pitch: Option<[i32; 3]>,
}

impl Calibration {
    /// What the detector judges the newest decision with: gyro bias and gravity from the
    /// steadiest still blocks ([`FootFrameEstimator::still_calibration`]), or the foot
    /// frame's rest before the first block qualifies, and the foot's standing up. `None`
    /// before the foot frame exists.
    pub fn of(frame: &FootFrameEstimator, accel_lsb_per_g: i32) -> Option<Calibration> {
        let f = frame.frame()?;
        let (gyro_bias, gravity_counts) = frame.still_calibration().unwrap_or((
            frame.gyro_bias(),
            f.gravity() * accel_lsb_per_g / FOOT_LSB_PER_G,
        ));
        Some(Calibration {
            gyro_bias,
            gravity_counts,
            up: f.up_row(),
            pitch: f.pitch_axis_q14(),
        })
    }
}

/// The candidate stance.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    index: u32,
    /// Energy (window sum).
    energy: u64,
    /// The stride's integrator at the candidate.
    snap: ZuptIntegrator,
    /// Gyro minus bias at the candidate (for the rolling velocity there).
    omega: [i32; 3],
    /// The accelerometer's gravity over the stance so far (sensor axes, counts·2⁸).
    gravity: [i64; 3],
    /// The energy after it has risen by the prominence.
    risen: bool,
    /// First sample of the low stretch it lies in: the movement's foot-flat.
    foot_flat: u32,
    /// The movement's length in the buffer up to the foot-flat.
    movement_len: usize,
    /// The movement's length in samples up to the foot-flat (more than the buffer holds:
    /// too long).
    movement_needed: u32,
    /// The next movement's heel-off, once the energy rose after the candidate, and where
    /// its samples start in the buffer.
    next_heel_off: Option<u32>,
    tail_pos: usize,
    /// The stride's flags up to it.
    flags: u16,
    /// The flags of the samples after it: the next stride's, once it is confirmed (or the
    /// stride's own, should a later candidate replace it).
    next_flags: u16,
    /// The low stretch has lasted longer than a stance in a stride.
    long_stance: bool,
    /// Samples were lost after it, with the swing after it already risen: it is confirmed
    /// at the next input, and the next stride (from it) is broken there (the hole's first
    /// sample and its position in that stride's movement buffer).
    confirm_now: bool,
    next_broken: Option<(u32, usize)>,
    /// The rest test found the foot at rest, in a run that began after the stride's heel-off,
    /// somewhere up to [`step_check::REST_NEAR_MS`] after the candidate or to the next
    /// heel-off, whichever is later: where the step check looks for the stride's landing and
    /// the next one's start.
    rest_seen: bool,
    /// The stride's heel-off (its start before one): where a rest counts for `rest_seen`.
    rest_from: u32,
    /// Not a stance: no rest near it and no swing that lands without one (see
    /// [`CycleDetector::is_a_landing`]); only a later candidate replaces it.
    no_landing: bool,
}

/// The stride in progress: from a confirmed stance instant.
#[derive(Clone, Copy, Debug)]
struct Current {
    start: u32,
    /// Energy at the instant.
    energy: u64,
    integrator: ZuptIntegrator,
    heel_off: Option<u32>,
    flags: u16,
    /// Samples were lost and detection restarted inside it: the first lost sample, and the
    /// movement buffer's length then (what comes after it is after the hole).
    broken: Option<(u32, usize)>,
}

/// Which integrator a [`Start`] is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Starting {
    /// The stride's, restarted at rest ([`Current::integrator`]).
    Current,
    /// The next stride's, from the candidate ([`CycleDetector::next`]).
    Next,
}

/// An integrator's start at a stance instant, not made yet: what
/// [`ZuptIntegrator::start_at`] is given there, and the first sample after it.
///
/// At rest the stance instant moves on with every sample, and while the energy falls into a
/// stance every sample is a deeper candidate: each started an integrator (the attitude
/// levelled from gravity, two 128-bit roots, the rolling contact's velocity) that the next
/// sample threw away. Deferred by one sample, a start is made only for an instant that
/// outlived the sample after it, or that something reads. The same samples are integrated in
/// the same order from the same start, so every stride is the same to the bit.
#[derive(Clone, Copy, Debug)]
struct Start {
    of: Starting,
    /// The stance's gravity (counts·2⁸, sensor axes), never zero.
    mean: [i64; 3],
    /// Rate there, less the bias, counts.
    omega: [i32; 3],
    gyro_bias: [i32; 3],
    /// Gravity's magnitude, counts·2⁸, positive.
    gravity_q8: i64,
    /// The first sample after the instant, not integrated yet.
    first: Option<RawSample>,
}

impl Start {
    /// The start of `of` at an instant whose stance's gravity is `mean` (counts·2⁸), with the
    /// rate `omega` there, the calibration's bias and gravity; `None` where no integrator can
    /// start: a zero `mean` (nothing to level the attitude by, [`QuatQ30::level_from_up`]) or
    /// a gravity that is not positive ([`ZuptIntegrator::start_at`]).
    fn at(
        of: Starting,
        mean: [i64; 3],
        omega: [i32; 3],
        cal: &Calibration,
        gravity_q8: i64,
    ) -> Option<Start> {
        (mean != [0; 3] && gravity_q8 > 0).then_some(Start {
            of,
            mean,
            omega,
            gyro_bias: cal.gyro_bias,
            gravity_q8,
            first: None,
        })
    }
}

/// The every-pace stance detector and its strides, keeping at most `M` samples of a
/// movement.
#[derive(Clone, Debug)]
pub struct CycleDetector<const M: usize> {
    cfg: CycleConfig,
    ring: [u32; ENERGY_CAPACITY],
    /// Σ of the window's energies.
    sum: u64,
    /// Inputs since the start or a gap.
    seen: u32,
    cur: Option<Current>,
    cand: Option<Candidate>,
    /// The integrator started at the candidate.
    next: ZuptIntegrator,
    /// The start of the stride's integrator or the next one's, deferred ([`Start`]).
    pending: Option<Start>,
    /// Tests: every start made at once, as before the deferral, and the starts made.
    #[cfg(test)]
    eager: bool,
    #[cfg(test)]
    starts_made: u32,
    /// Largest energy since the stance instant (or since the candidate, once there is one).
    peak: u64,
    peak_since_cand: u64,
    /// Σ f and count over the current low stretch, and where it began.
    low_sum: [i64; 3],
    low_n: u32,
    low_start: u32,
    in_low: bool,
    /// Movement buffer: `[vertical, sagittal, |f| − g, sagittal rate]` from the stride's
    /// heel-off (`movement[0]` is sample `mv_origin`), less the samples of a slow swing's dip
    /// that were taken for a stance (`mv_gap`: buffer position and samples skipped there).
    movement: Vec<[i16; MOVEMENT_COLUMNS], M>,
    /// Samples of a movement kept ([`crate::detect::seam::MAX_MOVEMENT_MS`] at the rate, at most
    /// `M`).
    max_movement: usize,
    mv_origin: u32,
    mv_gap: Option<(usize, u32)>,
    /// The stance before the candidate was long (a rest).
    from_rest: bool,
    next_index: u32,
    /// The last sample decided on.
    last_at: u32,
    /// Phase statistics of the last two strides, by index parity.
    stats: [(u32, StrideStats); 2],
    /// A stride released while filling a hole with no call to report it from.
    held: Option<Stride>,
    dropped: u32,
    /// The foot's pitch axis was known when the last sample was decided on: the sagittal
    /// rate in the buffer is about it.
    axis_known: bool,
    /// The duration of the last stride closed, samples (0 before one): the walker's cadence.
    last_cycle: u32,
    /// The newest sample the rest test judged (none before its first decision:
    /// [`CycleDetector::note_rest`]), the sample after the newest it found at rest, and
    /// where the newest run of rest began (none before one).
    rest_judged: Option<u32>,
    rest_end: Option<u32>,
    rest_run_from: Option<u32>,
}

/// The window sum's threshold for a per-sample energy in Q16.
const fn per_window(q16: u64, w: u32) -> u64 {
    q16 * w as u64
}

impl<const M: usize> CycleDetector<M> {
    /// The detector for data described by `config`.
    pub const fn new(config: &DetectConfig) -> Self {
        let mut cfg = CycleConfig::new(
            config.rate,
            config.accel,
            config.gyro,
            config.rails,
            config.phases,
            config.sensor_height_um,
        );
        cfg.restore_accel = config.restore_accel;
        cfg.integrator = ZuptIntegrator::reading(
            config.rate,
            config.accel,
            config.gyro,
            config.gravity_reading,
        );
        Self::with_config(cfg)
    }

    /// A detector with no history.
    pub const fn with_config(cfg: CycleConfig) -> Self {
        CycleDetector {
            cfg,
            ring: [0; ENERGY_CAPACITY],
            sum: 0,
            seen: 0,
            cur: None,
            cand: None,
            next: cfg.integrator,
            pending: None,
            #[cfg(test)]
            eager: false,
            #[cfg(test)]
            starts_made: 0,
            peak: 0,
            peak_since_cand: 0,
            low_sum: [0; 3],
            low_n: 0,
            low_start: 0,
            in_low: false,
            movement: Vec::new(),
            max_movement: if (cfg.max_movement as usize) < M {
                cfg.max_movement as usize
            } else {
                M
            },
            mv_origin: 0,
            mv_gap: None,
            from_rest: false,
            next_index: 0,
            last_at: 0,
            stats: [
                (u32::MAX, StrideStats::EMPTY),
                (u32::MAX, StrideStats::EMPTY),
            ],
            held: None,
            dropped: 0,
            axis_known: false,
            last_cycle: 0,
            rest_judged: None,
            rest_end: None,
            rest_run_from: None,
        }
    }

    /// Samples between the newest input and the sample a decision is about.
    pub const fn delay(&self) -> u32 {
        self.cfg.half
    }

    /// The phase statistics of stride `index` while kept (see
    /// [`crate::detect::stance_strides::StrideTracker::stats`]).
    pub fn stats(&self, index: u32) -> Option<&StrideStats> {
        let (at, stats) = &self.stats[(index & 1) as usize];
        (*at == index).then_some(stats)
    }

    /// Strides that could not be reported (none by construction).
    pub const fn dropped(&self) -> u32 {
        self.dropped
    }

    const fn window(&self) -> u32 {
        2 * self.cfg.half + 1
    }

    /// Sample `s` into the stride's integrator or the next one's (`which`): held as the
    /// first sample after a deferred start, or integrated (after that start is made).
    fn integrate(&mut self, which: Starting, s: &RawSample) {
        if let Some(p) = self.pending.as_mut().filter(|p| p.of == which) {
            if p.first.is_none() {
                p.first = Some(*s);
                return;
            }
            self.settle();
        }
        match which {
            Starting::Current => {
                if let Some(c) = self.cur.as_mut() {
                    c.integrator.process(s, &self.cfg.rails);
                }
            }
            Starting::Next => self.next.process(s, &self.cfg.rails),
        }
    }

    /// Defers a start at a stance instant ([`Start`]), making one of the other integrator
    /// that is still pending first.
    fn defer(&mut self, start: Start) {
        if self.pending.is_some_and(|p| p.of != start.of) {
            self.settle();
        }
        self.pending = Some(start);
        #[cfg(test)]
        if self.eager {
            self.settle();
        }
    }

    /// Makes the deferred start, if any, and integrates the sample held after it. Not
    /// inlined: the started integrator (≈ 300 B) is written in place.
    #[inline(never)]
    fn settle(&mut self) {
        let Some(p) = self.pending.take() else {
            return;
        };
        #[cfg(test)]
        {
            self.starts_made += 1;
        }
        let it = match p.of {
            Starting::Current => match self.cur.as_mut() {
                Some(c) => &mut c.integrator,
                None => return,
            },
            Starting::Next => &mut self.next,
        };
        // `mean` is not zero and the gravity positive (`Start::at`): both succeed.
        *it = self.cfg.integrator;
        if let Some(level) = QuatQ30::level_from_up(p.mean) {
            let unit_q8 = self.cfg.integrator.unit_q8_for(p.gravity_q8);
            let v0 = self.cfg.rolling.velocity_q8(level, p.omega, unit_q8);
            let _ = it.start_at(level, p.gyro_bias, p.gravity_q8, v0);
        }
        if let Some(first) = p.first.as_ref() {
            it.process(first, &self.cfg.rails);
        }
    }

    /// Samples were lost and detection restarts: the stride in progress is reported, at
    /// the next stance, as a gap stride. A candidate the swing after it has already risen
    /// from is kept and confirmed at the next input (on the sample path's stack, not the
    /// gap's), so that the hole costs only the stride it falls in, the one from that
    /// candidate, rather than merging it with the one before; an unrisen candidate is
    /// dropped with the history it was judged on.
    pub fn gap(&mut self) {
        let hole_at = self.last_at.wrapping_add(1);
        let keep = match self.cand.as_mut() {
            Some(c) if c.risen => {
                let pos = match c.next_heel_off {
                    Some(_) => self.movement.len().saturating_sub(c.tail_pos),
                    None => 0,
                };
                c.confirm_now = true;
                c.next_broken = c.next_broken.or(Some((hole_at, pos)));
                true
            }
            _ => false,
        };
        self.seen = 0;
        self.sum = 0;
        // The rest test starts again after the hole: its next rest is a new run.
        self.rest_end = None;
        if !keep {
            let hole = (hole_at, self.movement.len());
            if let Some(c) = self.cur.as_mut() {
                c.broken = c.broken.or(Some(hole));
            }
            self.cand = None;
            // The next stride's start goes with its candidate.
            if self.pending.is_some_and(|p| p.of == Starting::Next) {
                self.pending = None;
            }
        }
        self.in_low = false;
        self.low_n = 0;
        self.low_sum = [0; 3];
    }

    /// Feeds the newest input `newest` (its energy enters the window) and the sample the
    /// decision is about, [`CycleDetector::delay`] inputs back: its number `at`, raw values,
    /// mean-filtered foot-frame acceleration `[forward, left, up − g]` (g/2048) and origin.
    /// The stride it lets the detector report goes into `out` (if `out` is free). `steps`,
    /// the step check's ledger of the same samples where a pipeline keeps one, lets the
    /// detector pass over an instant where the foot cannot have landed (see the module).
    #[allow(clippy::too_many_arguments)]
    pub fn process_into(
        &mut self,
        newest: &RawSample,
        at: u32,
        s: &RawSample,
        foot: FootAccel,
        origin: Origin,
        cal: &Calibration,
        steps: Option<&StepLedger>,
        out: &mut Option<Stride>,
    ) {
        if self.cand.as_ref().is_some_and(|c| c.confirm_now) {
            self.confirm(out);
            self.peak = self.peak_since_cand;
        }
        let w = self.window();
        let e = self
            .cfg
            .energy_q16(newest, cal.gyro_bias, cal.gravity_counts);
        let slot = |i: u32| i as usize & (ENERGY_CAPACITY - 1);
        let n = self.seen;
        self.ring[slot(n)] = e;
        self.sum += e as u64;
        if n >= w {
            self.sum -= self.ring[slot(n.wrapping_sub(w))] as u64;
        }
        self.seen = self.seen.saturating_add(1);
        if self.seen < w {
            return;
        }
        self.decide(at, self.sum, s, foot, origin, cal, steps, out);
    }

    #[allow(clippy::too_many_arguments)]
    fn decide(
        &mut self,
        i: u32,
        t: u64,
        s: &RawSample,
        foot: FootAccel,
        origin: Origin,
        cal: &Calibration,
        steps: Option<&StepLedger>,
        out: &mut Option<Stride>,
    ) {
        self.last_at = i;
        self.axis_known = cal.pitch.is_some();
        // Not `let cfg = self.cfg`: the config holds an integrator, and this runs per sample.
        let (confirm_after, max_stance) = (self.cfg.confirm, self.cfg.max_stance);
        let w = self.window();
        let (pn, pd) = ratio(PROMINENCE_MILLIDECADES);
        let (sn, sd) = ratio(SUPERSEDE_MILLIDECADES);
        let (en, ed) = ratio(EDGE_MILLIDECADES);
        let rest = per_window(REST_Q16, w);
        let swing_min = per_window(SWING_MIN_Q16, w);
        let gravity_q8 = (cal.gravity_counts as i64) << 8;
        let omega = [0, 1, 2].map(|k| s.gyro[k] as i32 - cal.gyro_bias[k]);

        // The stride's integrator and the next one's take this sample.
        let in_low = self.in_low;
        if self.cur.as_ref().is_some_and(|c| i != c.start) {
            self.integrate(Starting::Current, s);
        }
        if let Some(c) = self.cur.as_mut() {
            // After a candidate the samples are the next stride's (below).
            if self.cand.is_none() {
                mark(
                    &mut c.flags,
                    s,
                    &self.cfg.rails,
                    origin,
                    c.heel_off.is_some() && !in_low,
                );
            }
            // Heel-off: the energy first above the instant's (or the rest's) by the edge
            // ratio.
            if c.heel_off.is_none()
                && self.cand.is_none()
                && i != c.start
                && t * ed >= c.energy.max(rest) * en
            {
                c.heel_off = Some(i);
                self.movement.clear();
                self.mv_origin = i;
                self.mv_gap = None;
            }
        }
        if self.cand.as_ref().is_some_and(|c| i != c.index) {
            self.integrate(Starting::Next, s);
        }
        if let Some(c) = self.cand.as_mut() {
            if i != c.index {
                mark(
                    &mut c.next_flags,
                    s,
                    &self.cfg.rails,
                    origin,
                    c.next_heel_off.is_some() && !in_low,
                );
            }
            // The next movement's heel-off: its samples go after the stride's movement.
            if c.next_heel_off.is_none() && i != c.index && t * ed >= c.energy.max(rest) * en {
                c.next_heel_off = Some(i);
                self.movement.truncate(c.movement_len);
                c.tail_pos = self.movement.len();
            }
        }
        let moving = self.cur.as_ref().is_some_and(|c| c.heel_off.is_some());
        if moving && self.movement.len() < self.max_movement {
            // Full: what is lost is counted when the stride closes (too long).
            let _ = self.movement.push([
                foot.up(),
                foot.forward(),
                foot.magnitude_minus_g(),
                cal.pitch.map_or(0, |axis| sagittal_rate(&axis, &omega)),
            ]);
        }
        self.peak = self.peak.max(t);
        self.peak_since_cand = self.peak_since_cand.max(t);

        // The low stretch: the energy the prominence under the swing, or at rest.
        let low = t * pn <= self.peak * pd || t <= rest;
        if low {
            if !self.in_low {
                self.in_low = true;
                self.low_start = i;
                self.low_sum = [0; 3];
                self.low_n = 0;
            }
            if self.low_n >= 1 << 16 {
                self.low_sum = self.low_sum.map(|v| v / 2);
                self.low_n /= 2;
            }
            for k in 0..3 {
                self.low_sum[k] += s.accel[k] as i64;
            }
            self.low_n += 1;
        } else {
            self.in_low = false;
        }
        let low_len = if self.in_low {
            i.wrapping_sub(self.low_start)
        } else {
            0
        };

        // Confirmation of the candidate.
        let (start, moved_from) = self
            .cur
            .as_ref()
            .map_or((i, i), |c| (c.start, c.heel_off.unwrap_or(c.start)));
        let step_max = self.cfg.step_max;
        if let Some(c) = self.cand.as_mut() {
            if t * pd >= c.energy.max(1) * pn {
                c.risen = true;
            }
            let waited = i.wrapping_sub(c.index) >= confirm_after;
            let rest_long = self.in_low && low_len > max_stance;
            if c.risen && waited && !rest_long && !c.no_landing {
                let cfg = &self.cfg;
                c.no_landing = !Self::is_a_landing(
                    (c.index, c.rest_seen),
                    start,
                    self.rest_judged,
                    cfg,
                    steps,
                    || Self::lands_a_step_away(c, cfg),
                );
            }
            // Passed over, the stride would be longer than a step (the step check's
            // `STEP_MAX_MS`): the instant ends it after all, as it would have.
            let too_long = c.no_landing && i.wrapping_sub(moved_from) > step_max;
            if (c.risen && waited && !c.no_landing) || rest_long || too_long {
                c.long_stance |= rest_long;
                self.confirm(out);
                // The next stride starts at the candidate; the swing since it counts.
                self.peak = self.peak_since_cand;
                return;
            }
        }

        // At rest with no stride under way: the stance instant follows the rest.
        if self.in_low
            && t <= rest
            && self.cand.is_none()
            && self.cur.is_some()
            && self.peak < swing_min
        {
            let long = low_len > max_stance || self.from_rest;
            self.from_rest = false;
            let was = self
                .cur
                .as_ref()
                .map_or(0, |c| c.flags & StrideFlags::FROM_REST);
            self.restart_at(i, t, omega, cal, gravity_q8, long || was != 0);
            return;
        }

        // A candidate.
        if !self.in_low || self.low_n == 0 {
            return;
        }
        let mean = self.low_sum.map(|v| (v << 8) / self.low_n as i64);
        if !flat(&mean, &cal.up) {
            return;
        }
        let first = self.cur.is_none();
        if self.pending.is_some_and(|p| p.of == Starting::Current) {
            self.settle();
        }
        if let Some(c) = self.cur.as_ref() {
            if !agrees(&c.integrator.attitude(), &mean) {
                return;
            }
            // A foot turning fast is mid-swing, unless the stride has lasted a cadence's
            // share of the one before (a runner's rolling stance).
            let w2: i64 = omega.iter().map(|&w| w as i64 * w as i64).sum();
            let lasted = i.wrapping_sub(c.start) as u64;
            if w2 > self.cfg.stance_rate_max_sq
                && lasted * 1000 < self.last_cycle as u64 * CADENCE_MIN_PERMILLE as u64
            {
                return;
            }
        }
        // The first stance: at rest, or (a recording that starts on the move, or whose
        // first rest ended before the calibration came) after a swing, like any other.
        let deep = self.peak >= swing_min || (first && t <= rest);
        let better = match self.cand.as_ref() {
            None => deep,
            Some(c) if c.no_landing => deep,
            Some(c) if c.risen => t * sn <= c.energy * sd,
            Some(c) => t < c.energy || (t <= rest && c.energy <= rest),
        };
        if !better {
            return;
        }
        self.take_candidate(i, t, omega, mean, cal, gravity_q8);
    }

    /// Sample `i` (energy `t`, rate `omega`, the low stretch's gravity `mean`) becomes the
    /// candidate: the next stride's integrator starts there and the stride's is kept as it
    /// is now. Not inlined: its integrators (≈ 1 KiB) take stack only while it runs, never
    /// under [`CycleDetector::confirm`]'s.
    #[inline(never)]
    fn take_candidate(
        &mut self,
        i: u32,
        t: u64,
        omega: [i32; 3],
        mean: [i64; 3],
        cal: &Calibration,
        gravity_q8: i64,
    ) {
        let Some(start) = Start::at(Starting::Next, mean, omega, cal, gravity_q8) else {
            return;
        };
        // Where the stride's movement ends in the buffer: at this low stretch's start. A
        // candidate that replaces one after the energy rose (a slow swing's dip) keeps the
        // samples stored since that one's "heel-off" after the movement so far.
        let ff = self.low_start;
        let heel_off = self.cur.as_ref().and_then(|c| c.heel_off);
        let (movement_len, needed) = match (heel_off, self.cand.as_ref()) {
            (None, _) => (0, 0),
            // The old candidate's stance had ended (its next heel-off came) and this low
            // stretch is a later one: the buffer skips the old stance's samples.
            (Some(h), Some(old))
                if old
                    .next_heel_off
                    .is_some_and(|nh| ff.wrapping_sub(nh) < u32::MAX / 2) =>
            {
                let nh = old.next_heel_off.unwrap_or(h);
                let skipped = nh.wrapping_sub(old.foot_flat);
                let tail_pos = old.tail_pos;
                if self.mv_gap.is_none() && skipped < u32::MAX / 2 {
                    self.mv_gap = Some((tail_pos, skipped));
                }
                let len = tail_pos + ff.wrapping_sub(nh).min(self.max_movement as u32) as usize;
                (len.min(self.movement.len()), ff.wrapping_sub(h))
            }
            // The movement ends where this low stretch began, at its buffer position: past
            // a skip only if it lies after it. (A stance that stirred, took its wiggle for
            // the next heel-off and settled again has its foot-flat before the skip: taking
            // the skip off there cut the swing's last samples, its heel-strike among them.)
            (Some(h), _) => {
                let needed = ff.wrapping_sub(h);
                let needed = if needed < u32::MAX / 2 { needed } else { 0 };
                let pos = match self.mv_gap {
                    Some((at, skipped)) if needed as usize > at => {
                        (needed.saturating_sub(skipped) as usize).max(at)
                    }
                    _ => needed as usize,
                };
                // Past an old candidate's next heel-off the buffer holds that movement's
                // samples, not this stretch's.
                let stored = match self.cand.as_ref() {
                    Some(old) if old.next_heel_off.is_some() => old.tail_pos,
                    _ => self.movement.len(),
                };
                (pos.min(stored).min(self.movement.len()), needed)
            }
        };
        // The next stride's integrator, started in place (an integrator is ≈ 300 B and the
        // M0's stack is small) once the instant outlives the next sample; at once for the
        // first stance, whose stride starts from it as it is.
        self.defer(start);
        if self.cur.is_none() {
            self.settle();
        }
        // The stride's flags: up to the first candidate, and since it (a candidate that
        // replaces another extends the stride over the samples after that one).
        let flags = self.cur.as_ref().map_or(0, |c| c.flags)
            | self.cand.as_ref().map_or(0, |c| c.flags | c.next_flags);
        // A rest counts for the stride ending here from its heel-off on.
        let rest_from = self
            .cur
            .as_ref()
            .map_or(i, |c| c.heel_off.unwrap_or(c.start));
        let rest_seen = self.cur.is_none()
            || self
                .rest_run_from
                .is_some_and(|r| r.wrapping_sub(rest_from) < u32::MAX / 2);
        self.peak_since_cand = t;
        self.cand = Some(Candidate {
            index: i,
            energy: t,
            snap: match self.cur.as_ref() {
                Some(c) => c.integrator,
                None => self.next,
            },
            omega,
            gravity: mean,
            risen: false,
            foot_flat: ff,
            movement_len,
            movement_needed: needed,
            next_heel_off: None,
            tail_pos: 0,
            flags,
            next_flags: 0,
            long_stance: false,
            confirm_now: false,
            next_broken: None,
            rest_seen,
            rest_from,
            no_landing: false,
        });
    }

    /// The rest test's decision on sample `at`, from a pipeline that runs it
    /// ([`Input::rest`]). Without any, every candidate can be confirmed.
    pub fn note_rest(&mut self, at: u32, rest: bool) {
        self.rest_judged = Some(at);
        if !rest {
            return;
        }
        // A blip of movement inside a rest (the test flickers on a foot that settles, or
        // that is leaving) does not end it: the rest goes on, as the step check's ledger
        // keeps its runs ([`step_check::REST_BLIP_MS`]).
        let goes_on = self
            .rest_end
            .is_some_and(|end| at.wrapping_sub(end) <= self.cfg.rest_blip);
        self.rest_end = Some(at.wrapping_add(1));
        if !goes_on {
            self.rest_run_from = Some(at);
        }
        let Some(from) = self.rest_run_from else {
            return;
        };
        let near = self.cfg.rest_near;
        if let Some(c) = self.cand.as_mut() {
            let after = |a: u32, b: u32| a.wrapping_sub(b).wrapping_sub(1) < u32::MAX / 2;
            // The stride's landing (from its heel-off to `REST_NEAR_MS` after the
            // candidate) or the next stride's start (up to its heel-off, while unknown).
            let late = after(at, c.index.wrapping_add(near))
                && c.next_heel_off.is_some_and(|h| after(at, h));
            // A rest that began before the heel-off is the stance the stride left (the rest
            // test still finds it for a moment after the energy rose), not its landing.
            c.rest_seen |= !after(c.rest_from, from) && !late;
        }
    }

    /// Whether the stride ending at candidate `c` came down on the level a step away, as the
    /// step check will read it: the stride's integration to the candidate, closed as
    /// [`CycleDetector::close`] closes it. Not inlined: its trajectory takes stack only
    /// while it runs, not in every sample's frame (the M0's stack).
    #[inline(never)]
    fn lands_a_step_away(c: &Candidate, cfg: &CycleConfig) -> bool {
        let d = Self::trajectory(c, cfg);
        // In the units the check reads of the stride ([`step_check::Path::of`]).
        step_check::lands_a_step_away(d.zupt_um() / 1000, d.climb_mm())
    }

    /// The stride's trajectory to candidate `c`: the integrator as it was there, the
    /// rolling contact's velocity imposed at the end, the clipped samples' loss restored.
    /// Inlined into each caller, so that the close's frame stays as it was.
    #[inline(always)]
    fn trajectory(c: &Candidate, cfg: &CycleConfig) -> Displacement {
        let v_end = cfg
            .rolling
            .velocity_q8(c.snap.attitude(), c.omega, c.snap.unit_q8());
        c.snap
            .displacement_restoring(v_end, c.gravity, &cfg.rails, cfg.restore_accel)
    }

    /// Whether the foot can have landed at the candidate `index` of the stride from `start`
    /// (`rest_seen`: [`Candidate::rest_seen`]): the step check
    /// ([`step_check::StepEvidence::judge`]) refuses a stride with no rest within
    /// [`step_check::REST_NEAR_MS`] after its heel-strike, unless its swing turned the foot
    /// as fast as a runner's ([`step_check::RUN_SWING_MRADPS`]), or as fast as a run starts
    /// ([`step_check::RUN_START_SWING_MRADPS`]) and the stride came down on the level a step
    /// away (`lands_a_step`: the stride's integration to the candidate, as its close will
    /// measure it; asked only then). Ending a stride at such an instant loses both halves of
    /// the movement it cuts (a slow stride whose swing dips, a crawl); not ending it there,
    /// the stride goes on to the next stance and is judged whole. Only where the rest test
    /// has judged every sample up to `REST_NEAR_MS` after the candidate (`judged`, the newest
    /// it judged), found no rest that began after the stride's heel-off, up to there or to
    /// the next heel-off, and the step check would refuse the swing as above is the answer
    /// no: a landing the step check might take is never refused here, and a next stride that
    /// starts from a rest is never merged.
    fn is_a_landing(
        (index, rest_seen): (u32, bool),
        start: u32,
        judged: Option<u32>,
        cfg: &CycleConfig,
        steps: Option<&StepLedger>,
        lands_a_step: impl FnOnce() -> bool,
    ) -> bool {
        let Some(steps) = steps else {
            return true;
        };
        // Only inside a walk: a stride that did not start where a step that counted landed
        // (the first out of standing, or a pedal's pause after pedalling) ends where the
        // detector says. Merged, a pedal stroke's pieces between two pauses pass for a step.
        if !steps.landed_at(start) {
            return true;
        }
        let covered = judged
            .is_some_and(|j| j.wrapping_sub(index.wrapping_add(cfg.rest_near)) < u32::MAX / 2);
        // The stride's swing, as the step check will measure it.
        let (swing_deg, peak_mradps) = steps.swing(start, index.wrapping_add(1));
        let swung = swing_deg >= step_check::SWING_MIN_DEG;
        // A runner's swing lands without a rest; a run's first stride (a rest before it
        // only) lands if it came down on the level a step away, which only the stride's
        // integration says (asked last: it costs a displacement).
        let runner = swung && peak_mradps >= step_check::RUN_SWING_MRADPS;
        let run_start = swung && peak_mradps >= step_check::RUN_START_SWING_MRADPS;
        !covered || rest_seen || runner || (run_start && lands_a_step())
    }

    /// The stance instant moves to `i` (at rest, nothing under way); `from_rest` when the
    /// rest has lasted longer than a stance in a stride. Not inlined, for its integrator.
    #[inline(never)]
    fn restart_at(
        &mut self,
        i: u32,
        t: u64,
        omega: [i32; 3],
        cal: &Calibration,
        gravity_q8: i64,
        from_rest: bool,
    ) {
        let mean = self.low_sum.map(|v| (v << 8) / self.low_n.max(1) as i64);
        let Some(start) = Start::at(Starting::Current, mean, omega, cal, gravity_q8) else {
            return;
        };
        // In place; its integrator starts once the instant outlives the next sample (at
        // rest it moves on with every sample).
        let Some(c) = self.cur.as_mut() else {
            return;
        };
        c.start = i;
        c.energy = t;
        c.heel_off = None;
        c.flags = if from_rest { StrideFlags::FROM_REST } else { 0 };
        c.broken = None;
        self.defer(start);
        self.movement.clear();
        self.mv_gap = None;
        self.peak = t;
    }

    /// Confirms the candidate: closes the stride before it and starts the next from it. Not
    /// inlined: the candidate and the stride it takes out (≈ 800 B) sit on the stack only
    /// while it runs, not under every sample's decision.
    #[inline(never)]
    fn confirm(&mut self, out: &mut Option<Stride>) {
        if self.cand.is_none() {
            return;
        }
        // The next stride starts from the candidate's integrator, as it is now.
        self.settle();
        let Some(c) = self.cand.as_ref() else {
            return;
        };
        let spaced = self
            .cur
            .as_ref()
            .is_some_and(|cur| c.index.wrapping_sub(cur.start) >= self.cfg.spacing);
        // What the next stride takes from the candidate, before it goes.
        let (index, energy, next_heel_off, tail_pos, next_flags, long_stance) = (
            c.index,
            c.energy,
            c.next_heel_off,
            c.tail_pos,
            c.next_flags,
            c.long_stance,
        );
        let next_broken = c.next_broken;
        if spaced {
            if let Some(cur) = self.cur.as_ref() {
                self.last_cycle = index.wrapping_sub(cur.start);
            }
            if let Some(stride) = self.close() {
                match out {
                    None => *out = Some(stride),
                    Some(_) => self.dropped = self.dropped.saturating_add(1),
                }
            }
        }
        self.cand = None;
        let from_rest = core::mem::take(&mut self.from_rest) || long_stance;
        // The next movement, if it began, moves to the front of the buffer.
        match next_heel_off {
            Some(h) => {
                let tail = tail_pos.min(self.movement.len());
                let n = self.movement.len() - tail;
                self.movement.copy_within(tail.., 0);
                self.movement.truncate(n);
                self.mv_origin = h;
            }
            None => self.movement.clear(),
        }
        self.mv_gap = None;
        let flags = next_flags | if from_rest { StrideFlags::FROM_REST } else { 0 };
        // In place: a `Current` is ≈ 300 B.
        match self.cur.as_mut() {
            Some(cur) => {
                cur.start = index;
                cur.energy = energy;
                cur.integrator = self.next;
                cur.heel_off = next_heel_off;
                cur.flags = flags;
                cur.broken = next_broken;
            }
            None => {
                self.cur = Some(Current {
                    start: index,
                    energy,
                    integrator: self.next,
                    heel_off: next_heel_off,
                    flags,
                    broken: next_broken,
                })
            }
        }
    }

    /// The stride from the current stride's instant to the candidate's (`None` without
    /// both). Not inlined: its temporaries (the split, the statistics) take stack only
    /// while it runs.
    #[inline(never)]
    fn close(&mut self) -> Option<Stride> {
        // The stride and the candidate are read where they are (≈ 700 B), not moved out.
        let CycleDetector {
            cfg,
            cur,
            cand,
            movement,
            max_movement,
            mv_origin,
            mv_gap,
            next_index,
            stats,
            axis_known,
            ..
        } = self;
        let (Some(cur), Some(c)) = (cur.as_ref(), cand.as_ref()) else {
            return None;
        };
        let (mv_origin, mv_gap) = (*mv_origin, *mv_gap);
        let sample_of = |p: u32| sample_of(mv_origin, mv_gap, p);
        let mut flags = c.flags;
        if c.long_stance {
            flags |= StrideFlags::TO_REST;
        }
        if cur.broken.is_some() {
            flags |= StrideFlags::GAP;
        }
        if c.movement_needed as usize > *max_movement {
            flags |= StrideFlags::TOO_LONG;
        }
        let len = c.movement_len.min(movement.len());
        // A candidate in the low stretch the stride started in (a rest): its foot-flat is
        // the stride's start, not the stretch's.
        let foot_flat = c.foot_flat.max(cur.start);
        let heel_off = cur.heel_off.unwrap_or(foot_flat).max(cur.start);
        let index = *next_index;
        *next_index = next_index.wrapping_add(1);
        // The statistics go straight into their slot (≈ 400 B, not through the stack): Huang's
        // phases, which his per-phase features are defined on. The events reported are the
        // sagittal rate's where it has them ([`gyro_events`]), Huang's boundaries where not:
        // before the pitch axis is learnt, and where the buffer skipped a slow swing's dip
        // (`mv_gap`: the swing's rate is then cut, and its size no longer tells it from the
        // push-off; measured on `ipol_gait_events`, reading the rate there anyway put 13 more
        // events over 100 ms from the annotations).
        let (toe_off, heel_strike, found) = {
            let movement = &movement[..len];
            let split = phases::split(movement, cfg.phases, cfg.merge);
            let slot = &mut stats[(index & 1) as usize];
            slot.0 = index;
            slot.1 = StrideStats::measure(movement, split.toe_off, split.heel_strike);
            let gyro = match *axis_known && mv_gap.is_none() {
                true => gyro_events::find(movement, SAGITTAL_RATE_COLUMN, cfg.swing_min),
                false => None,
            };
            match gyro {
                Some(e) => (e.toe_off, e.heel_strike, true),
                None => (split.toe_off, split.heel_strike, split.found),
            }
        };
        if !found {
            flags |= StrideFlags::PHASES_GUESSED;
        }
        if c.snap.turned_over_45_deg() {
            flags |= StrideFlags::TURN;
        }
        let d = Self::trajectory(c, cfg);
        let (toe_off, heel_strike) = match (cur.heel_off, cur.broken) {
            // Events found after the hole are set to it: the buffer does not count the
            // samples lost in it, and the restart did not see them.
            (Some(_), Some((hole, pos))) => {
                let at = |p: u32| {
                    if p as usize >= pos {
                        hole
                    } else {
                        sample_of(p)
                    }
                };
                (at(toe_off), at(heel_strike))
            }
            (Some(_), None) => (sample_of(toe_off), sample_of(heel_strike)),
            (None, _) => (heel_off, heel_off),
        };
        // Events in order whatever the buffer held.
        let heel_strike = heel_strike.min(foot_flat).max(heel_off);
        let toe_off = toe_off.min(heel_strike).max(heel_off);
        let mut stride = Stride {
            index,
            events: StrideEvents {
                start: cur.start,
                heel_off: heel_off.min(foot_flat),
                toe_off,
                heel_strike,
                foot_flat,
                end: c.index,
            },
            flags: StrideFlags(flags),
            ..Stride::default()
        };
        // No displacement across a hole.
        if cur.broken.is_none() {
            d.record_on(&mut stride, c.snap.heading_change_cdeg());
        }
        Some(stride)
    }

    /// At the end of a recording: the candidate, if any, is the last stance (the stride
    /// before it ends there, the last before rest).
    pub fn finish(&mut self, out: &mut Option<Stride>) {
        if let Some(c) = self.cand.as_mut() {
            c.long_stance = true;
            self.confirm(out);
        }
        self.cur = None;
        self.pending = None;
    }
}

/// The sample number of buffer position `p` of a movement whose buffer starts at sample
/// `origin` and skips `gap.1` samples at position `gap.0`.
fn sample_of(origin: u32, gap: Option<(usize, u32)>, p: u32) -> u32 {
    match gap {
        Some((at, skipped)) if p as usize >= at => origin.wrapping_add(p).wrapping_add(skipped),
        _ => origin.wrapping_add(p),
    }
}

/// What a sample sets in its stride's flags: a rail of either sensor (restored at the
/// stride's close), and an interpolated sample (in the movement a filled one makes it a gap
/// stride, anything else bridged).
fn mark(flags: &mut u16, s: &RawSample, rails: &Rails, origin: Origin, moving: bool) {
    if rails.accel_clipped(s) {
        *flags |= StrideFlags::ACCEL_CLIPPED;
    }
    if rails.gyro_clipped(s) {
        *flags |= StrideFlags::GYRO_CLIPPED;
    }
    match (origin, moving) {
        (Origin::Measured, _) => {}
        (Origin::Filled, true) => *flags |= StrideFlags::GAP,
        _ => *flags |= StrideFlags::BRIDGED,
    }
}

/// Gravity `mean` (counts·2⁸) within [`FLAT_MAX_DEG`] of the standing up `up`.
fn flat(mean: &[i64; 3], up: &[i32; 3]) -> bool {
    let dot: i128 = (0..3).map(|k| mean[k] as i128 * up[k] as i128).sum();
    if dot <= 0 {
        return false;
    }
    let m2: i128 = mean.iter().map(|&v| v as i128 * v as i128).sum();
    let u2: i128 = up.iter().map(|&v| v as i128 * v as i128).sum();
    // dot² ≥ cos²·|m|²·|u|² with cos² in Q30. |m| < 2²⁴ (counts·2⁸) and |u| < 2³²: dot <
    // 2⁵⁶, dot² < 2¹¹², m2·u2 < 2¹¹² are exact in i128; only the product with cos² needs
    // the 2³⁰ taken out first, which drops 30 of its 112 bits (a relative 2⁻⁸²).
    let lhs = dot * dot;
    let rhs = ((m2 * u2) >> 30) * COS2_60_Q30;
    lhs >= rhs
}

/// The gyro's up (the level frame's +z seen through `q`) within [`ATTITUDE_MAX_DEG`] of the
/// gravity `mean` (counts·2⁸).
fn agrees(q: &QuatQ30, mean: &[i64; 3]) -> bool {
    let r = q.matrix();
    // Up in sensor axes is the third row (Q30, unit).
    let dot: i128 = (0..3).map(|k| r[2][k] as i128 * mean[k] as i128).sum();
    if dot <= 0 {
        return false;
    }
    let m2: i128 = mean.iter().map(|&v| v as i128 * v as i128).sum();
    // dot² ≥ cos²(45°)·|m|²·2⁶⁰ (the row is unit in Q30).
    let lhs = (dot >> 30) * (dot >> 30);
    let rhs = (m2 * COS2_45_Q30) >> 30;
    lhs >= rhs
}

impl<const M: usize> StepDetector for CycleDetector<M> {
    fn delay(&self, _filter_delay: u32) -> u32 {
        self.cfg.half
    }

    fn process(&mut self, x: &Input<'_>, out: &mut Option<Stride>) {
        if out.is_none() {
            *out = self.held.take();
        }
        if let Some((at, rest)) = x.rest {
            self.note_rest(at, rest);
        }
        if x.since_reset <= self.cfg.half + x.filter_delay {
            return;
        }
        // The decision is about the sample `delay` back; its mean-filtered foot-frame value
        // was computed `filter delay` inputs after it.
        let at = x.index.wrapping_sub(self.cfg.half);
        let foot = x.lines.foot(at.wrapping_add(x.filter_delay));
        let raw = x.lines.raw(at);
        let Some(cal) = Calibration::of(x.frame, x.accel_lsb_per_g) else {
            return;
        };
        // With `out` taken, a stride released now is reported at the next call.
        let mut later = None;
        let into = if out.is_some() { &mut later } else { out };
        self.process_into(
            x.newest,
            at,
            &raw,
            foot,
            x.lines.origin(at),
            &cal,
            Some(x.steps),
            into,
        );
        if let Some(s) = later {
            self.hold(s);
        }
    }

    fn restart(&mut self, _: &Drain<'_>) -> Option<Stride> {
        CycleDetector::gap(self);
        self.held.take()
    }

    fn hold(&mut self, stride: Stride) {
        if self.held.is_none() {
            self.held = Some(stride);
        } else {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    fn finish(&mut self, _: &Drain<'_>) -> Option<Stride> {
        if let Some(s) = self.held.take() {
            return Some(s);
        }
        let mut last = None;
        CycleDetector::finish(self, &mut last);
        last
    }

    fn stats(&self, index: u32) -> Option<&StrideStats> {
        CycleDetector::stats(self, index)
    }

    fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    //! The deferred start ([`Start`]) against starting every integrator at once, on a made-up
    //! walk at 200 Hz: stands, strides whose swing turns the foot forth and back about y,
    //! and a stand mid-walk (14 strides; 218 starts made against 2 147). A start still held
    //! when its candidate is confirmed in the sample after it (a hole, the end, a stance
    //! grown too long) is rare and not reached here: the shared recordings' replays,
    //! byte-identical before and after the deferral, cover those.
    extern crate std;
    use super::*;

    const LSB_PER_G: i16 = 2048;
    const STEPS: usize = 12;

    /// One sample `k` of the walk: 2 s standing, then cycles of 0.6 s stance and a 0.4 s
    /// swing (a full period of pitch rate, so the foot lands flat), with a 1.5 s stand
    /// after the sixth stride.
    fn sample(k: usize) -> RawSample {
        let rest = RawSample {
            accel: [0, 0, LSB_PER_G],
            gyro: [0; 3],
            temp: 0,
        };
        let Some(k) = k.checked_sub(400) else {
            return rest;
        };
        let (cycle, at) = (k / 200, k % 200);
        let at = match cycle {
            0..6 => at,
            6 => return rest,
            _ => (k - 300) % 200,
        };
        if at < 120 {
            // A little noise in the stance: the energy is not flat.
            let n = ((k * 7919) % 13) as i16 - 6;
            return RawSample {
                accel: [n, -n, LSB_PER_G + n],
                gyro: [n, n / 2, -n],
                temp: 0,
            };
        }
        let phase = (at - 120) as f64 / 80.0 * core::f64::consts::TAU;
        RawSample {
            accel: [
                (900.0 * phase.sin()) as i16,
                0,
                LSB_PER_G + (700.0 * (2.0 * phase).sin()) as i16,
            ],
            gyro: [0, (6000.0 * phase.sin()) as i16, 0],
            temp: 0,
        }
    }

    fn run(eager: bool) -> (std::vec::Vec<Stride>, u32) {
        let rate = SampleRate::from_hz(200).unwrap();
        let cfg = CycleConfig::new(
            rate,
            AccelScale::from_lsb_per_g(LSB_PER_G as u32),
            GyroScale::from_lsb_per_dps_x10(164),
            Rails::FULL_SCALE,
            PhaseMethod::Augmented,
            SENSOR_HEIGHT_UM,
        );
        let mut d: CycleDetector<1024> = CycleDetector::with_config(cfg);
        d.eager = eager;
        let cal = Calibration {
            gyro_bias: [0; 3],
            gravity_counts: LSB_PER_G as i32,
            up: [0, 0, LSB_PER_G as i32],
            pitch: Some([0, 1 << 14, 0]),
        };
        let delay = d.delay() as usize;
        let n = 400 + STEPS * 200 + 300 + 600;
        let mut strides = std::vec::Vec::new();
        for i in delay..n {
            let (newest, s) = (sample(i), sample(i - delay));
            let foot = FootAccel([s.accel[0], s.accel[1], s.accel[2] - LSB_PER_G]);
            let mut out = None;
            d.process_into(
                &newest,
                (i - delay) as u32,
                &s,
                foot,
                Origin::Measured,
                &cal,
                None,
                &mut out,
            );
            strides.extend(out);
        }
        let mut out = None;
        d.finish(&mut out);
        strides.extend(out);
        (strides, d.starts_made)
    }

    #[test]
    fn an_instant_the_step_check_would_refuse_is_passed_over_only_then() {
        use crate::detect::step_check::{Rate, StepEvidence, StepLedger};
        use crate::record::stride::StrideEvents;
        let rate = SampleRate::from_hz(100).unwrap();
        let gyro = GyroScale::from_lsb_per_dps_x10(164);
        let cfg = CycleConfig::new(
            rate,
            AccelScale::from_lsb_per_g(LSB_PER_G as u32),
            gyro,
            Rails::FULL_SCALE,
            PhaseMethod::Augmented,
            SENSOR_HEIGHT_UM,
        );
        // 1 s at rest, where a step that counted landed at 90 (`walking`) or none did; then a
        // slow swing about the pitch axis (0.4 s at `dps` °/s: a lobe of 0.4·dps degrees),
        // then the foot turning back without a rest. The stride from 90 has its candidate
        // at 150.
        let landing = |dps: f64, walking: bool, rest_seen: bool, judged: u32, step_away: bool| {
            let mut l = StepLedger::new(rate, gyro);
            for i in 0..100 {
                l.process(i, true, Rate::Level([0, 0]));
            }
            if walking {
                let before = Stride {
                    events: StrideEvents {
                        end: 90,
                        ..StrideEvents::default()
                    },
                    ..Stride::default()
                };
                let landed = StepEvidence {
                    rest_after: true,
                    ..StepEvidence::default()
                };
                l.judged(&before, &landed, Ok(()));
            }
            for i in 100..140 {
                l.process(i, false, Rate::Level([(dps * 16.4) as i32, 0]));
            }
            for i in 140..250 {
                l.process(i, false, Rate::Level([-(10.0 * 16.4) as i32, 0]));
            }
            CycleDetector::<16>::is_a_landing(
                (150, rest_seen),
                90,
                Some(judged),
                &cfg,
                Some(&l),
                || step_away,
            )
        };
        // 150 °/s (2.6 rad/s) for 60°, slower than a run starts, and no rest after its
        // heel-off up to 0.3 s after the candidate: the step check refuses it for sure,
        // wherever it came down.
        assert!(!landing(150.0, true, false, 180, true));
        // A rest after its heel-off, or not yet judged 0.3 s on: it may be a landing.
        assert!(landing(150.0, true, true, 180, false));
        assert!(landing(150.0, true, false, 179, false));
        // A swing as fast as a run starts (250 °/s, 4.4 rad/s, over 25°) lands without a rest
        // where it came down on the level a step away; where it came down where it left, the
        // step check refuses it.
        assert!(landing(250.0, true, false, 180, true));
        assert!(!landing(250.0, true, false, 180, false));
        // A runner's swing (300 °/s, 5.2 rad/s) lands without a rest, wherever.
        assert!(landing(300.0, true, false, 180, false));
        // Outside a walk (no step landed where the stride starts) the detector decides; so
        // it does without a ledger.
        assert!(landing(150.0, false, false, 180, false));
        assert!(CycleDetector::<16>::is_a_landing(
            (150, false),
            90,
            Some(200),
            &cfg,
            None,
            || false,
        ));
    }

    #[test]
    fn a_deferred_start_changes_no_stride() {
        let (deferred, made) = run(false);
        let (eager, made_eagerly) = run(true);
        assert!(deferred.len() >= STEPS - 2, "{} strides", deferred.len());
        assert_eq!(deferred, eager);
        // What the deferral is for: most starts at a rest or a falling energy are never made.
        assert!(
            made * 4 < made_eagerly,
            "{made} starts made, {made_eagerly} eagerly"
        );
    }
}

//! Is it a step on the ground? The check every detector's stride passes before it counts,
//! and what the wearer did between strides.
//!
//! A shoe clip is worn all day. Pedalling turns the foot once a revolution, a car's floor
//! shakes it, an elevator lifts it, a seated or standing wearer shifts it: each of these has
//! the rhythm a step detector looks for, and each would add a stride with a length to the
//! day. What they lack is the mechanics of a step, which a foot-mounted IMU sees directly:
//!
//! - **A step leaves a rest and comes back to one.** A walking, shuffling or stair-climbing
//!   foot is still on the ground between its movements (the orientation-free rest test of
//!   [`crate::detect::rest`]: the specific force steady within 0.6 m/s², the rate under
//!   0.7 rad/s, over 50 ms), within [`REST_NEAR_MS`] of the stride's ends; or the step before
//!   landed where this one starts. A pedalling foot never rests: it circles the crank at
//!   1–1.5 m/s. A car's floor and an elevator leave the foot at rest, so rest alone is no step.
//! - **A step swings the foot.** The foot rolls onto its toes, then turns toe-up through the
//!   swing by 60–100° in walking (90–120° running, 30–60° on stairs), about its
//!   medio-lateral axis, or rolls about the axis across it in a sideways step; a car's
//!   vibration, an elevator or a shift of weight turns it by a few degrees. The check takes
//!   the largest one-way rotation (a lobe of the rate about either level axis,
//!   [`crate::detect::foot_frame::FootFrame::level_rates`]) inside the stride: at least
//!   [`SWING_MIN_DEG`], turning at least [`SWING_MIN_MRADPS`] at its fastest (a foot drifting on
//!   a seat turns slower). A shuffle slides the foot a step's length ([`STEP_MIN_MM`]) on the
//!   level ([`LEVEL_MAX_MM`]) turning it less ([`SHUFFLE_SWING_MIN_DEG`]) and slower
//!   ([`SHUFFLE_MIN_MRADPS`]: the length it slid is the evidence); a turn on the spot
//!   turns it about the vertical ([`TURN_STEP_MIN_DEG`]); a slow high step raises it
//!   ([`LIFT_STEP_MIN_MM`]) whatever it turns.
//! - **A running foot has no rest, but a runner's swing.** At a run the foot is never still
//!   by the rest test; its swing peaks at 6–20 rad/s, faster than pedalling's ankling ever
//!   turns it (2–4 rad/s; 2.7 the median of `hugadb_daily`'s rides): [`RUN_SWING_MRADPS`]
//!   stands for the rest. A stride into a run from standing, or out of one into standing,
//!   has a rest on one side only and a swing not yet (or no longer) a runner's: it counts
//!   where its swing is faster than pedalling turns a foot ([`RUN_START_SWING_MRADPS`]) and
//!   it lands on the level a step's length away, which a pedal's circle does not.
//! - **A step takes the time of a step.** A movement longer than [`STEP_MAX_MS`] is not one.
//! - **A step starts from standing.** A foot on a pedal pauses now and then, still by the
//!   rest test for a moment, and then moves as a shuffle or a stair step would (on
//!   `hugadb_daily`'s rides: 0.45 s at rest in all over 37 s of pedalling before such a
//!   movement). A foot that has moved for [`UNSETTLED_MS`] since its
//!   last step without standing still for [`STANCE_MIN_MS`] in all that time has not stood
//!   on the ground: its next movement is not a step unless it is a runner's swing. A walk
//!   that begins straight out of such a movement loses its first stride, not the walk: a
//!   movement refused so ends the unsettled time, and the next is judged afresh.
//!
//! **What it keeps.** Per sample, O(1) and integer, fed by the pipeline whatever the
//! detector: the runs of rest decisions (a ring of the last [`RESTS`], blips under
//! [`REST_BLIP_MS`] merged) and the one-way rotations about the level axes (a ring of the last
//! [`LOBES`] larger than [`LOBE_KEEP_DEG`]). A detector reports a stride later than its
//! samples (a centred window, a confirmation): by then both rings hold its span, which the
//! check reads back ([`StepLedger::evidence`], judged by [`StepEvidence::judge`]). A detector
//! that reports seconds late (Lu's) is beyond them: its strides count unchecked.
//!
//! **Between the strides.** The same rest runs tell the time between two strides that count
//! apart: still (at rest) or moving without walking (cycling, a vehicle, fidgeting, the
//! movements the check refused), [`Between`], handed on with the next stride.

use crate::record::stride::{Between, Stride};
use crate::sensor::rate::SampleRate;
use crate::sensor::units::GyroScale;

/// The smallest swing of a step, degrees. A car's floor, an elevator, a seated or standing
/// wearer's shift of weight turn the foot by 1–10° (`hugadb_daily`); the shallowest steps,
/// on stairs, by 30–60° (their toe-up rotation is what lifts the foot over the nosing).
pub const SWING_MIN_DEG: u32 = 25;
/// A swing turns the foot at least this fast, mrad/s, at its fastest: the slowest a foot can
/// turn and still carry itself a step's length (≥ [`STEP_MIN_MM`]) in a swing (≤ 1 s), rolling
/// about a heel or a toe ≈ 0.25 m away ([`crate::detect::gyro_events::SWING_MIN_MRADPS`], the
/// same bound); a foot drifting on a seat or a coasting pedal turns slower.
pub const SWING_MIN_MRADPS: u32 = crate::detect::gyro_events::SWING_MIN_MRADPS;
/// A runner's swing turns the foot at least this fast, mrad/s: with it a stride counts without
/// a rest (see the module). A walking swing peaks at 4–10 rad/s, a running one at 8–20;
/// pedalling's ankling at 2–4 rad/s (2.8 rad/s the median on `hugadb_daily`'s rides).
pub const RUN_SWING_MRADPS: u32 = 4500;
/// A stride with a rest on one side only (the first stride of a run, out of standing, or the
/// last, into it) counts if its swing turns the foot at least this fast, mrad/s, and it
/// lands on the level ([`LEVEL_MAX_MM`]) at least a step's length away ([`STEP_MIN_MM`]):
/// `pyshoe_vicon`'s first strides out of standing into a run peak at 3.8–4.3 rad/s, walking
/// swings at 4–10; pedalling turns the foot at 2–4 rad/s, and a pedal's movement between a
/// pause and the crank's turn ends above or below where it began (a crank's circle), or
/// carries the foot less than a step.
pub const RUN_START_SWING_MRADPS: u32 = 3500;
/// A stride whose swing is smaller counts if its foot moved this far, mm, on the level (a
/// shuffle slides the foot a step's length turning it by 10–25°; a shift of weight moves it
/// centimetres).
pub const STEP_MIN_MM: u32 = 200;
/// …turning it by at least this, degrees…
pub const SHUFFLE_SWING_MIN_DEG: u32 = 10;
/// …at least this fast at its fastest, mrad/s. A sliding foot is not carried by its turn
/// (the step's length it moved is the evidence), so [`SWING_MIN_MRADPS`] does not bound it:
/// `pyshoe_vicon`'s slowest shuffles slide 0.37–0.49 m turning at 0.81–0.98 rad/s at their
/// fastest. The turn need only be one: faster than the band the ledger tells a rotation from
/// the gyro's noise and bias by (0.5 rad/s, [`StepLedger`]); a pedal crept round by a resting
/// foot turns slower (0.38 rad/s on `hugadb_daily`).
pub const SHUFFLE_MIN_MRADPS: u32 = 500;
/// …and ending at most this far above or below where it started, mm (a pedal or a seated
/// wearer's raised foot moves in an arc).
pub const LEVEL_MAX_MM: u32 = 100;
/// A stride that lifted the foot (its rate reached [`SWING_MIN_MRADPS`]) and turned it by at
/// least this about the vertical is a turn on the spot, degrees: a U-turn takes two to four
/// steps of 45–90°; a seated foot pivots by less, and a car turning carries a foot at rest.
pub const TURN_STEP_MIN_DEG: u32 = 30;
/// A stride whose swing is small counts if the foot rose this far above where it left the
/// ground, mm, and came to rest again: a slow high step (over an obstacle, out of a crawl or
/// a kneel: `pyshoe_vicon`'s foot rises 0.3–0.6 m in such strides, turning 0–20°); a seated
/// or standing foot shifts centimetres.
pub const LIFT_STEP_MIN_MM: u32 = 200;
/// The longest a step's movement lasts (heel-off to foot-flat), ms: 0.3–1 s walking or
/// running, up to 2.7 s in the slowest shuffles and backward steps of `pyshoe_vicon`; longer is
/// a movement of something other than a step (the foot frame learns the heading only from
/// movements shorter than [`crate::detect::foot_frame::AXIS_MAX_MOVEMENT_MS`], for the same
/// reason, with a margin here).
pub const STEP_MAX_MS: u32 = 4000;
/// A rest this close before the movement or after it counts as the step's, ms: a walking
/// stance instant lies inside its rest; a detector whose events are not stance instants
/// (Lu's peaks and valleys) finds the rest this close to them.
pub const REST_NEAR_MS: u32 = 300;
/// A movement this short between two rests is a blip of the rest test on a settling foot, ms:
/// the rest goes on through it (one walking stance stays one rest).
pub const REST_BLIP_MS: u32 = 60;
/// Rotations smaller than this are not kept, degrees (a stride's swing is never one).
pub const LOBE_KEEP_DEG: u32 = 5;
/// Moving this long since the last step (or since a movement refused for it) without
/// [`STANCE_MIN_MS`] at rest in all that time, ms, the foot is not standing on the ground:
/// a few strides' time. A walker's foot rests in every stance, a standing or seated one for
/// seconds; a pedalling foot for moments (see the module). The rest is counted as far back
/// as the ledger's last [`RESTS`] rest runs reach.
pub const UNSETTLED_MS: u32 = 5000;
/// …the rest a foot standing on the ground shows in that time, ms: half a second of standing
/// before a step, or the stances of the steps it took.
pub const STANCE_MIN_MS: u32 = 500;
/// Rest runs kept: a walking stride has one, so these cover the few seconds a detector
/// reports late.
pub const RESTS: usize = 8;
/// Rotations kept: a walking stride has three or four (heel rise, swing, foot slap).
pub const LOBES: usize = 16;

/// Why a movement is not a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rejection {
    /// The foot never came to rest before it or after it, and did not swing as a runner's
    /// does: pedalling, a foot on a vibrating floor.
    NoRest = 0,
    /// The foot rested either side but did not swing, nor move a step's length: a shift of
    /// weight, a fidget, an elevator's or a vehicle's acceleration.
    NoSwing = 1,
    /// The foot moved for longer than a step takes ([`STEP_MAX_MS`]): pedalling or fidgeting
    /// that a detector took for one long stride.
    TooLong = 2,
    /// A step's movement, but the foot had not stood on the ground before it: moving for
    /// [`UNSETTLED_MS`] since the last step with under [`STANCE_MIN_MS`] at rest
    /// (pedalling).
    NoStance = 3,
}

impl Rejection {
    /// Every reason, in the order of [`Rejected::by_reason`].
    pub const ALL: [Rejection; 4] = [
        Rejection::NoRest,
        Rejection::NoSwing,
        Rejection::TooLong,
        Rejection::NoStance,
    ];

    /// The name the logs and `--json` use.
    pub const fn name(self) -> &'static str {
        match self {
            Rejection::NoRest => "no_rest",
            Rejection::NoSwing => "no_swing",
            Rejection::TooLong => "too_long",
            Rejection::NoStance => "no_stance",
        }
    }
}

/// Movements refused, by reason ([`Rejection::ALL`]'s order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rejected {
    /// Counts by reason.
    pub by_reason: [u32; 4],
    /// Strides let through unjudged: their detector reports them later than the ledger
    /// reaches back ([`crate::detect::seam::StepDetector::reports_late`]).
    pub unchecked: u32,
}

impl Rejected {
    /// All refused movements.
    pub const fn total(&self) -> u32 {
        self.by_reason[0]
            .saturating_add(self.by_reason[1])
            .saturating_add(self.by_reason[2])
            .saturating_add(self.by_reason[3])
    }
}

/// A movement the check refused: where it was, why, and what it showed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RejectedMovement {
    /// Its first sample (the detector's stride start).
    pub start: u32,
    /// Its end (exclusive).
    pub end: u32,
    /// Its movement: the detector's heel-off and foot-flat.
    pub movement: (u32, u32),
    /// Why.
    pub reason: Rejection,
    /// Its largest rotation about the pitch axis, degrees.
    pub swing_deg: u16,
    /// That rotation's fastest rate, mrad/s.
    pub swing_peak_mradps: u32,
    /// Whether it rested before and after.
    pub rest: (bool, bool),
    /// How far the detector's integration moved the foot, mm (0 where it does not integrate).
    pub horizontal_mm: u32,
    /// How far it rose, mm.
    pub climb_mm: i32,
    /// The highest the sensor rose above its start, mm.
    pub lift_mm: u16,
}

/// How the detector's integration moved the foot over a stride (all zero where the detector
/// does not integrate: Lu's steps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Path {
    /// Horizontal distance, mm.
    pub horizontal_mm: u32,
    /// Height gained, mm.
    pub climb_mm: i32,
    /// Heading change, centidegrees.
    pub turn_cdeg: i16,
    /// The highest the sensor rose above its start, mm.
    pub lift_mm: u32,
}

impl Path {
    /// What stride `s` records of its trajectory.
    pub const fn of(s: &Stride) -> Self {
        Path {
            horizontal_mm: s.zupt_um / 1000,
            climb_mm: s.climb_mm,
            turn_cdeg: s.turning_angle_cdeg,
            lift_mm: s.max_sensor_lift_mm as u32,
        }
    }
}

/// What the check found in a stride's span.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepEvidence {
    /// The largest one-way rotation about the pitch axis inside the movement (about any
    /// horizontal axis before the pitch axis is learnt), degrees.
    pub swing_deg: u32,
    /// The fastest rate of that rotation, mrad/s (0 where it is not measured).
    pub swing_peak_mradps: u32,
    /// A rest within [`REST_NEAR_MS`] before the movement, or the step before it landed
    /// where it starts.
    pub rest_before: bool,
    /// A rest within [`REST_NEAR_MS`] after it.
    pub rest_after: bool,
    /// The movement lasted no longer than [`STEP_MAX_MS`].
    pub short_enough: bool,
    /// The foot stood on the ground or stepped in the seconds before it: not moving for
    /// [`UNSETTLED_MS`] since the last step without [`STANCE_MIN_MS`] at rest.
    pub settled: bool,
}

impl StepEvidence {
    /// The judgement of a stride whose detector's integration moved the foot as `path` says
    /// (all zero where the detector does not integrate): `Ok` for a step on the ground (see
    /// the module).
    pub const fn judge(&self, path: Path) -> Result<(), Rejection> {
        match self.judge_movement(path) {
            // A runner's swing needs no stance before it.
            Ok(()) if !self.settled && self.swing_peak_mradps < RUN_SWING_MRADPS => {
                Err(Rejection::NoStance)
            }
            verdict => verdict,
        }
    }

    /// The movement alone, whatever the foot did before it.
    const fn judge_movement(&self, path: Path) -> Result<(), Rejection> {
        let (horizontal_mm, climb_mm) = (path.horizontal_mm, path.climb_mm);
        if !self.short_enough {
            return Err(Rejection::TooLong);
        }
        let swing = self.swing_deg;
        // The foot landed on the level a step's length from where it left.
        let level_step = lands_a_step_away(horizontal_mm, climb_mm);
        if !(self.rest_before && self.rest_after) {
            // No rest either side: only a runner's swing is a step; a rest on one side and a
            // swing faster than pedalling onto the level a step away is a run's first or
            // last stride.
            let runner = swing >= SWING_MIN_DEG && self.swing_peak_mradps >= RUN_SWING_MRADPS;
            let run_start = (self.rest_before || self.rest_after)
                && swing >= SWING_MIN_DEG
                && self.swing_peak_mradps >= RUN_START_SWING_MRADPS
                && level_step;
            return if runner || run_start {
                Ok(())
            } else {
                Err(Rejection::NoRest)
            };
        }
        // A shuffle: the foot slid a step's length, turning, and stayed on the level.
        let shuffle = swing >= SHUFFLE_SWING_MIN_DEG
            && self.swing_peak_mradps >= SHUFFLE_MIN_MRADPS
            && level_step;
        // Otherwise a rotation slower than a swing is the foot drifting, not stepping.
        if self.swing_peak_mradps < SWING_MIN_MRADPS {
            return if shuffle {
                Ok(())
            } else {
                Err(Rejection::NoSwing)
            };
        }
        // A turn on the spot: the foot lifted (the rate above) and turned about the
        // vertical, where a swing is small.
        let turn = path.turn_cdeg.unsigned_abs() as u32 >= TURN_STEP_MIN_DEG * 100;
        // A lifted step: the foot raised a step's height and set down again (the rest
        // after), however little it turned.
        let lifted = path.lift_mm >= LIFT_STEP_MIN_MM;
        if swing >= SWING_MIN_DEG || shuffle || turn || lifted {
            Ok(())
        } else {
            Err(Rejection::NoSwing)
        }
    }
}

/// Whether a movement of `horizontal_mm` that rose `climb_mm` landed on the level a step's
/// length from where it left ([`STEP_MIN_MM`], [`LEVEL_MAX_MM`]): what a shuffle, and a run's
/// first or last stride with a rest on one side only, must show.
pub const fn lands_a_step_away(horizontal_mm: u32, climb_mm: i32) -> bool {
    horizontal_mm >= STEP_MIN_MM && climb_mm.unsigned_abs() <= LEVEL_MAX_MM
}

/// A sample's angular rate, as the ledger measures rotations by it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rate {
    /// About the two level axes a step turns the foot about (pitch, and roll across it),
    /// counts, signed ([`crate::detect::foot_frame::FootFrame::level_rates`]).
    Level([i32; 2]),
    /// Before the foot frame exists.
    Unknown,
}

/// A run of rest decisions: samples `[first, end)`, and the rest samples before `first`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct RestRun {
    first: u32,
    end: u32,
    rest_before: u32,
}

/// A one-way rotation: its size (counts·samples while it goes on; kept in 1/16 °), its
/// fastest rate (counts) and where that was. Where it was fastest places it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Lobe {
    peak_at: u32,
    area: u32,
    peak: u16,
}

/// A kept rotation: eight bytes, sixteen of them in the ring.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct KeptLobe {
    peak_at: u32,
    /// Size, 1/16 ° (saturated at 4 095.9°).
    area_q4: u16,
    peak: u16,
}

/// The per-sample record of rests and rotations, and the check of strides against it.
#[derive(Clone, Debug)]
pub struct StepLedger {
    rests: [RestRun; RESTS],
    /// Rest runs stored (the newest at `(rests_n − 1) % RESTS`).
    rests_n: u32,
    /// The run in progress, if the last sample was at rest.
    resting: bool,
    /// Rest samples so far.
    rest_total: u32,
    lobes: [KeptLobe; LOBES],
    lobes_n: u32,
    /// The rotation in progress about each level axis, and its way.
    lobe: [Lobe; 2],
    lobe_negative: [bool; 2],
    /// The rate must pass this the other way to end a rotation (counts): half of 1 rad/s,
    /// as [`crate::detect::gyro_events`] turns its lobes.
    band: i32,
    /// Counts·samples per degree of rotation at the rate and scale.
    per_deg: u32,
    /// The gyroscope's scale.
    gyro: GyroScale,
    /// Samples of [`REST_NEAR_MS`].
    near: u32,
    /// Samples of [`REST_BLIP_MS`].
    blip: u32,
    /// Samples of [`STEP_MAX_MS`].
    step_max: u32,
    /// The next sample to be fed.
    next: u32,
    /// Whether any sample has been fed (the rings are valid).
    started: bool,
    /// Where the last stride that counted ended, and the between-time not yet handed on.
    last_end: Option<u32>,
    /// Between-time from before a hole, for the next stride.
    pending: Between,
    /// Where the last movement refused for [`Rejection::NoStance`] ended: the unsettled time
    /// starts again there (see the module).
    unsettled_from: Option<u32>,
    /// Where the last step that counted landed: its end, if it ended on the ground (at rest,
    /// or in a runner's stance). The next stride starts from the ground there.
    landed: Option<u32>,
    rate: SampleRate,
}

impl StepLedger {
    /// A ledger for samples at `rate` with gyro counts of `gyro`.
    pub const fn new(rate: SampleRate, gyro: GyroScale) -> Self {
        // degrees × (lsb/dps counts per °/s) × (rate samples per s): counts·samples.
        let per_deg =
            (gyro.lsb() as u64 * rate.millihertz() as u64 / (1_000 * gyro.dps() as u64)) as u32;
        let band = gyro.counts_of_mrad_per_s(500) as i32;
        StepLedger {
            rests: [RestRun {
                first: 0,
                end: 0,
                rest_before: 0,
            }; RESTS],
            rests_n: 0,
            resting: false,
            rest_total: 0,
            lobes: [KeptLobe {
                peak_at: 0,
                area_q4: 0,
                peak: 0,
            }; LOBES],
            lobes_n: 0,
            lobe: [Lobe {
                peak_at: 0,
                area: 0,
                peak: 0,
            }; 2],
            lobe_negative: [false; 2],
            band: if band < 1 { 1 } else { band },
            per_deg: if per_deg < 1 { 1 } else { per_deg },
            gyro,
            near: rate.samples_in_ms(REST_NEAR_MS),
            blip: rate.samples_in_ms(REST_BLIP_MS),
            step_max: rate.samples_in_ms(STEP_MAX_MS),
            next: 0,
            started: false,
            last_end: None,
            unsettled_from: None,
            landed: None,
            pending: Between {
                still_ms: 0,
                moving_ms: 0,
            },
            rate,
        }
    }

    /// Feeds sample `at` (sample numbers need not be contiguous: a hole skips them): whether
    /// it is at rest, and its angular rate ([`Rate`]).
    pub fn process(&mut self, at: u32, rest: bool, rate: Rate) {
        self.next = at.wrapping_add(1);
        self.started = true;
        match (self.resting, rest) {
            (false, true) => {
                let last = (self.rests_n.wrapping_sub(1) as usize) % RESTS;
                let gap = at.wrapping_sub(self.rests[last].end);
                if self.rests_n > 0 && gap <= self.blip {
                    // A blip of movement inside a rest (the test flickers on a foot that
                    // settles): the rest goes on, the blip counted as part of it.
                    self.rests[last].end = at.wrapping_add(1);
                    self.rest_total = self.rest_total.wrapping_add(gap);
                } else {
                    let k = (self.rests_n as usize) % RESTS;
                    self.rests[k] = RestRun {
                        first: at,
                        end: at.wrapping_add(1),
                        rest_before: self.rest_total,
                    };
                    self.rests_n = self.rests_n.wrapping_add(1);
                }
            }
            (true, true) => {
                let k = (self.rests_n.wrapping_sub(1) as usize) % RESTS;
                self.rests[k].end = at.wrapping_add(1);
            }
            _ => {}
        }
        self.resting = rest;
        if rest {
            self.rest_total = self.rest_total.wrapping_add(1);
        }
        let rates = match rate {
            // A rotation ends where the foot comes to rest: a rate inside the band there is
            // the gyro's bias, not a turn of the foot.
            Rate::Level(r) if !rest => r,
            _ => {
                self.close_lobe(0, at);
                self.close_lobe(1, at);
                return;
            }
        };
        for (k, &r) in rates.iter().enumerate() {
            let along = if self.lobe_negative[k] { -r } else { r };
            if along < -self.band {
                // Turned: the rotation the other way begins here.
                self.close_lobe(k, at);
                self.lobe_negative[k] = !self.lobe_negative[k];
                self.lobe[k] = Lobe {
                    peak_at: at,
                    area: (-along) as u32,
                    peak: (-along).min(u16::MAX as i32) as u16,
                };
            } else {
                let l = &mut self.lobe[k];
                l.area = l.area.saturating_add(along.max(0) as u32);
                let v = along.clamp(0, u16::MAX as i32) as u16;
                if v > l.peak {
                    l.peak = v;
                    l.peak_at = at;
                }
            }
        }
    }

    /// Ends the rotation in progress about level axis `k` at `at` (kept if large enough).
    fn close_lobe(&mut self, k: usize, at: u32) {
        let l = self.lobe[k];
        if l.area >= LOBE_KEEP_DEG * self.per_deg {
            let slot = (self.lobes_n as usize) % LOBES;
            self.lobes[slot] = KeptLobe {
                peak_at: l.peak_at,
                area_q4: (l.area as u64 * 16 / self.per_deg as u64).min(u16::MAX as u64) as u16,
                peak: l.peak,
            };
            self.lobes_n = self.lobes_n.wrapping_add(1);
        }
        self.lobe[k] = Lobe {
            peak_at: at,
            area: 0,
            peak: 0,
        };
    }

    /// Whether sample `a` comes before sample `b` (within half the number range).
    const fn before(a: u32, b: u32) -> bool {
        b.wrapping_sub(a).wrapping_sub(1) < u32::MAX / 2
    }

    /// Whether `[a, b)` and `[c, d)` overlap.
    const fn overlap(a: u32, b: u32, c: u32, d: u32) -> bool {
        Self::before(a, d) && Self::before(c, b)
    }

    /// What the ledger holds of the stride with these events: the largest rotation inside
    /// it, and rests near either end.
    pub fn evidence(&self, s: &Stride) -> StepEvidence {
        let e = &s.events;
        // The stride's whole span: a detector's movement (heel-off to foot-flat) holds the
        // swing, and one whose events are not stance instants (Lu's peak and valley) has it
        // between them.
        let (swing_deg, swing_peak_mradps) = self.swing(e.start, e.end.wrapping_add(1));
        let before = (e.start.wrapping_sub(self.near), e.heel_off.wrapping_add(1));
        let after = (e.heel_strike, e.end.wrapping_add(self.near).wrapping_add(1));
        // A stride starts from the ground where the step before it landed.
        let (mut rest_before, mut rest_after) = (self.landed == Some(e.start), false);
        for r in self.rests.iter().take((self.rests_n as usize).min(RESTS)) {
            rest_before |= Self::overlap(r.first, r.end, before.0, before.1);
            rest_after |= Self::overlap(r.first, r.end, after.0, after.1);
        }
        // What the foot did since its last step (or since the last movement refused for
        // want of a stance, so that a walk out of pedalling loses one stride, not all).
        let last = self.last_end.unwrap_or(0);
        let from = match self.unsettled_from {
            Some(r) if Self::before(last, r) => r,
            _ => last,
        };
        let since = self.split(from, e.start);
        StepEvidence {
            swing_deg,
            swing_peak_mradps,
            rest_before,
            rest_after,
            short_enough: e.foot_flat.wrapping_sub(e.heel_off) <= self.step_max,
            settled: since.moving_ms <= UNSETTLED_MS || since.still_ms >= STANCE_MIN_MS,
        }
    }

    /// Whether the last step that counted landed at sample `start`.
    pub fn landed_at(&self, start: u32) -> bool {
        self.landed == Some(start)
    }

    /// The swing of samples `[mv_first, mv_end)`: the largest one-way rotation about a level
    /// axis that was fastest among them, degrees, and that fastest rate, mrad/s
    /// ([`StepEvidence::swing_deg`], [`StepEvidence::swing_peak_mradps`]).
    pub fn swing(&self, mv_first: u32, mv_end: u32) -> (u32, u32) {
        // Sizes in 1/16 °: the kept rotations' own, and the two in progress converted.
        let (mut largest, mut peak) = (0u32, 0u16);
        let stored = (self.lobes_n as usize).min(LOBES);
        let in_progress = self.lobe.map(|l| KeptLobe {
            peak_at: l.peak_at,
            area_q4: (l.area as u64 * 16 / self.per_deg as u64).min(u16::MAX as u64) as u16,
            peak: l.peak,
        });
        for l in self.lobes[..stored].iter().chain(in_progress.iter()) {
            // A rotation counts where it was fastest.
            let at = l.peak_at;
            if l.area_q4 as u32 > largest && Self::overlap(mv_first, mv_end, at, at.wrapping_add(1))
            {
                (largest, peak) = (l.area_q4 as u32, l.peak);
            }
        }
        // counts → mrad/s: · (dps/lsb) °/s · (π/180) · 1000 = · 17.4533·dps/lsb.
        let peak_mradps = (peak as u64 * 174_533 * self.gyro.dps() as u64
            / (self.gyro.lsb() as u64 * 10_000)) as u32;
        (largest / 16, peak_mradps)
    }

    /// The verdict on the stride `s` whose evidence was `evidence`: where a step that counted
    /// landed on the ground, the next stride starts from it ([`StepEvidence::rest_before`]).
    pub fn judged(&mut self, s: &Stride, evidence: &StepEvidence, verdict: Result<(), Rejection>) {
        let on_ground = evidence.rest_after || evidence.swing_peak_mradps >= RUN_SWING_MRADPS;
        self.landed = (verdict.is_ok() && on_ground).then_some(s.events.end);
        if verdict == Err(Rejection::NoStance) {
            self.unsettled_from = Some(s.events.end);
        }
    }

    /// Rest samples before sample `n`, as far back as the ring reaches (older samples count
    /// as moving).
    fn rests_before(&self, n: u32) -> u32 {
        let stored = (self.rests_n as usize).min(RESTS);
        // The newest run that began before `n`.
        let mut best: Option<&RestRun> = None;
        for r in self.rests.iter().take(stored) {
            if Self::before(r.first, n.wrapping_add(1))
                && best.is_none_or(|b| Self::before(b.first, r.first))
            {
                best = Some(r);
            }
        }
        match best {
            Some(r) => {
                let len = r.end.wrapping_sub(r.first);
                let into = n.wrapping_sub(r.first).min(len);
                r.rest_before.wrapping_add(into)
            }
            None => self
                .rests
                .iter()
                .take(stored)
                .map(|r| r.rest_before)
                .min()
                .unwrap_or(self.rest_total),
        }
    }

    /// The time between the last stride that counted (or the first sample) and sample
    /// `start`, by what the foot did; from then on the between-time starts at `end`.
    pub fn between(&mut self, start: u32, end: u32) -> Between {
        let from = self.last_end.unwrap_or(0);
        self.last_end = Some(end);
        let b = self.split(from, start);
        self.take_pending(b)
    }

    /// `b` and what was held over from before a hole, once.
    fn take_pending(&mut self, b: Between) -> Between {
        let p = core::mem::take(&mut self.pending);
        Between {
            still_ms: b.still_ms.saturating_add(p.still_ms),
            moving_ms: b.moving_ms.saturating_add(p.moving_ms),
        }
    }

    /// The between-time from the last stride that counted to the last sample fed (the end
    /// of a recording), handed out once.
    pub fn tail(&mut self) -> Between {
        let from = self.last_end.unwrap_or(0);
        self.last_end = Some(self.next);
        if !self.started {
            return self.take_pending(Between::default());
        }
        let b = self.split(from, self.next);
        self.take_pending(b)
    }

    /// A hole of `missing` samples after sample `at` (lost, or not sampled while the sensor
    /// slept): the time before it is held over for the next stride's between-time (the hole's
    /// own samples are neither still nor moving), which resumes after it.
    pub fn hole(&mut self, at: u32, missing: u32) {
        let from = self.last_end.unwrap_or(0);
        self.last_end = Some(at.wrapping_add(missing));
        if Self::before(from, at) {
            let b = self.split(from, at);
            self.pending = Between {
                still_ms: self.pending.still_ms.saturating_add(b.still_ms),
                moving_ms: self.pending.moving_ms.saturating_add(b.moving_ms),
            };
        }
    }

    fn split(&self, from: u32, to: u32) -> Between {
        if !Self::before(from, to) {
            return Between::default();
        }
        let samples = to.wrapping_sub(from);
        let still = self
            .rests_before(to)
            .wrapping_sub(self.rests_before(from))
            .min(samples);
        Between {
            still_ms: self.rate.ms_of_samples(still),
            moving_ms: self.rate.ms_of_samples(samples - still),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::stride::StrideEvents;

    fn ledger() -> StepLedger {
        StepLedger::new(
            SampleRate::from_hz(100).unwrap(),
            GyroScale::from_lsb_per_dps_x10(164),
        )
    }

    fn stride(start: u32, heel_off: u32, heel_strike: u32, end: u32) -> Stride {
        Stride {
            events: StrideEvents {
                start,
                heel_off,
                toe_off: heel_off,
                heel_strike,
                foot_flat: heel_strike,
                end,
            },
            ..Stride::default()
        }
    }

    fn path(horizontal_mm: u32, climb_mm: i32) -> Path {
        Path {
            horizontal_mm,
            climb_mm,
            turn_cdeg: 0,
            lift_mm: 0,
        }
    }

    /// 16.4 counts per °/s: a rate of `dps` °/s about the pitch axis, none across it.
    fn pitch(dps: f64) -> Rate {
        Rate::Level([(dps * 16.4).round() as i32, 0])
    }

    /// Feeds samples `from..to` at rest or not, at one rate.
    fn feed(l: &mut StepLedger, from: u32, to: u32, rest: bool, rate: Rate) {
        for i in from..to {
            l.process(i, rest, rate);
        }
    }

    /// 0.5 s at rest, 0.2 s heel rise (−200 °/s: 40°), 0.4 s swing (+225 °/s: 90°), rest.
    fn step(l: &mut StepLedger) {
        feed(l, 0, 50, true, pitch(0.0));
        feed(l, 50, 70, false, pitch(-200.0));
        feed(l, 70, 110, false, pitch(225.0));
        feed(l, 110, 200, true, pitch(0.0));
    }

    #[test]
    fn a_step_is_a_rest_a_swing_and_a_rest() {
        let mut l = ledger();
        step(&mut l);
        let e = l.evidence(&stride(25, 50, 110, 140));
        assert_eq!(e.swing_deg, 90);
        assert_eq!(e.swing_peak_mradps, 3926, "225 °/s");
        assert!(e.rest_before && e.rest_after && e.short_enough);
        assert_eq!(e.judge(path(1400, 10)), Ok(()));
        // The same rotation without the rests: not a step, unless it is a runner's swing.
        let mut pedalling = e;
        (pedalling.rest_before, pedalling.rest_after) = (false, false);
        assert_eq!(pedalling.judge(path(1400, 10)), Err(Rejection::NoRest));
        pedalling.swing_peak_mradps = RUN_SWING_MRADPS;
        assert_eq!(pedalling.judge(path(1400, 10)), Ok(()));
        // A run's first stride: a rest before, none after, a swing faster than pedalling
        // onto the level a step away; not a pedal's arc, nor a pedal's slower turn.
        let run_start = StepEvidence {
            rest_after: false,
            swing_peak_mradps: RUN_START_SWING_MRADPS,
            ..e
        };
        assert_eq!(run_start.judge(path(STEP_MIN_MM, 40)), Ok(()));
        let run_end = StepEvidence {
            rest_before: false,
            rest_after: true,
            ..run_start
        };
        assert_eq!(run_end.judge(path(900, -40)), Ok(()));
        assert_eq!(
            run_start.judge(path(900, LEVEL_MAX_MM as i32 + 1)),
            Err(Rejection::NoRest),
            "up a crank's arc"
        );
        assert_eq!(
            run_start.judge(path(STEP_MIN_MM - 1, 0)),
            Err(Rejection::NoRest),
            "less than a step"
        );
        let slow = StepEvidence {
            swing_peak_mradps: RUN_START_SWING_MRADPS - 1,
            ..run_start
        };
        assert_eq!(
            slow.judge(path(900, 0)),
            Err(Rejection::NoRest),
            "pedalling"
        );
        let small = StepEvidence {
            swing_deg: SWING_MIN_DEG - 1,
            ..run_start
        };
        assert_eq!(small.judge(path(900, 0)), Err(Rejection::NoRest));
        let neither = StepEvidence {
            rest_before: false,
            ..run_start
        };
        assert_eq!(neither.judge(path(900, 0)), Err(Rejection::NoRest));
        // A few degrees between rests: a shift of weight.
        let fidget = StepEvidence {
            swing_deg: 4,
            swing_peak_mradps: 1200,
            ..e
        };
        assert_eq!(fidget.judge(path(50, 0)), Err(Rejection::NoSwing));
        // A shuffle: a small turn, a step's length on the level; not up an arc.
        let shuffle = StepEvidence {
            swing_deg: SHUFFLE_SWING_MIN_DEG,
            ..fidget
        };
        assert_eq!(shuffle.judge(path(STEP_MIN_MM, 20)), Ok(()));
        assert_eq!(
            shuffle.judge(path(STEP_MIN_MM - 1, 20)),
            Err(Rejection::NoSwing)
        );
        assert_eq!(
            shuffle.judge(path(STEP_MIN_MM, LEVEL_MAX_MM as i32 + 1)),
            Err(Rejection::NoSwing)
        );
        // A slow shuffle slides as far, turning slower than a swing; a pedal crept round
        // turns slower still.
        let slow_shuffle = StepEvidence {
            swing_peak_mradps: SHUFFLE_MIN_MRADPS,
            ..shuffle
        };
        assert_eq!(slow_shuffle.judge(path(STEP_MIN_MM, 20)), Ok(()));
        assert_eq!(
            slow_shuffle.judge(path(STEP_MIN_MM - 1, 20)),
            Err(Rejection::NoSwing)
        );
        let creep = StepEvidence {
            swing_peak_mradps: SHUFFLE_MIN_MRADPS - 1,
            ..shuffle
        };
        assert_eq!(creep.judge(path(600, 20)), Err(Rejection::NoSwing));
        // A slow drift is no swing, however far it turns, unless it slid a step's length.
        let drift = StepEvidence {
            swing_deg: 40,
            swing_peak_mradps: SWING_MIN_MRADPS - 1,
            ..e
        };
        assert_eq!(
            drift.judge(path(STEP_MIN_MM - 1, 0)),
            Err(Rejection::NoSwing)
        );
        assert_eq!(drift.judge(path(1000, 200)), Err(Rejection::NoSwing));
        // A turn on the spot: the foot lifted and turned about the vertical.
        let pivot = Path {
            turn_cdeg: -(TURN_STEP_MIN_DEG as i16) * 100,
            ..path(80, 0)
        };
        assert_eq!(fidget.judge(pivot), Ok(()));
        assert_eq!(drift.judge(pivot), Err(Rejection::NoSwing), "a car turning");
        // A slow high step: the foot raised a step's height, turning little.
        let high = Path {
            lift_mm: LIFT_STEP_MIN_MM,
            ..path(80, 300)
        };
        assert_eq!(fidget.judge(high), Ok(()));
        let shift = Path {
            lift_mm: LIFT_STEP_MIN_MM - 1,
            ..high
        };
        assert_eq!(fidget.judge(shift), Err(Rejection::NoSwing));
        assert_eq!(
            drift.judge(high),
            Err(Rejection::NoSwing),
            "lifted too slowly"
        );
        // A movement longer than a step.
        let long = StepEvidence {
            short_enough: false,
            ..e
        };
        assert_eq!(long.judge(path(1400, 0)), Err(Rejection::TooLong));
    }

    #[test]
    fn a_sideways_step_rolls_the_foot_across_the_pitch_axis() {
        let mut l = ledger();
        feed(&mut l, 0, 50, true, Rate::Level([0, 0]));
        // 0.3 s rolling at 150 °/s about the forward axis: 45°.
        feed(
            &mut l,
            50,
            80,
            false,
            Rate::Level([0, (150.0f64 * 16.4) as i32]),
        );
        feed(&mut l, 80, 150, true, Rate::Level([0, 0]));
        assert_eq!(l.evidence(&stride(25, 50, 80, 100)).swing_deg, 45);
    }

    #[test]
    fn a_brief_turn_back_does_not_split_a_rotation_and_a_rest_ends_one() {
        let mut l = ledger();
        feed(&mut l, 0, 20, true, pitch(0.0));
        // 200 °/s for 0.2 s, a dip to −20 °/s (inside the band of 0.5 rad/s), 0.2 s more.
        feed(&mut l, 20, 40, false, pitch(200.0));
        feed(&mut l, 40, 43, false, pitch(-20.0));
        feed(&mut l, 43, 63, false, pitch(200.0));
        feed(&mut l, 63, 90, true, pitch(0.0));
        assert_eq!(l.evidence(&stride(10, 20, 63, 70)).swing_deg, 80);
        // A gyro bias of 3 °/s through a long rest is no rotation.
        let mut l = ledger();
        feed(&mut l, 0, 2000, true, pitch(3.0));
        assert_eq!(l.evidence(&stride(0, 100, 1900, 2000)).swing_deg, 0);
    }

    #[test]
    fn a_stride_starts_from_the_ground_where_the_step_before_landed() {
        let mut l = ledger();
        step(&mut l);
        let first = stride(25, 50, 110, 230);
        let e = l.evidence(&first);
        l.judged(&first, &e, Ok(()));
        // The next stride starts at 230 with no rest near it (a run begins): it starts from
        // the ground the last step landed on.
        feed(&mut l, 200, 300, false, pitch(-200.0));
        let next = stride(230, 235, 290, 300);
        assert!(l.evidence(&next).rest_before);
        // Not after a movement that did not count.
        l.judged(&first, &e, Err(Rejection::NoSwing));
        assert!(!l.evidence(&next).rest_before);
    }

    /// 6 s of pedalling at 100 Hz: the foot circles at 200 °/s either way, pausing 0.1 s
    /// (still) at each dead centre every 0.5 s for 30 ms: 0.36 s at rest in all.
    fn pedal(l: &mut StepLedger, from: u32, to: u32) {
        for i in from..to {
            let phase = (i - from) % 50;
            let rate = if (i - from) / 50 % 2 == 0 {
                200.0
            } else {
                -200.0
            };
            l.process(i, phase < 3, pitch(if phase < 3 { 0.0 } else { rate }));
        }
    }

    /// A step-like movement at `at` (0.5 s rest, heel rise, swing, rest), as [`step`] does
    /// at 0: its stride `(at − 25, at, at + 60, at + 90)`.
    fn step_at(l: &mut StepLedger, at: u32, rest_before: u32) -> Stride {
        feed(l, at - rest_before, at, true, pitch(0.0));
        feed(l, at, at + 20, false, pitch(-200.0));
        feed(l, at + 20, at + 60, false, pitch(225.0));
        feed(l, at + 60, at + 150, true, pitch(0.0));
        stride(at - 25.min(rest_before), at, at + 60, at + 90)
    }

    #[test]
    fn a_step_out_of_pedalling_needs_a_stance_first() {
        // Pedalling never stood for STANCE_MIN_MS in its 6 s; a step-like movement after a
        // 0.2 s pause is not a step.
        let mut l = ledger();
        pedal(&mut l, 0, 600);
        let s = step_at(&mut l, 620, 20);
        let e = l.evidence(&s);
        assert!(e.rest_before && e.rest_after && !e.settled);
        assert_eq!(e.judge(path(1400, 10)), Err(Rejection::NoStance));
        // A runner's swing needs no stance.
        let runner = StepEvidence {
            swing_peak_mradps: RUN_SWING_MRADPS,
            ..e
        };
        assert_eq!(runner.judge(path(1400, 10)), Ok(()));
        // The movement refused ends the unsettled time: a walk out of pedalling loses its
        // first stride, not the walk.
        l.judged(&s, &e, Err(Rejection::NoStance));
        let next = step_at(&mut l, 790, 20);
        let e = l.evidence(&next);
        assert!(e.settled);
        assert_eq!(e.judge(path(1400, 10)), Ok(()));

        // Standing after pedalling settles the foot.
        let mut l = ledger();
        pedal(&mut l, 0, 600);
        let s = step_at(&mut l, 700, 100);
        assert!(l.evidence(&s).settled);
        // Under five seconds of it too (a wearer shifting on a pedal before stepping off).
        let mut l = ledger();
        pedal(&mut l, 0, 450);
        let s = step_at(&mut l, 470, 20);
        assert!(l.evidence(&s).settled);
        // And a step counted since: a walk's own strides never need one.
        let mut l = ledger();
        pedal(&mut l, 0, 600);
        let first = step_at(&mut l, 650, 50);
        let e = l.evidence(&first);
        l.judged(&first, &e, Ok(()));
        let _ = l.between(first.events.start, first.events.end);
        pedal(&mut l, 800, 1000);
        let s = step_at(&mut l, 1010, 10);
        assert!(l.evidence(&s).settled);
    }

    #[test]
    fn a_blip_in_a_rest_does_not_end_it() {
        let mut l = ledger();
        feed(&mut l, 0, 100, true, pitch(0.0));
        feed(&mut l, 100, 103, false, pitch(0.0));
        feed(&mut l, 103, 200, true, pitch(0.0));
        assert_eq!(l.rests_n, 1);
        assert_eq!(
            l.tail(),
            Between {
                still_ms: 2000,
                moving_ms: 0
            }
        );
    }

    #[test]
    fn the_time_between_strides_is_split_by_the_rests() {
        let mut l = ledger();
        // 1 s still, 2 s moving (pedalling), 1 s still, then a stride from 400 to 500.
        feed(&mut l, 0, 100, true, Rate::Unknown);
        feed(&mut l, 100, 300, false, Rate::Unknown);
        for i in 300..520 {
            l.process(i, !(400..480).contains(&i), Rate::Unknown);
        }
        assert_eq!(
            l.between(400, 500),
            Between {
                still_ms: 2000,
                moving_ms: 2000
            }
        );
        // The next stride right after: nothing between them.
        assert_eq!(l.between(500, 600), Between::default());
        // A hole: the time before it is held for the next stride (or the end), the hole
        // itself is neither.
        feed(&mut l, 600, 700, true, Rate::Unknown);
        l.hole(700, 1000);
        feed(&mut l, 1700, 1750, false, Rate::Unknown);
        assert_eq!(
            l.tail(),
            Between {
                still_ms: 1000,
                moving_ms: 500
            }
        );
    }
}

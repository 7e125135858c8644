//! Per-stride gait parameters: what a runner's watch and a clinician's stride list read, from
//! the stride's events and length.
//!
//! The last stage of the pipeline: after the length model has set [`Stride::length_mm`], the
//! stride's events give its timing (named as gaitmap's `SpatialParameterCalculation` /
//! `TemporalParameterCalculation` name them, for strides that run from one stance to the
//! next):
//!
//! - `stride_time` = heel-strike − the previous stride's heel-strike (gaitmap's `ic −
//!   pre_ic`), when the previous stride ends where this one starts; otherwise `end − start`
//!   (one cycle between the two stance instants); `swing_time` = `heel_strike − toe_off`,
//!   `stance_time` = `stride_time − swing_time` (the ground contact from the previous
//!   heel-strike to toe-off), each also as ‰ of the cycle;
//! - `gait_velocity` = length / (`end − start`), the interval whose displacement the length
//!   is (the two durations differ stride by stride by where the stance instants fall, not on
//!   average); cadence = two steps per stride time, in steps per minute (the instrumented
//!   foot sees every other step);
//! - the sensor's lift and the heading change come from the detector's ZUPT trajectory
//!   ([`Stride::max_sensor_lift_mm`], [`Stride::turning_angle_cdeg`]);
//! - walking or running from the **duty factor** (stance time over stride time,
//!   [`RUNNING_STANCE_MAX_PERMILLE`]), or stairs up or down from the **climb** where the
//!   stride rose or fell a stair's height at a stair's slope ([`stairs`]).
//!
//! **Walking or running.** A gait is a run when it has a flight phase, both feet off the
//! ground at once. With the two feet's cycles half a cycle apart, that happens exactly when
//! each foot's stance is shorter than half of its cycle: duty factor β < 0.5 (Alexander,
//! "Optimization and gaits in the locomotion of vertebrates", Physiol. Rev. 69, 1989: walking
//! β > 0.5, running β < 0.5; Novacheck, "The biomechanics of running", Gait & Posture 7, 1998:
//! stance ≈ 62 % of the cycle walking, ≈ 39 % running, ≈ 36 % sprinting). The threshold is
//! that physical boundary, not a value fitted to a dataset; how the IMU's events place it
//! against Vicon speeds is in docs/accuracy.md.
//!
//! Integer throughout: times in ms from sample counts ([`SampleRate::ms_of_samples`]),
//! ratios and velocity by rounded integer division.

use crate::record::gait::{Gait, GaitParameters};
use crate::record::stride::{Stride, StrideFlags};
use crate::sensor::rate::SampleRate;

/// Stance below this share of the cycle, ‰, is running (a flight phase, duty factor < 0.5).
pub const RUNNING_STANCE_MAX_PERMILLE: u16 = 500;

/// A stride that climbs at least this much is on stairs, mm (if steep enough,
/// [`STAIRS_MIN_SLOPE_PERMILLE`]): a stride climbs one riser step-to-step, two step-over-step,
/// and risers are 150–200 mm (building codes); a walked slope climbs under 150 mm in a stride
/// of 1.4 m even at 10 %.
pub const STAIRS_MIN_CLIMB_MM: u32 = 150;
/// …at a slope of at least this, ‰ (rise over run: stairs are 0.5–0.8, a ramp at most 0.083
/// and a steep street 0.2), so that a long stride up a hill is not a flight of stairs.
pub const STAIRS_MIN_SLOPE_PERMILLE: u32 = 300;

/// A stride on stairs spans at most this far, mm: two treads step-over-step, four taken two
/// at a time, and treads are 0.25–0.35 m. Longer, its climb is not a staircase's but an
/// integration's error (sprint strides at both rails "climb" 0.8–1.4 m over 1.6–2.4 m on the
/// level `esangeni_course`), and its class is the duty factor's.
pub const STAIRS_MAX_LEVEL_MM: u32 = 1400;
/// …and climbs at most this, mm: four risers of at most 0.2 m.
pub const STAIRS_MAX_CLIMB_MM: u32 = 800;

/// Flags under which the stride's times do not describe one gait cycle: a stride from or
/// into a rest spans the standing, a gap hides events.
const NOT_A_CYCLE: u16 = StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::GAP;

/// The gait-parameter stage: remembers where the last stride ended and its heel-strike, for
/// the next stride's heel-strike-to-heel-strike time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GaitTimer {
    rate: SampleRate,
    /// The last stride's end and heel-strike.
    previous: Option<(u32, u32)>,
}

impl GaitTimer {
    /// A stage that has seen no stride, at `rate`.
    pub const fn new(rate: SampleRate) -> Self {
        GaitTimer {
            rate,
            previous: None,
        }
    }

    /// Sets `stride.gait` (its length already set).
    pub fn process(&mut self, stride: &mut Stride) {
        let previous_heel_strike = match self.previous {
            Some((end, heel_strike)) if end == stride.events.start => Some(heel_strike),
            _ => None,
        };
        stride.gait = GaitParameters::of(stride, previous_heel_strike, self.rate);
        // A gap stride's heel-strike may sit in the hole (set to its first missing sample):
        // the next stride times itself from its own cycle instead.
        self.previous = if stride.flags.has(StrideFlags::GAP) {
            None
        } else {
            Some((stride.events.end, stride.events.heel_strike))
        };
    }
}

impl GaitParameters {
    /// The parameters of `stride` (its length already set) at `rate`, with the heel-strike
    /// of the stride before it when that one ended where this one starts.
    pub const fn of(stride: &Stride, previous_heel_strike: Option<u32>, rate: SampleRate) -> Self {
        let cycle_ms = rate.ms_of_samples(stride.events.end.wrapping_sub(stride.events.start));
        let stride_ms = match previous_heel_strike {
            // Heel-strikes in order (a detector's always are); otherwise the cycle.
            Some(p) if p <= stride.events.heel_strike => {
                rate.ms_of_samples(stride.events.heel_strike - p)
            }
            _ => cycle_ms,
        };
        let swing_ms = rate.ms_of_samples(
            stride
                .events
                .heel_strike
                .wrapping_sub(stride.events.toe_off),
        );
        // Events are ordered within the stride; a swing longer than the cycle is not one.
        let swing_ms = if swing_ms > stride_ms {
            stride_ms
        } else {
            swing_ms
        };
        let stance_ms = stride_ms - swing_ms;
        let (stance_permille, swing_permille, cadence) = if stride_ms == 0 {
            (0, 0, 0)
        } else {
            let t = stride_ms as u64;
            let stance = (stance_ms as u64 * 1000 + t / 2) / t;
            (stance, 1000 - stance, (2 * 60_000 + t / 2) / t)
        };
        let velocity = if cycle_ms == 0 {
            0
        } else {
            let t = cycle_ms as u64;
            (stride.length_mm as u64 * 1000 + t / 2) / t
        };
        let gait = if let Some(stairs) = stairs(stride) {
            stairs
        } else if stride.flags.0 & NOT_A_CYCLE != 0 || stride_ms == 0 {
            Gait::Unknown
        } else if stance_permille < RUNNING_STANCE_MAX_PERMILLE as u64 {
            Gait::Running
        } else {
            Gait::Walking
        };
        GaitParameters {
            stride_time_ms: saturate_u16(stride_ms as u64),
            stance_time_ms: saturate_u16(stance_ms as u64),
            swing_time_ms: saturate_u16(swing_ms as u64),
            stance_permille: stance_permille as u16,
            swing_permille: swing_permille as u16,
            gait_velocity_mm_s: saturate_u16(velocity),
            cadence_spm: saturate_u16(cadence),
            gait,
        }
    }
}

/// Stairs up or down, where the stride climbed a stair's height at a stair's slope
/// ([`STAIRS_MIN_CLIMB_MM`], [`STAIRS_MIN_SLOPE_PERMILLE`]) over no more than a flight's
/// stride allows ([`STAIRS_MAX_LEVEL_MM`], [`STAIRS_MAX_CLIMB_MM`]); `None` on the level, on
/// a slope a walker walks, for a climb no staircase gives, and for a stride without a ZUPT
/// trajectory (Lu's steps, a gap).
pub const fn stairs(stride: &Stride) -> Option<Gait> {
    if stride.zupt_um == 0 || stride.flags.0 & StrideFlags::GAP != 0 {
        return None;
    }
    let climb = stride.climb_mm.unsigned_abs() as u64;
    let level_mm = stride.zupt_um as u64 / 1000;
    if climb < STAIRS_MIN_CLIMB_MM as u64
        || climb * 1000 < level_mm * STAIRS_MIN_SLOPE_PERMILLE as u64
        || climb > STAIRS_MAX_CLIMB_MM as u64
        || level_mm > STAIRS_MAX_LEVEL_MM as u64
    {
        return None;
    }
    Some(if stride.climb_mm > 0 {
        Gait::StairsUp
    } else {
        Gait::StairsDown
    })
}

/// `v` as a `u16`, saturated.
const fn saturate_u16(v: u64) -> u16 {
    if v > u16::MAX as u64 {
        u16::MAX
    } else {
        v as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::stride::StrideEvents;

    fn stride(start: u32, toe_off: u32, heel_strike: u32, end: u32, mm: u32) -> Stride {
        Stride {
            events: StrideEvents {
                start,
                heel_off: toe_off.saturating_sub(10).max(start),
                toe_off,
                heel_strike,
                foot_flat: heel_strike,
                end,
            },
            length_mm: mm,
            ..Stride::default()
        }
    }

    #[test]
    fn stairs_are_a_stair_climb_over_a_stair_stride() {
        let path = |level_mm: u32, climb_mm: i32| Stride {
            zupt_um: level_mm * 1000,
            climb_mm,
            ..stride(0, 20, 80, 100, level_mm)
        };
        // Step-over-step: two risers over two treads, up and down.
        assert_eq!(stairs(&path(600, 340)), Some(Gait::StairsUp));
        assert_eq!(stairs(&path(600, -340)), Some(Gait::StairsDown));
        // Two at a time: four of each.
        assert_eq!(stairs(&path(1200, 700)), Some(Gait::StairsUp));
        // The level, a ramp's stride, a street's.
        assert_eq!(stairs(&path(1400, 20)), None);
        assert_eq!(stairs(&path(1400, 116)), None);
        assert_eq!(stairs(&path(1400, 280)), None);
        // Beyond any flight's stride: a sprint stride's integration at the rails.
        assert_eq!(stairs(&path(2100, 950)), None);
        assert_eq!(stairs(&path(STAIRS_MAX_LEVEL_MM + 1, 600)), None);
        assert_eq!(stairs(&path(600, STAIRS_MAX_CLIMB_MM as i32 + 1)), None);
        // Without a trajectory.
        assert_eq!(stairs(&path(0, 340)), None);
    }

    #[test]
    fn walking_stride_at_200_hz() {
        let rate = SampleRate::from_hz(200).unwrap();
        // 1.1 s cycle, 0.42 s swing, 1.40 m.
        let g = GaitParameters::of(&stride(1000, 1100, 1184, 1220, 1400), None, rate);
        assert_eq!(g.stride_time_ms, 1100);
        assert_eq!(g.swing_time_ms, 420);
        assert_eq!(g.stance_time_ms, 680);
        assert_eq!(g.stance_permille, 618);
        assert_eq!(g.swing_permille, 382);
        assert_eq!(g.gait_velocity_mm_s, 1273);
        assert_eq!(g.cadence_spm, 109);
        assert_eq!(g.gait, Gait::Walking);
    }

    #[test]
    fn running_stride_has_a_flight_phase() {
        let rate = SampleRate::from_hz(100).unwrap();
        // 0.72 s cycle, 0.46 s swing: stance 36 %.
        let g = GaitParameters::of(&stride(0, 20, 66, 72, 2600), None, rate);
        assert_eq!((g.stride_time_ms, g.swing_time_ms), (720, 460));
        assert_eq!(g.stance_permille, 361);
        assert_eq!(g.gait, Gait::Running);
        assert_eq!(g.cadence_spm, 167);
        assert_eq!(g.gait_velocity_mm_s, 3611);
    }

    #[test]
    fn the_boundary_is_half_the_cycle() {
        let rate = SampleRate::from_hz(100).unwrap();
        assert_eq!(
            GaitParameters::of(&stride(0, 25, 75, 100, 1000), None, rate).gait,
            Gait::Walking
        );
        assert_eq!(
            GaitParameters::of(&stride(0, 25, 76, 100, 1000), None, rate).gait,
            Gait::Running
        );
    }

    #[test]
    fn stride_time_runs_heel_strike_to_heel_strike_when_strides_join() {
        let rate = SampleRate::from_hz(200).unwrap();
        let mut timer = GaitTimer::new(rate);
        let mut first = stride(1000, 1100, 1184, 1220, 1400);
        timer.process(&mut first);
        assert_eq!(
            first.gait.stride_time_ms, 1100,
            "no stride before: the cycle"
        );
        // The next stride starts where the first ended: heel-strike 1184 → 1410.
        let mut second = stride(1220, 1330, 1410, 1440, 1500);
        timer.process(&mut second);
        assert_eq!(second.gait.stride_time_ms, 1130);
        assert_eq!(second.gait.swing_time_ms, 400);
        assert_eq!(
            second.gait.stance_time_ms, 730,
            "previous heel-strike to toe-off"
        );
        // Velocity over the stride's own interval, 1.1 s.
        assert_eq!(second.gait.gait_velocity_mm_s, 1364);
        // A stride that does not join (after a gap) times its own cycle.
        let mut third = stride(1600, 1700, 1780, 1820, 1500);
        timer.process(&mut third);
        assert_eq!(third.gait.stride_time_ms, 1100);
    }

    #[test]
    fn a_gap_strides_heel_strike_times_nothing() {
        let rate = SampleRate::from_hz(200).unwrap();
        let mut timer = GaitTimer::new(rate);
        // A gap stride whose heel-strike is the hole's first missing sample (1010).
        let mut gap = stride(1000, 1005, 1010, 1220, 0);
        gap.flags = StrideFlags(StrideFlags::GAP);
        timer.process(&mut gap);
        // The stride after it joins it, but times its own cycle (1100 ms), not 1410 − 1010.
        let mut next = stride(1220, 1330, 1410, 1440, 1500);
        timer.process(&mut next);
        assert_eq!(next.gait.stride_time_ms, 1100);
        assert_eq!(next.gait.stance_time_ms, 700);
    }

    #[test]
    fn not_a_cycle_and_degenerate_strides() {
        let rate = SampleRate::from_hz(200).unwrap();
        for flag in [
            StrideFlags::FROM_REST,
            StrideFlags::TO_REST,
            StrideFlags::GAP,
        ] {
            let mut s = stride(0, 100, 180, 220, 1300);
            s.flags = StrideFlags(flag);
            let g = GaitParameters::of(&s, None, rate);
            assert_eq!(g.gait, Gait::Unknown);
            assert_eq!(g.stride_time_ms, 1100, "times are still reported");
        }
        let g = GaitParameters::of(&stride(5, 5, 5, 5, 0), None, rate);
        assert_eq!(g, GaitParameters::default());
        // Events out of order (never made by a detector) cannot underflow.
        let mut s = stride(0, 150, 100, 120, 900);
        s.events.heel_off = 0;
        let g = GaitParameters::of(&s, None, rate);
        assert!(g.swing_time_ms <= g.stride_time_ms);
        // A stride of the counter's wrap and a huge length saturate.
        let g = GaitParameters::of(&stride(u32::MAX - 10, 0, 0, 50, u32::MAX), None, rate);
        assert_eq!(g.stride_time_ms, 305);
        assert_eq!(g.gait_velocity_mm_s, u16::MAX);
    }
}

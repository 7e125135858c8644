//! The stride record: one per stride the detector finds, its events, length, trajectory
//! summary, gait parameters and the flags that qualify them. What every stage after the
//! detector reads and no detector owns.
//!
//! Indices are sample numbers since the pipeline started (holes counted), lengths mm.

use crate::record::gait::GaitParameters;
use crate::sensor::rate::SampleRate;

/// The longest stride a person makes, mm: an elite sprinter's stride (two steps) is about
/// 5 m. A model that says more was fed something else, and the stride is flagged
/// [`StrideFlags::IMPLAUSIBLE`].
pub const MAX_STRIDE_MM: u32 = 6000;

/// Properties of a stride that qualify its length.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StrideFlags(pub u16);

impl StrideFlags {
    /// A sample of the movement sat at a rail and nothing put back what it lost: the length
    /// is not measured (it is estimated, [`StrideFlags::ESTIMATED`]). Set by the stance
    /// detector (Huang's method, which restores nothing) for any rail; the cycle detector
    /// restores both sensors instead ([`StrideFlags::ACCEL_CLIPPED`],
    /// [`StrideFlags::GYRO_CLIPPED`]).
    pub const SATURATED: u16 = 1 << 0;
    /// The movement lasted longer than the movement buffer holds ([`MAX_MOVEMENT_MS`](crate::detect::seam::MAX_MOVEMENT_MS), or
    /// fewer samples on a board that picks a smaller buffer): not a walking stride.
    pub const TOO_LONG: u16 = 1 << 1;
    /// The stride starts from a stance longer than [`MAX_STANCE_IN_STRIDE_MS`](crate::detect::seam::MAX_STANCE_IN_STRIDE_MS): the first
    /// step after standing (informational).
    pub const FROM_REST: u16 = 1 << 2;
    /// The stance after the stride lasted longer than [`MAX_STANCE_IN_STRIDE_MS`](crate::detect::seam::MAX_STANCE_IN_STRIDE_MS), or the
    /// recording ended in it: the last step before standing, often a half-stride.
    pub const TO_REST: u16 = 1 << 3;
    /// The heading changed by more than 45° over the movement: a turn.
    pub const TURN: u16 = 1 << 4;
    /// The phase splitter found no major peak-valley pair for a boundary: toe-off and
    /// heel-strike are cluster centres, not measured events.
    pub const PHASES_GUESSED: u16 = 1 << 5;
    /// Samples were lost inside the stride's movement (a gap longer than
    /// [`crate::pipeline::config::BRIDGE_MAX_MS`]): it has no length. Its events outside the hole
    /// are measured; an event that falls inside the hole is unknown and set to the hole's
    /// first missing sample (see [`crate::pipeline::Pipeline::gap`]).
    pub const GAP: u16 = 1 << 6;
    /// The length model gave more than [`MAX_STRIDE_MM`]; the length is clamped to it.
    pub const IMPLAUSIBLE: u16 = 1 << 7;
    /// A short hole of lost samples (at most [`crate::pipeline::config::BRIDGE_MAX_MS`], or a
    /// longer one inside the stance) was bridged by interpolation: the stride and its
    /// length stay valid (informational).
    pub const BRIDGED: u16 = 1 << 8;
    /// The gyroscope sat at a rail in the movement; the tilt the clipped rates lost was
    /// restored from the end stance's gravity
    /// ([`crate::detect::zupt::ZuptIntegrator::displacement_restoring`]): the length stays
    /// valid (informational).
    pub const GYRO_CLIPPED: u16 = 1 << 9;
    /// The accelerometer sat at a rail in the movement; what it lost was put back where it
    /// was lost ([`crate::detect::clipping`]): the length stays valid (informational).
    pub const ACCEL_CLIPPED: u16 = 1 << 10;
    /// The length was not measured (a flag in [`StrideFlags::INVALID`] says why) and is the
    /// estimate from the strides before it at the same cadence ([`crate::length::estimate`]): it
    /// counts in the distance.
    pub const ESTIMATED: u16 = 1 << 11;
    /// The stride lasted several gait cycles (holes swallowed a stance instant): its
    /// estimated length is the cycles' ([`crate::length::estimate`], at most
    /// [`crate::length::estimate::MAX_CYCLES`] × [`MAX_STRIDE_MM`]), its times theirs, and
    /// it is not one stride to report as one (a watch's stride length, cadence).
    pub const SEVERAL_CYCLES: u16 = 1 << 12;
    /// Flags that make a measured length untrustworthy: such a stride's length is estimated
    /// instead ([`StrideFlags::ESTIMATED`]).
    pub const INVALID: u16 = Self::SATURATED | Self::TOO_LONG | Self::GAP | Self::IMPLAUSIBLE;

    /// True when no flag in [`StrideFlags::INVALID`] is set.
    pub const fn valid(self) -> bool {
        self.0 & Self::INVALID == 0
    }

    /// True when `flag` is set.
    pub const fn has(self, flag: u16) -> bool {
        self.0 & flag != 0
    }

    /// True when the stride's length counts in the distance: measured and valid, or
    /// estimated.
    pub const fn counts_distance(self) -> bool {
        self.valid() || self.has(Self::ESTIMATED)
    }
}

/// A stride's gait events: the one definition of them that the stride record, its logs and
/// the host's evaluation share. Indices are sample numbers since the pipeline started; in
/// order, `start ≤ heel_off ≤ toe_off ≤ heel_strike ≤ foot_flat ≤ end`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StrideEvents {
    /// First sample (a foot-flat, or at most [`MAX_STANCE_IN_STRIDE_MS`](crate::detect::seam::MAX_STANCE_IN_STRIDE_MS) before heel-off).
    pub start: u32,
    /// End of stance: first sample of the movement.
    pub heel_off: u32,
    /// Toe-off: push-off ends, swing begins.
    pub toe_off: u32,
    /// Heel-strike: swing ends.
    pub heel_strike: u32,
    /// Foot-flat: the movement ends, the next stance begins (for the stance detector, the
    /// same as `end`).
    pub foot_flat: u32,
    /// The stride's exclusive end, the next stride's start: the next foot-flat (stance
    /// detector) or the next stance instant (cycle detector).
    pub end: u32,
}

impl StrideEvents {
    /// Every event mapped by `f` (from core sample numbers to a recording's indices across
    /// its holes, say).
    pub fn map(self, f: impl Fn(u32) -> u32) -> Self {
        StrideEvents {
            start: f(self.start),
            heel_off: f(self.heel_off),
            toe_off: f(self.toe_off),
            heel_strike: f(self.heel_strike),
            foot_flat: f(self.foot_flat),
            end: f(self.end),
        }
    }

    /// The stride's times at `rate`. The four phases add up to the duration (each interval
    /// is rounded on its own, so they may differ from it by a millisecond or two).
    pub fn times_ms(&self, rate: SampleRate) -> StrideTimesMs {
        let ms = |a: u32, b: u32| rate.ms_of_samples(b.wrapping_sub(a));
        StrideTimesMs {
            start: rate.ms_of_samples(self.start),
            duration: ms(self.start, self.end),
            stance: ms(self.start, self.heel_off),
            push_off: ms(self.heel_off, self.toe_off),
            swing: ms(self.toe_off, self.heel_strike),
            heel_strike: ms(self.heel_strike, self.end),
        }
    }
}

/// One stride. Indices are sample numbers since the pipeline started.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Stride {
    /// Running stride number, from 0, among the strides that count (the pipeline numbers
    /// them after the step check; a detector numbers the movements it hands out).
    pub index: u32,
    /// Its gait events.
    pub events: StrideEvents,
    /// Length of the stride, mm, from the pipeline's length model
    /// ([`crate::length::models`]); 0 until the pipeline sets it.
    pub length_mm: u32,
    /// Horizontal ZUPT displacement over the movement, µm (saturates at 4.29 km).
    pub zupt_um: u32,
    /// Height gained over the stride, mm (stairs, slopes).
    pub climb_mm: i32,
    /// Highest point of the sensor above its start over the movement, mm (gaitmap's
    /// `max_sensor_lift`, [`crate::detect::zupt::Displacement::max_lift_um`]); 0 without a ZUPT
    /// trajectory (Lu's steps, a gap).
    pub max_sensor_lift_mm: u16,
    /// Heading change over the movement, centidegrees, counter-clockwise seen from above
    /// positive (gaitmap's `turning_angle`, [`crate::detect::zupt::ZuptIntegrator::heading_change_cdeg`]);
    /// 0 without a ZUPT trajectory.
    pub turning_angle_cdeg: i16,
    /// Which way the foot travelled over the stride, centidegrees counter-clockwise seen from
    /// above, in (−18 000, 18 000]: the direction of the horizontal ZUPT displacement in the
    /// level frame of the stride's start, whose x axis is the sensor's x axis laid level
    /// ([`crate::fixed::QuatQ30::level_from_up`]). The foot stands the same way on the
    /// sensor at every stance, so this is the direction of travel against the foot, offset
    /// by how the clip is mounted: a backward stride reads 180° from a forward one, a
    /// sideways one 90° (not a compass heading). 0 without a ZUPT trajectory.
    pub travel_cdeg: i16,
    /// Timing, velocity, cadence, walking or running: the pipeline's last stage
    /// ([`crate::gait`]), once the length is set.
    pub gait: GaitParameters,
    /// Qualifiers.
    pub flags: StrideFlags,
    /// The largest one-way rotation of the foot about its pitch axis in the movement, degrees
    /// (the swing; [`crate::detect::step_check`]).
    pub swing_deg: u16,
    /// What the foot did since the last stride that counted
    /// ([`crate::detect::step_check`]).
    pub between: Between,
}

/// The time between two strides that count, by what the foot did: at rest, or moving
/// without a step (cycling, a vehicle, fidgeting, and the movements the step check refused).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Between {
    /// At rest, ms.
    pub still_ms: u32,
    /// Moving, not walking, ms.
    pub moving_ms: u32,
}

/// A stride's times in milliseconds, as every log of it states them (the defmt line, the
/// serial line): one definition of what `t`, `dur` and the four phases are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StrideTimesMs {
    /// The start (the stance instant) since the first sample.
    pub start: u32,
    /// Start to end.
    pub duration: u32,
    /// Start to heel-off: the part of this stride's stance before the foot rolls.
    pub stance: u32,
    /// Heel-off to toe-off.
    pub push_off: u32,
    /// Toe-off to heel-strike.
    pub swing: u32,
    /// Heel-strike to the end (the next stance instant).
    pub heel_strike: u32,
}

impl Stride {
    /// The stride's times at `rate` ([`StrideEvents::times_ms`]).
    pub fn times_ms(&self, rate: SampleRate) -> StrideTimesMs {
        self.events.times_ms(rate)
    }

    /// Sets the length, clamped to [`MAX_STRIDE_MM`] and flagged
    /// [`StrideFlags::IMPLAUSIBLE`] above it.
    pub fn set_length_mm(&mut self, mm: u32) {
        if mm > MAX_STRIDE_MM {
            self.flags.0 |= StrideFlags::IMPLAUSIBLE;
        }
        self.length_mm = mm.min(MAX_STRIDE_MM);
    }
}

/// What Lu's length chain needs of one of the peak-valley detector's steps
/// ([`crate::detect::peak_valley`]), handed to the length stage with the step's record.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StepAmplitude {
    /// Peak minus valley of the low-passed vertical acceleration, g/32 768.
    pub peak_to_valley: i32,
    /// Samples since the previous step's peak (0 for a walk's first step).
    pub period: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_the_intervals_between_the_events() {
        let s = StrideEvents {
            start: 200,
            heel_off: 210,
            toe_off: 240,
            heel_strike: 301,
            end: 400,
            ..StrideEvents::default()
        };
        let t = s.times_ms(SampleRate::from_hz(200).unwrap());
        assert_eq!(
            t,
            StrideTimesMs {
                start: 1000,
                duration: 1000,
                stance: 50,
                push_off: 150,
                swing: 305,
                heel_strike: 495,
            }
        );
        // A 204.8 Hz recording: 1024 samples are exactly 5 s.
        let t = StrideEvents {
            end: 1024,
            ..StrideEvents::default()
        }
        .times_ms(SampleRate::from_millihertz(204_800).unwrap());
        assert_eq!(t.duration, 5000);
    }
}

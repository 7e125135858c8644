//! Toe-off and heel-strike from the foot's sagittal angular rate.
//!
//! A foot-mounted gyro sees the foot pitch about its medio-lateral axis through every step,
//! and the contact events are turns of that rotation (Jasiewicz et al., "Gait event detection
//! using linear accelerometers or angular velocity transducers in able-bodied and spinal-cord
//! injured individuals", Gait & Posture 24, 2006, the foot's sagittal angular velocity;
//! Rampp et al., "Inertial sensor-based stride parameter calculation from gait sequences in
//! geriatric patients", IEEE TBME 62(4), 2015, gaitmap's `RamppEventDetection`):
//!
//! - **the swing** is the movement's largest rotation: of the runs of one sign of the rate
//!   (lobes), the one with the largest integral (the toe-up swing turns the foot 60–100°, the
//!   push-off's heel rise 30–50°, the foot slap 10–20°), whose fastest rate reaches
//!   [`SWING_MIN_MRADPS`];
//! - **toe-off** is the push-off peak before it: the fastest rotation the other way (heel up,
//!   the foot rolling over its toes until they leave the ground);
//! - **heel-strike** is the zero crossing that ends the swing: the toe-up rotation stops when
//!   the heel meets the ground (the foot then slaps flat, the other way again).
//!
//! The rate is about the steps' principal rotation axis
//! ([`crate::detect::foot_frame::FootFrame::pitch_axis_q14`]), which has no sign of its own, so
//! the swing's sign comes from each movement (by its size, not its direction). That axis, not
//! the foot frame's horizontal left axis, because on a sensor whose steps turn about a tilted
//! axis the horizontal projection loses half the swing (`ipol_gait_events` subject 1's right
//! foot: the push-off 12 rad/s, the swing 2 rad/s about it, 6 rad/s about the principal axis).
//!
//! Which turn of the rate each event is was chosen against motion capture, not fitted:
//! on `gaitmap_walk`'s mocap events the push-off peak lies 5 ms before toe-off (signed
//! median) and the swing-end crossing 4 ms after heel-strike, where Rampp's toe-off (the
//! zero crossing after the push-off peak) lies 17 ms after it and the foot-slap peak 49 ms
//! after heel-strike, as did Huang's acceleration pair (the impact) at 59 ms (`gaitclip
//! events`, docs/accuracy.md). `ipol_gait_events`' annotations follow a template of their
//! own (CyrilVoisard/ipol_gaitevents, `deal_stride.py`: toe-off 3 samples after the
//! template's push-off peak, heel-strike 2.4 samples after its swing-end crossing, at
//! 100 Hz), so these events lie 20–30 ms before them by definition.
//!
//! The heel-strike is the sample nearest the crossing (of the last one of the swing's sign and
//! the first of the other); both events are whole samples. Integer, two passes over the
//! movement, no buffer of its own.

/// What [`find`] needs to call a rotation a swing: its fastest toe-up rate at least this,
/// mrad/s (1 rad/s: a step's swing reaches 4–10 rad/s, a shuffle or a fidget less).
pub const SWING_MIN_MRADPS: u32 = 1000;

/// A movement's toe-off and heel-strike, as offsets from its first sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GyroEvents {
    /// The push-off peak.
    pub toe_off: u32,
    /// The end of the swing.
    pub heel_strike: u32,
}

/// One rotation one way: the samples up to `end`, their integral and their fastest rate
/// (signed along the lobe's way, so that a brief turn back inside it subtracts), and where
/// that is.
#[derive(Clone, Copy, Debug, Default)]
struct Lobe {
    end: usize,
    negative: bool,
    area: i64,
    peak: i32,
    peak_at: usize,
}

impl Lobe {
    fn add(&mut self, i: usize, v: i32) {
        self.area += v as i64;
        if v > self.peak {
            (self.peak, self.peak_at) = (v, i);
        }
    }
}

/// The events of one movement whose column `column` holds the sagittal rate (any scale and
/// sign), or `None` when it has no swing (no lobe whose rate reaches `swing_min`), no lobe
/// the other way before it (the push-off) or no end of the swing inside it.
///
/// A lobe turns only when the rate passes `swing_min / 2` the other way (hysteresis): a swing
/// whose rate touches zero half way and goes on (a sensor's axis a little off the foot's)
/// stays one swing, and ends at its last zero crossing (a sample at zero is a crossing).
/// Never panics.
// Not inlined: its lobes take stack only while it runs, after the phase splitter has
// returned, not under the splitter's (the M0's stack).
#[inline(never)]
pub fn find<const N: usize>(
    movement: &[[i16; N]],
    column: usize,
    swing_min: i16,
) -> Option<GyroEvents> {
    if column >= N || movement.is_empty() {
        return None;
    }
    let rate = |i: usize| movement[i][column] as i32;
    let band = (swing_min.max(2) / 2) as i32;
    let along = |i: usize, negative: bool| if negative { -rate(i) } else { rate(i) };
    // The swing (the lobe of the largest integral among those fast enough) and the lobe
    // before it.
    let mut swing: Option<(Lobe, Option<Lobe>)> = None;
    let mut before: Option<Lobe> = None;
    let mut lobe = Lobe {
        negative: rate(0) < 0,
        ..Lobe::default()
    };
    // The first sample of the run the other way (or at zero) the lobe ends in, if any.
    let mut crossed: Option<usize> = None;
    for i in 0..=movement.len() {
        let turned = i < movement.len() && along(i, lobe.negative) < -band;
        if i < movement.len() {
            crossed = match along(i, lobe.negative) <= 0 {
                true => crossed.or(Some(i)),
                false => None,
            };
        }
        if i == movement.len() || turned {
            // It ends at the crossing: the run the other way belongs to the next lobe.
            let end = crossed.unwrap_or(i);
            let mut next = Lobe {
                negative: !lobe.negative,
                ..Lobe::default()
            };
            for k in end..i {
                lobe.area -= along(k, lobe.negative) as i64;
                next.add(k, along(k, next.negative));
            }
            lobe.end = end;
            let fast = lobe.peak >= swing_min.max(1) as i32;
            if fast && swing.is_none_or(|(s, _)| lobe.area > s.area) {
                swing = Some((lobe, before));
            }
            if i == movement.len() {
                break;
            }
            before = Some(lobe);
            lobe = next;
            crossed = None;
        }
        lobe.add(i, along(i, lobe.negative));
    }
    let (swing, push) = swing?;
    // Toe-off: the push-off's peak, the fastest rotation of the lobe before the swing.
    let push = push.filter(|p| p.peak > 0)?;
    if swing.end >= movement.len() || swing.end == 0 {
        return None;
    }
    // Heel-strike: the sample nearest the crossing that ends the swing.
    let (last, first) = (swing.end - 1, swing.end);
    let heel_strike = if rate(last).abs() < rate(first).abs() {
        last
    } else {
        first
    };
    Some(GyroEvents {
        toe_off: push.peak_at as u32,
        heel_strike: heel_strike as u32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn movement(rate: &[i16]) -> heapless::Vec<[i16; 4], 64> {
        rate.iter().map(|&r| [0, 0, 0, r]).collect()
    }

    #[test]
    fn toe_off_is_the_push_off_peak_and_heel_strike_the_crossing_after_the_swing() {
        // Push-off up to 900 at 3, swing down to −5000 at 8, crossing between 11 and 12
        // (−40, +300: 11 is nearer), foot slap at 13.
        let m = movement(&[
            100, 400, 700, 900, 600, -200, -2000, -4000, -5000, -3000, -800, -40, 300, 1500, 200,
        ]);
        assert_eq!(
            find(&m, 3, 1000),
            Some(GyroEvents {
                toe_off: 3,
                heel_strike: 11
            })
        );
        // The first non-negative sample when it is the nearer.
        let m = movement(&[500, -3000, -900, 10, 800]);
        assert_eq!(find(&m, 3, 1000).map(|e| e.heel_strike), Some(3));
    }

    #[test]
    fn the_swing_is_the_largest_rotation_whatever_its_sign() {
        // The same step with the axis the other way round: the same events.
        let step = [
            100, 400, 700, 900, 600, -200, -2000, -4000, -5000, -3000, -800, -40, 300, 1500, 200,
        ];
        let flipped: heapless::Vec<i16, 64> = step.iter().map(|r| -r).collect();
        assert_eq!(
            find(&movement(&step), 3, 1000),
            find(&movement(&flipped), 3, 1000)
        );
        // A foot slap faster than the swing but short: the swing is the larger rotation.
        let m = movement(&[
            800, 1200, 300, -1500, -2500, -2600, -2400, -1500, -300, 200, 6000, 500, 100,
        ]);
        assert_eq!(
            find(&m, 3, 1000),
            Some(GyroEvents {
                toe_off: 1,
                heel_strike: 9
            })
        );
    }

    #[test]
    fn a_swing_that_touches_zero_half_way_stays_one_swing() {
        // The swing's rate comes back to +100 for a sample (less than half of 1 000) and goes
        // on: one swing, ending at the last crossing (between 9 and 10).
        let m = movement(&[
            300, 900, 200, -1500, -2500, 100, -2000, -1800, -600, -30, 400, 2000, 300,
        ]);
        assert_eq!(
            find(&m, 3, 1000),
            Some(GyroEvents {
                toe_off: 1,
                heel_strike: 9
            })
        );
        // Past the band the other way, it is two rotations: the larger is the swing.
        let m = movement(&[
            300, 900, 200, -1500, -2500, 800, -2000, -1800, -600, -30, 400, 2000, 300,
        ]);
        assert_eq!(
            find(&m, 3, 1000),
            Some(GyroEvents {
                toe_off: 5,
                heel_strike: 9
            })
        );
    }

    #[test]
    fn no_swing_no_push_off_or_no_end_give_none() {
        // The fastest toe-up rotation is no swing.
        assert_eq!(find(&movement(&[300, -900, -500, 200]), 3, 1000), None);
        // Nothing of the other sign before the swing.
        assert_eq!(find(&movement(&[-100, -3000, -500, 200]), 3, 1000), None);
        // The swing never ends in the movement.
        assert_eq!(find(&movement(&[300, -3000, -500, -20]), 3, 1000), None);
        // Empty, a column that is not there.
        assert_eq!(find(&movement(&[]), 3, 1000), None);
        assert_eq!(find(&movement(&[300, -3000, 200]), 4, 1000), None);
        // The extremes the column can hold.
        assert_eq!(
            find(&movement(&[1, i16::MIN, 0]), 3, i16::MAX).map(|e| e.heel_strike),
            Some(2)
        );
        assert_eq!(
            find(&movement(&[-1, i16::MAX, -1]), 3, i16::MAX).map(|e| e.heel_strike),
            Some(2)
        );
    }
}

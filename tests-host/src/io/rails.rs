//! Where a recording's sensor clipped, axis by axis: learnt from the data, or given.
//!
//! Real parts clip below their nominal range (a ±16 g accelerometer axis at −15.6 g, a
//! ±2000 °/s gyro at ±1 988 °/s), and a replay that assumed the nominal rails would neither
//! flag nor restore those samples. A rail shows in the data as a **flat run at an
//! extreme**: the samples within [`FLAT_TOLERANCE`] of the axis's most extreme value, seen
//! more than once (a clipped heel strike every stride) or for [`MIN_RUN`] samples in a row. A
//! smooth peak, however fast the sampling, has one sample at its top, and different peaks
//! reach different heights; a rail makes different events stop at the same level.
//!
//! Without such a plateau the axis's rail is its nominal range: given (`--acc-range-g`,
//! `--gyro-range-dps`, or `acc_range_g` / `gyro_range_dps` in a `meta.json`), or else the
//! MPU6050 range the replay converts to (±16 g, ±2000 °/s), whose counts saturate there.
//! The learnt or nominal rail goes to the core in counts ([`gaitclip::sensor::sample::Rails`]).

use gaitclip::sensor::sample::{AxisRails, Rails, RawSample};
use serde::Serialize;

use crate::io::trace::{GivenRanges, ImuSample, Ranges, G_MPS2};

/// A sample within this share of an axis's extreme value sits on the plateau (a real part's
/// rail wanders by ±0.3 % with the other axes' cross-coupling: `esangeni_run`).
pub const FLAT_TOLERANCE: f64 = 0.005;
/// A flat run at the extreme of at least this many samples is a rail.
pub const MIN_RUN: usize = 3;
/// Or: this many separate flat runs of at least two samples, or this many samples exactly at
/// the extreme (a digital rail repeats its value; a smooth peak's top is one sample, and two
/// peaks within 0.5 % of each other happen by chance: `pyshoe_vicon` at 7.97 g).
pub const MIN_EVENTS: usize = 2;
/// An extreme below this share of the nominal range is no rail, however flat (a stance
/// reading nothing but gravity).
pub const MIN_SHARE_OF_RANGE: f64 = 0.5;

/// How one side of one axis's rail was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RailSource {
    /// A flat run at the extreme.
    Learnt,
    /// The nominal range (given, or the conversion's).
    Nominal,
}

/// One side of one axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Rail {
    /// The rail, in the axis's unit (m/s² or rad/s), signed.
    pub value: f64,
    /// How it was found.
    pub source: RailSource,
}

/// Both rails of one axis, and how many samples sat at them.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AxisReport {
    /// `acc_x` … `gyr_z`.
    pub axis: &'static str,
    /// The negative rail.
    pub low: Rail,
    /// The positive rail.
    pub high: Rail,
    /// Samples at either rail (counted in the counts fed to the core).
    pub clipped: usize,
}

/// The rails of a recording, axis by axis, and the core's rails in counts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RailsReport {
    /// Accelerometer x, y, z, then gyroscope x, y, z.
    pub axes: Vec<AxisReport>,
    /// What the core is told.
    #[serde(skip)]
    pub rails: Rails,
}

/// Axis names, in [`RailsReport::axes`] order.
pub const AXES: [&str; 6] = ["acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"];

impl RailsReport {
    /// Axes that clipped, as `name n` items, or `none`.
    pub fn clipped_line(&self) -> String {
        let c: Vec<String> = self
            .axes
            .iter()
            .filter(|a| a.clipped > 0)
            .map(|a| {
                let (unit, scale) = if a.axis.starts_with("acc") {
                    ("g", 1.0 / G_MPS2)
                } else {
                    ("°/s", 180.0 / std::f64::consts::PI)
                };
                let side = |r: &Rail| {
                    format!(
                        "{:+.2} {unit}{}",
                        r.value * scale,
                        if r.source == RailSource::Learnt {
                            " learnt"
                        } else {
                            ""
                        }
                    )
                };
                format!(
                    "{} {} at {} / {}",
                    a.axis,
                    a.clipped,
                    side(&a.low),
                    side(&a.high)
                )
            })
            .collect();
        if c.is_empty() {
            "none".into()
        } else {
            c.join(", ")
        }
    }

    /// Samples with any axis at a rail.
    pub fn clipped_total(&self) -> usize {
        self.axes.iter().map(|a| a.clipped).sum()
    }
}

/// The value of channel `k` (0–2 accelerometer, 3–5 gyroscope) of a sample.
fn channel(s: &ImuSample, k: usize) -> f64 {
    if k < 3 {
        s.acc_mps2[k]
    } else {
        s.gyr_radps[k - 3]
    }
}

/// The rail on each side (low, high) of every channel (0–2 accelerometer, 3–5 gyroscope),
/// from a flat run at the extreme, where the data shows one above [`MIN_SHARE_OF_RANGE`] of
/// `nominal[k]` (> 0, the axis's unit). Two passes over the samples for all twelve sides: the
/// extremes, then the runs at them.
fn plateaus<I: Iterator<Item = ImuSample>>(
    samples: &impl Fn() -> I,
    nominal: [f64; 6],
) -> [[Option<f64>; 2]; 6] {
    const SIGNS: [f64; 2] = [-1.0, 1.0];
    let mut m = [[f64::NEG_INFINITY; 2]; 6];
    for s in samples() {
        let s = &s;
        for (k, mk) in m.iter_mut().enumerate() {
            let v = channel(s, k);
            if v.is_finite() {
                for (side, sign) in SIGNS.iter().enumerate() {
                    mk[side] = mk[side].max(sign * v);
                }
            }
        }
    }
    // Per side: the edge of the plateau, and its (flat runs, longest run, run, exact) counts.
    // `m` is −∞ for no finite sample: no rail either.
    let edge = m.map(|mk| mk.map(|m| m - FLAT_TOLERANCE * m));
    let candidate: [[bool; 2]; 6] = core::array::from_fn(|k| {
        core::array::from_fn(|side| {
            let mk = m[k][side];
            !(mk.is_nan() || mk < MIN_SHARE_OF_RANGE * nominal[k])
        })
    });
    let mut counts = [[(0usize, 0usize, 0usize, 0usize); 2]; 6];
    // The candidate sides only, listed once (channel, side, sign, extreme, edge): the pass
    // over the samples then tests no flag per side and sample.
    let sides: Vec<(usize, usize, f64, f64, f64)> = (0..6)
        .flat_map(|k| (0..2).map(move |side| (k, side)))
        .filter(|&(k, side)| candidate[k][side])
        .map(|(k, side)| (k, side, SIGNS[side], m[k][side], edge[k][side]))
        .collect();
    if !sides.is_empty() {
        for s in samples() {
            let s = &s;
            for &(k, side, sign, extreme, edge) in &sides {
                let v = sign * channel(s, k);
                let (flat_runs, longest, run, exact) = &mut counts[k][side];
                if v >= extreme {
                    *exact += 1;
                }
                if v >= edge {
                    *run += 1;
                    if *run == 2 {
                        *flat_runs += 1;
                    }
                    *longest = (*longest).max(*run);
                } else {
                    *run = 0;
                }
            }
        }
    }
    core::array::from_fn(|k| {
        core::array::from_fn(|side| {
            let (flat_runs, longest, _, exact) = counts[k][side];
            (candidate[k][side]
                && (longest >= MIN_RUN || flat_runs >= MIN_EVENTS || exact >= MIN_EVENTS))
                .then_some(edge[k][side])
        })
    })
}

/// The rails of `samples`, converted at `ranges` (the core's counts), with the nominal
/// ranges `given` where known.
pub fn learn(samples: &[ImuSample], ranges: Ranges, given: GivenRanges) -> RailsReport {
    let counts: Vec<RawSample> = samples.iter().map(ranges.converter()).collect();
    learn_counted(samples, &counts, ranges, given)
}

/// [`learn`] where the counts are at hand: `counts[i]` is [`Ranges::to_counts`] of
/// `samples[i]`.
pub fn learn_counted(
    samples: &[ImuSample],
    counts: &[RawSample],
    ranges: Ranges,
    given: GivenRanges,
) -> RailsReport {
    learn_counted_of(
        &|| samples.iter().copied(),
        counts.iter().copied(),
        ranges,
        given,
    )
}

/// [`learn_counted`] of the samples each call of `samples` yields in order (two passes) and
/// their `counts` (one pass): a recording read as a stream, nothing kept per sample.
pub fn learn_counted_of<I: Iterator<Item = ImuSample>>(
    samples: &impl Fn() -> I,
    counts: impl Iterator<Item = RawSample>,
    ranges: Ranges,
    given: GivenRanges,
) -> RailsReport {
    // The conversion's own full scale: its counts saturate there.
    let acc_full = 32768.0 / ranges.accel_counts_per_mps2();
    let gyr_full = 32768.0 / ranges.gyro_counts_per_radps();
    let acc_nominal = given.acc_g.map_or(acc_full, |g| (g * G_MPS2).min(acc_full));
    let gyr_nominal = given
        .gyro_dps
        .map_or(gyr_full, |d| d.to_radians().min(gyr_full));
    let mut axes = Vec::with_capacity(6);
    let mut rails = Rails::FULL_SCALE;
    let nominal_of = |k: usize| if k < 3 { acc_nominal } else { gyr_nominal };
    let found = plateaus(samples, core::array::from_fn(nominal_of));
    for (k, &axis) in AXES.iter().enumerate() {
        let (nominal, per_unit) = if k < 3 {
            (acc_nominal, ranges.accel_counts_per_mps2())
        } else {
            (gyr_nominal, ranges.gyro_counts_per_radps())
        };
        let side = |sign: f64| match found[k][usize::from(sign > 0.0)] {
            Some(v) => Rail {
                value: sign * v.min(nominal),
                source: if v < nominal {
                    RailSource::Learnt
                } else {
                    RailSource::Nominal
                },
            },
            None => Rail {
                value: sign * nominal,
                source: RailSource::Nominal,
            },
        };
        let (low, high) = (side(-1.0), side(1.0));
        // A sample at or beyond the rail in the unit reads at or beyond these counts.
        let to_counts = |v: f64, round: fn(f64) -> f64| {
            round(v * per_unit).clamp(i16::MIN as f64, i16::MAX as f64) as i16
        };
        let r = AxisRails::new(
            to_counts(low.value, f64::ceil),
            to_counts(high.value, f64::floor),
        )
        .unwrap_or(AxisRails::FULL_SCALE);
        if k < 3 {
            rails.accel[k] = r;
        } else {
            rails.gyro[k - 3] = r;
        }
        axes.push(AxisReport {
            axis,
            low,
            high,
            clipped: 0,
        });
    }
    // Counted in a local array, not through the reports (which the loop would write back
    // on every sample).
    let mut clipped = [0usize; 6];
    for c in counts {
        let bits = rails.clipped_axes(&c);
        // Bits 0–2 accelerometer, 3–5 gyroscope: the same order as `AXES`.
        for (k, n) in clipped.iter_mut().enumerate() {
            *n += usize::from(bits & (1 << k) != 0);
        }
    }
    for (a, n) in axes.iter_mut().zip(clipped) {
        a.clipped = n;
    }
    RailsReport { axes, rails }
}

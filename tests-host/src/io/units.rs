//! The units a recording is in, and the check that they are what they say.
//!
//! A recording read in the wrong unit replays without complaint and measures nonsense: an
//! accelerometer in g read as m/s² gives a tenth of the distance, a gyro in °/s read as rad/s
//! a handful of strides. Every reader (CSV, MCAP, a Python DataFrame) declares its units
//! (the datasets' m/s² and rad/s unless a flag, a keyword or `meta.json` says otherwise),
//! converts to m/s² and rad/s here, and then [`check`]s them against physics, not against a
//! format: a foot reads about 1 g for most of any recording, and no IMU turns faster than
//! ±4000 °/s. A unit that fails the check is refused with the unit the values look like and
//! how to say so; nothing is rescaled behind the user's back.

use crate::io::clock::nth_smallest;
use std::fmt;

use crate::io::trace::ImuSample;

/// Standard gravity, m/s² (the unit `g`).
pub const G_MPS2: f64 = 9.80665;
/// The lower quartile of the accelerometer's magnitude over a recording lies in this range,
/// m/s², whatever the wearer does: a foot at rest or in stance reads about 1 g for a quarter
/// of any recording (0.81–1.17 g over the 310 shared recordings, bicycling to running, whose
/// median reaches 2.16 g), and a unit off by ten or a thousand lands far outside it.
pub const ACC_QUARTILE_MPS2: (f64, f64) = (0.5 * G_MPS2, 2.0 * G_MPS2);
/// No IMU in a shoe clip turns faster than this, rad/s: ±4000 °/s (69.8 rad/s) is the
/// largest gyro range on the market. A gyro in °/s read as rad/s reads a walk's swing at
/// 300–700 "rad/s".
pub const GYRO_MAX_RADPS: f64 = 75.0;
/// A foot that steps turns faster than this at its 99.9th percentile, rad/s (30 °/s); a
/// gyro in rad/s read as °/s reads a walk's swing at 0.1 "rad/s".
pub const GYRO_STEPPING_MIN_RADPS: f64 = core::f64::consts::FRAC_PI_6;
/// The accelerometer's magnitude spreads (standard deviation) by more than this, m/s², when
/// the foot steps.
pub const ACC_STEPPING_SPREAD_MPS2: f64 = 2.0;

/// The unit of the accelerometer's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccUnit {
    /// m/s² (the datasets' layout).
    #[default]
    MetresPerSecondSquared,
    /// Standard gravities, 9.80665 m/s².
    G,
    /// Thousandths of a standard gravity.
    MilliG,
}

/// The unit of the gyroscope's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroUnit {
    /// rad/s (the datasets' layout).
    #[default]
    RadiansPerSecond,
    /// °/s.
    DegreesPerSecond,
}

impl AccUnit {
    /// Every unit, in the order a likely one is looked for.
    pub const ALL: [AccUnit; 3] = [AccUnit::MetresPerSecondSquared, AccUnit::G, AccUnit::MilliG];

    /// The name the flags, `meta.json` and Python take.
    pub const fn name(self) -> &'static str {
        match self {
            AccUnit::MetresPerSecondSquared => "m/s^2",
            AccUnit::G => "g",
            AccUnit::MilliG => "mg",
        }
    }

    /// m/s² per unit.
    pub const fn mps2(self) -> f64 {
        match self {
            AccUnit::MetresPerSecondSquared => 1.0,
            AccUnit::G => G_MPS2,
            AccUnit::MilliG => G_MPS2 / 1000.0,
        }
    }

    /// The unit a name spells (`m/s^2`, `m/s²`, `m/s2`, `g`, `mg`), case as written for `g`
    /// and `mg` too.
    pub fn from_name(s: &str) -> Option<Self> {
        match s.trim() {
            "m/s^2" | "m/s²" | "m/s2" | "m s^-2" => Some(AccUnit::MetresPerSecondSquared),
            "g" | "G" => Some(AccUnit::G),
            "mg" | "mG" => Some(AccUnit::MilliG),
            _ => None,
        }
    }
}

impl GyroUnit {
    /// Both units.
    pub const ALL: [GyroUnit; 2] = [GyroUnit::RadiansPerSecond, GyroUnit::DegreesPerSecond];

    /// The name the flags, `meta.json` and Python take.
    pub const fn name(self) -> &'static str {
        match self {
            GyroUnit::RadiansPerSecond => "rad/s",
            GyroUnit::DegreesPerSecond => "deg/s",
        }
    }

    /// rad/s per unit.
    pub const fn radps(self) -> f64 {
        match self {
            GyroUnit::RadiansPerSecond => 1.0,
            GyroUnit::DegreesPerSecond => core::f64::consts::PI / 180.0,
        }
    }

    /// The unit a name spells (`rad/s`, `deg/s`, `°/s`, `dps`).
    pub fn from_name(s: &str) -> Option<Self> {
        match s.trim() {
            "rad/s" | "rad s^-1" => Some(GyroUnit::RadiansPerSecond),
            "deg/s" | "°/s" | "dps" => Some(GyroUnit::DegreesPerSecond),
            _ => None,
        }
    }
}

/// The units of a recording's values (time is always in s).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Units {
    /// The accelerometer's.
    pub acc: AccUnit,
    /// The gyroscope's.
    pub gyro: GyroUnit,
}

/// Where a unit was declared: the error says how to declare another there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Front {
    /// The command line (`--acc-unit`, `--gyr-unit`, or `meta.json`'s `units`).
    #[default]
    CommandLine,
    /// Python's `acc_unit=` / `gyr_unit=` keywords (or `meta.json`'s `units` beside a path).
    Python,
}

/// A recording whose values cannot be in the units declared for them.
#[derive(Clone, Debug, PartialEq)]
pub enum UnitError {
    /// The accelerometer's lower quartile of magnitude is not about 1 g in the unit declared.
    Acc {
        /// The unit declared.
        declared: AccUnit,
        /// The lower quartile of its magnitude, read in it, m/s².
        quartile_mps2: f64,
        /// The unit that would make it about 1 g, if one does.
        likely: Option<AccUnit>,
        /// Where to say so.
        front: Front,
    },
    /// The gyro turns faster than any IMU can in the unit declared.
    GyroTooFast {
        /// The unit declared.
        declared: GyroUnit,
        /// Its 99.9th percentile of |ω|, rad/s.
        top_radps: f64,
        /// Where to say so.
        front: Front,
    },
    /// The accelerometer shows steps but the gyro barely turns in the unit declared.
    GyroTooSlow {
        /// The unit declared.
        declared: GyroUnit,
        /// Its 99.9th percentile of |ω|, rad/s.
        top_radps: f64,
        /// Where to say so.
        front: Front,
    },
    /// A unit name that is none of the known ones.
    UnknownName {
        /// `acc` or `gyr`.
        sensor: &'static str,
        /// The name as given.
        name: String,
    },
}

impl UnitError {
    /// Where this error says to declare the unit.
    fn front(&self) -> Front {
        match self {
            UnitError::Acc { front, .. }
            | UnitError::GyroTooFast { front, .. }
            | UnitError::GyroTooSlow { front, .. } => *front,
            UnitError::UnknownName { .. } => Front::CommandLine,
        }
    }
}

/// How to declare `unit` of `sensor` (`acc` or `gyr`) at `front`.
fn how(front: Front, sensor: &str, unit: &str) -> String {
    match front {
        Front::CommandLine => format!(
            "pass --{sensor}-unit {unit} (or \"units\": {{\"{sensor}\": \"{unit}\"}} in a meta.json beside the file)"
        ),
        Front::Python => format!(
            "pass {sensor}_unit='{unit}' (or \"units\": {{\"{sensor}\": \"{unit}\"}} in a meta.json beside the file)"
        ),
    }
}

impl fmt::Display for UnitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UnitError::Acc {
                declared,
                quartile_mps2,
                likely,
                ..
            } => {
                write!(
                    f,
                    "the accelerometer reads {:.4} {} where the foot is stillest (the lower quartile of its magnitude), where a foot reads about 1 g: ",
                    quartile_mps2 / declared.mps2(),
                    declared.name()
                )?;
                match likely {
                    Some(u) => write!(
                        f,
                        "its values look like {}: {}",
                        u.name(),
                        how(self.front(), "acc", u.name())
                    ),
                    None => write!(
                        f,
                        "in none of {} is that about 1 g: are these accelerometer values?",
                        AccUnit::ALL.map(|u| u.name()).join(", ")
                    ),
                }
            }
            UnitError::GyroTooFast {
                declared,
                top_radps,
                ..
            } => write!(
                f,
                "the gyro reaches {:.0} {} (99.9th percentile), beyond any IMU's range (±4000 °/s): its values look like deg/s: {}",
                top_radps / declared.radps(),
                declared.name(),
                how(self.front(), "gyr", GyroUnit::DegreesPerSecond.name())
            ),
            UnitError::GyroTooSlow {
                declared,
                top_radps,
                ..
            } => write!(
                f,
                "the accelerometer shows steps but the gyro stays under {:.3} {} (99.9th percentile, under 30 °/s): its values look like rad/s: {}",
                top_radps / declared.radps(),
                declared.name(),
                how(self.front(), "gyr", GyroUnit::RadiansPerSecond.name())
            ),
            UnitError::UnknownName { sensor, name } => {
                let known: Vec<&str> = if *sensor == "acc" {
                    AccUnit::ALL.iter().map(|u| u.name()).collect()
                } else {
                    GyroUnit::ALL.iter().map(|u| u.name()).collect()
                };
                write!(
                    f,
                    "unknown {sensor} unit {name:?}: one of {}",
                    known.join(", ")
                )
            }
        }
    }
}

impl std::error::Error for UnitError {}

impl Units {
    /// Units from the names given (`None`: the datasets' m/s², rad/s).
    pub fn from_names(acc: Option<&str>, gyro: Option<&str>) -> Result<Self, UnitError> {
        let acc = match acc {
            None => AccUnit::default(),
            Some(n) => AccUnit::from_name(n).ok_or_else(|| UnitError::UnknownName {
                sensor: "acc",
                name: n.to_owned(),
            })?,
        };
        let gyro = match gyro {
            None => GyroUnit::default(),
            Some(n) => GyroUnit::from_name(n).ok_or_else(|| UnitError::UnknownName {
                sensor: "gyr",
                name: n.to_owned(),
            })?,
        };
        Ok(Units { acc, gyro })
    }

    /// Converts samples read in these units to m/s² and rad/s, in place.
    pub fn to_si(self, samples: &mut [ImuSample]) {
        let (ka, kg) = (self.acc.mps2(), self.gyro.radps());
        if ka == 1.0 && kg == 1.0 {
            return;
        }
        for s in samples {
            s.acc_mps2 = s.acc_mps2.map(|v| v * ka);
            s.gyr_radps = s.gyr_radps.map(|v| v * kg);
        }
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The rank of the `q` quantile (0–1) of `n` values (`n` > 0): the index a sort puts it at.
fn quantile_rank(n: usize, q: f64) -> usize {
    ((n as f64 * q) as usize).min(n - 1)
}

/// Checks that samples converted from `declared` ([`Units::to_si`]) can be in those units:
/// the accelerometer's lower quartile of magnitude within [`ACC_QUARTILE_MPS2`]; the gyro's 99.9th
/// percentile of |ω| under [`GYRO_MAX_RADPS`], and over [`GYRO_STEPPING_MIN_RADPS`] where
/// the accelerometer shows steps. An empty recording passes (the readers refuse it).
pub fn check(samples: &[ImuSample], declared: Units, front: Front) -> Result<(), UnitError> {
    check_of(&|| samples.iter().copied(), samples.len(), declared, front)
}

/// [`check`] of the `n` samples each call of `samples` yields in order (a recording read as
/// a stream): the same arithmetic in the same order, the quantiles exact order statistics
/// ([`crate::io::clock::nth_smallest`]), nothing kept per sample.
pub fn check_of<I: Iterator<Item = ImuSample>>(
    samples: &impl Fn() -> I,
    n: usize,
    declared: Units,
    front: Front,
) -> Result<(), UnitError> {
    if n == 0 {
        return Ok(());
    }
    let acc = || samples().map(|s| norm(s.acc_mps2));
    let mean = acc().sum::<f64>() / n as f64;
    let spread = (acc().map(|a| (a - mean) * (a - mean)).sum::<f64>() / n as f64).sqrt();
    let quartile = nth_smallest(&acc, quantile_rank(n, 0.25));
    let about_1g = |m: f64| m >= ACC_QUARTILE_MPS2.0 && m <= ACC_QUARTILE_MPS2.1;
    if !about_1g(quartile) {
        let raw = quartile / declared.acc.mps2();
        return Err(UnitError::Acc {
            declared: declared.acc,
            quartile_mps2: quartile,
            likely: AccUnit::ALL
                .into_iter()
                .find(|u| *u != declared.acc && about_1g(raw * u.mps2())),
            front,
        });
    }
    let top = nth_smallest(
        &|| samples().map(|s| norm(s.gyr_radps)),
        quantile_rank(n, 0.999),
    );
    if top > GYRO_MAX_RADPS {
        return Err(UnitError::GyroTooFast {
            declared: declared.gyro,
            top_radps: top,
            front,
        });
    }
    // The spread is in m/s² whatever the declared unit: the accelerometer passed above.
    if spread > ACC_STEPPING_SPREAD_MPS2 && top < GYRO_STEPPING_MIN_RADPS {
        return Err(UnitError::GyroTooSlow {
            declared: declared.gyro,
            top_radps: top,
            front,
        });
    }
    Ok(())
}

/// [`Units::to_si`], then [`check`].
pub fn apply(samples: &mut [ImuSample], declared: Units, front: Front) -> Result<(), UnitError> {
    declared.to_si(samples);
    check(samples, declared, front)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walk in m/s² and rad/s: 1 s strides at 100 Hz, the foot at rest half of each and
    /// swinging (±5 rad/s, ±2 g) the other half.
    fn walk() -> Vec<ImuSample> {
        (0..1000)
            .map(|i| {
                let t = i as f64 / 100.0;
                let phase = t.fract();
                let (acc, gyr) = if phase < 0.5 {
                    ([0.0, 0.0, G_MPS2], [0.0, 0.0, 0.0])
                } else {
                    let s = (2.0 * std::f64::consts::PI * 2.0 * phase).sin();
                    ([15.0 * s, 0.0, G_MPS2 + 8.0 * s], [0.0, 5.0 * s, 0.0])
                };
                ImuSample {
                    t_s: t,
                    acc_mps2: acc,
                    gyr_radps: gyr,
                }
            })
            .collect()
    }

    fn scaled(acc: f64, gyr: f64) -> Vec<ImuSample> {
        walk()
            .into_iter()
            .map(|s| ImuSample {
                acc_mps2: s.acc_mps2.map(|v| v * acc),
                gyr_radps: s.gyr_radps.map(|v| v * gyr),
                ..s
            })
            .collect()
    }

    #[test]
    fn the_datasets_units_pass_and_convert_to_themselves() {
        let mut s = walk();
        apply(&mut s, Units::default(), Front::CommandLine).unwrap();
        assert_eq!(s, walk());
    }

    #[test]
    fn g_read_as_mps2_is_refused_and_named() {
        let mut s = scaled(1.0 / G_MPS2, 1.0);
        let e = apply(&mut s, Units::default(), Front::CommandLine).unwrap_err();
        assert!(matches!(
            e,
            UnitError::Acc {
                likely: Some(AccUnit::G),
                ..
            }
        ));
        let m = e.to_string();
        assert!(m.contains("--acc-unit g"), "{m}");
        // Declared, it converts and passes.
        let mut s = scaled(1.0 / G_MPS2, 1.0);
        let units = Units {
            acc: AccUnit::G,
            ..Units::default()
        };
        apply(&mut s, units, Front::CommandLine).unwrap();
        for (a, b) in s.iter().zip(walk()) {
            for k in 0..3 {
                assert!((a.acc_mps2[k] - b.acc_mps2[k]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn milli_g_and_mps2_read_as_g_are_named() {
        let units = Units {
            acc: AccUnit::G,
            ..Units::default()
        };
        let mut s = scaled(1000.0 / G_MPS2, 1.0);
        let e = apply(&mut s, units, Front::Python).unwrap_err();
        assert!(matches!(
            e,
            UnitError::Acc {
                likely: Some(AccUnit::MilliG),
                ..
            }
        ));
        assert!(e.to_string().contains("acc_unit='mg'"), "{e}");
        let mut s = walk();
        let e = apply(&mut s, units, Front::CommandLine).unwrap_err();
        assert!(e.to_string().contains("--acc-unit m/s^2"), "{e}");
    }

    #[test]
    fn deg_per_s_read_as_rad_per_s_is_refused_both_ways() {
        let mut s = scaled(1.0, 180.0 / std::f64::consts::PI);
        let e = apply(&mut s, Units::default(), Front::CommandLine).unwrap_err();
        assert!(matches!(e, UnitError::GyroTooFast { .. }), "{e}");
        assert!(e.to_string().contains("--gyr-unit deg/s"), "{e}");
        // rad/s declared as deg/s: the swing shrinks to a few °/s.
        let mut s = walk();
        let units = Units {
            gyro: GyroUnit::DegreesPerSecond,
            ..Units::default()
        };
        let e = apply(&mut s, units, Front::CommandLine).unwrap_err();
        assert!(matches!(e, UnitError::GyroTooSlow { .. }), "{e}");
        assert!(e.to_string().contains("--gyr-unit rad/s"), "{e}");
    }

    #[test]
    fn standing_still_passes_in_either_gyro_unit() {
        let still: Vec<ImuSample> = (0..500)
            .map(|i| ImuSample {
                t_s: i as f64 / 100.0,
                acc_mps2: [0.1, 0.2, G_MPS2],
                gyr_radps: [0.001, 0.0, 0.002],
            })
            .collect();
        for gyro in GyroUnit::ALL {
            let mut s = still.clone();
            let units = Units {
                gyro,
                ..Units::default()
            };
            apply(&mut s, units, Front::CommandLine).unwrap();
        }
    }

    #[test]
    fn names_round_trip_and_unknown_ones_list_the_known() {
        for u in AccUnit::ALL {
            assert_eq!(AccUnit::from_name(u.name()), Some(u));
        }
        for u in GyroUnit::ALL {
            assert_eq!(GyroUnit::from_name(u.name()), Some(u));
        }
        let e = Units::from_names(Some("ft/s^2"), None).unwrap_err();
        assert!(e.to_string().contains("m/s^2, g, mg"), "{e}");
        let e = Units::from_names(None, Some("rpm")).unwrap_err();
        assert!(e.to_string().contains("rad/s, deg/s"), "{e}");
    }
}

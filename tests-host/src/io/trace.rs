//! A recorded trace in physical units and its conversion to MPU6050 counts.

use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip_mpu6050::{AccelRange, GyroRange};
use serde::Serialize;

/// Standard gravity, m/s² per g.
pub const G_MPS2: f64 = 9.80665;

/// One sample in physical units, sensor axes.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ImuSample {
    /// Time in the trace's own clock, s.
    pub t_s: f64,
    /// Specific force (gravity included), m/s².
    pub acc_mps2: [f64; 3],
    /// Angular rate, rad/s.
    pub gyr_radps: [f64; 3],
}

/// A recording: samples in physical units and the nominal rate.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Trace {
    /// The samples, in time order.
    pub samples: Vec<ImuSample>,
    /// Nominal sample rate, Hz (`--rate`, `meta.json`, or estimated from the stamps); the
    /// replay recovers the sensor's own clock from the stamps ([`crate::io::clock`]).
    pub rate_hz: f64,
    /// Samples dropped by the reader as re-sent: a stamp equal to the one before, or
    /// earlier by less than half a period ([`crate::io::clock::drop_repeats`]).
    pub repeated: usize,
    /// The sensor's nominal ranges, where known (`--acc-range-g`, `--gyro-range-dps`,
    /// `meta.json`): the rails where no flat run shows others ([`crate::io::rails`]).
    pub given: GivenRanges,
}

/// Sensor ranges used to turn physical units into counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Ranges {
    /// Accelerometer range.
    pub accel: AccelRange,
    /// Gyroscope range.
    pub gyro: GyroRange,
}

impl Ranges {
    /// Counts per m/s².
    pub fn accel_counts_per_mps2(self) -> f64 {
        self.accel.lsb_per_g() as f64 / G_MPS2
    }

    /// Counts per rad/s.
    pub fn gyro_counts_per_radps(self) -> f64 {
        self.gyro.lsb_per_dps_x10() as f64 / 10.0 * 180.0 / std::f64::consts::PI
    }

    /// Converts to counts as the sensor would report them: rounded to the nearest count and
    /// saturated at the rails (a heel strike beyond ±16 g reads as the rail).
    pub fn to_counts(self, s: &ImuSample) -> RawSample {
        self.converter()(s)
    }

    /// [`Ranges::to_counts`] with its two factors worked out once, for the samples of a
    /// recording (their four divisions were a third of the conversion's time).
    pub fn converter(self) -> impl Fn(&ImuSample) -> RawSample + Copy {
        let a = self.accel_counts_per_mps2();
        let g = self.gyro_counts_per_radps();
        move |s| RawSample {
            accel: s.acc_mps2.map(|v| quantize(v * a)),
            gyro: s.gyr_radps.map(|v| quantize(v * g)),
            temp: 0,
        }
    }

    /// The physical value of counts (inverse of [`Ranges::to_counts`] up to quantisation).
    pub fn to_physical(self, t_s: f64, r: &RawSample) -> ImuSample {
        let a = self.accel_counts_per_mps2();
        let g = self.gyro_counts_per_radps();
        ImuSample {
            t_s,
            acc_mps2: r.accel.map(|c| c as f64 / a),
            gyr_radps: r.gyro.map(|c| c as f64 / g),
        }
    }
}

/// Rounds to the nearest count (halves away from zero, as [`f64::round`]) and saturates to
/// the i16 range; NaN reads as 0 (it passes the clamp, casts to 0 and fails both ties' tests:
/// one branch less per value). Without `f64::round`, a libm call on baseline x86-64: a
/// value clamped just beyond the range (where both ways saturate) truncates exactly to an
/// `i32`, and its fraction `v − trunc(v)` is exact there.
pub fn quantize(v: f64) -> i16 {
    let c = v.clamp(i16::MIN as f64 - 1.0, i16::MAX as f64 + 1.0);
    let t = c as i32;
    let frac = c - t as f64;
    let r = t + (frac >= 0.5) as i32 - (frac <= -0.5) as i32;
    r.clamp(i16::MIN as i32, i16::MAX as i32) as i16
}

impl Trace {
    /// The nominal rate as the core's [`SampleRate`], if within 100–1000 Hz.
    pub fn sample_rate(&self) -> Option<SampleRate> {
        SampleRate::from_millihertz((self.rate_hz * 1000.0).round() as u32)
    }

    /// Estimates the nominal rate from the stamps ([`crate::io::clock::nominal_period`]).
    pub fn rate_from_timestamps(samples: &[ImuSample]) -> Option<f64> {
        let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
        crate::io::clock::nominal_period(&t).map(|p| 1.0 / p)
    }

    /// Drops re-sent samples ([`crate::io::clock::drop_repeats`] at the nominal rate, or at
    /// the rate the stamps suggest when it is not known yet), counting them in
    /// [`Trace::repeated`]. On a stamp that goes back further, the index of its sample.
    pub fn drop_repeats(
        samples: Vec<ImuSample>,
        rate_hz: Option<f64>,
    ) -> Result<(Vec<ImuSample>, usize), crate::io::clock::TimeGoesBack> {
        match Self::repeats_kept(&samples, rate_hz)? {
            None => Ok((samples, 0)),
            Some(keep) => {
                let dropped = samples.len() - keep.len();
                Ok((keep.into_iter().map(|i| samples[i]).collect(), dropped))
            }
        }
    }

    /// The rows [`Trace::drop_repeats`] keeps, or `None` when it keeps them all.
    pub fn repeats_kept(
        samples: &[ImuSample],
        rate_hz: Option<f64>,
    ) -> Result<Option<Vec<usize>>, crate::io::clock::TimeGoesBack> {
        let t: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
        let period = match rate_hz {
            Some(r) if r > 0.0 => 1.0 / r,
            _ => crate::io::clock::nominal_period(&t).unwrap_or(0.0),
        };
        let keep = crate::io::clock::drop_repeats(&t, period)?;
        Ok((keep.len() != samples.len()).then_some(keep))
    }
}

/// The nominal ranges a recording's sensor was set to, where known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GivenRanges {
    /// Accelerometer full scale, g.
    pub acc_g: Option<f64>,
    /// Gyroscope full scale, °/s.
    pub gyro_dps: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::quantize;
    use rand::{Rng, SeedableRng};

    /// `quantize` is `round` then saturate, exactly: at ties, near them, at every scale and
    /// beyond the range.
    #[test]
    fn quantize_rounds_as_f64_round_and_saturates() {
        let reference = |v: f64| -> i16 {
            if v.is_nan() {
                0
            } else {
                v.round().clamp(i16::MIN as f64, i16::MAX as f64) as i16
            }
        };
        let mut edges = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            0.49999999999999994,
            -0.49999999999999994,
            1.5,
            -1.5,
            2.5,
            -2.5,
            32766.5,
            32767.5,
            -32768.5,
            -32769.5,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            4503599627370495.5,
            9.3e18,
            -9.3e18,
        ];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200_000 {
            let scale = 10f64.powi(rng.random_range(-3..7));
            let v: f64 = rng.random_range(-1.0..1.0) * scale;
            edges.push(v);
            edges.push(v.trunc() + 0.5);
            edges.push(v.trunc() - 0.5);
        }
        for v in edges {
            assert_eq!(quantize(v), reference(v), "{v:e}");
        }
    }
}

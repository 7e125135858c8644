//! `f64` twin of the cycle detector's stride ([`gaitclip::cycle`]): every stride the core
//! reports, measured again in floating point from the same raw samples, the same stance
//! instants and the same calibration, so that the fixed-point arithmetic (levelling, the
//! rolling contact, the strapdown integration, dedrift, the rail reconstruction and the
//! tilt put back on clipped samples) is checked against exact arithmetic stride by stride.
//!
//! The twin takes the core's *decisions* (which sample is a stance instant, where its low
//! stretch began, the calibration the detector judged with) and recomputes everything
//! measured from them. The decisions themselves rest on integer comparisons of the
//! detector's energy, whose arithmetic [`energy`] checks against the same formula in `f64`
//! (`tests/fixed_point.rs`).

use gaitclip::cycle::{Calibration, CycleConfig, SIGMA_A_MMPS2, SIGMA_W_MRADPS};
use gaitclip::pipeline::{Config, Pipeline};
use gaitclip::sample::RawSample;
use gaitclip::stride::{Stride, StrideFlags};
use nalgebra::{UnitQuaternion, Vector3};

use crate::clock::Gap;

/// Standard gravity, m/s².
const G: f64 = 9.806_65;

/// A core run kept for the twin: the strides, and by sample number the raw sample (none
/// where a hole lost it) and the calibration the decision about that sample used.
pub struct CoreRun {
    /// The core's strides.
    pub strides: Vec<Stride>,
    samples: Vec<Option<RawSample>>,
    calibration: Vec<Option<Calibration>>,
    config: Config,
}

/// Runs the core over `counts` with `gaps` declared (as [`crate::replay::core_run`] does)
/// and keeps what the twin needs.
pub fn run(counts: &[RawSample], gaps: &[Gap], config: Config) -> CoreRun {
    let mut p = Pipeline::new(config);
    let mut strides = Vec::new();
    let mut samples = Vec::with_capacity(counts.len());
    let mut calibration: Vec<Option<Calibration>> = Vec::with_capacity(counts.len());
    let mut next_gap = gaps.iter().peekable();
    for (i, s) in counts.iter().enumerate() {
        while let Some(g) = next_gap.next_if(|g| g.before <= i) {
            strides.extend(p.gap(g.missing));
            samples.extend(std::iter::repeat_n(None, g.missing as usize));
        }
        let n = p.next_index() as usize;
        samples.resize(n, None);
        samples.push(Some(*s));
        strides.extend(p.process(s));
        // The decision this call made was about sample next − 1 − latency.
        let decided = (p.next_index() as usize).checked_sub(1 + p.latency() as usize);
        if let Some(at) = decided {
            if calibration.len() <= at {
                calibration.resize(at + 1, None);
            }
            calibration[at] = p.cycle_calibration();
        }
    }
    strides.extend(std::iter::from_fn(|| p.finish()));
    CoreRun {
        strides,
        samples,
        calibration,
        config,
    }
}

/// The energy of one sample in `f64`, (rad/s)² over σ² as [`CycleConfig::energy_q16`]
/// defines it: `|ω − b|²/σω² + (|f| − g)²/σa²`, for counts at the config's ranges.
pub fn energy(config: &Config, s: &RawSample, bias: [i32; 3], gravity_counts: i32) -> f64 {
    let rad_per_count = rad_per_count(config);
    let w2: f64 = (0..3)
        .map(|k| ((s.gyro[k] as f64 - bias[k] as f64) * rad_per_count).powi(2))
        .sum();
    let f = Vector3::new(s.accel[0] as f64, s.accel[1] as f64, s.accel[2] as f64).norm();
    let d = (f - gravity_counts as f64) * G / config.accel.lsb_per_g() as f64;
    let sw = SIGMA_W_MRADPS as f64 / 1e3;
    let sa = SIGMA_A_MMPS2 as f64 / 1e3;
    w2 / (sw * sw) + d * d / (sa * sa)
}

fn rad_per_count(config: &Config) -> f64 {
    std::f64::consts::PI / 180.0 / (config.gyro.lsb_per_dps_x10() as f64 / 10.0)
}

/// Why the twin did not measure a stride.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Skipped {
    /// Not a valid stride (gap, too long) or bridged: interpolated samples in it.
    Flagged,
    /// The first stride after a rest or a restart: its start's low stretch is not known
    /// from the records (it began before the stride before).
    NoPrevious,
    /// A sample or the calibration of it is missing.
    Missing,
    /// A low stretch longer than 2¹⁶ samples: the core halves its sums there.
    LongRest,
}

/// The twin's horizontal ZUPT distance of stride `k` of `run`, m.
pub fn zupt_m(run: &CoreRun, k: usize) -> Result<f64, Skipped> {
    let s = &run.strides[k];
    if !s.flags.valid() || s.flags.has(StrideFlags::BRIDGED) {
        return Err(Skipped::Flagged);
    }
    let prev = k
        .checked_sub(1)
        .map(|j| &run.strides[j])
        .filter(|p| p.end == s.start)
        .ok_or(Skipped::NoPrevious)?;
    let (i0, i1) = (s.start as usize, s.end as usize);
    let (low0, low1) = (prev.foot_flat as usize, s.foot_flat as usize);
    if i0 - low0 >= 1 << 16 || i1 - low1 >= 1 << 16 {
        return Err(Skipped::LongRest);
    }
    let sample = |i: usize| {
        run.samples
            .get(i)
            .copied()
            .flatten()
            .ok_or(Skipped::Missing)
    };
    let cal = |i: usize| {
        run.calibration
            .get(i)
            .copied()
            .flatten()
            .ok_or(Skipped::Missing)
    };
    let (cal0, cal1) = (cal(i0)?, cal(i1)?);
    let mean = |a: usize, b: usize| -> Result<Vector3<f64>, Skipped> {
        let mut m = Vector3::zeros();
        for i in a..=b {
            let x = sample(i)?;
            m += Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64);
        }
        Ok(m / (b - a + 1) as f64)
    };
    let (up0, up1) = (mean(low0, i0)?, mean(low1, i1)?);

    let config = &run.config;
    let dt = 1e3 / config.rate.millihertz() as f64;
    let rad = rad_per_count(config);
    let h_m = config.sensor_height_um as f64 / 1e6;
    let g_counts = cal0.gravity_counts as f64;
    let omega = |x: &RawSample, b: [i32; 3]| {
        Vector3::new(
            (x.gyro[0] as f64 - b[0] as f64) * rad,
            (x.gyro[1] as f64 - b[1] as f64) * rad,
            (x.gyro[2] as f64 - b[2] as f64) * rad,
        )
    };
    // The sensor's velocity over the rolling contact, ω × (h·up), level frame.
    let rolling = |q: &UnitQuaternion<f64>, w: Vector3<f64>| {
        let wl = q * w;
        Vector3::new(h_m * wl.y, -h_m * wl.x, 0.0)
    };

    let mut q = UnitQuaternion::rotation_between(&up0, &Vector3::z()).ok_or(Skipped::Missing)?;
    let mut v = rolling(&q, omega(&sample(i0)?, cal0.gyro_bias));
    let mut p = Vector3::zeros();
    let mut rails = [RailRunF64::default(); 3];
    let (mut clipped, mut s1, mut s2) = (0u64, 0f64, 0f64);
    for (c, i) in (i0 + 1..=i1).enumerate() {
        let x = sample(i)?;
        q *= UnitQuaternion::from_scaled_axis(omega(&x, cal0.gyro_bias) * dt);
        let f = q * Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64);
        let a = (f - Vector3::new(0.0, 0.0, g_counts)) * (G / g_counts);
        let v_prev = v;
        v += a * dt;
        p += (v_prev + v) * (dt / 2.0);
        for (r, &g) in rails.iter_mut().zip(x.gyro.iter()) {
            r.process(g);
        }
        if x.gyro_saturated() {
            let c = (c + 1) as f64;
            clipped += 1;
            s1 += c;
            s2 += c * c;
        }
    }
    let n = (i1 - i0) as f64;
    let v_end = rolling(&q, omega(&sample(i1)?, cal1.gyro_bias));
    p -= (v - v_end) * (n * dt / 2.0);
    if clipped > 0 {
        let level = q * up1;
        let (norm, lxy) = (level.norm(), level.xy().norm());
        if norm > 0.0 && lxy > 0.0 {
            let lost: f64 = rails.iter().map(|r| r.lost()).sum::<f64>() * rad * dt;
            let h = if lxy / norm > lost {
                level.xy() * (lost / lxy)
            } else {
                level.xy() / norm
            };
            let w = n * s1 - s2;
            p.x += h.x * w / clipped as f64 * G * dt * dt / 2.0;
            p.y += h.y * w / clipped as f64 * G * dt * dt / 2.0;
        }
    }
    Ok(p.xy().norm())
}

/// [`gaitclip::zupt::RailRun`] in `f64`: the parabola's area above the rail per clipped
/// run, counts·samples.
#[derive(Clone, Copy, Debug, Default)]
struct RailRunF64 {
    prev: [f64; 2],
    seen: u8,
    run: u32,
    slope_in: f64,
    ended: Option<(u32, f64, f64)>,
    lost: f64,
}

impl RailRunF64 {
    fn area(run: u32, s_in: f64, s_out: f64) -> f64 {
        let l = run as f64;
        (s_in + s_out) * l.powi(3) / (12.0 * (l + 2.0))
    }

    fn rail(v: f64) -> f64 {
        if v >= 0.0 {
            i16::MAX as f64
        } else {
            i16::MIN as f64
        }
    }

    fn process(&mut self, raw: i16) {
        let v = raw as f64;
        let at_rail = raw == i16::MAX || raw == i16::MIN;
        if let Some((run, s_in, after)) = self.ended.take() {
            let s_out = if at_rail {
                (Self::rail(after) - after).abs()
            } else {
                (after - v).abs()
            };
            self.lost += Self::area(run, s_in, s_out);
        }
        if at_rail {
            if self.run == 0 {
                self.slope_in = match self.seen {
                    2 => (self.prev[0] - self.prev[1]).abs(),
                    1 => (v - self.prev[0]).abs(),
                    _ => 0.0,
                };
            }
            self.run += 1;
        } else if self.run > 0 {
            self.ended = Some((self.run, self.slope_in, v));
            self.run = 0;
        }
        self.prev = [v, self.prev[0]];
        self.seen = (self.seen + 1).min(2);
    }

    fn lost(&self) -> f64 {
        let mut lost = self.lost;
        if let Some((run, s_in, after)) = self.ended {
            lost += Self::area(run, s_in, (Self::rail(after) - after).abs());
        }
        if self.run > 0 {
            lost += Self::area(self.run, self.slope_in, self.slope_in);
        }
        lost
    }
}

/// The cycle detector's constants for `config` (its phases and sensor height).
pub fn cycle_config(config: &Config) -> CycleConfig {
    CycleConfig::new(
        config.rate,
        config.accel,
        config.gyro,
        config.phases,
        config.sensor_height_um,
    )
}

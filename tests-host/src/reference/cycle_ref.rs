//! `f64` twin of the cycle detector's stride ([`gaitclip::detect::cycle`]): every stride the core
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

use gaitclip::detect::clipping::SHAPED_RUN_MIN;
use gaitclip::detect::cycle::{Calibration, CycleConfig, SIGMA_A_MMPS2, SIGMA_W_MRADPS};
use gaitclip::detect::zupt::{GravityReading, MAX_GRAVITY_OFFSET_MILLI_G};
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::sample::{AxisRails, RawSample};
use nalgebra::{UnitQuaternion, Vector2, Vector3};

use crate::io::clock::Gap;

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

impl CoreRun {
    /// The stride before stride `k` when it ends where `k` starts (its foot-flat bounds the
    /// low stretch `k`'s start instant was chosen in).
    fn previous_contiguous(&self, k: usize) -> Result<&Stride, Skipped> {
        let s = &self.strides[k];
        k.checked_sub(1)
            .map(|j| &self.strides[j])
            .filter(|p| p.events.end == s.events.start)
            .ok_or(Skipped::NoPrevious)
    }

    /// Sample `i` as the core read it.
    fn sample(&self, i: usize) -> Result<RawSample, Skipped> {
        self.samples
            .get(i)
            .copied()
            .flatten()
            .ok_or(Skipped::Missing)
    }

    /// The calibration the core's decision about sample `i` used.
    fn calibration(&self, i: usize) -> Result<Calibration, Skipped> {
        self.calibration
            .get(i)
            .copied()
            .flatten()
            .ok_or(Skipped::Missing)
    }
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
    std::f64::consts::PI / 180.0 / (config.gyro.lsb_per_dps())
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
    horizontal(run, k).map(|p| p.norm())
}

/// The twin's direction of travel of stride `k` of `run` (the core's
/// [`gaitclip::record::stride::Stride::travel_cdeg`]), degrees counter-clockwise from the x
/// axis of the level frame of its start.
pub fn travel_deg(run: &CoreRun, k: usize) -> Result<f64, Skipped> {
    horizontal(run, k).map(|p| p.y.atan2(p.x).to_degrees())
}

/// The twin's horizontal ZUPT displacement of stride `k` of `run`, level frame of its start,
/// m.
pub fn horizontal(run: &CoreRun, k: usize) -> Result<Vector2<f64>, Skipped> {
    integration(run, k).map(|i| i.linear().xy())
}

/// Stride `k`'s strapdown integration in `f64` up to its zero-velocity update: what the core's
/// dedrift works from, and what the corrections it does not make
/// ([`crate::eval::constraints`]) would work from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integration {
    /// The displacement at the end, level frame of the start, m: the rails' losses put back,
    /// nothing removed.
    pub displacement: Vector3<f64>,
    /// The velocity left at the end less what the rolling contact imposes there (the
    /// zero-velocity residual), m/s.
    pub residual: Vector3<f64>,
    /// The tilt the gyro's rails lost, put back as the gravity it leaked (the core's
    /// correction, zero without a clipped gyro sample), m.
    pub rail_tilt: Vector2<f64>,
    /// Whether a gyro sample sat at a rail.
    pub gyro_clipped: bool,
    /// The gravity the end's rest reads, turned into the start's level frame by the
    /// integrated attitude: its horizontal part, m/s² (zero where the attitude came back
    /// level).
    pub end_leak: Vector2<f64>,
    /// The sample of the largest acceleration in the movement's second half, from the start
    /// (a touch-down's impact).
    pub impact: f64,
    /// The largest accelerometer reading against its axis's rail, 0–1 (1: at the rail; 0
    /// without rails).
    pub of_rail: f64,
    /// Samples from the start to the end.
    pub samples: f64,
    /// Sample period, s.
    pub dt: f64,
}

impl Integration {
    /// The core's displacement: the residual removed as a drift grown linearly over the
    /// movement, the rails' tilt put back, m.
    pub fn linear(&self) -> Vector3<f64> {
        self.displacement - self.residual * (self.samples * self.dt / 2.0) + self.tilt()
    }

    /// The displacement with the residual removed as a velocity error that appeared at once at
    /// sample `c` from the start (a touch-down's), rails' tilt put back, m.
    pub fn step_at(&self, c: f64) -> Vector3<f64> {
        self.displacement - self.residual * ((self.samples - c + 0.5) * self.dt) + self.tilt()
    }

    fn tilt(&self) -> Vector3<f64> {
        Vector3::new(self.rail_tilt.x, self.rail_tilt.y, 0.0)
    }
}

/// Stride `k`'s [`Integration`].
pub fn integration(run: &CoreRun, k: usize) -> Result<Integration, Skipped> {
    integration_shifted(run, k, 0)
}

/// Stride `k`'s [`Integration`] with the gyro read `gyro_shift` samples late against the
/// accelerometer (negative: early; a sample the shift reaches outside the recording, or
/// into a hole, is the unshifted one): a delay between the two sensors' clocks.
pub fn integration_shifted(
    run: &CoreRun,
    k: usize,
    gyro_shift: i32,
) -> Result<Integration, Skipped> {
    let s = &run.strides[k];
    if !s.flags.valid() || s.flags.has(StrideFlags::BRIDGED) {
        return Err(Skipped::Flagged);
    }
    let prev = run.previous_contiguous(k)?;
    let (i0, i1) = (s.events.start as usize, s.events.end as usize);
    let (low0, low1) = (prev.events.foot_flat as usize, s.events.foot_flat as usize);
    if i0 - low0 >= 1 << 16 || i1 - low1 >= 1 << 16 {
        return Err(Skipped::LongRest);
    }
    let (cal0, cal1) = (run.calibration(i0)?, run.calibration(i1)?);
    let mean = |a: usize, b: usize| -> Result<Vector3<f64>, Skipped> {
        let mut m = Vector3::zeros();
        for i in a..=b {
            let x = run.sample(i)?;
            m += Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64);
        }
        Ok(m / (b - a + 1) as f64)
    };
    let (up0, up1) = (mean(low0, i0)?, mean(low1, i1)?);

    let config = &run.config;
    let dt = 1e3 / config.rate.millihertz() as f64;
    let rad = rad_per_count(config);
    let h_m = config.sensor_height_um as f64 / 1e6;
    let (offset, g_counts, unit) = reading_terms(config, cal0.gravity_counts as f64, &up0);
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

    // The core's level frame (`QuatQ30::level_from_up`): a sensor hanging upside down is
    // first turned 180° about x, so that the frame's x axis is the sensor's laid level (the
    // direction of travel is measured from it); the shortest rotation onto +z after that.
    let flip = if up0.z < 0.0 {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    } else {
        UnitQuaternion::identity()
    };
    let mut q = UnitQuaternion::rotation_between(&(flip * up0), &Vector3::z())
        .ok_or(Skipped::Missing)?
        * flip;
    let mut v = rolling(&q, omega(&run.sample(i0)?, cal0.gyro_bias));
    let mut p = Vector3::zeros();
    let config_rails = run.config.rails;
    let mut rails = [RailRunF64::default(); 3];
    let (mut clipped, mut s1, mut s2) = (0u64, 0f64, 0f64);
    // The accelerometer's rails: per axis the run's direction and first sample; the steps of
    // shaped runs (m/s, with their centre) and the single samples' directions.
    let mut accel_runs = [RailRunF64::default(); 3];
    let mut accel_dir = [(Vector3::zeros(), 0f64); 3];
    let mut steps: Vec<(Vector3<f64>, f64)> = Vec::new();
    let mut singles: Vec<(Vector3<f64>, f64)> = Vec::new();
    let (mut min_rail, mut climbs) = (f64::INFINITY, 0f64);
    let (mut impact, mut impact_a, mut of_rail) = (0f64, 0f64, 0f64);
    let half = (i1 - i0) / 2;
    let to_mps = G / unit * dt;
    let mut book = |k: usize,
                    (len, area, climb): Done,
                    (dir, first): (Vector3<f64>, f64),
                    steps: &mut Vec<(Vector3<f64>, f64)>,
                    singles: &mut Vec<(Vector3<f64>, f64)>| {
        if len >= SHAPED_RUN_MIN {
            steps.push((dir * (area * to_mps), first + (len as f64 - 1.0) / 2.0));
        } else {
            for j in 0..len {
                singles.push((dir, first + j as f64));
            }
            min_rail = min_rail.min(config_rails.accel[k].min_magnitude() as f64);
            climbs += climb * len as f64;
        }
    };
    for (c, i) in (i0 + 1..=i1).enumerate() {
        let x = run.sample(i)?;
        let gyro = (i as i64 + gyro_shift as i64)
            .try_into()
            .ok()
            .and_then(|at: usize| run.sample(at).ok())
            .unwrap_or(x);
        q *= UnitQuaternion::from_scaled_axis(omega(&gyro, cal0.gyro_bias) * dt);
        let f =
            q * (Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64) - offset);
        let a = (f - Vector3::new(0.0, 0.0, g_counts)) * (G / unit);
        let v_prev = v;
        v += a * dt;
        p += (v_prev + v) * (dt / 2.0);
        if c >= half && a.norm() > impact_a {
            (impact, impact_a) = ((c + 1) as f64, a.norm());
        }
        for (k, &raw) in x.accel.iter().enumerate() {
            let rail = config_rails.accel[k].min_magnitude();
            if rail > 0 {
                of_rail = of_rail.max((raw as f64).abs() / rail as f64);
            }
        }
        let m = q.to_rotation_matrix();
        for k in 0..3 {
            let raw = x.accel[k];
            let r = config_rails.accel[k];
            // A run this sample completes was booked with its own direction before a run
            // this sample starts takes the next.
            if let Some(done) = accel_runs[k].process(raw, r) {
                book(k, done, accel_dir[k], &mut steps, &mut singles);
            }
            if r.clipped(raw) && accel_runs[k].run == 1 {
                let sign = if raw > 0 { 1.0 } else { -1.0 };
                accel_dir[k] = (m.matrix().column(k) * sign, (c + 1) as f64);
            }
        }
        for ((r, &g), &rails) in rails
            .iter_mut()
            .zip(x.gyro.iter())
            .zip(config_rails.gyro.iter())
        {
            r.process(g, rails);
        }
        if config_rails.gyro_clipped(&x) {
            let c = (c + 1) as f64;
            clipped += 1;
            s1 += c;
            s2 += c * c;
        }
    }
    let n = (i1 - i0) as f64;
    let v_end = rolling(&q, omega(&run.sample(i1)?, cal1.gyro_bias));
    // Accelerometer: runs still open at the end booked as they stand, then each loss put
    // back as a velocity step where it happened (a step at sample c moves the trapezoidal
    // position by (N − c + ½)·dt).
    for k in 0..3 {
        if let Some(done) = accel_runs[k].pending(config_rails.accel[k]) {
            book(k, done, accel_dir[k], &mut steps, &mut singles);
        }
    }
    for &(d, c) in &steps {
        v += d;
        p += d * ((n - c + 0.5) * dt);
    }
    if !singles.is_empty() {
        let u: Vector3<f64> = singles.iter().map(|s| s.0).sum();
        // The core takes the mean climb in whole counts.
        let cap = (climbs / singles.len() as f64).floor().min(min_rail) * to_mps;
        let alpha = ((v_end - v).dot(&u) / u.dot(&u)).max(0.0).min(cap);
        for &(dir, c) in &singles {
            v += dir * alpha;
            p += dir * (alpha * (n - c + 0.5) * dt);
        }
    }
    let level = q * up1;
    // The leak of the gravity the sensor reads, m/s².
    let leak = G * g_counts / unit;
    let end_leak = if level.norm() > 0.0 {
        level.xy() * (leak / level.norm())
    } else {
        Vector2::zeros()
    };
    let mut rail_tilt = Vector2::zeros();
    if clipped > 0 {
        let (norm, lxy) = (level.norm(), level.xy().norm());
        if norm > 0.0 && lxy > 0.0 {
            let lost: f64 = rails
                .iter()
                .zip(config_rails.gyro.iter())
                .map(|(r, &rails)| r.lost(rails))
                .sum::<f64>()
                * rad
                * dt;
            let h = if lxy / norm > lost {
                level.xy() * (lost / lxy)
            } else {
                level.xy() / norm
            };
            let w = n * s1 - s2;
            rail_tilt.x = h.x * w / clipped as f64 * leak * dt * dt / 2.0;
            rail_tilt.y = h.y * w / clipped as f64 * leak * dt * dt / 2.0;
        }
    }
    Ok(Integration {
        displacement: p,
        residual: v - v_end,
        rail_tilt,
        gyro_clipped: clipped > 0,
        end_leak,
        impact,
        of_rail: of_rail.min(1.0),
        samples: n,
        dt,
    })
}

/// [`gaitclip::detect::clipping::RailRun`] in `f64`: the parabola's area above the rail per clipped
/// run, counts·samples.
#[derive(Clone, Copy, Debug, Default)]
struct RailRunF64 {
    prev: [f64; 2],
    seen: u8,
    run: u32,
    slope_in: f64,
    before: f64,
    /// A run waiting for its slope out: length, slope in, value before, value after.
    ended: Option<(u32, f64, f64, f64)>,
    lost: f64,
}

/// A completed run: length, area above the rail, and the mean climb of its neighbours to
/// the rail (whole counts, as the core's).
type Done = (u32, f64, f64);

impl RailRunF64 {
    fn area(run: u32, s_in: f64, s_out: f64) -> f64 {
        let l = run as f64;
        (s_in + s_out) * l.powi(3) / (12.0 * (l + 2.0))
    }

    fn rail(v: f64, rails: AxisRails) -> f64 {
        if v >= 0.0 {
            rails.high as f64
        } else {
            rails.low as f64
        }
    }

    fn climb(rail: f64, before: f64, after: f64) -> f64 {
        (((rail - before).abs() + (rail - after).abs()) / 2.0).floor()
    }

    /// The run this sample completed.
    fn process(&mut self, raw: i16, rails: AxisRails) -> Option<Done> {
        let v = raw as f64;
        let at_rail = rails.clipped(raw);
        let mut done = None;
        if let Some((run, s_in, before, after)) = self.ended.take() {
            let s_out = if at_rail {
                (Self::rail(after, rails) - after).abs()
            } else {
                (after - v).abs()
            };
            let a = Self::area(run, s_in, s_out);
            self.lost += a;
            done = Some((run, a, Self::climb(Self::rail(after, rails), before, after)));
        }
        if at_rail {
            if self.run == 0 {
                self.slope_in = match self.seen {
                    2 => (self.prev[0] - self.prev[1]).abs(),
                    1 => (v - self.prev[0]).abs(),
                    _ => 0.0,
                };
                self.before = if self.seen > 0 { self.prev[0] } else { v };
            }
            self.run += 1;
        } else if self.run > 0 {
            self.ended = Some((self.run, self.slope_in, self.before, v));
            self.run = 0;
        }
        self.prev = [v, self.prev[0]];
        self.seen = (self.seen + 1).min(2);
        done
    }

    fn pending(&self, rails: AxisRails) -> Option<Done> {
        if let Some((run, s_in, before, after)) = self.ended {
            let rail = Self::rail(after, rails);
            return Some((
                run,
                Self::area(run, s_in, (rail - after).abs()),
                Self::climb(rail, before, after),
            ));
        }
        (self.run > 0).then(|| {
            let rail = Self::rail(self.prev[0], rails);
            (
                self.run,
                Self::area(self.run, self.slope_in, self.slope_in),
                Self::climb(rail, self.before, self.before),
            )
        })
    }

    fn lost(&self, rails: AxisRails) -> f64 {
        self.lost + self.pending(rails).map_or(0.0, |p| p.1)
    }
}

/// What the core makes of the rest's gravity `g_counts` (counts) with the stance's
/// up `up` (sensor axes, any scale), as [`gaitclip::detect::zupt::GravityReading`] says: the
/// offset removed from every sample (counts), the gravity removed from the levelled force
/// (counts) and the counts of 1 g in metres.
fn reading_terms(config: &Config, g_counts: f64, up: &Vector3<f64>) -> (Vector3<f64>, f64, f64) {
    let nominal = config.accel.lsb_per_g() as f64;
    match config.gravity_reading {
        GravityReading::Offset => {
            let bound = nominal * MAX_GRAVITY_OFFSET_MILLI_G as f64 / 1000.0;
            let d = (g_counts - nominal).clamp(-bound, bound);
            (up.normalize() * d, g_counts - d, nominal)
        }
        GravityReading::Ignored => (Vector3::zeros(), g_counts, nominal),
        GravityReading::Gain => (Vector3::zeros(), g_counts, g_counts),
    }
}

/// The cycle detector's constants for `config` (its phases and sensor height).
pub fn cycle_config(config: &Config) -> CycleConfig {
    CycleConfig::new(
        config.rate,
        config.accel,
        config.gyro,
        config.rails,
        config.phases,
        config.sensor_height_um,
    )
}

/// What a stride's end says about the lever arm of the rolling contact
/// ([`end_residual`]): in the level frame of its start, horizontal components.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndResidual {
    /// The end velocity integrated from zero at the start instant (h = 0), m/s: the
    /// residual a plain zero-velocity update leaves.
    pub r: [f64; 2],
    /// The rolling contact's velocity per metre of h at the start instant, `ω × up`, m/s per m.
    pub u0: [f64; 2],
    /// The same at the end instant.
    pub u1: [f64; 2],
}

/// The end residual of stride `k` of `run` in `f64`, for a lever-arm fit: with the sensor
/// `h` above the contact the sensor moves at `h·u` at each instant, so the residual of the
/// integration from zero is `h·(u₁ − u₀)` plus the integration's own error. Strides that
/// clipped are skipped (their restoration is not modelled here).
pub fn end_residual(run: &CoreRun, k: usize) -> Result<EndResidual, Skipped> {
    let s = &run.strides[k];
    if !s.flags.valid()
        || s.flags.has(StrideFlags::BRIDGED)
        || s.flags.has(StrideFlags::GYRO_CLIPPED)
        || s.flags.has(StrideFlags::ACCEL_CLIPPED)
    {
        return Err(Skipped::Flagged);
    }
    let prev = run.previous_contiguous(k)?;
    let (i0, i1) = (s.events.start as usize, s.events.end as usize);
    let low0 = prev.events.foot_flat as usize;
    if i0 - low0 >= 1 << 16 {
        return Err(Skipped::LongRest);
    }
    let (cal0, cal1) = (run.calibration(i0)?, run.calibration(i1)?);
    let mut up0 = Vector3::zeros();
    for i in low0..=i0 {
        let x = run.sample(i)?;
        up0 += Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64);
    }
    let config = &run.config;
    let dt = 1e3 / config.rate.millihertz() as f64;
    let rad = rad_per_count(config);
    let (offset, g_counts, unit) = reading_terms(config, cal0.gravity_counts as f64, &up0);
    let omega = |x: &RawSample, b: [i32; 3]| {
        Vector3::new(
            (x.gyro[0] as f64 - b[0] as f64) * rad,
            (x.gyro[1] as f64 - b[1] as f64) * rad,
            (x.gyro[2] as f64 - b[2] as f64) * rad,
        )
    };
    let per_metre = |q: &UnitQuaternion<f64>, w: Vector3<f64>| {
        let wl = q * w;
        [wl.y, -wl.x]
    };
    let mut q = UnitQuaternion::rotation_between(&up0, &Vector3::z()).ok_or(Skipped::Missing)?;
    let u0 = per_metre(&q, omega(&run.sample(i0)?, cal0.gyro_bias));
    let mut v = Vector3::zeros();
    for i in i0 + 1..=i1 {
        let x = run.sample(i)?;
        q *= UnitQuaternion::from_scaled_axis(omega(&x, cal0.gyro_bias) * dt);
        let f =
            q * (Vector3::new(x.accel[0] as f64, x.accel[1] as f64, x.accel[2] as f64) - offset);
        v += (f - Vector3::new(0.0, 0.0, g_counts)) * (G / unit) * dt;
    }
    Ok(EndResidual {
        r: [v.x, v.y],
        u0,
        u1: per_metre(&q, omega(&run.sample(i1)?, cal1.gyro_bias)),
    })
}

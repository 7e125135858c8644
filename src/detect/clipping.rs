//! What a sensor at its rail lost, and putting it back.
//!
//! A reading at a rail ([`crate::sensor::sample::AxisRails`]) says only that the true value lay at
//! or beyond it. The strapdown integration of a stride ([`crate::detect::zupt`]) then misses what lay
//! beyond: a gyro's lost rotation tilts the level frame for the rest of the movement, an
//! accelerometer's lost specific force is a step in the velocity from the clipped sample on.
//! Both are put back, from two independent pieces of evidence:
//!
//! - **The shape of the run** ([`RailRun`]): a clipped run of `L ≥ 2` samples is taken to be
//!   the top of a parabola that crosses the rail with the slopes measured either side of it;
//!   its area above the rail is what was lost. This is what an 800 Hz recording's clipped
//!   heel strike looks like (runs of 3–7 samples).
//! - **The stance's zero-velocity residual**, for what the shape cannot give: a run of one
//!   sample (a heel strike's spike at 200 Hz) has no shape, but the foot is back on the ground
//!   at the stride's end, so the velocity the integration is left with there, beyond what the
//!   rolling contact gives, says how much was lost. It is projected onto the directions
//!   (in the level frame) the clipped samples lost force along, never negative, and at most
//!   what the samples either side climb to reach the rail, on average, per clipped sample: a
//!   spike rises beyond the rail by less than its flanks climb to it (measured on one-sample
//!   spikes of the datasets clipped at ±8 g: a median of 0.49 of it, 90 % under 0.84). The
//!   bound matters: the residual's noise (±0.2–0.3 m/s vertically on unclipped strides) would
//!   otherwise put that much on a sample that lost a fraction of it.
//!
//! An accelerometer's loss is a velocity step at the clipped sample, which the linear
//! dedrift of a stride would spread over the whole movement; it is instead put back where it
//! happened, in closed form: a step `D` at sample `c` of `N` moves the trapezoidal doubled
//! position by `D·(2N + 1 − 2c)`. How far this gets, measured by clipping real recordings at
//! ±8 g and ±4 g against their unclipped selves: `gaitclip clipping`, `docs/`.
//!
//! Integer throughout, bounded: per axis one run in progress, per stride a few sums.

// Three parallel per-axis arrays are indexed together throughout.
#![allow(clippy::needless_range_loop)]

use crate::sensor::sample::AxisRails;

/// The parabola's area above the rail of a clipped run of `run` samples entered and left with
/// the slopes `slope_in` and `slope_out` (counts per sample): `(s_in + s_out)·L³ / (12·(L + 2))`
/// counts·samples (see [`RailRun`]), saturated.
const fn area(run: u32, slope_in: u32, slope_out: u32) -> i64 {
    let l = run as i128;
    let a = (slope_in as i128 + slope_out as i128) * l * l * l / (12 * (l + 2));
    if a > i64::MAX as i128 {
        i64::MAX
    } else {
        a as i64
    }
}

/// The area one gyro axis lost at its rail, reconstructed per clipped run: the true value is
/// taken to rise over the rail and fall back as a parabola. A parabola that stays above the
/// rail for `T` samples and crosses it with slope `s` holds `s·T²/6` counts·samples above it.
/// `T` is taken as the run's clipped samples `L`; the slope at the crossing from the secant of
/// the two unclipped samples next to the run, which on a parabola lies about one sample
/// further out and is steeper by the factor `(L + 2)/L`; the two sides averaged:
/// `(s_in + s_out)·L³ / (12·(L + 2))`. Against the exact area of parabolic peaks 6–40
/// samples wide, within the bound the host test asserts; a plateau makes it high, a sharper
/// peak low. Range: runs up to 2¹⁶ samples; the sum saturates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RailRun {
    /// The two samples before this one, newest first (counts); `seen` of them are real.
    prev: [i32; 2],
    seen: u8,
    /// Clipped samples in the current run, and the slope into it (counts per sample).
    run: u32,
    slope_in: i32,
    /// A run that ended at the last sample, waiting for one more to measure its slope out:
    /// its length (0: none), slope in and the first unclipped value after it.
    ended_run: u32,
    ended_slope_in: i32,
    ended_after: i32,
    /// Σ of finished runs' reconstructed area, counts·samples.
    lost: i64,
}

impl RailRun {
    /// No run seen.
    pub const NEW: RailRun = RailRun {
        prev: [0; 2],
        seen: 0,
        run: 0,
        slope_in: 0,
        ended_run: 0,
        ended_slope_in: 0,
        ended_after: 0,
        lost: 0,
    };

    /// Takes the next raw sample of the axis (counts) and its rails.
    pub fn process(&mut self, raw: i16, rails: AxisRails) {
        let v = raw as i32;
        let at_rail = rails.clipped(raw);
        if self.ended_run > 0 {
            let after = self.ended_after;
            let slope_out = if at_rail {
                (rails.rail_of(after) - after).abs()
            } else {
                (after - v).abs()
            };
            let a = area(
                self.ended_run,
                self.ended_slope_in.unsigned_abs(),
                slope_out.unsigned_abs(),
            );
            self.lost = self.lost.saturating_add(a);
            self.ended_run = 0;
        }
        if at_rail {
            if self.run == 0 {
                self.slope_in = match self.seen {
                    2 => (self.prev[0] - self.prev[1]).abs(),
                    1 => (v - self.prev[0]).abs(),
                    _ => 0,
                };
            }
            self.run = self.run.saturating_add(1);
        } else if self.run > 0 {
            self.ended_run = self.run;
            self.ended_slope_in = self.slope_in;
            self.ended_after = v;
            self.run = 0;
        }
        self.prev = [v, self.prev[0]];
        self.seen = if self.seen < 2 { self.seen + 1 } else { 2 };
    }

    /// The area above the rail so far, counts·samples, runs still open included (an open
    /// run's slope out taken equal to its slope in).
    pub fn lost_counts_samples(&self, rails: AxisRails) -> i64 {
        let mut lost = self.lost;
        if self.ended_run > 0 {
            let out = (rails.rail_of(self.ended_after) - self.ended_after).unsigned_abs();
            lost = lost.saturating_add(area(
                self.ended_run,
                self.ended_slope_in.unsigned_abs(),
                out,
            ));
        }
        if self.run > 0 {
            let s = self.slope_in.unsigned_abs();
            lost = lost.saturating_add(area(self.run, s, s));
        }
        lost
    }
}

/// Clipped runs shorter than this have no shape to reconstruct; their loss comes from the
/// stance's zero-velocity residual. Measured (`gaitclip clipping`): a run of one sample
/// reconstructs to 4 % of its true area at ±8 g, runs of two to 32 %, of four to 81 %; putting
/// runs of two on the residual too was worse on both datasets.
pub const SHAPED_RUN_MIN: u32 = 2;

/// Unit directions are kept in Q14 (`i16`): 6·10⁻⁵, far finer than what they scale.
const DIR_SHIFT: u32 = 16;

/// One accelerometer axis's clipped run in progress, for [`ClippedAccel`]: as [`RailRun`]
/// reconstructs it, in `i16` counts, and the direction it loses force along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct AccelRun {
    /// The two samples before this one, newest first; `seen` of them are real.
    prev: [i16; 2],
    seen: u8,
    /// Clipped samples in the run (0: none), the slope into it and the value before it.
    run: u16,
    slope_in: u16,
    before: i16,
    /// A run that ended at the last sample, waiting for its slope out: length (0: none),
    /// slope in, value before it, first value after it.
    ended_run: u16,
    ended_slope_in: u16,
    ended_before: i16,
    ended_after: i16,
    /// The level-frame unit direction the run loses force along (Q14), taken at its first
    /// sample, and that sample's number (1-based).
    dir: [i16; 3],
    first: u16,
}

/// A completed accelerometer run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Finished {
    len: u32,
    area: i64,
    /// How far the samples either side lie below the rail, counts, averaged: a bound on a
    /// one-sample spike's excess.
    climb: u32,
    dir: [i16; 3],
    first: u32,
}

impl AccelRun {
    const NEW: AccelRun = AccelRun {
        prev: [0; 2],
        seen: 0,
        run: 0,
        slope_in: 0,
        before: 0,
        ended_run: 0,
        ended_slope_in: 0,
        ended_before: 0,
        ended_after: 0,
        dir: [0; 3],
        first: 0,
    };

    const fn climb(rail: i32, before: i16, after: i16) -> u32 {
        ((rail - before as i32).unsigned_abs() + (rail - after as i32).unsigned_abs()) / 2
    }

    /// Sample `c` of the axis (`raw` counts, `column` the axis's level-frame direction, Q30);
    /// the run it completed, if any.
    fn process(
        &mut self,
        c: u32,
        raw: i16,
        rails: AxisRails,
        column: [i32; 3],
    ) -> Option<Finished> {
        let at_rail = rails.clipped(raw);
        let mut done = None;
        if self.ended_run > 0 {
            let after = self.ended_after as i32;
            let rail = rails.rail_of(after);
            let slope_out = if at_rail {
                (rail - after).unsigned_abs()
            } else {
                (after - raw as i32).unsigned_abs()
            };
            done = Some(Finished {
                len: self.ended_run as u32,
                area: area(self.ended_run as u32, self.ended_slope_in as u32, slope_out),
                climb: Self::climb(rail, self.ended_before, self.ended_after),
                dir: self.dir,
                first: self.first as u32,
            });
            self.ended_run = 0;
        }
        if at_rail {
            if self.run == 0 {
                self.slope_in = match self.seen {
                    2 => (self.prev[0] as i32 - self.prev[1] as i32).unsigned_abs() as u16,
                    1 => (raw as i32 - self.prev[0] as i32).unsigned_abs() as u16,
                    _ => 0,
                };
                self.before = if self.seen > 0 { self.prev[0] } else { raw };
                // The loss lies beyond the rail: along +axis at the high rail, −axis at the
                // low one.
                let sign = if raw > 0 { 1 } else { -1 };
                self.dir = column.map(|m| ((sign * m) >> DIR_SHIFT) as i16);
                self.first = c.min(u16::MAX as u32) as u16;
            }
            self.run = self.run.saturating_add(1);
        } else if self.run > 0 {
            self.ended_run = self.run;
            self.ended_slope_in = self.slope_in;
            self.ended_before = self.before;
            self.ended_after = raw;
            self.run = 0;
        }
        self.prev = [raw, self.prev[0]];
        self.seen = if self.seen < 2 { self.seen + 1 } else { 2 };
        done
    }

    /// The run not yet complete, if any: one that ended at the last sample (its slope out
    /// taken to the rail) or one still open (its slope out taken equal to its slope in).
    fn pending(&self, rails: AxisRails) -> Option<Finished> {
        if self.ended_run > 0 {
            let rail = rails.rail_of(self.ended_after as i32);
            let out = (rail - self.ended_after as i32).unsigned_abs();
            return Some(Finished {
                len: self.ended_run as u32,
                area: area(self.ended_run as u32, self.ended_slope_in as u32, out),
                climb: Self::climb(rail, self.ended_before, self.ended_after),
                dir: self.dir,
                first: self.first as u32,
            });
        }
        if self.run > 0 {
            let rail = rails.rail_of(self.prev[0] as i32);
            return Some(Finished {
                len: self.run as u32,
                area: area(self.run as u32, self.slope_in as u32, self.slope_in as u32),
                climb: Self::climb(rail, self.before, self.before),
                dir: self.dir,
                first: self.first as u32,
            });
        }
        None
    }
}

/// What a stride's integration lost at the accelerometer's rails, and what puts it back
/// (see the [module](self)): per axis the run in progress and the level-frame direction it
/// loses force along; per stride the velocity steps of the reconstructed runs and the
/// directions of the samples whose loss the residual will give.
///
/// Units are the integrator's ([`crate::detect::zupt::ZuptIntegrator`]): velocity in
/// accelerometer counts·2⁸ summed over samples, doubled position in those summed again.
/// Range: movements up to 2¹⁶ samples, with any number of clipped samples in them (sums
/// saturate rather than wrap). ≈ 200 bytes: three of these ride in every cycle detector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClippedAccel {
    runs: [AccelRun; 3],
    /// Σ of the reconstructed runs' velocity steps `D`, and of `D·2c` (`c` the run's centre).
    step: [i64; 3],
    step_2c: [i64; 3],
    /// Σ of the unit directions (Q14) of the samples left to the residual, and of `u·2c`.
    single: [i32; 3],
    single_2c: [i64; 3],
    /// Of those samples: how many, the smallest rail among them, and Σ of their climbs: the
    /// most one may have lost is their mean climb, never more than the rail.
    singles: u16,
    single_rail: u16,
    single_climb: u32,
    /// Samples with an axis at a rail.
    clipped: u16,
}

impl ClippedAccel {
    /// Nothing clipped.
    pub const NEW: ClippedAccel = ClippedAccel {
        runs: [AccelRun::NEW; 3],
        step: [0; 3],
        step_2c: [0; 3],
        single: [0; 3],
        single_2c: [0; 3],
        singles: 0,
        single_rail: u16::MAX,
        single_climb: 0,
        clipped: 0,
    };

    /// Samples of the movement with an accelerometer axis at a rail (saturates at 65 535).
    pub const fn clipped(&self) -> u32 {
        self.clipped as u32
    }

    /// Takes sample number `c` (1-based) of the movement: its raw accelerometer counts, the
    /// rails, and the attitude matrix it was rotated with (rows: level x, y, z in sensor axes,
    /// Q30), whose column `k` is where sensor axis `k` points.
    pub fn process(&mut self, c: u32, accel: &[i16; 3], rails: &[AxisRails; 3], r: &[[i32; 3]; 3]) {
        let mut any = false;
        for k in 0..3 {
            any |= rails[k].clipped(accel[k]);
            let column = [r[0][k], r[1][k], r[2][k]];
            if let Some(run) = self.runs[k].process(c, accel[k], rails[k], column) {
                self.add(run, rails[k]);
            }
        }
        if any {
            self.clipped = self.clipped.saturating_add(1);
        }
    }

    /// Books a completed run.
    fn add(&mut self, run: Finished, rails: AxisRails) {
        let (dir, first) = (run.dir, run.first as i64);
        if run.len >= SHAPED_RUN_MIN {
            // Doubled centre of the run: 2·first + L − 1 (a parabola is symmetric).
            let c2 = 2 * first + run.len as i64 - 1;
            for i in 0..3 {
                // area (counts·samples) × unit (Q14) → counts·2⁸: ≫ 6.
                let d = ((run.area as i128 * dir[i] as i128) >> 6)
                    .clamp(i64::MIN as i128, i64::MAX as i128) as i64;
                self.step[i] = self.step[i].saturating_add(d);
                self.step_2c[i] = self.step_2c[i].saturating_add(d.saturating_mul(c2));
            }
        } else {
            // Each sample of the run (one, below the shaped minimum) on its own.
            for j in 0..run.len as i64 {
                let c2 = 2 * (first + j);
                for i in 0..3 {
                    self.single[i] = self.single[i].saturating_add(dir[i] as i32);
                    self.single_2c[i] = self.single_2c[i].saturating_add(dir[i] as i64 * c2);
                }
            }
            let rail = rails.min_magnitude().min(u16::MAX as u32) as u16;
            if rail < self.single_rail {
                self.single_rail = rail;
            }
            self.single_climb = self
                .single_climb
                .saturating_add(run.climb.saturating_mul(run.len));
            self.singles = self
                .singles
                .saturating_add(run.len.min(u16::MAX as u32) as u16);
        }
    }

    /// The stride's velocity `v` and doubled position `p` (integrator units) after `n`
    /// samples, with what the rails lost put back for an end velocity the sensor should have
    /// of `v_end` (see the [module](self)). Without clipped samples: `v` and `p` as they
    /// are. Never panics; the sums are exact in `i128`.
    #[inline(never)]
    pub fn restore(
        &self,
        v: [i64; 3],
        p: [i64; 3],
        n: u32,
        rails: &[AxisRails; 3],
        v_end: [i64; 3],
    ) -> ([i64; 3], [i64; 3]) {
        // Runs not yet complete at the end are booked as they stand, on a copy of the sums
        // only (not of the run trackers).
        let mut sums = ClippedAccel {
            runs: [AccelRun::NEW; 3],
            ..*self
        };
        for k in 0..3 {
            if let Some(run) = self.runs[k].pending(rails[k]) {
                sums.add(run, rails[k]);
            }
        }
        let two_n1 = 2 * n as i128 + 1;
        let mut v2 = [0i128; 3];
        let mut p2 = [0i128; 3];
        for i in 0..3 {
            v2[i] = v[i] as i128 + sums.step[i] as i128;
            p2[i] = p[i] as i128 + sums.step[i] as i128 * two_n1 - sums.step_2c[i] as i128;
        }
        sums.singles_from_residual(&mut v2, &mut p2, v_end, two_n1);
        let sat = |v: i128| v.clamp(i64::MIN as i128, i64::MAX as i128) as i64;
        (v2.map(sat), p2.map(sat))
    }

    /// Puts the single-sample losses back on `v` and `p` (the shaped runs already restored)
    /// for the end velocity `v_end`: the residual `v_end − v` projected onto the samples'
    /// directions `U = Σu` as one magnitude `α` per sample, `α = max(0, (v_end − v)·U / U·U)`,
    /// at most their neighbours' mean climb to the rail (never more than the rail).
    fn singles_from_residual(
        &self,
        v: &mut [i128; 3],
        p: &mut [i128; 3],
        v_end: [i64; 3],
        two_n1: i128,
    ) {
        if self.singles == 0 {
            return;
        }
        // U: a sum of Q14 units over at most 2¹⁶ samples (< 2³¹); U·U < 2⁶³.
        let u = self.single.map(|x| x as i128);
        let uu: i128 = u.iter().map(|x| x * x).sum();
        if uu == 0 {
            return;
        }
        // The residual clamped to 2⁴⁰ counts·2⁸ (far beyond any stride): |rem·U| < 2⁷³.
        let lim = 1i128 << 40;
        let ru: i128 = (0..3)
            .map(|i| (v_end[i] as i128 - v[i]).clamp(-lim, lim) * u[i])
            .sum();
        if ru <= 0 {
            return;
        }
        // α in counts·2⁸ per sample: D_j = α·u_j / 2¹⁴.
        let climb = (self.single_climb / self.singles as u32).min(self.single_rail as u32);
        let alpha = ((ru << 14) / uu).min((climb as i128) << 8);
        for i in 0..3 {
            v[i] += (alpha * u[i]) >> 14;
            p[i] += (alpha * (u[i] * two_n1 - self.single_2c[i] as i128)) >> 14;
        }
    }
}

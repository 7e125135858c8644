//! A critically damped two-pole low-pass in integer arithmetic: Lu's 3 Hz filter.
//!
//! Lu et al. filter the vertical user acceleration with a 3 Hz low-pass before looking for
//! peaks and valleys (§2; the order is not given). Here it is two identical one-pole
//! sections in cascade: no overshoot, so the filter invents no peaks of its own, and it is
//! two multiplies per sample on a Cortex-M0.
//!
//! **Design.** Each section is `y ← y + α·(x − y)`, with the power gain
//! `|H₁(e^{jω})|² = α² / (1 − 2(1 − α)·cos ω + (1 − α)²)`. Two equal sections are −3 dB where
//! each is −1.5 dB, so `α` is solved for `|H₁|² = 1/√2` at ω of [`CUTOFF_MHZ`] (3 Hz) at the
//! sample rate: with `k = 1/√2`, `p = 1 − k·cos ω`, `q = 1 − k`, `1 − α = (p − √(p² − q²)) / q`
//! ([`alpha_q16`], evaluated at compile time). The cut-off is therefore 3 Hz at every rate,
//! not only where a continuous-time design would warp little (the host test measures the gain
//! at 3 Hz at 25–1000 Hz: 0.7070–0.7071).
//!
//! **Scaling.** Input: g/[`crate::sensor::units::FOOT_LSB_PER_G`] (`i16`, ±16 g). Output:
//! g/[`LOW_PASS_LSB_PER_G`] (`i32`), 16 times finer, so that thresholds of 0.01 g are not
//! at the resolution of the input. State: input · 2¹² (`i32`; |state| < 2²⁸), `α` in Q16,
//! products in `i64`.
//!
//! **Error.** Against the same recursion in `f64` (with the same `α`): at most 1 output unit
//! (g/32 768, 0.03 mg) for any `i16` input at 25–1000 Hz; asserted by a host test
//! (measured: 0.51).
//!
//! **Delay.** A one-pole section delays slow signals by `(1 − α)/α` samples; [`LowPass::delay`]
//! is the cascade's, rounded, so that the peak-valley detector can report the sample an
//! extreme of the unfiltered signal belongs to (about 32 ms per section, 64 ms in all).

use crate::sensor::rate::SampleRate;

/// Cut-off (−3 dB) of the cascade, mHz: Lu's 3 Hz.
pub const CUTOFF_MHZ: u32 = 3_000;
/// Output scale: g/32 768 (the input's g/2048 times 16).
pub const LOW_PASS_LSB_PER_G: i32 = 32_768;
/// Extra fractional bits of the state over the input.
const STATE_SHIFT: u32 = 12;
/// Output bits over the input: 32 768 / 2048 = 2⁴.
const OUT_SHIFT: u32 = 4;

/// `α` of a section at `rate`, Q16 (rounded; 0.0289 at 1 kHz … 0.2528 at 100 Hz, more down to 25 Hz): the
/// cascade is −3 dB at [`CUTOFF_MHZ`] (see the module's design note).
pub const fn alpha_q16(rate: SampleRate) -> i64 {
    let w = 2.0 * core::f64::consts::PI * CUTOFF_MHZ as f64 / rate.millihertz() as f64;
    let k = core::f64::consts::FRAC_1_SQRT_2;
    let (p, q) = (1.0 - k * cos_small(w), 1.0 - k);
    let beta = (p - sqrt(p * p - q * q)) / q;
    ((1.0 - beta) * 65_536.0 + 0.5) as i64
}

/// cos of `w` ≤ 0.76 rad (3 Hz at 25 Hz): Taylor to `w⁸`, error below 2·10⁻⁸ (`w¹⁰/10!`).
const fn cos_small(w: f64) -> f64 {
    let w2 = w * w;
    1.0 - w2 / 2.0 * (1.0 - w2 / 12.0 * (1.0 - w2 / 30.0 * (1.0 - w2 / 56.0)))
}

/// √x for 0 < x ≤ 1 by Newton's method, to the last bit.
const fn sqrt(x: f64) -> f64 {
    let mut r = 1.0;
    let mut i = 0;
    while i < 60 {
        r = 0.5 * (r + x / r);
        i += 1;
    }
    r
}

/// Two one-pole sections in cascade, −3 dB at 3 Hz, at any supported rate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LowPass {
    alpha_q16: i64,
    first: i32,
    second: i32,
    primed: bool,
}

impl LowPass {
    /// A filter for samples at `rate`; it takes its first input as its settled state.
    pub const fn new(rate: SampleRate) -> Self {
        LowPass {
            alpha_q16: alpha_q16(rate),
            first: 0,
            second: 0,
            primed: false,
        }
    }

    /// Samples by which the output lags a slow input: `2·(1 − α)/α`, rounded (13 at
    /// 204.8 Hz, 6 at 100 Hz).
    pub const fn delay(&self) -> u32 {
        let a = self.alpha_q16;
        ((2 * ((1 << 16) - a) + a / 2) / a) as u32
    }

    /// Forgets the signal: the next input is taken as the settled state (after a gap).
    pub fn reset(&mut self) {
        self.primed = false;
    }

    /// Filters one input, g/2048; returns g/32 768.
    pub fn process(&mut self, x: i16) -> i32 {
        let x = (x as i32) << STATE_SHIFT;
        if !self.primed {
            self.first = x;
            self.second = x;
            self.primed = true;
        }
        // |x − y| < 2²⁸ and α < 2¹⁶: the product fits an i64; the step is smaller than the
        // difference, so the state stays between its old value and the input.
        let step = |y: i32, x: i32| {
            let d = (x - y) as i64 * self.alpha_q16;
            y + ((d + (1 << 15)) >> 16) as i32
        };
        self.first = step(self.first, x);
        self.second = step(self.second, self.first);
        let shift = STATE_SHIFT - OUT_SHIFT;
        (self.second + (1 << (shift - 1))) >> shift
    }
}

//! A critically damped two-pole low-pass in integer arithmetic: Lu's 3 Hz filter.
//!
//! Lu et al. filter the vertical user acceleration with a 3 Hz low-pass before looking for
//! peaks and valleys (§2; the order is not given). Here it is two identical one-pole
//! sections in cascade: no overshoot, so the filter invents no peaks of its own, and it is
//! two multiplies per sample on a Cortex-M0.
//!
//! **Design.** Each section is the backward-Euler discretisation of an RC stage,
//! `y ← y + α·(x − y)` with `α = w / (f_s + w)`, where `w` is the section's corner in rad/s.
//! Two equal sections are −3 dB where each is −1.5 dB, at `w / (2π) · √(√2 − 1)`; the
//! sections are therefore placed at `CUTOFF_MHZ / √(√2 − 1)` = 4.66 Hz so that the cascade
//! is −3 dB at [`CUTOFF_MHZ`] (3 Hz). `α` follows the sample rate, so the cut-off is the same
//! at every rate (the host test measures the gain at 3 Hz at 100–1000 Hz: 0.706–0.707).
//!
//! **Scaling.** Input: g/[`crate::foot_frame::FOOT_LSB_PER_G`] (`i16`, ±16 g). Output:
//! g/[`LOW_PASS_LSB_PER_G`] (`i32`), 16 times finer, so that thresholds of 0.01 g are not
//! at the resolution of the input. State: input · 2¹² (`i32`; |state| < 2²⁸), `α` in Q16,
//! products in `i64`.
//!
//! **Error.** Against the same recursion in `f64` (with the same `α`): at most 1 output unit
//! (g/32 768, 0.03 mg) for any `i16` input at 100–1000 Hz; asserted by a host test.
//!
//! **Delay.** A one-pole section delays slow signals by `(1 − α)/α` samples; [`LowPass::delay`]
//! is the cascade's, rounded, so that the peak-valley detector can report the sample an
//! extreme of the unfiltered signal belongs to (34 ms per section, 68 ms in all).

use crate::rate::SampleRate;

/// Cut-off (−3 dB) of the cascade, mHz: Lu's 3 Hz.
pub const CUTOFF_MHZ: u32 = 3_000;
/// Corner of each section, rad/s × 1000: 2π · 3 Hz / √(√2 − 1) = 29.2876 rad/s.
pub const SECTION_CORNER_MRAD_PER_S: u64 = 29_288;
/// Output scale: g/32 768 (the input's g/2048 times 16).
pub const LOW_PASS_LSB_PER_G: i32 = 32_768;
/// Extra fractional bits of the state over the input.
const STATE_SHIFT: u32 = 12;
/// Output bits over the input: 32 768 / 2048 = 2⁴.
const OUT_SHIFT: u32 = 4;

/// `α` of a section at `rate`, Q16: `w / (f_s + w)`, 0.0285 at 1 kHz … 0.2266 at 100 Hz.
pub const fn alpha_q16(rate: SampleRate) -> i64 {
    let w = SECTION_CORNER_MRAD_PER_S;
    // f_s in mHz against w in mrad/s: both are thousandths, the ratio is the same.
    let den = rate.millihertz() as u64 + w;
    (((w << 16) + den / 2) / den) as i64
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

    /// Samples by which the output lags a slow input: `2·(1 − α)/α`, rounded (14 at
    /// 204.8 Hz, 7 at 100 Hz).
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

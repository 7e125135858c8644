//! Lu's length chain for the peak-valley detector's steps ([`crate::detect::peak_valley`]): the
//! fuzzy Weinberg coefficient of the step's amplitude and frequency, no training.

use crate::fixed::{div_round_i128, root_q16, Q16_ONE};
use crate::length::fuzzy;
use crate::record::stride::StepAmplitude;
use crate::sensor::rate::SampleRate;

/// Lu's whole chain on one of the peak-valley detector's steps
/// ([`crate::detect::peak_valley::PeakValleySteps`]), with the paper's constants and no training:
/// `D` = peak − valley (eq. 11) and the step frequency `f` give the fuzzy `k` over the
/// paper's universes ([`fuzzy::D_UNIVERSE_Q16`], [`fuzzy::F_UNIVERSE_Q16`]), and Weinberg's
/// `k·(a_max − a_min)^¼` (eq. 6) is taken with the step's own peak and valley as `a_max`
/// and `a_min`. Returns the foot's stride, µm.
///
/// On a foot the detector sees one peak-valley pair per stride of that foot, so the
/// walker's step frequency is twice the pairs' (`f = 2·rate/period`), and the foot's
/// stride is two of the walker's steps: the stride is `2·k·D^¼`. The first step of a walk
/// has no period; it takes `f` at the bottom of the universe (1 Hz), as a walk starts slowly.
// Not inlined: the cost benchmark counts Lu's chain per step by this symbol.
#[inline(never)]
pub fn lu_chain_um(step: &StepAmplitude, rate: SampleRate) -> i64 {
    // D in g, Q16: the low-pass unit is g/32 768 = 2⁻¹⁵ g.
    let d_q16 = (step.peak_to_valley.max(0) as i64) << 1;
    let f_q16 = if step.period == 0 {
        fuzzy::F_UNIVERSE_Q16.0
    } else {
        // 2 · rate(mHz)/1000 / period, Hz, Q16.
        div_round_i128(
            2 * rate.millihertz() as i128 * Q16_ONE as i128,
            1000 * step.period as i128,
        ) as i64
    };
    let k = fuzzy::lu_k_q16(f_q16, fuzzy::F_UNIVERSE_Q16, d_q16, fuzzy::D_UNIVERSE_Q16);
    let root = root_q16(d_q16 as u64, 4) as i64;
    // 2 · k · D^¼, Q32 → µm.
    div_round_i128(2 * k as i128 * root as i128 * 1_000_000, 1i128 << 32) as i64
}

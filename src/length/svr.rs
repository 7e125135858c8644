//! ε-SVR with an RBF kernel, evaluated in fixed point, and AdaBoost.R2 ensembles of them.
//!
//! A trained SVR predicts `y = Σᵢ αᵢ·exp(−γ‖z − zᵢ‖²) − ρ` where `z` is the z-scored
//! feature vector (`(x − μ)/σ` with the training mean and deviation) and the `zᵢ` are the
//! support vectors. The host trains it (`gaitclip train`, linfa-svm) and writes the numbers
//! into [`crate::length::trained`]; here it is evaluated with integers only:
//!
//! - features are Q16 ([`crate::length::features`]); `z = (x − μ)·σ⁻¹` with `σ⁻¹` in Q32, rounded
//!   to Q16 and clamped to ±256 (a deviation never seen in training);
//! - support vectors are Q16 (`i32`), `‖z − zᵢ‖²` is Q32 in a `u64` (exact);
//! - `γ‖z − zᵢ‖²` is Q32, `exp` comes from [`crate::fixed::exp_neg_q32`] (Q62, error
//!   ≤ 8e−12 relative);
//! - `αᵢ` and `ρ` are integer nanometres; `Σ αᵢ·K` is summed in `i128`.
//!
//! The error against the f64 model is dominated by the Q16 rounding of `z` and `zᵢ`
//! (≤ 7.6e−6 each); `tests-host` asserts the stride lengths agree within 1 mm on every
//! training and test stride. Cost: one pass over the support vectors, `n_sv · n_features`
//! multiply-adds and `n_sv` exponentials per stride.

use crate::fixed::exp_neg_q32;
use crate::length::features::Features;

/// Most features one SVR may use (keeps `‖z − zᵢ‖²` exact in a `u64`).
pub const MAX_FEATURES: usize = 32;
/// Most members of a boosted ensemble.
pub const MAX_MEMBERS: usize = 8;
/// Largest |z| kept, Q16 (256 standard deviations).
const Z_LIMIT_Q16: i64 = 256 << 16;

/// One trained RBF ε-SVR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Svr<'a> {
    /// Indices into [`Features`] of the inputs, in order.
    pub features: &'a [u8],
    /// Training mean of each input, Q16 of the feature's unit.
    pub mean_q16: &'a [i64],
    /// 1 / training deviation of each input, Q32 per unit.
    pub inv_std_q32: &'a [i64],
    /// Kernel width γ (per squared z unit), Q32.
    pub gamma_q32: u64,
    /// Support vectors, row-major `n_sv × features.len()`, z-scores in Q16.
    pub support_q16: &'a [i32],
    /// Dual coefficient of each support vector, nm.
    pub alpha_nm: &'a [i64],
    /// Offset ρ, nm.
    pub rho_nm: i64,
}

impl Svr<'static> {
    /// A model that is not in this build (the firmware was built without the
    /// `all-models` feature): it predicts nothing.
    pub const ABSENT: Svr<'static> = Svr {
        features: &[],
        mean_q16: &[],
        inv_std_q32: &[],
        gamma_q32: 0,
        support_q16: &[],
        alpha_nm: &[],
        rho_nm: 0,
    };
}

impl Svr<'_> {
    /// True when the model has support vectors, i.e. it was trained and shipped.
    pub const fn is_present(&self) -> bool {
        !self.features.is_empty() && !self.alpha_nm.is_empty()
    }

    /// The z-scores of the inputs, Q16; `None` if the model is malformed (more than
    /// [`MAX_FEATURES`] inputs, or tables of mismatched lengths).
    fn inputs(&self, f: &Features) -> Option<[i64; MAX_FEATURES]> {
        let n = self.features.len();
        if n > MAX_FEATURES || self.mean_q16.len() != n || self.inv_std_q32.len() != n {
            return None;
        }
        let mut z = [0i64; MAX_FEATURES];
        for (k, z) in z.iter_mut().enumerate().take(n) {
            let x = f.get(self.features[k] as usize);
            let d = x.saturating_sub(self.mean_q16[k]) as i128;
            let v = (d * self.inv_std_q32[k] as i128 + (1 << 31)) >> 32;
            *z = v.clamp(-Z_LIMIT_Q16 as i128, Z_LIMIT_Q16 as i128) as i64;
        }
        Some(z)
    }

    /// The prediction for `f`, nm; `None` if the model is malformed.
    pub fn predict_nm(&self, f: &Features) -> Option<i64> {
        let n = self.features.len();
        let z = self.inputs(f)?;
        if n == 0 || self.support_q16.len() != n * self.alpha_nm.len() {
            return None;
        }
        let mut acc: i128 = 0;
        for (sv, &alpha) in self.support_q16.chunks_exact(n).zip(self.alpha_nm.iter()) {
            let mut d2: u64 = 0;
            for (&s, &zk) in sv.iter().zip(z.iter()) {
                let d = (zk - s as i64).unsigned_abs();
                d2 = d2.saturating_add(d * d);
            }
            let t = ((self.gamma_q32 as u128 * d2 as u128 + (1 << 31)) >> 32).min(u64::MAX as u128);
            acc += alpha as i128 * exp_neg_q32(t as u64) as i128;
        }
        let sum_nm = (acc + (1 << 61)) >> 62;
        Some((sum_nm - self.rho_nm as i128).clamp(i64::MIN as i128, i64::MAX as i128) as i64)
    }
}

/// AdaBoost.R2 (Drucker 1997) over SVRs: the prediction is the weighted median of the
/// members' predictions, member `t` weighted `ln(1/β_t)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Boosted<'a> {
    /// The members, at most [`MAX_MEMBERS`].
    pub members: &'a [Svr<'a>],
    /// `ln(1/β_t)` of each member, Q16.
    pub weights_q16: &'a [u32],
}

impl Boosted<'static> {
    /// An ensemble that is not in this build (see [`Svr::ABSENT`]).
    pub const ABSENT: Boosted<'static> = Boosted {
        members: &[],
        weights_q16: &[],
    };
}

impl Boosted<'_> {
    /// True when every member is present.
    pub fn is_present(&self) -> bool {
        !self.members.is_empty() && self.members.iter().all(Svr::is_present)
    }

    /// The weighted median of the members' predictions for `f`, nm; `None` if empty or
    /// malformed.
    pub fn predict_nm(&self, f: &Features) -> Option<i64> {
        let n = self.members.len();
        if n == 0 || n > MAX_MEMBERS || self.weights_q16.len() != n {
            return None;
        }
        let mut p = [(0i64, 0u64); MAX_MEMBERS];
        for ((slot, m), &w) in p.iter_mut().zip(self.members).zip(self.weights_q16) {
            *slot = (m.predict_nm(f)?, w as u64);
        }
        let p = &mut p[..n];
        p.sort_unstable_by_key(|&(y, _)| y);
        let total: u64 = p.iter().map(|&(_, w)| w).sum();
        // Smallest prediction whose cumulative weight reaches half the total (Drucker's
        // weighted median: Σ_{t: y_t ≤ y} ln(1/β_t) ≥ ½ Σ_t ln(1/β_t)).
        let mut cum = 0u64;
        for &(y, w) in p.iter() {
            cum += w;
            if 2 * cum >= total {
                return Some(y);
            }
        }
        p.last().map(|&(y, _)| y)
    }
}

//! Stride-length models, all evaluated in fixed point on the same [`Features`].
//!
//! | name | model | source |
//! |---|---|---|
//! | `zupt` | strapdown displacement between two zero-velocity updates | foot-mounted INS |
//! | `weinberg` | `K·(a_max − a_min)^¼`, vertical | Weinberg; Huang Table 2 |
//! | `kim` | `K·(Σ\|a\|/N)^⅓`, magnitude | Kim; Huang Table 2 |
//! | `scarlett` | `K·(Σ\|a\|/N − a_min)/(a_max − a_min)`, vertical | Scarlett; Huang Table 2 |
//! | `ladetto` | `A·f + B·var + C` | Ladetto; Zhang eq. 1 |
//! | `zhang` | `h·(A·f + B·var + C) + D` | Zhang eq. 2 |
//! | `lu_fuzzy` | `G·k(f, D)·(a_max − a_min)^¼`, `k` from the fuzzy rules | Lu §3 |
//! | `ho` | `G·(0.68 − 0.37·v + 0.15·v²)·(a_max − a_min)^¼` | Ho, in Lu eq. 9 |
//! | `strozzi` | `β·(a_max − a_min)^¼ / a_max^⅓` | Strozzi, in Lu eq. 10 |
//! | `vezocnik` | `β·range(\|a\|)^0.1` | Vezočnik eq. 13 |
//! | `tian` | `K·h·√F` | Tian, in Vezočnik Table 1 |
//! | `huang_svr_fusion` | mean of three per-phase RBF ε-SVRs | Huang §2.4.3 |
//! | `huang_svr_whole` | one RBF ε-SVR on whole-movement features | Huang Table 6 |
//! | `huang_svr_adaboost` | mean of three per-phase AdaBoost.R2 ensembles of SVRs | Huang Table 6 |
//!
//! Signals and units: `a` is foot-frame acceleration in g over the movement (heel-off to
//! foot-flat), vertical with gravity removed, `|a|` the specific-force magnitude minus 1 g;
//! `f` the stride frequency and `F` the step frequency (2·f), Hz; `var` the vertical
//! variance, g²; `h` the wearer's height, m (a device setting, [`Settings`]); `v` the mean
//! speed over the stride, m/s (ZUPT displacement / stride time); `D` Lu's peak-to-valley
//! difference, here the vertical range mapped from the training data's 5th–95th percentile
//! onto Lu's universe, since a foot sees several g where a hand sees 0.12–0.9 g.
//!
//! Every closed-form model is linear in at most four fixed-point basis terms
//! ([`basis`]); `gaitclip train` fits their coefficients by least squares (the fixed
//! constants of Ho and of Lu's rule base stay as published, a gain `G` absorbs units) and
//! writes them with the SVRs into [`crate::length::trained`]. Step models predict a step; fitted on
//! strides, their constant simply doubles.

use crate::detect::phase_stats::{Channel, Segment, StrideStats};
use crate::fixed::{div_round_i128, root_q16, tenth_root_q16, Q16_ONE};
use crate::length::features::{self, Features};
use crate::length::fuzzy;
use crate::length::svr::{Boosted, Svr};
use crate::record::stride::{StepAmplitude, Stride, StrideFlags};

/// Number of models.
pub const MODELS: usize = 14;
/// Number of closed-form (least-squares) models: those before the SVRs in [`Model::ALL`],
/// ZUPT excepted.
pub const LINEAR_MODELS: usize = 10;
/// Most basis terms of a closed-form model.
pub const MAX_TERMS: usize = 4;

/// A stride-length model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Model {
    /// ZUPT strapdown displacement.
    Zupt = 0,
    /// Weinberg.
    Weinberg = 1,
    /// Kim.
    Kim = 2,
    /// Scarlett.
    Scarlett = 3,
    /// Ladetto.
    Ladetto = 4,
    /// Zhang, height-adaptive Ladetto.
    Zhang = 5,
    /// Weinberg with Lu's fuzzy-logic K.
    LuFuzzy = 6,
    /// Weinberg with Ho's speed-adaptive K.
    Ho = 7,
    /// Weinberg with Strozzi's peak-adaptive K.
    Strozzi = 8,
    /// Vezočnik's magnitude-range power law.
    Vezocnik = 9,
    /// Tian's height and frequency model.
    Tian = 10,
    /// Huang: mean of per-phase SVRs.
    HuangSvrFusion = 11,
    /// Huang: one SVR on the whole movement.
    HuangSvrWhole = 12,
    /// Huang: mean of per-phase AdaBoost.R2 SVR ensembles.
    HuangSvrAdaBoost = 13,
}

impl Model {
    /// Every model, in index order.
    pub const ALL: [Model; MODELS] = [
        Model::Zupt,
        Model::Weinberg,
        Model::Kim,
        Model::Scarlett,
        Model::Ladetto,
        Model::Zhang,
        Model::LuFuzzy,
        Model::Ho,
        Model::Strozzi,
        Model::Vezocnik,
        Model::Tian,
        Model::HuangSvrFusion,
        Model::HuangSvrWhole,
        Model::HuangSvrAdaBoost,
    ];

    /// The model's name, as `--model` takes it.
    pub const fn name(self) -> &'static str {
        match self {
            Model::Zupt => "zupt",
            Model::Weinberg => "weinberg",
            Model::Kim => "kim",
            Model::Scarlett => "scarlett",
            Model::Ladetto => "ladetto",
            Model::Zhang => "zhang",
            Model::LuFuzzy => "lu_fuzzy",
            Model::Ho => "ho",
            Model::Strozzi => "strozzi",
            Model::Vezocnik => "vezocnik",
            Model::Tian => "tian",
            Model::HuangSvrFusion => "huang_svr_fusion",
            Model::HuangSvrWhole => "huang_svr_whole",
            Model::HuangSvrAdaBoost => "huang_svr_adaboost",
        }
    }

    /// The model called `name`.
    pub fn from_name(name: &str) -> Option<Model> {
        Model::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Index into [`ModelParams::linear`] of a closed-form model.
    pub const fn linear_index(self) -> Option<usize> {
        let i = self as usize;
        if i >= 1 && i <= LINEAR_MODELS {
            Some(i - 1)
        } else {
            None
        }
    }
}

/// Device settings some models need.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// The wearer's height, mm (Zhang, Tian).
    pub height_mm: u16,
}

impl Settings {
    /// Height used when the user set none: 1.75 m.
    pub const DEFAULT: Settings = Settings { height_mm: 1750 };
}

/// Everything trained: coefficients of the closed-form models and the SVRs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelParams<'a> {
    /// Per closed-form model ([`Model::linear_index`]): coefficient of each basis term, µm
    /// per basis unit, Q16; unused terms 0.
    pub linear: [[i64; MAX_TERMS]; LINEAR_MODELS],
    /// Foot vertical range mapped onto Lu's D universe: (low, high), g, Q16.
    pub lu_d_range_q16: (i64, i64),
    /// Per-phase SVRs: push-off, swing, heel-strike.
    pub fusion: [Svr<'a>; 3],
    /// The whole-movement SVR.
    pub whole: Svr<'a>,
    /// Per-phase boosted ensembles: push-off, swing, heel-strike.
    pub adaboost: [Boosted<'a>; 3],
}

impl ModelParams<'_> {
    /// True when this build carries what `model` needs. The SVR models other than the
    /// pipeline's default are only in builds with the `all-models` feature (they are
    /// 300 KiB of tables); the closed-form models and ZUPT are always there.
    pub fn ships(&self, model: Model) -> bool {
        match model {
            Model::HuangSvrFusion => self.fusion.iter().all(Svr::is_present),
            Model::HuangSvrWhole => self.whole.is_present(),
            Model::HuangSvrAdaBoost => self.adaboost.iter().all(Boosted::is_present),
            _ => true,
        }
    }
}

/// The basis terms, Q16, of a closed-form model: its length is `Σ cᵢ·termᵢ`. `None` for
/// ZUPT and the SVRs. Units per term are in the module table.
pub fn basis(
    model: Model,
    f: &Features,
    settings: Settings,
    params: &ModelParams,
) -> Option<[i64; MAX_TERMS]> {
    use features::Stat::*;
    let mv = Segment::Movement;
    let weinberg = f.stat(mv, Channel::Vertical, Weinberg);
    let stride_f = f.get(features::STRIDE_FREQUENCY);
    let var = f.stat(mv, Channel::Vertical, Variance);
    let h = (settings.height_mm as i64 * Q16_ONE + 500) / 1000;
    let mul = |a: i64, b: i64| ((a as i128 * b as i128 + (1 << 15)) >> 16) as i64;
    let t = match model {
        Model::Zupt | Model::HuangSvrFusion | Model::HuangSvrWhole | Model::HuangSvrAdaBoost => {
            return None
        }
        Model::Weinberg => [weinberg, 0, 0, 0],
        Model::Kim => [f.stat(mv, Channel::Magnitude, Kim), 0, 0, 0],
        Model::Scarlett => [f.stat(mv, Channel::Vertical, Scarlett), 0, 0, 0],
        Model::Ladetto => [stride_f, var, Q16_ONE, 0],
        Model::Zhang => [mul(h, stride_f), mul(h, var), h, Q16_ONE],
        Model::LuFuzzy => {
            let step_f = 2 * stride_f;
            let d = f.stat(mv, Channel::Vertical, Range);
            let k = fuzzy::lu_k_q16(step_f, fuzzy::F_UNIVERSE_Q16, d, params.lu_d_range_q16);
            [mul(k, weinberg), 0, 0, 0]
        }
        Model::Ho => {
            // v = ZUPT length / stride time = length · stride frequency, m/s.
            let v = mul(f.get(features::ZUPT_LENGTH), stride_f);
            let k = 44_564 - mul(24_248, v) + mul(9_830, mul(v, v)); // 0.68, 0.37, 0.15
            [mul(k, weinberg), 0, 0, 0]
        }
        Model::Strozzi => {
            // a_max of |a|, floored at 1/16 g so that a flat record cannot divide by ~0.
            let a_max = f.stat(mv, Channel::Magnitude, Max).max(Q16_ONE / 16);
            let cube = root_q16(a_max as u64, 3) as i64;
            [
                div_round_i128(weinberg as i128 * Q16_ONE as i128, cube as i128) as i64,
                0,
                0,
                0,
            ]
        }
        Model::Vezocnik => {
            let range = f.stat(mv, Channel::Magnitude, Range).max(0);
            [tenth_root_q16(range as u64) as i64, 0, 0, 0]
        }
        Model::Tian => {
            let step_f = (2 * stride_f).max(0) as u64;
            [mul(h, root_q16(step_f, 2) as i64), 0, 0, 0]
        }
    };
    Some(t)
}

/// The stride length predicted by `model`, µm (may be negative for a nonsensical
/// stride; callers clamp); `None` if a trained model is malformed.
pub fn predict_um(
    model: Model,
    f: &Features,
    settings: Settings,
    params: &ModelParams,
) -> Option<i64> {
    let nm_to_um = |nm: i64| div_round_i128(nm as i128, 1000) as i64;
    match model {
        Model::Zupt => Some(div_round_i128(
            f.get(features::ZUPT_LENGTH) as i128 * 1_000_000,
            Q16_ONE as i128,
        ) as i64),
        Model::HuangSvrFusion => {
            let mut sum = 0i64;
            for s in &params.fusion {
                sum = sum.saturating_add(s.predict_nm(f)?);
            }
            Some(nm_to_um(sum / 3))
        }
        Model::HuangSvrWhole => params.whole.predict_nm(f).map(nm_to_um),
        Model::HuangSvrAdaBoost => {
            let mut sum = 0i64;
            for b in &params.adaboost {
                sum = sum.saturating_add(b.predict_nm(f)?);
            }
            Some(nm_to_um(sum / 3))
        }
        _ => {
            let terms = basis(model, f, settings, params)?;
            let c = params.linear[model.linear_index()?];
            let sum: i128 = terms
                .iter()
                .zip(c.iter())
                .map(|(&t, &c)| t as i128 * c as i128)
                .sum();
            Some(((sum + (1 << 31)) >> 32).clamp(i64::MIN as i128, i64::MAX as i128) as i64)
        }
    }
}

/// The stride length predicted by `model`, mm, clamped at 0 and rounded; `None` if a
/// trained model is malformed.
pub fn predict_mm(
    model: Model,
    f: &Features,
    settings: Settings,
    params: &ModelParams,
) -> Option<u32> {
    predict_um(model, f, settings, params).map(um_to_mm)
}

/// A length in µm as whole mm: clamped at 0, rounded, saturated at `u32::MAX`.
pub const fn um_to_mm(um: i64) -> u32 {
    let um = if um < 0 { 0 } else { um };
    let mm = um.saturating_add(500) / 1000;
    if mm > u32::MAX as i64 {
        u32::MAX
    } else {
        mm as u32
    }
}

/// What fills in a stride's length: the configured model with its settings and trained
/// parameters, and the ZUPT displacement, which needs no training, when that model cannot
/// give one.
#[derive(Clone, Copy, Debug)]
pub struct LengthChain {
    /// The model.
    pub model: Model,
    /// The wearer's settings.
    pub settings: Settings,
    /// Trained coefficients and SVRs.
    pub params: &'static ModelParams<'static>,
    /// Sample rate (the features' durations).
    pub rate: crate::sensor::rate::SampleRate,
}

impl LengthChain {
    /// Fills in `s`'s length: a peak-valley step (`step`, Lu's detector) by Lu's chain
    /// ([`crate::length::lu::lu_chain_um`]); a stride from its features (`stats`: its phase
    /// statistics, if still kept); a gap stride keeps none.
    // Not inlined: the per-stride work stays out of the per-sample frame (stack), and
    // `gaitclip cost` counts it apart from the sample path.
    #[inline(never)]
    pub fn measure(
        &self,
        s: &mut Stride,
        stats: Option<&StrideStats>,
        step: Option<StepAmplitude>,
    ) {
        if let Some(step) = step {
            s.set_length_mm(um_to_mm(crate::length::lu::lu_chain_um(&step, self.rate)));
            return;
        }
        if s.flags.has(StrideFlags::GAP) {
            // No length across a gap; `length_mm` stays 0.
            return;
        }
        // The ZUPT model, the fallback, needs no statistics: empty ones if they were gone.
        let f = if self.model == Model::Zupt {
            Features::zupt_only(s)
        } else {
            Features::of(s, stats.unwrap_or(&StrideStats::EMPTY), self.rate)
        };
        let mm = predict_mm(self.model, &f, self.settings, self.params)
            .or_else(|| predict_mm(Model::Zupt, &f, self.settings, self.params))
            .unwrap_or(0);
        s.set_length_mm(mm);
    }
}

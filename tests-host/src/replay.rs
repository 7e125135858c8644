//! Runs a trace through the firmware core, exactly as the board does, and reports strides
//! in the trace's own clock.

use std::collections::BTreeMap;

use gaitclip::features::Features;
use gaitclip::models::{self, Model};
use gaitclip::pipeline::{Config, Detector, Pipeline};
use gaitclip::rate::SampleRate;
use gaitclip::sample::RawSample;
use gaitclip::stride::{Stride, StrideFlags};
use serde::Serialize;

use crate::gaps::{self, Gap, GapClock};
use crate::trace::{Ranges, Trace};

/// Why a trace cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The rate is outside what the core supports.
    #[error("sample rate {0} Hz is outside 100–1000 Hz")]
    Rate(f64),
    /// The timestamps go backwards or repeat.
    #[error(transparent)]
    Time(#[from] crate::gaps::TimeError),
}

/// A stride as the host reports it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrideReport {
    /// Stride number from 0.
    pub index: u32,
    /// Start (foot-flat), s in the trace's clock.
    pub start_s: f64,
    /// End (next foot-flat), s.
    pub end_s: f64,
    /// Length from the pipeline's model (the default unless `--model` chose one), m.
    pub length_m: f64,
    /// Name of the model behind `length_m`.
    pub model: &'static str,
    /// The step detector (`stance`, or `lu`: then `heel_off_s`/`toe_off_s` are the step's
    /// peak, `heel_strike_s`/`foot_flat_s` its valley).
    pub detector: &'static str,
    /// Every model's length, m, by model name (`--all-models`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lengths_m: Option<BTreeMap<&'static str, f64>>,
    /// The ZUPT displacement, m.
    pub zupt_m: f64,
    /// Heel-off (end of stance), s.
    pub heel_off_s: f64,
    /// Toe-off, s.
    pub toe_off_s: f64,
    /// Heel-strike, s.
    pub heel_strike_s: f64,
    /// Foot-flat ending the stride, s (same as `end_s`).
    pub foot_flat_s: f64,
    /// Height gained, m.
    pub climb_m: f64,
    /// False when the length is not to be trusted (see `flags`).
    pub valid: bool,
    /// Names of the flags set.
    pub flags: Vec<&'static str>,
    /// The core's integer record, as the firmware logs it.
    #[serde(skip)]
    pub raw: Stride,
}

/// Names of the stride flags, in bit order.
pub fn flag_names(f: StrideFlags) -> Vec<&'static str> {
    let mut v = Vec::new();
    if f.has(StrideFlags::SATURATED) {
        v.push("saturated");
    }
    if f.has(StrideFlags::TOO_LONG) {
        v.push("too_long");
    }
    if f.has(StrideFlags::FROM_REST) {
        v.push("from_rest");
    }
    if f.has(StrideFlags::TO_REST) {
        v.push("to_rest");
    }
    if f.has(StrideFlags::TURN) {
        v.push("turn");
    }
    if f.has(StrideFlags::PHASES_GUESSED) {
        v.push("phases_guessed");
    }
    if f.has(StrideFlags::GAP) {
        v.push("gap");
    }
    if f.has(StrideFlags::IMPLAUSIBLE) {
        v.push("implausible");
    }
    v
}

/// Replays raw counts at `rate` through the core with the default configuration. `t_s(i)`
/// gives the time of sample `i`.
pub fn replay_counts(
    samples: &[RawSample],
    rate: SampleRate,
    ranges: Ranges,
    t_s: impl Fn(u32) -> f64,
) -> Vec<StrideReport> {
    let config = Config::new(rate, ranges.accel, ranges.gyro);
    replay_counts_with(samples, config, t_s)
}

/// The core's strides for raw counts without gaps, in the order it reports them.
pub fn core_strides(samples: &[RawSample], config: Config) -> Vec<Stride> {
    core_strides_gapped(samples, &[], config)
}

/// The core's strides for raw counts with `gaps` (sorted by position) declared to it as
/// the firmware declares a FIFO overflow.
pub fn core_strides_gapped(samples: &[RawSample], gaps: &[Gap], config: Config) -> Vec<Stride> {
    let mut p = Pipeline::new(config);
    let mut strides = Vec::new();
    let mut next_gap = gaps.iter().peekable();
    for (i, s) in samples.iter().enumerate() {
        while let Some(g) = next_gap.next_if(|g| g.before <= i) {
            strides.extend(p.gap(g.missing));
        }
        strides.extend(p.process(s));
    }
    strides.extend(p.finish().into_iter().flatten());
    while let Some(s) = p.take() {
        strides.push(s);
    }
    strides
}

/// The raw counts of a trace at `ranges`, the gaps in its timestamps and the sample rate,
/// ready for [`core_strides_gapped`].
pub fn prepare(
    trace: &Trace,
    ranges: Ranges,
) -> Result<(Vec<RawSample>, Vec<Gap>, SampleRate), ReplayError> {
    let rate = trace
        .sample_rate()
        .ok_or(ReplayError::Rate(trace.rate_hz))?;
    let gaps = gaps::find(&trace.samples, trace.rate_hz)?;
    let counts = trace.samples.iter().map(|s| ranges.to_counts(s)).collect();
    Ok((counts, gaps, rate))
}

/// Replays raw counts through the core configured by `config`.
pub fn replay_counts_with(
    samples: &[RawSample],
    config: Config,
    t_s: impl Fn(u32) -> f64,
) -> Vec<StrideReport> {
    core_strides(samples, config)
        .into_iter()
        .map(|s| report(s, config, &t_s))
        .collect()
}

/// Replays a trace in physical units with the default model.
pub fn replay(trace: &Trace, ranges: Ranges) -> Result<Vec<StrideReport>, ReplayError> {
    replay_model(
        trace,
        ranges,
        Detector::Stance,
        gaitclip::pipeline::DEFAULT_MODEL,
        false,
    )
}

/// Replays a trace in physical units: converts to counts at `ranges` (with saturation)
/// first; `detector` segments it, `model` gives `length_m` (the stance detector's strides;
/// the peak-valley detector's steps are measured by Lu's chain), and with `all_models` every
/// model's length is added (stance detector only: the models need its features).
pub fn replay_model(
    trace: &Trace,
    ranges: Ranges,
    detector: Detector,
    model: Model,
    all_models: bool,
) -> Result<Vec<StrideReport>, ReplayError> {
    let (counts, gaps, rate) = prepare(trace, ranges)?;
    let clock = GapClock::new(&trace.samples, &gaps, trace.rate_hz);
    let mut config = Config::new(rate, ranges.accel, ranges.gyro);
    config.model = model;
    config.detector = detector;
    let mut out: Vec<StrideReport> = core_strides_gapped(&counts, &gaps, config)
        .into_iter()
        .map(|s| report(s, config, &|n| clock.t_s(n)))
        .collect();
    if all_models && detector == Detector::Stance {
        for r in &mut out {
            if r.raw.flags.has(StrideFlags::GAP) {
                // No length across a gap, from any model.
                continue;
            }
            let f = Features::of(&r.raw, rate);
            r.lengths_m = Some(
                Model::ALL
                    .iter()
                    .map(|&m| {
                        let mm = models::predict_mm(m, &f, config.settings, config.params);
                        (m.name(), mm.unwrap_or(0) as f64 / 1000.0)
                    })
                    .collect(),
            );
        }
    }
    Ok(out)
}

fn report(s: Stride, config: Config, t_s: &impl Fn(u32) -> f64) -> StrideReport {
    StrideReport {
        index: s.index,
        start_s: t_s(s.start),
        end_s: t_s(s.end),
        length_m: s.length_mm as f64 / 1000.0,
        model: config.length_model().name(),
        detector: config.detector.name(),
        lengths_m: None,
        zupt_m: s.zupt_um as f64 / 1e6,
        heel_off_s: t_s(s.heel_off),
        toe_off_s: t_s(s.toe_off),
        heel_strike_s: t_s(s.heel_strike),
        foot_flat_s: t_s(s.end),
        climb_m: s.climb_mm as f64 / 1000.0,
        valid: s.flags.valid(),
        flags: flag_names(s.flags),
        raw: s,
    }
}

//! Runs a trace through the firmware core, exactly as the board does, and reports strides
//! in the trace's own clock.

use std::collections::BTreeMap;

use gaitclip::detect::phase_stats::StrideStats;
use gaitclip::detect::step_check::{Rejected, RejectedMovement, Rejection};
use gaitclip::length::features::Features;
use gaitclip::length::models::{self, Model};
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::pipeline::{BetweenTotals, HoleCounts, Pipeline};
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use serde::Serialize;

use crate::io::clock::{Gap, SampleClock, TimeGoesBack};
use crate::io::rails::{self, AxisReport, RailsReport};
use crate::io::trace::{ImuSample, Ranges, Trace};

/// Why a trace cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The rate is outside what the core supports.
    #[error("sample rate {0:.4} Hz is outside 25–1000 Hz{hint}", hint = rate_hint(*.0))]
    Rate(f64),
    /// The trace has no samples.
    #[error("no samples")]
    Empty,
    /// The timestamps go back by more than a re-sent sample's.
    #[error(transparent)]
    Time(#[from] TimeGoesBack),
}

/// Where a rate outside the core's is a sensor's in stamps of the wrong unit (`t_s` in ms
/// or µs, or the rate given in kHz), the hint that says so.
fn rate_hint(hz: f64) -> &'static str {
    let ok = |r: f64| (25.0..=1000.0).contains(&r);
    if ok(hz * 1e3) {
        ": are the stamps in milliseconds? t_s is in seconds"
    } else if ok(hz * 1e6) {
        ": are the stamps in microseconds? t_s is in seconds"
    } else if ok(hz * 1e9) {
        ": are the stamps in nanoseconds? t_s is in seconds"
    } else {
        ""
    }
}

/// What was done to a recording's samples before and while the core measured them: the
/// last line or record of `replay`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Samples read from the file.
    pub samples_read: usize,
    /// Re-sent samples dropped (a repeated stamp).
    pub repeated_dropped: usize,
    /// Holes found in the stamps.
    pub holes: usize,
    /// Sample periods lost in them.
    pub lost_samples: u64,
    /// Holes bridged by interpolation (short enough to measure through), and their samples.
    pub bridged: u32,
    /// Samples interpolated across the bridged holes.
    pub bridged_samples: u32,
    /// Holes that are gaps (strides across them have no length), and their samples.
    pub gaps: u32,
    /// Samples lost in the gaps.
    pub gap_samples: u32,
    /// Of the gaps, those still interpolated so that events outside them are found.
    pub gaps_filled: u32,
    /// Strides reported, and how many of them are valid.
    pub strides: usize,
    /// Valid strides.
    pub valid_strides: usize,
    /// Strides flagged bridged.
    pub bridged_strides: usize,
    /// Gap strides.
    pub gap_strides: usize,
    /// Strides whose length was not measured and is estimated from the strides before them
    /// (they count in the distance).
    pub estimated_strides: usize,
    /// Strides with no length at all: not measured, and nothing measured before them to
    /// estimate from (left out of the distance).
    pub unestimated_strides: usize,
    /// Summed length of the strides that have one (measured, or estimated), m: what the
    /// foot pod's total shows.
    pub distance_m: f64,
    /// Of it, the estimated strides', m.
    pub estimated_distance_m: f64,
    /// Per axis, its rails (learnt or nominal) and the samples at them.
    pub rails: Vec<AxisReport>,
    /// The nominal rate (`--rate`, `meta.json`, or the stamps), Hz.
    pub nominal_rate_hz: f64,
    /// The sensor clock recovered from the stamps: rate, Hz…
    pub clock_rate_hz: f64,
    /// …and the time of the first sample, s.
    pub clock_offset_s: f64,
    /// The rate the core ran at (the clock's, to the millihertz), Hz.
    pub core_rate_hz: f64,
    /// Stamps more than a quarter period off the recovered clock (re-timed onto it).
    pub retimed_stamps: usize,
    /// The farthest a stamp lay from the clock, ms.
    pub max_stamp_offset_ms: f64,
    /// Movements the step check refused (not steps on the ground: they count nowhere), by
    /// reason.
    pub rejected: BTreeMap<&'static str, u32>,
    /// Strides counted without the step check: the detector reported them after the check's
    /// record of their samples was gone (Lu's detector, up to 16 s late).
    pub unchecked_strides: u32,
    /// Time outside the strides that counted: at rest, min…
    pub still_min: f64,
    /// …and moving without a step (cycling, a vehicle, fidgeting, the refused movements), min.
    pub moving_min: f64,
    /// The refused movements one by one (`replay` prints them; not in the summary's JSON).
    #[serde(skip)]
    pub rejected_movements: Vec<RejectedReport>,
}

/// A movement the step check refused, as the host reports it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RejectedReport {
    /// Start, s in the trace's clock.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// Its movement (the detector's heel-off to foot-flat), s.
    pub movement_s: (f64, f64),
    /// Why: [`gaitclip::detect::step_check::Rejection::name`] (`no_rest`, `no_swing`,
    /// `too_long`, `no_stance`).
    pub reason: &'static str,
    /// The foot's largest rotation about its pitch axis in it, degrees.
    pub swing_deg: u16,
    /// That rotation's fastest rate, rad/s.
    pub swing_peak_rad_s: f64,
    /// Whether the foot rested before it, and after it.
    pub rest_before: bool,
    /// See `rest_before`.
    pub rest_after: bool,
    /// How far the detector's integration moved the foot, m.
    pub horizontal_m: f64,
    /// How far it rose, m.
    pub climb_m: f64,
    /// The highest the sensor rose above its start, m.
    pub lift_m: f64,
}

impl Summary {
    /// Adds the counts of `o` (the clock fields are left as they are).
    pub fn add(&mut self, o: &Summary) {
        self.samples_read += o.samples_read;
        self.repeated_dropped += o.repeated_dropped;
        self.holes += o.holes;
        self.lost_samples += o.lost_samples;
        self.bridged += o.bridged;
        self.bridged_samples += o.bridged_samples;
        self.gaps += o.gaps;
        self.gap_samples += o.gap_samples;
        self.gaps_filled += o.gaps_filled;
        self.strides += o.strides;
        self.valid_strides += o.valid_strides;
        self.bridged_strides += o.bridged_strides;
        self.gap_strides += o.gap_strides;
        self.estimated_strides += o.estimated_strides;
        self.unestimated_strides += o.unestimated_strides;
        self.distance_m += o.distance_m;
        self.estimated_distance_m += o.estimated_distance_m;
        if self.rails.is_empty() {
            self.rails = o.rails.clone();
        } else {
            for (a, b) in self.rails.iter_mut().zip(&o.rails) {
                a.clipped += b.clipped;
            }
        }
        self.retimed_stamps += o.retimed_stamps;
        for (k, v) in &o.rejected {
            *self.rejected.entry(k).or_default() += v;
        }
        self.unchecked_strides += o.unchecked_strides;
        self.still_min += o.still_min;
        self.moving_min += o.moving_min;
    }

    /// The summary as one line of text.
    pub fn line(&self) -> String {
        let mut s = format!(
            "summary: {} strides ({} valid, {} bridged, {} gap, {} estimated, {} without a length), {:.3} m ({:.3} m estimated); {} samples read, {} repeated dropped; {} holes ({} samples lost): {} bridged ({} samples), {} left as gaps ({} samples; {} filled for their events); clock {:.4} Hz (nominal {:.4} Hz, {:+.1} ppm), first sample at {:.6} s, core at {:.3} Hz",
            self.strides,
            self.valid_strides,
            self.bridged_strides,
            self.gap_strides,
            self.estimated_strides,
            self.unestimated_strides,
            // `+ 0.0`: an empty sum is −0.0.
            self.distance_m + 0.0,
            self.estimated_distance_m + 0.0,
            self.samples_read,
            self.repeated_dropped,
            self.holes,
            self.lost_samples,
            self.bridged,
            self.bridged_samples,
            self.gaps,
            self.gap_samples,
            self.gaps_filled,
            self.clock_rate_hz,
            self.nominal_rate_hz,
            // No "-0.0 ppm" for a clock on its nominal rate.
            ((self.clock_rate_hz / self.nominal_rate_hz - 1.0) * 1e6 * 10.0).round() / 10.0 + 0.0,
            // No "-0.000000 s" for an offset that is zero to print precision.
            if self.clock_offset_s.abs() < 5e-7 {
                0.0
            } else {
                self.clock_offset_s
            },
            self.core_rate_hz,
        );
        let clipped: Vec<String> = self
            .rails
            .iter()
            .filter(|a| a.clipped > 0)
            .map(|a| format!("{} {}", a.axis, a.clipped))
            .collect();
        s += &format!(
            "; clipped samples: {}",
            if clipped.is_empty() {
                "none".to_string()
            } else {
                clipped.join(", ")
            }
        );
        let refused: u32 = self.rejected.values().sum();
        s += &format!(
            "; not steps: {refused} refused ({}); between strides {:.1} min still, {:.1} min moving",
            self.rejected
                .iter()
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", "),
            self.still_min + 0.0,
            self.moving_min + 0.0
        );
        if self.unchecked_strides > 0 {
            s += &format!(
                " ({} strides reported too late to check)",
                self.unchecked_strides
            );
        }
        if self.core_rate_hz > 0.0 && self.core_rate_hz < LOW_RATE_HZ {
            s += &format!(
                "; warning: {:.1} Hz is below {LOW_RATE_HZ} Hz, where gait events are coarse and lengths untested",
                self.core_rate_hz
            );
        }
        if self.retimed_stamps > 0 {
            s += &format!(
                "; re-timed: {} stamps off the clock by more than a quarter period (at most {:.2} ms)",
                self.retimed_stamps, self.max_stamp_offset_ms
            );
        }
        s
    }
}

/// Below this rate a replay warns: the datasets that check the core run at 100–800 Hz.
pub const LOW_RATE_HZ: f64 = 100.0;

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
    /// The step detector (`cycle`, `stance`, or `lu`: then `heel_off_s`/`toe_off_s` are the step's
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
    /// Foot-flat ending the movement, s (the stance detector's `end_s`; the cycle
    /// detector's stride goes on to the stance instant, `end_s`).
    pub foot_flat_s: f64,
    /// Height gained, m.
    pub climb_m: f64,
    /// One gait cycle, `end_s − start_s` on the sample grid, s (gaitmap's `stride_time`).
    pub stride_time_s: f64,
    /// Ground contact within the cycle, `stride_time − swing_time`, s.
    pub stance_time_s: f64,
    /// Toe-off to heel-strike, s.
    pub swing_time_s: f64,
    /// Stance time per stride time, %.
    pub stance_pct: f64,
    /// Swing time per stride time, %.
    pub swing_pct: f64,
    /// Length per stride time, m/s (gaitmap's `gait_velocity`).
    pub gait_velocity_m_s: f64,
    /// Steps per minute (two per cycle of the instrumented foot).
    pub cadence_spm: u16,
    /// Highest point of the sensor above its start, m (gaitmap's `max_sensor_lift`).
    pub max_sensor_lift_m: f64,
    /// Heading change over the movement, degrees, counter-clockwise seen from above
    /// (gaitmap's `turning_angle`).
    pub turning_angle_deg: f64,
    /// Which way the foot travelled, degrees counter-clockwise seen from above, against the
    /// foot (the sensor's x axis laid level at the stride's start): a backward stride reads
    /// 180° from a forward one, a sideways one 90°; not a compass heading.
    pub travel_deg: f64,
    /// `walking`, `running` (stance under half the cycle) or `unknown` (not one cycle).
    pub gait: &'static str,
    /// The foot's largest one-way rotation about its pitch axis in the movement (the swing;
    /// about any horizontal axis before the pitch axis is learnt), degrees.
    pub swing_deg: u16,
    /// Since the last stride that counted: time at rest, s…
    pub still_before_s: f64,
    /// …and time moving without a step, s.
    pub moving_before_s: f64,
    /// False when the length was not measured or is not to be trusted (see `flags`; an
    /// `estimated` one still counts in the distance).
    pub valid: bool,
    /// Names of the flags set.
    pub flags: Vec<&'static str>,
    /// The core's integer record, as the firmware logs it.
    #[serde(skip)]
    pub raw: Stride,
    /// Its phase statistics (the features' input).
    #[serde(skip)]
    pub stats: StrideStats,
}

/// Every field of a stride's JSON record (`replay --json`, MCAP's `/strides`, Python's
/// columns), in the order it is written, with what it holds: `gaitclip docs` writes the list
/// into docs/host-tool.md, and a test holds it to the serialised record.
pub const STRIDE_FIELDS: [(&str, &str); 30] = [
    ("index", "stride number from 0 (strides that count)"),
    ("start_s", "start: the stance instant the stride leaves, s in the trace's own clock"),
    ("end_s", "end: the next stance instant, s"),
    ("length_m", "length from the model named in `model`, m"),
    ("model", "the length model behind `length_m`"),
    ("detector", "the step detector: `cycle`, `stance` or `lu` (then `heel_off_s`/`toe_off_s` are the step's peak, `heel_strike_s`/`foot_flat_s` its valley)"),
    ("lengths_m", "every model's length, m, by model name (only with `--all-models`)"),
    ("zupt_m", "the strapdown (ZUPT) stride's horizontal displacement, m"),
    ("heel_off_s", "heel-off, the end of the stance's foot-flat, s"),
    ("toe_off_s", "toe-off, s"),
    ("heel_strike_s", "heel-strike, s"),
    ("foot_flat_s", "foot-flat after the heel-strike, s"),
    ("climb_m", "height gained, m"),
    ("stride_time_s", "one gait cycle, `end_s − start_s` on the sample grid, s"),
    ("stance_time_s", "ground contact within the cycle, `stride_time_s − swing_time_s`, s"),
    ("swing_time_s", "toe-off to heel-strike, s"),
    ("stance_pct", "stance time per stride time, %"),
    ("swing_pct", "swing time per stride time, %"),
    ("gait_velocity_m_s", "length per stride time, m/s"),
    ("cadence_spm", "steps per minute (two per cycle of the instrumented foot)"),
    ("max_sensor_lift_m", "highest point of the sensor above its start, m"),
    ("turning_angle_deg", "heading change over the movement, degrees, counter-clockwise seen from above"),
    ("travel_deg", "direction of travel against the foot (the sensor's x axis laid level), degrees, counter-clockwise: backward 180° from forward, sideways 90°"),
    ("gait", "`walking`, `running`, `stairs_up`, `stairs_down` or `unknown`"),
    ("swing_deg", "the foot's largest one-way rotation about its pitch axis in the movement, degrees"),
    ("still_before_s", "since the last stride that counted: time at rest, s"),
    ("moving_before_s", "since the last stride that counted: time moving without a step, s"),
    ("valid", "false when the length was not measured or is not to be trusted (an `estimated` one still counts in the distance)"),
    ("flags", "names of the flags set (docs/output.md lists them)"),
    ("rejected", "not a stride field: a `{\"rejected\": …}` line is a movement the step check refused, with its `reason`"),
];

/// docs/host-tool.md's list of the JSON fields ([`STRIDE_FIELDS`]), as Markdown.
pub fn fields_report(_datasets: &std::path::Path) -> anyhow::Result<String> {
    Ok(STRIDE_FIELDS
        .iter()
        .map(|(name, what)| format!("- `{name}`: {what}\n"))
        .collect())
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
    if f.has(StrideFlags::BRIDGED) {
        v.push("bridged");
    }
    if f.has(StrideFlags::GYRO_CLIPPED) {
        v.push("gyro_clipped");
    }
    if f.has(StrideFlags::ACCEL_CLIPPED) {
        v.push("accel_clipped");
    }
    if f.has(StrideFlags::ESTIMATED) {
        v.push("estimated");
    }
    if f.has(StrideFlags::SEVERAL_CYCLES) {
        v.push("several_cycles");
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
    let config = Config::new(rate, ranges.accel.scale(), ranges.gyro.scale());
    replay_counts_with(samples, config, t_s)
}

/// The core's strides for raw counts without gaps, in the order it reports them.
pub fn core_strides(samples: &[RawSample], config: Config) -> Vec<Stride> {
    core_strides_gapped(samples, &[], config)
}

/// The core's strides for raw counts with `gaps` (sorted by position) declared to it as
/// the firmware declares a FIFO overflow.
pub fn core_strides_gapped(samples: &[RawSample], gaps: &[Gap], config: Config) -> Vec<Stride> {
    core_run(samples, gaps, config).0
}

/// [`core_strides_gapped`], and what the core did with the holes.
pub fn core_run(samples: &[RawSample], gaps: &[Gap], config: Config) -> (Vec<Stride>, HoleCounts) {
    let (strides, holes) = core_run_with_stats(samples, gaps, config);
    (strides.into_iter().map(|(s, _)| s).collect(), holes)
}

/// [`core_run`], each stride with its phase statistics (the features' input; empty for a
/// gap stride or a peak-valley step), taken from the pipeline as it hands the stride out.
pub fn core_run_with_stats(
    samples: &[RawSample],
    gaps: &[Gap],
    config: Config,
) -> (Vec<(Stride, StrideStats)>, HoleCounts) {
    let r = core_run_full(samples, gaps, config);
    (r.strides, r.holes)
}

/// Everything a run of the core gives: the strides with their phase statistics, the holes,
/// the movements the step check refused (each, and counted) and the time outside the
/// strides.
#[derive(Clone, Debug, Default)]
pub struct CoreRun {
    /// The strides and their statistics.
    pub strides: Vec<(Stride, StrideStats)>,
    /// What was done with the holes.
    pub holes: HoleCounts,
    /// The refused movements, as the pipeline handed them out.
    pub rejected: Vec<RejectedMovement>,
    /// Refused movements, counted by reason.
    pub rejected_counts: Rejected,
    /// Time outside the strides, still and moving.
    pub between: BetweenTotals,
    /// Strides the detector could not hand out (none by construction).
    pub dropped: u32,
}

/// [`core_run_with_stats`] and the rest of what the pipeline tells ([`CoreRun`]).
pub fn core_run_full(samples: &[RawSample], gaps: &[Gap], config: Config) -> CoreRun {
    let mut strides = Vec::new();
    let mut r = core_run_each(samples.iter().copied(), gaps, config, |s, stats| {
        strides.push((s, stats))
    });
    r.strides = strides;
    r
}

/// [`core_run_full`] over counts read as a stream: each stride, with its phase statistics,
/// goes to `stride` as the pipeline hands it out; the run returned holds everything else
/// (its `strides` empty).
pub fn core_run_each(
    samples: impl Iterator<Item = RawSample>,
    gaps: &[Gap],
    config: Config,
    mut stride: impl FnMut(Stride, StrideStats),
) -> CoreRun {
    let mut p = Pipeline::new(config);
    let mut r = CoreRun::default();
    let mut out = |p: &Pipeline, s: Stride| stride(s, p.stats(&s).copied().unwrap_or_default());
    let mut next_gap = gaps.iter().peekable();
    for (i, s) in samples.enumerate() {
        while let Some(g) = next_gap.next_if(|g| g.before <= i) {
            if let Some(st) = p.gap(g.missing) {
                out(&p, st);
            }
            r.rejected.extend(p.take_rejected());
        }
        if let Some(st) = p.process(&s) {
            out(&p, st);
        }
        r.rejected.extend(p.take_rejected());
    }
    loop {
        let st = p.finish();
        r.rejected.extend(p.take_rejected());
        match st {
            Some(st) => out(&p, st),
            None => break,
        }
    }
    r.holes = p.holes();
    r.rejected_counts = p.rejected();
    r.between = p.between();
    r.dropped = gaitclip::detect::seam::StepDetector::dropped(p.detector());
    r
}

/// The summary's counts of the strides, taken one by one in the order the core hands them
/// out (the distance summed in that order).
#[derive(Clone, Copy, Debug)]
pub struct StrideTally {
    strides: usize,
    valid: usize,
    bridged: usize,
    gap: usize,
    estimated: usize,
    unestimated: usize,
    distance_m: f64,
    estimated_distance_m: f64,
}

impl Default for StrideTally {
    /// No stride: the sums start where `Iterator::sum` of `f64` starts (−0.0), so that an
    /// empty recording reports what it reported when the strides were summed in a list.
    fn default() -> Self {
        StrideTally {
            strides: 0,
            valid: 0,
            bridged: 0,
            gap: 0,
            estimated: 0,
            unestimated: 0,
            distance_m: -0.0,
            estimated_distance_m: -0.0,
        }
    }
}

impl StrideTally {
    /// Counts stride `s`.
    pub fn add(&mut self, s: &Stride) {
        self.strides += 1;
        self.valid += usize::from(s.flags.valid());
        self.bridged += usize::from(s.flags.has(StrideFlags::BRIDGED));
        self.gap += usize::from(s.flags.has(StrideFlags::GAP));
        self.estimated += usize::from(s.flags.has(StrideFlags::ESTIMATED));
        self.unestimated += usize::from(!s.flags.counts_distance());
        if s.flags.counts_distance() {
            self.distance_m += s.length_mm as f64 / 1000.0;
        }
        if s.flags.has(StrideFlags::ESTIMATED) {
            self.estimated_distance_m += s.length_mm as f64 / 1000.0;
        }
    }
}

/// What a summary says of a recording besides its strides: how it was read and prepared.
#[derive(Clone, Debug)]
pub struct Preparation<'a> {
    /// Rows read and re-sent samples dropped.
    pub read: (usize, usize),
    /// The recovered clock.
    pub clock: &'a SampleClock,
    /// The rails.
    pub rails: &'a RailsReport,
    /// The nominal rate, Hz.
    pub nominal_hz: f64,
    /// The core's rate.
    pub rate: SampleRate,
}

impl Preparation<'_> {
    /// The summary of `run` (its strides counted in `tally`).
    pub fn summary(&self, run: &CoreRun, tally: &StrideTally) -> Summary {
        let h = run.holes;
        let clock = self.clock;
        Summary {
            samples_read: self.read.0,
            repeated_dropped: self.read.1,
            holes: clock.holes.len(),
            lost_samples: clock.lost(),
            bridged: h.bridged,
            bridged_samples: h.bridged_samples,
            gaps: h.gaps(),
            gap_samples: h.gap_samples(),
            gaps_filled: h.filled,
            strides: tally.strides,
            valid_strides: tally.valid,
            bridged_strides: tally.bridged,
            gap_strides: tally.gap,
            estimated_strides: tally.estimated,
            unestimated_strides: tally.unestimated,
            distance_m: tally.distance_m,
            estimated_distance_m: tally.estimated_distance_m,
            rails: self.rails.axes.clone(),
            nominal_rate_hz: self.nominal_hz,
            clock_rate_hz: clock.rate_hz(),
            clock_offset_s: clock.offset_s,
            core_rate_hz: self.rate.millihertz() as f64 / 1000.0,
            retimed_stamps: clock.retimed,
            max_stamp_offset_ms: clock.max_offclock_s * 1e3,
            rejected: Rejection::ALL
                .iter()
                .map(|r| (r.name(), run.rejected_counts.by_reason[*r as usize]))
                .collect(),
            unchecked_strides: run.rejected_counts.unchecked,
            still_min: run.between.still_ms as f64 / 60_000.0,
            moving_min: run.between.moving_ms as f64 / 60_000.0,
            rejected_movements: run
                .rejected
                .iter()
                .map(|m| RejectedReport {
                    start_s: clock.t_s(m.start),
                    end_s: clock.t_s(m.end),
                    movement_s: (clock.t_s(m.movement.0), clock.t_s(m.movement.1)),
                    reason: m.reason.name(),
                    swing_deg: m.swing_deg,
                    swing_peak_rad_s: m.swing_peak_mradps as f64 / 1000.0,
                    rest_before: m.rest.0,
                    rest_after: m.rest.1,
                    horizontal_m: m.horizontal_mm as f64 / 1000.0,
                    climb_m: m.climb_mm as f64 / 1000.0,
                    lift_m: m.lift_mm as f64 / 1000.0,
                })
                .collect(),
        }
    }
}

/// A trace made ready for the core: its counts, its recovered sample clock (with the holes
/// in its stamps) and the core's rate (the clock's, to the millihertz).
#[derive(Clone, Debug)]
pub struct Prepared {
    /// Counts at the ranges asked for, one per row (re-sent samples dropped).
    pub counts: Vec<RawSample>,
    /// The sensor clock.
    pub clock: SampleClock,
    /// The rate the core runs at.
    pub rate: SampleRate,
    /// Where each axis clipped ([`crate::io::rails`]), and how often.
    pub rails: RailsReport,
    /// Rows read and re-sent samples dropped.
    read: (usize, usize),
    nominal_hz: f64,
}

impl Prepared {
    /// The core's strides with `config`, the holes declared where the clock found them.
    pub fn strides(&self, config: Config) -> Vec<Stride> {
        core_strides_gapped(&self.counts, &self.clock.holes, config)
    }

    /// [`Prepared::strides`] with their phase statistics.
    pub fn strides_with_stats(&self, config: Config) -> Vec<(Stride, StrideStats)> {
        core_run_with_stats(&self.counts, &self.clock.holes, config).0
    }

    /// [`Prepared::strides_with_stats`] and the summary of what was done to the samples.
    pub fn run(&self, config: Config) -> (Vec<(Stride, StrideStats)>, Summary) {
        let mut run = core_run_full(&self.counts, &self.clock.holes, config);
        let strides = std::mem::take(&mut run.strides);
        let mut tally = StrideTally::default();
        strides.iter().for_each(|(s, _)| tally.add(s));
        let summary = Preparation {
            read: self.read,
            clock: &self.clock,
            rails: &self.rails,
            nominal_hz: self.nominal_hz,
            rate: self.rate,
        }
        .summary(&run, &tally);
        (strides, summary)
    }

    /// The default configuration at the core's rate and `ranges`, with the recording's
    /// rails.
    pub fn config(&self, ranges: Ranges) -> Config {
        let mut c = Config::new(self.rate, ranges.accel.scale(), ranges.gyro.scale());
        c.rails = self.rails.rails;
        c
    }
}

/// A trace ready for the core ([`Prepared`]): converted to counts at `ranges`, its sample
/// clock recovered from its stamps ([`crate::io::clock`]).
pub fn prepare(trace: &Trace, ranges: Ranges) -> Result<Prepared, ReplayError> {
    // Re-sent samples dropped; the trace's own samples when there are none (most).
    let (samples, repeated) = match Trace::repeats_kept(&trace.samples, Some(trace.rate_hz))? {
        None => (std::borrow::Cow::Borrowed(&trace.samples[..]), 0),
        Some(keep) => {
            let dropped = trace.samples.len() - keep.len();
            let kept: Vec<ImuSample> = keep.into_iter().map(|i| trace.samples[i]).collect();
            (std::borrow::Cow::Owned(kept), dropped)
        }
    };
    let stamps: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    let mut clock = SampleClock::recover(&stamps, Some(trace.rate_hz)).ok_or(ReplayError::Empty)?;
    let mhz = (clock.rate_hz() * 1000.0).round();
    let rate = SampleRate::from_millihertz(mhz.clamp(0.0, u32::MAX as f64) as u32)
        .ok_or(ReplayError::Rate(clock.rate_hz()))?;
    let counts: Vec<RawSample> = samples.iter().map(ranges.converter()).collect();
    let rails = rails::learn_counted(&samples, &counts, ranges, trace.given);
    // Holes inside a host's bursts, placed by the angular rate.
    clock.place_holes(&stamps, |row| counts[row].gyro.map(|v| v as f64));
    Ok(Prepared {
        counts,
        clock,
        rate,
        rails,
        read: (
            trace.samples.len() + trace.repeated,
            trace.repeated + repeated,
        ),
        nominal_hz: trace.rate_hz,
    })
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
        Detector::Cycle,
        gaitclip::pipeline::config::DEFAULT_MODEL,
        false,
    )
}

/// Replays a trace in physical units: converts to counts at `ranges` (with saturation)
/// first; `detector` segments it, `model` gives `length_m` (the cycle and stance detectors'
/// strides; the peak-valley detector's steps are measured by Lu's chain), and with
/// `all_models` every model's length is added (not for peak-valley steps: the models need
/// the phases' features).
pub fn replay_model(
    trace: &Trace,
    ranges: Ranges,
    detector: Detector,
    model: Model,
    all_models: bool,
) -> Result<Vec<StrideReport>, ReplayError> {
    Ok(replay_summarised(trace, ranges, detector, model, all_models)?.0)
}

/// [`replay_model`], with the summary of what was done to the samples.
pub fn replay_summarised(
    trace: &Trace,
    ranges: Ranges,
    detector: Detector,
    model: Model,
    all_models: bool,
) -> Result<(Vec<StrideReport>, Summary), ReplayError> {
    let (strides, summary, _) = replay_clocked(trace, ranges, detector, model, all_models)?;
    Ok((strides, summary))
}

/// [`replay_summarised`], with the sensor clock the replay recovered (its sample numbers are
/// the strides' `raw.events`; [`SampleClock::row_of_number`] maps them to the trace's rows).
pub fn replay_clocked(
    trace: &Trace,
    ranges: Ranges,
    detector: Detector,
    model: Model,
    all_models: bool,
) -> Result<(Vec<StrideReport>, Summary, SampleClock), ReplayError> {
    let prepared = prepare(trace, ranges)?;
    let rate = prepared.rate;
    let mut config = prepared.config(ranges);
    config.model = model;
    config.detector = detector;
    let (strides, summary) = prepared.run(config);
    let clock = &prepared.clock;
    let mut out: Vec<StrideReport> = strides
        .into_iter()
        .map(|(s, stats)| StrideReport {
            stats,
            ..report(s, config, &|n| clock.t_s(n))
        })
        .collect();
    if all_models && detector != Detector::PeakValley {
        for r in &mut out {
            add_all_models(r, config, rate);
        }
    }
    Ok((out, summary, prepared.clock))
}

/// Every model's length of `r` (`lengths_m`), from its features at `rate` with `config`; none
/// across a gap.
pub fn add_all_models(r: &mut StrideReport, config: Config, rate: SampleRate) {
    if r.raw.flags.has(StrideFlags::GAP) {
        // No length across a gap, from any model.
        return;
    }
    let f = Features::of(&r.raw, &r.stats, rate);
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

/// The host's report of a core stride `s` made with `config`, times by `t_s` (sample number to
/// the trace's clock).
pub fn report(s: Stride, config: Config, t_s: &impl Fn(u32) -> f64) -> StrideReport {
    StrideReport {
        index: s.index,
        start_s: t_s(s.events.start),
        end_s: t_s(s.events.end),
        length_m: s.length_mm as f64 / 1000.0,
        model: config.length_model().name(),
        detector: config.detector.name(),
        lengths_m: None,
        zupt_m: s.zupt_um as f64 / 1e6,
        heel_off_s: t_s(s.events.heel_off),
        toe_off_s: t_s(s.events.toe_off),
        heel_strike_s: t_s(s.events.heel_strike),
        foot_flat_s: t_s(s.events.foot_flat),
        climb_m: s.climb_mm as f64 / 1000.0,
        stride_time_s: s.gait.stride_time_ms as f64 / 1000.0,
        stance_time_s: s.gait.stance_time_ms as f64 / 1000.0,
        swing_time_s: s.gait.swing_time_ms as f64 / 1000.0,
        stance_pct: s.gait.stance_permille as f64 / 10.0,
        swing_pct: s.gait.swing_permille as f64 / 10.0,
        gait_velocity_m_s: s.gait.gait_velocity_mm_s as f64 / 1000.0,
        cadence_spm: s.gait.cadence_spm,
        max_sensor_lift_m: s.max_sensor_lift_mm as f64 / 1000.0,
        turning_angle_deg: s.turning_angle_cdeg as f64 / 100.0,
        travel_deg: s.travel_cdeg as f64 / 100.0,
        gait: s.gait.gait.name(),
        swing_deg: s.swing_deg,
        still_before_s: s.between.still_ms as f64 / 1000.0,
        moving_before_s: s.between.moving_ms as f64 / 1000.0,
        valid: s.flags.valid(),
        flags: flag_names(s.flags),
        raw: s,
        stats: StrideStats::EMPTY,
    }
}

//! `gaitclip eval`: strides, gait events, phases and stance against the ground truth of the
//! recordings in `../shared/datasets`.
//!
//! **Clock.** Everything is compared in the sensor clock's sample numbers, which the core
//! counts (rows plus the periods lost in holes, [`crate::clock`]): a reference given as a
//! row is mapped to its number, a reference given as a time (`ipol_gait_events`'
//! `toe_off_s`/`heel_strike_s`, the walk bounds `walk_*_s`) to the number nearest it on the
//! recovered clock. Event errors are then whole periods of the sensor, unaffected by holes.
//!
//! **Matching.** A detected stride is its movement, heel-off to foot-flat. A reference stride
//! is the interval its dataset defines (`gaitmap_walk`: mid-stance to mid-stance;
//! `pyshoe_vicon`: end of stance to end of stance; `ipol_gait_events`: the footstep, toe-off
//! to heel-strike). Each contains the foot's one movement, so a detection matches a
//! reference when their overlap is at least half the shorter of the two; pairs are taken
//! greedily by overlap, one to one. Only detections overlapping the labelled part of a
//! recording count (from the first to the last reference stride; `ipol_gait_events`: its
//! walk bounds). Flagged references (first/last strides, turns, shuffles, U-turn steps) and
//! the detections matched to them or lying mostly (half their movement or more) inside one
//! count neither as found nor as missed nor as extra (*not scored*); so do detections mostly
//! inside `ipol_gait_events`' U-turn, whose steps are labelled only in part. A detection
//! matched to nothing that `pyshoe_vicon`'s Vicon stance label shows to be a movement of the
//! foot (moving over half of it or more: a shuffle, or a stride inside borders that merged
//! two) is counted apart as an *unbordered movement*, not as extra: the stride borders of
//! that dataset were drawn in part by an automatic detector.
//!
//! **Events.** Toe-off and heel-strike errors are detected minus reference, over clean
//! matched strides, reported as the median and 95th percentile of their absolute value.
//!
//! **Phases** (Huang eq. 7–13). Swing is toe-off → heel-strike; contact is the previous
//! heel-strike → toe-off (heel-strike phase, stance and push-off together, which is what the
//! labels bound). A detected phase is a true positive when its IoU with the reference phase
//! of the matched stride is at least 0.5; the IoU column is the mean over true positives.
//!
//! **Stance** (`pyshoe_vicon`): sample-wise F1 of "not inside a detected movement" against
//! the Vicon stance label, over the labelled part of each trial.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use crate::clock::SampleClock;
use crate::csv_trace;
use crate::trace::{ImuSample, Ranges, Trace};

/// One detected stride, in sample indices of its trial.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Detected {
    /// Start of the stance before the movement.
    pub start: u32,
    /// Heel-off.
    pub heel_off: u32,
    /// Toe-off.
    pub toe_off: u32,
    /// Heel-strike.
    pub heel_strike: u32,
    /// Foot-flat: the movement's end.
    pub foot_flat: u32,
    /// The stride's end (the next stride's start).
    pub end: u32,
    /// The movement overflowed the movement buffer ([`gaitclip::stride::StrideFlags::TOO_LONG`]):
    /// strides merged.
    pub too_long: bool,
}

impl From<&gaitclip::stride::Stride> for Detected {
    fn from(s: &gaitclip::stride::Stride) -> Self {
        Detected {
            start: s.start,
            heel_off: s.heel_off,
            toe_off: s.toe_off,
            heel_strike: s.heel_strike,
            foot_flat: s.foot_flat,
            end: s.end,
            too_long: s.flags.0 & gaitclip::stride::StrideFlags::TOO_LONG != 0,
        }
    }
}

impl Detected {
    /// The stride with every event index mapped by `f` (core sample numbers to recording
    /// indices across gaps).
    pub fn map(self, f: impl Fn(u32) -> u32) -> Self {
        Detected {
            start: f(self.start),
            heel_off: f(self.heel_off),
            toe_off: f(self.toe_off),
            heel_strike: f(self.heel_strike),
            foot_flat: f(self.foot_flat),
            end: f(self.end),
            too_long: self.too_long,
        }
    }
}

/// Times of a reference's events, s, where the dataset gives them (they override the
/// rows when mapped to sample numbers).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceTimes {
    /// Start of the interval holding the stride's movement.
    pub start_s: Option<f64>,
    /// Its end.
    pub end_s: Option<f64>,
    /// Toe-off.
    pub toe_off_s: Option<f64>,
    /// Heel-strike ending the swing.
    pub heel_strike_s: Option<f64>,
    /// Heel-strike that began the stride's ground contact.
    pub prev_heel_strike_s: Option<f64>,
}

/// One reference stride (rows of the trial's CSV; [`Reference::in_numbers`] maps them to the
/// sensor clock's sample numbers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Interval that contains the stride's movement.
    pub start: u32,
    /// End of that interval.
    pub end: u32,
    /// Not clean straight walking: neither counted nor missed.
    pub flagged: bool,
    /// Toe-off, where labelled.
    pub toe_off: Option<u32>,
    /// Heel-strike ending the swing, where labelled.
    pub heel_strike: Option<u32>,
    /// Heel-strike that began the stride's ground contact, where labelled.
    pub prev_heel_strike: Option<u32>,
    /// Reference stride length, m, where the dataset has one.
    pub length_m: Option<f64>,
    /// Event times, where the dataset gives them.
    pub times: ReferenceTimes,
}

impl Reference {
    /// The reference in sample numbers of `clock`: events given as times go to the nearest
    /// number, the others from their rows.
    pub fn in_numbers(&self, clock: &SampleClock) -> Reference {
        let row = |r: u32| clock.number_of_row(r as usize);
        let event = |t: Option<f64>, r: Option<u32>| match t {
            Some(t) => Some(clock.number_at(t)),
            None => r.map(row),
        };
        Reference {
            start: event(self.times.start_s, Some(self.start)).unwrap_or(0),
            end: event(self.times.end_s, Some(self.end)).unwrap_or(0),
            toe_off: event(self.times.toe_off_s, self.toe_off),
            heel_strike: event(self.times.heel_strike_s, self.heel_strike),
            prev_heel_strike: event(self.times.prev_heel_strike_s, self.prev_heel_strike),
            ..*self
        }
    }
}

/// One recording and its ground truth.
#[derive(Clone, Debug)]
pub struct Trial {
    /// Name as the dataset gives it.
    pub name: String,
    /// The trial's CSV.
    pub csv: PathBuf,
    /// Reference strides.
    pub references: Vec<Reference>,
    /// Labelled part of the recording, rows `[from, to)`.
    pub span: (u32, u32),
    /// The same bounds as times, s, where the dataset gives them (they override the rows).
    pub span_s: Option<(f64, f64)>,
    /// A part of the span whose steps are not labelled one by one, s (`ipol_gait_events`'
    /// U-turn): detections lying mostly inside it are not scored.
    pub unscored_s: Option<(f64, f64)>,
    /// Per-sample stance label, where the dataset has one.
    pub stance: Option<Vec<bool>>,
    /// The walker's height, m, where the dataset gives it.
    pub height_m: Option<f64>,
    /// Distance walked over `span`, m, where the dataset gives it (not per stride).
    pub distance_m: Option<f64>,
}

/// A dataset folder.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// Folder name (`gaitmap_walk`, …).
    pub name: String,
    /// Nominal sample rate, Hz.
    pub rate_hz: f64,
    /// Its trials.
    pub trials: Vec<Trial>,
}

#[derive(Deserialize)]
struct Meta {
    name: String,
    sample_rate_hz: f64,
}

fn read_rows(path: &Path) -> Result<Vec<BTreeMap<String, String>>> {
    let mut r = csv::Reader::from_path(path).with_context(|| format!("{}", path.display()))?;
    let mut out = Vec::new();
    for row in r.deserialize() {
        out.push(row.with_context(|| format!("{}", path.display()))?);
    }
    Ok(out)
}

fn field<'a>(row: &'a BTreeMap<String, String>, k: &str, path: &Path) -> Result<&'a str> {
    row.get(k)
        .map(String::as_str)
        .with_context(|| format!("{}: no column `{k}`", path.display()))
}

fn index(row: &BTreeMap<String, String>, k: &str, path: &Path) -> Result<u32> {
    let v = field(row, k, path)?;
    v.trim()
        .parse()
        .with_context(|| format!("{}: `{k}` = {v:?} is not an index", path.display()))
}

/// Loads a dataset folder of `../shared/datasets` (its layout is described there).
pub fn load(dir: &Path) -> Result<Dataset> {
    let meta_path = dir.join("meta.json");
    let meta: Meta = serde_json::from_slice(
        &std::fs::read(&meta_path).with_context(|| format!("{}", meta_path.display()))?,
    )
    .with_context(|| format!("{}", meta_path.display()))?;
    let trials = match meta.name.as_str() {
        "gaitmap_walk" | "pyshoe_vicon" => load_strides(dir, &meta.name)?,
        "ipol_gait_events" => load_ipol(dir)?,
        other => bail!("{}: unknown dataset {other:?}", dir.display()),
    };
    Ok(Dataset {
        name: meta.name,
        rate_hz: meta.sample_rate_hz,
        trials,
    })
}

fn load_strides(dir: &Path, name: &str) -> Result<Vec<Trial>> {
    let path = dir.join("strides.csv");
    let mut by_trial: BTreeMap<String, Vec<Reference>> = BTreeMap::new();
    for row in read_rows(&path)? {
        let opt = |k: &str| -> Result<Option<u32>> {
            match row.get(k) {
                Some(_) => index(&row, k, &path).map(Some),
                None => Ok(None),
            }
        };
        let r = Reference {
            start: index(&row, "start_idx", &path)?,
            end: index(&row, "end_idx", &path)?,
            flagged: !field(&row, "flag", &path)?.trim().is_empty(),
            toe_off: opt("tc_idx")?,
            heel_strike: opt("ic_idx")?,
            prev_heel_strike: opt("pre_ic_idx")?,
            length_m: Some(
                field(&row, "length_m", &path)?
                    .trim()
                    .parse()
                    .with_context(|| format!("{}: length_m is not a number", path.display()))?,
            ),
            times: ReferenceTimes::default(),
        };
        by_trial
            .entry(field(&row, "trial", &path)?.to_string())
            .or_default()
            .push(r);
    }
    let mut trials = Vec::new();
    for (trial, references) in by_trial {
        let span = (
            references.iter().map(|r| r.start).min().unwrap_or(0),
            references.iter().map(|r| r.end).max().unwrap_or(0),
        );
        let stance = if name == "pyshoe_vicon" {
            let p = dir.join(format!("{trial}.reference.csv"));
            let mut v = Vec::new();
            for row in read_rows(&p)? {
                v.push(field(&row, "stance_vicon", &p)?.trim() == "1");
            }
            Some(v)
        } else {
            None
        };
        trials.push(Trial {
            csv: dir.join(format!("{trial}.csv")),
            name: trial,
            references,
            span,
            span_s: None,
            stance,
            unscored_s: None,
            height_m: None,
            distance_m: None,
        });
    }
    Ok(trials)
}

fn load_ipol(dir: &Path) -> Result<Vec<Trial>> {
    let tpath = dir.join("trials.csv");
    let mut spans = BTreeMap::new();
    let number = |row: &BTreeMap<String, String>, k: &str| -> Result<f64> {
        let v = field(row, k, &tpath)?;
        v.trim()
            .parse()
            .with_context(|| format!("{}: `{k}` = {v:?} is not a number", tpath.display()))
    };
    for row in read_rows(&tpath)? {
        spans.insert(
            field(&row, "trial", &tpath)?.to_string(),
            (
                (
                    index(&row, "walk_start_idx", &tpath)?,
                    index(&row, "walk_end_idx", &tpath)?,
                ),
                (number(&row, "walk_start_s")?, number(&row, "walk_end_s")?),
                (number(&row, "uturn_start_s")?, number(&row, "uturn_end_s")?),
                // Some subjects' heights are not given: left empty.
                match field(&row, "height_m", &tpath)?.trim() {
                    "" => None,
                    _ => Some(number(&row, "height_m")?),
                },
                number(&row, "distance_m")?,
            ),
        );
    }
    let epath = dir.join("events.csv");
    let mut by_trial: BTreeMap<(String, String), Vec<(u32, Reference)>> = BTreeMap::new();
    let seconds = |row: &BTreeMap<String, String>, k: &str| -> Result<f64> {
        let v = field(row, k, &epath)?;
        v.trim()
            .parse()
            .with_context(|| format!("{}: `{k}` = {v:?} is not a number", epath.display()))
    };
    for row in read_rows(&epath)? {
        let to = index(&row, "toe_off_idx", &epath)?;
        let hs = index(&row, "heel_strike_idx", &epath)?;
        let r = Reference {
            start: to,
            end: hs,
            flagged: field(&row, "in_uturn", &epath)?.trim() == "True",
            toe_off: Some(to),
            heel_strike: Some(hs),
            prev_heel_strike: None,
            length_m: None,
            times: {
                let (to_s, hs_s) = (seconds(&row, "toe_off_s")?, seconds(&row, "heel_strike_s")?);
                ReferenceTimes {
                    start_s: Some(to_s),
                    end_s: Some(hs_s),
                    toe_off_s: Some(to_s),
                    heel_strike_s: Some(hs_s),
                    prev_heel_strike_s: None,
                }
            },
        };
        let key = (
            field(&row, "trial", &epath)?.to_string(),
            field(&row, "foot", &epath)?.to_string(),
        );
        by_trial
            .entry(key)
            .or_default()
            .push((index(&row, "step", &epath)?, r));
    }
    let mut trials = Vec::new();
    for ((trial, foot), mut steps) in by_trial {
        steps.sort_by_key(|s| s.0);
        let mut references: Vec<Reference> = steps.into_iter().map(|s| s.1).collect();
        for k in 1..references.len() {
            references[k].prev_heel_strike = references[k - 1].heel_strike;
            references[k].times.prev_heel_strike_s = references[k - 1].times.heel_strike_s;
        }
        let (span, span_s, uturn_s, height, distance) = *spans
            .get(&trial)
            .with_context(|| format!("{}: no trial {trial}", tpath.display()))?;
        trials.push(Trial {
            csv: dir.join(format!("{trial}_{foot}.csv")),
            name: format!("{trial}_{foot}"),
            references,
            // The rows are the left foot's: the right foot's file has its own holes.
            span,
            span_s: Some(span_s),
            unscored_s: Some(uturn_s),
            stance: None,
            height_m: height,
            distance_m: Some(distance),
        });
    }
    Ok(trials)
}

/// Everything counted over trials.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Trials.
    pub trials: usize,
    /// Clean reference strides.
    pub clean: usize,
    /// Matched clean strides.
    pub tp: usize,
    /// Detections matched to nothing.
    pub fp: usize,
    /// Clean references matched to nothing.
    pub fn_: usize,
    /// Detections not scored, neither found nor extra: matched to a flagged reference or
    /// lying mostly inside one, or inside a part not labelled step by step (a U-turn).
    pub unscored: usize,
    /// Detections matched to no reference that the dataset's own motion capture shows to be
    /// a movement of the foot (`pyshoe_vicon`'s stance label says "moving" over at least half
    /// of it): a movement the stride borders leave out (a shuffle, a merged stride), not a
    /// false detection. Counted here, not as extra.
    pub unbordered: usize,
    /// Toe-off errors, ms.
    pub toe_off_ms: Vec<f64>,
    /// Heel-strike errors, ms.
    pub heel_strike_ms: Vec<f64>,
    /// Swing phase: (tp, fp, fn, IoUs of the true positives).
    pub swing: PhaseTally,
    /// Contact phase.
    pub contact: PhaseTally,
    /// Stance samples: (tp, fp, fn).
    pub stance: Option<(u64, u64, u64)>,
    /// Stance instants (stride starts) inside a labelled stance, and all of them.
    pub instants: Option<(usize, usize)>,
    /// Detections overlapping the labelled span (Lu's `E`).
    pub detected: usize,
    /// Detections flagged too long (a movement longer than the buffer: strides merged),
    /// anywhere in the recordings.
    pub too_long: usize,
    /// Reference strides, flagged ones included (Lu's `T`).
    pub references: usize,
    /// Per trial, Lu's eq. 13 step-count error `|E − T| / T`.
    pub count_errors: Vec<f64>,
}

/// Counts for one phase.
#[derive(Clone, Debug, Default)]
pub struct PhaseTally {
    /// True positives.
    pub tp: usize,
    /// False positives.
    pub fp: usize,
    /// False negatives.
    pub fn_: usize,
    /// IoU of each true positive.
    pub iou: Vec<f64>,
    /// Whether the dataset labels this phase.
    pub labelled: bool,
}

impl PhaseTally {
    fn add(&mut self, o: &PhaseTally) {
        self.tp += o.tp;
        self.fp += o.fp;
        self.fn_ += o.fn_;
        self.iou.extend_from_slice(&o.iou);
        self.labelled |= o.labelled;
    }

    /// Huang's F-score (eq. 9).
    pub fn f_score(&self) -> f64 {
        f1(self.tp as f64, self.fp as f64, self.fn_ as f64)
    }

    /// Mean IoU of the true positives (eq. 10).
    pub fn mean_iou(&self) -> f64 {
        mean(&self.iou)
    }
}

impl Tally {
    /// Adds another tally into this one.
    pub fn add(&mut self, o: &Tally) {
        self.trials += o.trials;
        self.clean += o.clean;
        self.tp += o.tp;
        self.fp += o.fp;
        self.fn_ += o.fn_;
        self.unscored += o.unscored;
        self.unbordered += o.unbordered;
        self.toe_off_ms.extend_from_slice(&o.toe_off_ms);
        self.heel_strike_ms.extend_from_slice(&o.heel_strike_ms);
        self.swing.add(&o.swing);
        self.contact.add(&o.contact);
        self.detected += o.detected;
        self.too_long += o.too_long;
        self.references += o.references;
        self.count_errors.extend_from_slice(&o.count_errors);
        self.stance = match (self.stance, o.stance) {
            (Some(a), Some(b)) => Some((a.0 + b.0, a.1 + b.1, a.2 + b.2)),
            (a, b) => a.or(b),
        };
        self.instants = match (self.instants, o.instants) {
            (Some(a), Some(b)) => Some((a.0 + b.0, a.1 + b.1)),
            (a, b) => a.or(b),
        };
    }

    /// Stride precision.
    pub fn precision(&self) -> f64 {
        ratio(self.tp as f64, (self.tp + self.fp) as f64)
    }

    /// Stride recall.
    pub fn recall(&self) -> f64 {
        ratio(self.tp as f64, (self.tp + self.fn_) as f64)
    }

    /// Stride F1.
    pub fn f1(&self) -> f64 {
        f1(self.tp as f64, self.fp as f64, self.fn_ as f64)
    }

    /// Lu's eq. 13 over the pooled counts: `|ΣE − ΣT| / ΣT`.
    pub fn pooled_count_error(&self) -> f64 {
        ratio(
            (self.detected as f64 - self.references as f64).abs(),
            self.references as f64,
        )
    }

    /// Stance sample-wise F1, if labelled.
    pub fn stance_f1(&self) -> Option<f64> {
        self.stance
            .map(|(tp, fp, fn_)| f1(tp as f64, fp as f64, fn_ as f64))
    }

    /// Share of the zero-velocity instants inside a labelled stance.
    pub fn instants_in_stance(&self) -> Option<f64> {
        self.instants.map(|(i, n)| ratio(i as f64, n as f64))
    }
}

fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        f64::NAN
    }
}

fn f1(tp: f64, fp: f64, fn_: f64) -> f64 {
    ratio(2.0 * tp, 2.0 * tp + fp + fn_)
}

fn mean(v: &[f64]) -> f64 {
    ratio(v.iter().sum(), v.len() as f64)
}

pub use crate::stats::abs_quantile;

fn overlap(a: (u32, u32), b: (u32, u32)) -> u32 {
    a.1.min(b.1).saturating_sub(a.0.max(b.0))
}

fn iou(a: (u32, u32), b: (u32, u32)) -> f64 {
    let union = a.1.max(b.1).saturating_sub(a.0.min(b.0));
    ratio(overlap(a, b) as f64, union as f64)
}

/// Pairs detections with references (indices), greedily by overlap, one to one.
pub fn match_strides(det: &[Detected], refs: &[Reference]) -> Vec<(usize, usize)> {
    let mut cand = Vec::new();
    for (i, d) in det.iter().enumerate() {
        let dm = (d.heel_off, d.foot_flat);
        for (j, r) in refs.iter().enumerate() {
            let rm = (r.start, r.end);
            let ov = overlap(dm, rm);
            let shorter = (dm.1 - dm.0).min(rm.1.saturating_sub(rm.0));
            if ov > 0 && 2 * ov >= shorter {
                cand.push((ov, i, j));
            }
        }
    }
    cand.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    let (mut used_d, mut used_r) = (vec![false; det.len()], vec![false; refs.len()]);
    let mut out = Vec::new();
    for (_, i, j) in cand {
        if !used_d[i] && !used_r[j] {
            used_d[i] = true;
            used_r[j] = true;
            out.push((i, j));
        }
    }
    out
}

/// A detector's strides on one trial, in the sample numbers of the trial's recovered
/// clock (the core's own numbering), and that clock.
#[derive(Clone, Debug)]
pub struct Detections {
    /// The strides.
    pub strides: Vec<Detected>,
    /// The trial's sample clock.
    pub clock: SampleClock,
}

impl Trial {
    /// The labelled span in sample numbers of `clock`.
    pub fn span_in_numbers(&self, clock: &SampleClock) -> (u32, u32) {
        match self.span_s {
            Some((a, b)) => (clock.number_at(a), clock.number_at(b)),
            None => (
                clock.number_of_row(self.span.0 as usize),
                clock.number_of_row(self.span.1 as usize),
            ),
        }
    }

    /// The references in sample numbers of `clock` ([`Reference::in_numbers`]).
    pub fn references_in_numbers(&self, clock: &SampleClock) -> Vec<Reference> {
        self.references
            .iter()
            .map(|r| r.in_numbers(clock))
            .collect()
    }
}

/// What one detection counts as (see the module's *Matching*).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scored {
    /// Matched to the clean reference of this index.
    Found(usize),
    /// Not scored: matched to a flagged reference, mostly inside one, or in a U-turn.
    Unscored,
    /// A real movement the borders leave out ([`Tally::unbordered`]).
    Unbordered,
    /// A false detection.
    Extra,
}

/// How each of `det` (one trial's detections, in sample numbers of `clock`) is scored
/// against the trial's references `refs` (in the same numbers).
pub fn classify(
    trial: &Trial,
    clock: &SampleClock,
    det: &[Detected],
    refs: &[Reference],
) -> Vec<Scored> {
    let mut out: Vec<Scored> = vec![Scored::Extra; det.len()];
    for (i, j) in match_strides(det, refs) {
        out[i] = if refs[j].flagged {
            Scored::Unscored
        } else {
            Scored::Found(j)
        };
    }
    // Mostly inside: at least half the detected movement.
    let mostly_in = |d: &Detected, (a, b): (u32, u32)| {
        2 * overlap((d.heel_off, d.foot_flat), (a, b)) >= d.foot_flat - d.heel_off
    };
    let uturn = trial
        .unscored_s
        .map(|(a, b)| (clock.number_at(a), clock.number_at(b)));
    let unscored = |d: &Detected| {
        uturn.is_some_and(|u| mostly_in(d, u))
            || refs
                .iter()
                .any(|r| r.flagged && mostly_in(d, (r.start, r.end)))
    };
    let vicon_moving = |d: &Detected| {
        trial.stance.as_ref().is_some_and(|label| {
            let from = clock.row_of_number(d.heel_off) as usize;
            let to = clock.row_of_number(d.foot_flat) as usize;
            let moving = (from..to).filter(|&k| label.get(k) == Some(&false)).count();
            to > from && 2 * moving >= to - from
        })
    };
    for (d, c) in det.iter().zip(out.iter_mut()) {
        if *c == Scored::Extra {
            *c = if unscored(d) {
                Scored::Unscored
            } else if vicon_moving(d) {
                Scored::Unbordered
            } else {
                Scored::Extra
            };
        }
    }
    out
}

/// The detections of `strides` that overlap the trial's labelled span.
pub fn in_span(trial: &Trial, clock: &SampleClock, strides: &[Detected]) -> Vec<Detected> {
    let span = trial.span_in_numbers(clock);
    strides
        .iter()
        .copied()
        .filter(|d| overlap((d.heel_off, d.foot_flat), span) > 0)
        .collect()
}

/// Scores one trial's detections.
pub fn score(trial: &Trial, run: &Detections) -> Tally {
    let clock = &run.clock;
    let det = in_span(trial, clock, &run.strides);
    let refs = &trial.references_in_numbers(clock);
    let scored = classify(trial, clock, &det, refs);
    let mut t = Tally {
        trials: 1,
        clean: refs.iter().filter(|r| !r.flagged).count(),
        detected: det.len(),
        too_long: run.strides.iter().filter(|d| d.too_long).count(),
        references: refs.len(),
        count_errors: vec![ratio(
            (det.len() as f64 - refs.len() as f64).abs(),
            refs.len() as f64,
        )],
        ..Tally::default()
    };
    let ms = |samples: f64| samples * 1000.0 * clock.period_s;
    t.swing.labelled = refs.iter().any(|r| r.toe_off.is_some());
    t.contact.labelled = refs.iter().any(|r| r.prev_heel_strike.is_some());
    for (i, d) in det.iter().enumerate() {
        let prev = i
            .checked_sub(1)
            .map(|k| det[k])
            .filter(|p| p.end == d.start);
        match scored[i] {
            Scored::Unscored => t.unscored += 1,
            Scored::Unbordered => t.unbordered += 1,
            Scored::Found(j) => {
                let r = refs[j];
                t.tp += 1;
                if let (Some(to), Some(hs)) = (r.toe_off, r.heel_strike) {
                    t.toe_off_ms.push(ms(d.toe_off as f64 - to as f64));
                    t.heel_strike_ms.push(ms(d.heel_strike as f64 - hs as f64));
                    let v = iou((d.toe_off, d.heel_strike), (to, hs));
                    phase(&mut t.swing, Some(v));
                }
                if let (Some(phs), Some(to)) = (r.prev_heel_strike, r.toe_off) {
                    let v = prev.map(|p| iou((p.heel_strike, d.toe_off), (phs, to)));
                    phase(&mut t.contact, v);
                }
            }
            Scored::Extra => {
                t.fp += 1;
                t.swing.fp += t.swing.labelled as usize;
                t.contact.fp += (t.contact.labelled && prev.is_some()) as usize;
            }
        }
    }
    t.fn_ = t.clean - t.tp;
    for (ph, labelled) in [
        (
            &mut t.swing,
            refs.iter()
                .filter(|r| !r.flagged && r.toe_off.is_some())
                .count(),
        ),
        (
            &mut t.contact,
            refs.iter()
                .filter(|r| !r.flagged && r.prev_heel_strike.is_some())
                .count(),
        ),
    ] {
        ph.fn_ = labelled - ph.tp;
    }
    if let Some(label) = &trial.stance {
        // Labels are per row; a row is "moving" when its sample number is inside a
        // detected movement.
        let numbers = clock.number_of_row(label.len()) as usize + 1;
        let mut moving = vec![false; numbers];
        for d in &det {
            for m in moving
                .iter_mut()
                .take(d.foot_flat as usize)
                .skip(d.heel_off as usize)
            {
                *m = true;
            }
        }
        let (mut tp, mut fp, mut fn_) = (0, 0, 0);
        let to = (trial.span.1 as usize).min(label.len());
        let from = (trial.span.0 as usize).min(to);
        for (k, &labelled) in label.iter().enumerate().take(to).skip(from) {
            let n = clock.number_of_row(k) as usize;
            match (!moving[n], labelled) {
                (true, true) => tp += 1,
                (true, false) => fp += 1,
                (false, true) => fn_ += 1,
                (false, false) => {}
            }
        }
        t.stance = Some((tp, fp, fn_));
        // The zero-velocity instants (each stride's start) inside a Vicon stance.
        let rows = from..to;
        let instants: Vec<bool> = det
            .iter()
            .map(|d| clock.row_of_number(d.start) as usize)
            .filter(|k| rows.contains(k))
            .map(|k| label[k])
            .collect();
        t.instants = Some((instants.iter().filter(|&&s| s).count(), instants.len()));
    }
    t
}

/// A matched phase: a true positive at IoU ≥ 0.5, else one false positive (the detected
/// segment is wrong) — its reference is then counted missed by the caller's `fn_`.
fn phase(p: &mut PhaseTally, v: Option<f64>) {
    match v {
        Some(v) if v >= 0.5 => {
            p.tp += 1;
            p.iou.push(v);
        }
        Some(_) => p.fp += 1,
        None => {}
    }
}

/// A rotation matrix drawn uniformly (from a random unit quaternion).
pub fn random_rotation(rng: &mut impl Rng) -> [[f64; 3]; 3] {
    let q: [f64; 4] = loop {
        let v = [0; 4].map(|_| rng.random_range(-1.0..1.0f64));
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 0.1 && n <= 1.0 {
            break v.map(|x| x / n);
        }
    };
    rotation_matrix(q)
}

/// The rotation matrix of a unit quaternion `[w, x, y, z]` (`v' = M·v`).
pub fn rotation_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The trace as a clip mounted at rotation `r` would have recorded it.
pub fn rotate(samples: &[ImuSample], r: &[[f64; 3]; 3]) -> Vec<ImuSample> {
    let mul = |v: [f64; 3]| r.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2]);
    samples
        .iter()
        .map(|s| ImuSample {
            t_s: s.t_s,
            acc_mps2: mul(s.acc_mps2),
            gyr_radps: mul(s.gyr_radps),
        })
        .collect()
}

/// A detector under evaluation: from a trace (counts at `ranges`) to strides.
pub type Detector<'a> = &'a dyn Fn(&Trace, Ranges) -> Result<Detections>;

/// The core's detector with `config` adjusted by `setup`, as `gaitclip eval` runs it: the
/// trace is prepared ([`crate::replay::prepare`]: counts, recovered clock, holes) and its
/// strides reported in sample numbers.
pub fn core_detector(
    setup: impl Fn(&mut gaitclip::pipeline::Config),
) -> impl Fn(&Trace, Ranges) -> Result<Detections> {
    move |t: &Trace, r: Ranges| {
        let prepared = crate::replay::prepare(t, r)?;
        let mut config = prepared.config(r);
        setup(&mut config);
        Ok(Detections {
            strides: prepared
                .strides(config)
                .iter()
                .map(Detected::from)
                .collect(),
            clock: prepared.clock,
        })
    }
}

/// Results of one dataset: the tally of the unrotated traces, and one per rotation.
pub struct DatasetResult {
    /// Dataset name.
    pub name: String,
    /// As recorded.
    pub tally: Tally,
    /// After each random rotation.
    pub rotated: Vec<Tally>,
}

/// Runs `detector` on every trial of `dataset`, as recorded and after `rotations` random
/// rotations (seeded by `seed`, one sequence per trial).
pub fn evaluate(
    dataset: &Dataset,
    detector: Detector,
    rotations: usize,
    seed: u64,
) -> Result<DatasetResult> {
    let ranges = Ranges::default();
    let mut tally = Tally::default();
    let mut rotated = vec![Tally::default(); rotations];
    for (k, trial) in dataset.trials.iter().enumerate() {
        let trace = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        tally.add(&score(trial, &detector(&trace, ranges)?));
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (k as u64).wrapping_mul(0x9E37_79B9));
        for r in rotated.iter_mut() {
            let m = random_rotation(&mut rng);
            let t = Trace {
                samples: rotate(&trace.samples, &m),
                ..trace.clone()
            };
            r.add(&score(trial, &detector(&t, ranges)?));
        }
    }
    Ok(DatasetResult {
        name: dataset.name.clone(),
        tally,
        rotated,
    })
}

fn fmt3(v: f64) -> String {
    if v.is_nan() {
        "–".into()
    } else {
        format!("{v:.3}")
    }
}

pub use crate::stats::median;

fn fmt_ms(v: &[f64]) -> String {
    if v.is_empty() {
        "–".into()
    } else {
        format!(
            "{:.0} / {:.0} ({:+.0})",
            abs_quantile(v, 0.5),
            abs_quantile(v, 0.95),
            median(v)
        )
    }
}

/// The cells `found | extra | missed | not scored | unbordered | precision | recall | F1`
/// of a tally.
fn detection_cells(t: &Tally) -> String {
    format!(
        "{} | {} | {} | {} | {} | {} | {} | {}",
        t.tp,
        t.fp,
        t.fn_,
        t.unscored,
        t.unbordered,
        fmt3(t.precision()),
        fmt3(t.recall()),
        fmt3(t.f1())
    )
}

fn phase_cell(p: &PhaseTally) -> String {
    if p.labelled {
        format!("{} / {}", fmt3(p.f_score()), fmt3(p.mean_iou()))
    } else {
        "–".into()
    }
}

/// The Markdown table: one row per dataset and an overall row; with rotations, one more
/// table of the rotated runs pooled and the largest change of any rotation.
pub fn table(results: &[DatasetResult]) -> String {
    let mut s = String::new();
    let header = "| dataset | trials | clean strides | found | extra | missed | not scored | unbordered movements | precision | recall | F1 | toe-off \\|error\\| ms: median / p95 (signed median) | heel-strike \\|error\\| ms: median / p95 (signed median) | swing F / IoU | contact F / IoU | stance F1 | zero-velocity instants in a Vicon stance |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    let row = |s: &mut String, name: &str, t: &Tally| {
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            t.trials,
            t.clean,
            detection_cells(t),
            fmt_ms(&t.toe_off_ms),
            fmt_ms(&t.heel_strike_ms),
            phase_cell(&t.swing),
            phase_cell(&t.contact),
            t.stance_f1().map_or("–".into(), fmt3),
            t.instants.map_or("–".into(), |(i, n)| format!(
                "{i} / {n} ({:.1} %)",
                100.0 * ratio(i as f64, n as f64)
            )),
        );
    };
    s.push_str(header);
    let mut overall = Tally::default();
    for r in results {
        row(&mut s, &r.name, &r.tally);
        overall.add(&r.tally);
    }
    if results.len() > 1 {
        row(&mut s, "**overall**", &overall);
    }
    let n = results.first().map_or(0, |r| r.rotated.len());
    if n > 0 {
        let _ = writeln!(s, "\nAfter {n} random rotations of every trace (pooled):\n");
        s.push_str(header);
        let mut overall = Tally::default();
        for r in results {
            let mut pooled = Tally::default();
            for t in &r.rotated {
                pooled.add(t);
            }
            row(&mut s, &r.name, &pooled);
            overall.add(&pooled);
        }
        if results.len() > 1 {
            row(&mut s, "**overall**", &overall);
        }
        let _ = writeln!(
            s,
            "\nLargest change of any single rotation from the unrotated figures:\n\n| dataset | F1 | toe-off median ms | heel-strike median ms | swing IoU | stance F1 |\n|---|---|---|---|---|---|"
        );
        for r in results {
            let t = &r.tally;
            let d = |f: &dyn Fn(&Tally) -> f64| {
                r.rotated
                    .iter()
                    .map(|x| (f(x) - f(t)).abs())
                    .filter(|v| !v.is_nan())
                    .fold(0.0f64, f64::max)
            };
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.1} | {:.1} | {:.3} | {} |",
                r.name,
                d(&|x| x.f1()),
                d(&|x| abs_quantile(&x.toe_off_ms, 0.5)),
                d(&|x| abs_quantile(&x.heel_strike_ms, 0.5)),
                d(&|x| x.swing.mean_iou()),
                if t.stance.is_some() {
                    format!("{:.3}", d(&|x| x.stance_f1().unwrap_or(f64::NAN)))
                } else {
                    "–".into()
                },
            );
        }
    }
    s
}

/// What the recordings' stamps and holes cost, per dataset: the replay's summaries
/// ([`crate::replay::Summary`]) of every trial added up.
pub fn data_table(datasets: &[Dataset]) -> Result<String> {
    let mut s = String::from(
        "| dataset | trials | samples read | repeated samples dropped | trials with holes | holes (samples lost) | bridged holes (samples) | gap holes: filled / restart (samples) | strides | bridged strides | gap strides | trials re-timed (stamps off the clock) |\n|---|---:|---:|---:|---:|---|---|---|---:|---:|---:|---|\n",
    );
    for d in datasets {
        let mut t = crate::replay::Summary::default();
        let (mut holed, mut retimed) = (0, 0);
        for trial in &d.trials {
            let trace = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
            let p = crate::replay::prepare(&trace, Ranges::default())
                .with_context(|| format!("{}", trial.csv.display()))?;
            let (_, one) = p.run(p.config(Ranges::default()));
            holed += (one.holes > 0) as usize;
            retimed += (one.retimed_stamps > 0) as usize;
            t.add(&one);
        }
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {holed} | {} ({}) | {} ({}) | {} / {} ({}) | {} | {} | {} | {retimed} ({}) |",
            d.name,
            d.trials.len(),
            t.samples_read,
            t.repeated_dropped,
            t.holes,
            t.lost_samples,
            t.bridged,
            t.bridged_samples,
            t.gaps_filled,
            t.gaps - t.gaps_filled,
            t.gap_samples,
            t.strides,
            t.bridged_strides,
            t.gap_strides,
            t.retimed_stamps,
        );
    }
    Ok(s)
}

/// Step detection side by side: one row per dataset and detector (the `Tally` of each, as
/// recorded), with Lu's eq. 13 step-count error as the mean over trials and pooled.
pub fn detectors_table(rows: &[(&str, &str, &Tally)]) -> String {
    let mut s = String::from(
        "| dataset | detector | strides (all / clean) | detected | found | extra | missed | not scored | unbordered movements | precision | recall | F1 | count error (eq. 13): mean of trials / pooled | too long (merged) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for (dataset, detector, t) in rows {
        let pct = |v: f64| {
            if v.is_nan() {
                "–".to_string()
            } else {
                format!("{:.1} %", 100.0 * v)
            }
        };
        let _ = writeln!(
            s,
            "| {dataset} | {detector} | {} / {} | {} | {} | {} / {} | {} |",
            t.references,
            t.clean,
            t.detected,
            detection_cells(t),
            pct(mean(&t.count_errors)),
            pct(t.pooled_count_error()),
            t.too_long,
        );
    }
    s
}

//! Detected strides against reference strides: one-to-one matching by overlap, the
//! classification of each detection, and the tallies (detection, events, phases, stance)
//! that [`crate::eval::scoring`] sums and [`crate::eval::tables`] writes.

use crate::io::clock::SampleClock;
use crate::io::datasets::{Reference, Trial};
use gaitclip::record::stride::{Stride, StrideEvents, StrideFlags};

/// One detected stride, in sample indices of its trial: the core's events
/// ([`gaitclip::record::stride::StrideEvents`]) and whether strides merged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Detected {
    /// The stride's events.
    pub events: StrideEvents,
    /// The movement overflowed the movement buffer ([`StrideFlags::TOO_LONG`]): strides
    /// merged.
    pub too_long: bool,
}

impl From<&Stride> for Detected {
    fn from(s: &Stride) -> Self {
        Detected {
            events: s.events,
            too_long: s.flags.has(StrideFlags::TOO_LONG),
        }
    }
}

impl Detected {
    /// The stride with every event index mapped by `f` (core sample numbers to recording
    /// indices across gaps).
    pub fn map(self, f: impl Fn(u32) -> u32) -> Self {
        Detected {
            events: self.events.map(f),
            ..self
        }
    }
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

pub(crate) fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 {
        a / b
    } else {
        f64::NAN
    }
}

fn f1(tp: f64, fp: f64, fn_: f64) -> f64 {
    ratio(2.0 * tp, 2.0 * tp + fp + fn_)
}

pub(crate) fn mean(v: &[f64]) -> f64 {
    ratio(v.iter().sum(), v.len() as f64)
}

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
        let dm = (d.events.heel_off, d.events.foot_flat);
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
        2 * overlap((d.events.heel_off, d.events.foot_flat), (a, b))
            >= d.events.foot_flat - d.events.heel_off
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
            let from = clock.row_of_number(d.events.heel_off) as usize;
            let to = clock.row_of_number(d.events.foot_flat) as usize;
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
        .filter(|d| overlap((d.events.heel_off, d.events.foot_flat), span) > 0)
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
            .filter(|p| p.events.end == d.events.start);
        match scored[i] {
            Scored::Unscored => t.unscored += 1,
            Scored::Unbordered => t.unbordered += 1,
            Scored::Found(j) => {
                let r = refs[j];
                t.tp += 1;
                if let (Some(to), Some(hs)) = (r.toe_off, r.heel_strike) {
                    t.toe_off_ms.push(ms(d.events.toe_off as f64 - to as f64));
                    t.heel_strike_ms
                        .push(ms(d.events.heel_strike as f64 - hs as f64));
                    let v = iou((d.events.toe_off, d.events.heel_strike), (to, hs));
                    phase(&mut t.swing, Some(v));
                }
                if let (Some(phs), Some(to)) = (r.prev_heel_strike, r.toe_off) {
                    let v = prev.map(|p| iou((p.events.heel_strike, d.events.toe_off), (phs, to)));
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
                .take(d.events.foot_flat as usize)
                .skip(d.events.heel_off as usize)
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
            .map(|d| clock.row_of_number(d.events.start) as usize)
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

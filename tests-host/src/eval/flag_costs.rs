//! `gaitclip flags`: what each stride flag costs in accuracy, measured.
//!
//! **As they occur.** Every trial of the four datasets replayed as the firmware runs; for
//! each flag, the strides carrying it, and for those matched to a clean reference stride
//! (`gaitmap_walk`, `pyshoe_vicon`), the reported length (what the foot pod counts: measured,
//! or estimated) against the reference.
//!
//! **Made on purpose.** What a degradation does to a stride, against the same stride without
//! it, on the walking strides of `gaitmap_walk` and `pyshoe_vicon` (every other one cut at a
//! time, so that the estimate has measured neighbours, as [`crate::eval::hole_sweep`] does):
//! a hole bridged (20 ms), a hole filled (60 ms: a gap stride, estimated), a hole after which
//! detection restarts (300 ms: estimated), the accelerometer clipped (±8 g, ±4 g: restored),
//! the gyro clipped (±500 °/s: restored); and the estimate itself as a predictor of every
//! measured gait cycle from the ones before it, on all datasets with strides.

use anyhow::Result;
use gaitclip::pipeline::config::BRIDGE_MAX_MS;
use gaitclip::record::stride::{Stride, StrideFlags};
use gaitclip_mpu6050::{AccelRange, GyroRange};

use crate::eval::clip_sweep::{self, Clipping};
use crate::eval::hole_sweep::{self, Pattern};
use crate::eval::markdown::{cm_cell, Table};
use crate::eval::matching::{self, Detected, Scored};
use crate::io::datasets;
use crate::io::trace::Ranges;
use crate::{io::csv_trace, replay};

/// Every flag, in bit order, with what it does to the length.
pub const FLAGS: [(u16, &str, &str); 13] = [
    (
        StrideFlags::SATURATED,
        "saturated",
        "not measured: estimated",
    ),
    (StrideFlags::TOO_LONG, "too_long", "not measured: estimated"),
    (StrideFlags::FROM_REST, "from_rest", "informational"),
    (StrideFlags::TO_REST, "to_rest", "informational"),
    (StrideFlags::TURN, "turn", "informational"),
    (
        StrideFlags::PHASES_GUESSED,
        "phases_guessed",
        "informational",
    ),
    (StrideFlags::GAP, "gap", "not measured: estimated"),
    (
        StrideFlags::IMPLAUSIBLE,
        "implausible",
        "not measured: estimated",
    ),
    (StrideFlags::BRIDGED, "bridged", "measured through the hole"),
    (StrideFlags::GYRO_CLIPPED, "gyro_clipped", "restored"),
    (StrideFlags::ACCEL_CLIPPED, "accel_clipped", "restored"),
    (
        StrideFlags::ESTIMATED,
        "estimated",
        "the length is the estimate",
    ),
    (
        StrideFlags::SEVERAL_CYCLES,
        "several_cycles",
        "the estimate of its cycles",
    ),
];

/// The datasets of the first table.
pub const DATASETS: [&str; 4] = [
    "gaitmap_walk",
    "pyshoe_vicon",
    "ipol_gait_events",
    "esangeni_run",
];

/// One dataset's strides and, for those matched to a clean reference, reported − reference.
struct Occurring {
    strides: Vec<Stride>,
    /// (flags, reported − reference m) of the matched strides.
    errors: Vec<(StrideFlags, f64)>,
}

fn occurring(root: &std::path::Path, name: &str) -> Result<Occurring> {
    let d = datasets::load(&root.join(name))?;
    let ranges = Ranges::default();
    let mut out = Occurring {
        strides: Vec::new(),
        errors: Vec::new(),
    };
    for trial in &d.trials {
        let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
        let p = replay::prepare(&t, ranges)?;
        let strides = p.strides(p.config(ranges));
        if trial.references.iter().any(|r| r.length_m.is_some()) {
            let det: Vec<Detected> = strides.iter().map(Detected::from).collect();
            let refs = trial.references_in_numbers(&p.clock);
            for (i, c) in matching::classify(trial, &p.clock, &det, &refs)
                .iter()
                .enumerate()
            {
                let Scored::Found(j) = *c else { continue };
                let (s, r) = (&strides[i], &refs[j]);
                if let (Some(len), false, true) = (r.length_m, r.flagged, s.flags.counts_distance())
                {
                    out.errors
                        .push((s.flags, s.length_mm as f64 / 1000.0 - len));
                }
            }
        }
        out.strides.extend(strides);
    }
    Ok(out)
}

/// Reported − uncut length of the strides cut by hole pattern `p` (every walking stride of
/// every trial, half at a time), and the flags they carry.
fn holes(walks: &[hole_sweep::Walk], p: Pattern) -> (Vec<f64>, u16, usize) {
    let (mut e, mut flags, mut lost) = (Vec::new(), 0u16, 0usize);
    for w in walks {
        for parity in 0..2 {
            let (cut, got) = hole_sweep::cut_replay(w, p, parity);
            for &i in &cut {
                let want = &w.strides[i];
                match hole_sweep::matching_stride(want, &got) {
                    Some(g) if g.flags.counts_distance() => {
                        flags |= g.flags.0;
                        e.push((g.length_mm as f64 - want.length_mm as f64) / 1000.0);
                    }
                    _ => lost += 1,
                }
            }
        }
    }
    (e, flags, lost)
}

fn flag_list(bits: u16) -> String {
    let v: Vec<&str> = FLAGS
        .iter()
        .filter(|(b, _, _)| bits & b != 0)
        .map(|(_, n, _)| *n)
        .collect();
    if v.is_empty() {
        "–".into()
    } else {
        v.join(", ")
    }
}

/// The estimate ([`gaitclip::length::estimate`]) as a predictor of every measured gait cycle from the
/// ones before it: predicted − measured, m.
fn predictor(strides: &[Stride]) -> Vec<f64> {
    let mut est = gaitclip::length::estimate::LengthEstimator::new();
    let mut e = Vec::new();
    let not_a_cycle = StrideFlags::FROM_REST | StrideFlags::TO_REST | StrideFlags::GAP;
    for s in strides {
        if s.index == 0 {
            // A new trial: nothing carries over.
            est = gaitclip::length::estimate::LengthEstimator::new();
        }
        if s.flags.valid() && !s.flags.has(not_a_cycle) {
            if let Some(p) = est.estimate_mm() {
                e.push((p as f64 - s.length_mm as f64) / 1000.0);
            }
        }
        est.process(&mut s.clone());
    }
    e
}

/// The two tables, Markdown.
pub fn report(root: &std::path::Path) -> Result<String> {
    let sets: Vec<(&str, Occurring)> = DATASETS
        .iter()
        .map(|&n| occurring(root, n).map(|o| (n, o)))
        .collect::<Result<_>>()?;
    let mut header = vec!["flag".to_string(), "length".to_string()];
    for (n, _) in &sets {
        header.push(format!("{n}: strides (of all) · vs reference"));
    }
    let mut t = Table::new(header);
    for (bit, name, what) in FLAGS.iter().copied().chain([(0u16, "(none)", "measured")]) {
        let mut row = vec![format!("`{name}`"), what.to_string()];
        for (_, o) in &sets {
            let has = |f: StrideFlags| if bit == 0 { f.0 == 0 } else { f.has(bit) };
            let n = o.strides.iter().filter(|s| has(s.flags)).count();
            let e: Vec<f64> = o
                .errors
                .iter()
                .filter(|(f, _)| has(*f))
                .map(|x| x.1)
                .collect();
            row.push(if o.errors.is_empty() {
                format!("{n} ({})", o.strides.len())
            } else {
                format!("{n} ({}) · {}", o.strides.len(), cm_cell(&e))
            });
        }
        t.row(row);
    }

    let mut walks = hole_sweep::walks(root, 1)?;
    for w in &mut walks {
        w.config.bridge_max_ms = BRIDGE_MAX_MS;
    }
    let mut m = Table::new([
        "made on purpose",
        "flags it gave",
        "strides",
        "reported length vs the stride undegraded: RMSE / bias cm",
        "strides lost",
    ]);
    for (label, ms) in [
        ("hole of 20 ms in the swing (bridged)", 20.0),
        ("hole of 60 ms in the swing (filled: a gap stride)", 60.0),
        ("hole of 300 ms in the swing (detection restarts)", 300.0),
    ] {
        let (mut e, mut flags, mut lost) = (Vec::new(), 0u16, 0usize);
        for w in &walks {
            let len = (ms / w.period_ms).round().max(1.0) as u32;
            let p = Pattern {
                len,
                cluster: false,
                swing: true,
            };
            let (we, wf, wl) = holes(std::slice::from_ref(w), p);
            e.extend(we);
            flags |= wf;
            lost += wl;
        }
        m.row([
            label.to_string(),
            flag_list(flags),
            e.len().to_string(),
            cm_cell(&e),
            lost.to_string(),
        ]);
    }
    for c in &clip_sweep::CLIPPINGS[..2] {
        for name in ["gaitmap_walk", "pyshoe_vicon"] {
            let d = datasets::load(&root.join(name))?;
            let r = clip_sweep::sweep(&d, c)?;
            let e: Vec<f64> = r.strides.iter().map(|s| s.restored_m).collect();
            m.row([
                format!("accelerometer at {}, {name}", c.label),
                "accel_clipped".into(),
                e.len().to_string(),
                cm_cell(&e),
                r.moved.to_string() + " (instants moved)",
            ]);
        }
    }
    let gyro = Clipping {
        label: "±500 °/s",
        ranges: Ranges {
            accel: AccelRange::G16,
            gyro: GyroRange::Dps500,
        },
        clamp_g: None,
    };
    for name in ["gaitmap_walk", "pyshoe_vicon"] {
        let d = datasets::load(&root.join(name))?;
        let e = gyro_clipped(&d, gyro.ranges)?;
        m.row([
            format!("gyro at {}, {name}", gyro.label),
            "gyro_clipped".into(),
            e.len().to_string(),
            cm_cell(&e),
            "–".into(),
        ]);
    }
    for (n, o) in &sets {
        let e = predictor(&o.strides);
        m.row([
            format!("the estimate for every measured gait cycle of {n}"),
            "(estimated)".into(),
            e.len().to_string(),
            cm_cell(&e),
            "–".into(),
        ]);
    }
    Ok(format!(
        "Flags as they occur (reported length, measured or estimated, against clean matched reference strides; RMSE / bias cm (strides)):\n\n{}\n\
         Flags made on purpose, each stride against itself undegraded:\n\n{}",
        t.render(),
        m.render()
    ))
}

/// Reported − unclipped length of the strides a gyro clipped at `ranges` marks, between the
/// same two instants.
fn gyro_clipped(d: &datasets::Dataset, ranges: Ranges) -> Result<Vec<f64>> {
    let mut e = Vec::new();
    for trial in &d.trials {
        let t = csv_trace::read(&trial.csv, Some(d.rate_hz))?;
        let full = replay::prepare(&t, Ranges::default())?;
        let want = full.strides(full.config(Ranges::default()));
        let p = replay::prepare(&t, ranges)?;
        for s in p.strides(p.config(ranges)) {
            if !s.flags.has(StrideFlags::GYRO_CLIPPED) {
                continue;
            }
            if let Some(w) = clip_sweep::same_instants(&s, &want) {
                e.push((s.length_mm as f64 - w.length_mm as f64) / 1000.0);
            }
        }
    }
    Ok(e)
}

//! `gaitclip zupt-sweep`: what the ZUPT stride's two physical settings do to its length, so
//! that they are documented by measurement.
//!
//! - **Sensor height** above the foot's rolling contact ([`gaitclip::pipeline::config::Config`]'s
//!   `sensor_height_um`, default [`gaitclip::detect::cycle::SENSOR_HEIGHT_UM`]): at the stance
//!   instant the foot rolls and the sensor moves at `ω × (h·up)`; `h = 0` is the plain
//!   zero-velocity update. A clip on the side of a shoe sits lower than one on the laces.
//! - **Gyro full-scale range**: the recordings are converted to MPU6050 counts at ±2000,
//!   ±500 and ±250 °/s; at the lower ranges the swing's pitch rate clips and the tilt the
//!   rails lost is put back ([`gaitclip::detect::zupt::ZuptIntegrator::displacement_restoring`]),
//!   reported for clipped and unclipped strides apart.
//!
//! Scored as `gaitclip eval` scores the `zupt` model: the cycle detector's valid strides
//! matched to clean reference strides of `gaitmap_walk` and `pyshoe_vicon` (unscored spans,
//! and references holding a movement the Vicon labels show unbordered, left out), error =
//! ZUPT length − reference, binned by the reference stride's speed.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::Result;
use gaitclip_mpu6050::{AccelRange, GyroRange};

use crate::eval::bias;
use crate::eval::length_eval::SPEED_BINS;
use crate::eval::markdown::Table;
use crate::io::csv_trace;
use crate::io::datasets;
use crate::io::trace::Ranges;

/// Sensor heights swept, mm.
pub const HEIGHTS_MM: [u32; 6] = [0, 40, 60, 80, 100, 120];

/// One scored stride: reference speed (m/s), error (m), clipped gyro.
type Scoredstride = (f64, f64, bool);

/// The ZUPT errors of one dataset at one height and range.
fn errors(
    dataset: &datasets::Dataset,
    ranges: Ranges,
    height_um: u32,
) -> Result<Vec<Scoredstride>> {
    let mut out = Vec::new();
    for trial in &dataset.trials {
        let t = csv_trace::read(&trial.csv, Some(dataset.rate_hz))?;
        let run = bias::run_trial(trial, &t, ranges, &|c| c.sensor_height_um = height_um)?;
        out.extend(
            run.strides
                .iter()
                .map(|e| (e.speed_mps, e.error_m, e.gyro_clipped)),
        );
    }
    Ok(out)
}

/// `n, RMSE / bias cm` of `e`, or `–`.
fn cell(e: &[f64]) -> String {
    if e.is_empty() {
        return "–".into();
    }
    let n = e.len() as f64;
    let rmse = (e.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    let bias = e.iter().sum::<f64>() / n;
    format!("{:.1} / {:+.1} ({})", rmse * 100.0, bias * 100.0, e.len())
}

/// The two tables, Markdown.
pub fn report(root: &Path) -> Result<String> {
    let mut s = String::new();
    let sets: Vec<datasets::Dataset> = ["gaitmap_walk", "pyshoe_vicon"]
        .iter()
        .map(|n| datasets::load(&root.join(n)))
        .collect::<Result<_>>()?;
    let bin_name = |bin: (f64, f64)| crate::eval::length_eval::bin_label(bin, "m/s");
    writeln!(
        s,
        "ZUPT stride by sensor height above the rolling contact (cycle detector, ±2000 °/s; RMSE / bias cm (strides)):\n"
    )?;
    let mut header = vec!["height".to_string()];
    for d in &sets {
        header.push(format!("{} all", d.name));
        for b in SPEED_BINS.iter().take(4) {
            header.push(format!("{} {}", d.name, bin_name(*b)));
        }
    }
    let mut by_height = Table::new(header);
    for h in HEIGHTS_MM {
        let mut row = vec![format!("{h} mm")];
        for d in &sets {
            let e = errors(d, Ranges::default(), h * 1000)?;
            let all: Vec<f64> = e.iter().map(|x| x.1).collect();
            row.push(cell(&all));
            for (lo, hi) in SPEED_BINS.iter().take(4).copied() {
                let b: Vec<f64> = e
                    .iter()
                    .filter(|x| x.0 >= lo && x.0 < hi)
                    .map(|x| x.1)
                    .collect();
                row.push(cell(&b));
            }
        }
        by_height.row(row);
    }
    s.push_str(&by_height.render());
    writeln!(
        s,
        "\nZUPT stride by gyro full-scale range (cycle detector, sensor height {} mm; RMSE / bias cm (strides)):\n",
        gaitclip::detect::cycle::SENSOR_HEIGHT_UM / 1000
    )?;
    let mut header = vec!["gyro range".to_string()];
    for d in &sets {
        header.push(format!("{} all", d.name));
        header.push(format!("{} clipped", d.name));
        header.push(format!("{} not clipped", d.name));
    }
    let mut by_range = Table::new(header);
    for (gyro, label) in [
        (GyroRange::Dps2000, "±2000 °/s"),
        (GyroRange::Dps500, "±500 °/s"),
        (GyroRange::Dps250, "±250 °/s"),
    ] {
        let ranges = Ranges {
            accel: AccelRange::G16,
            gyro,
        };
        let mut row = vec![label.to_string()];
        for d in &sets {
            let e = errors(d, ranges, gaitclip::detect::cycle::SENSOR_HEIGHT_UM)?;
            let pick = |f: &dyn Fn(&Scoredstride) -> bool| -> Vec<f64> {
                e.iter().filter(|x| f(x)).map(|x| x.1).collect()
            };
            row.push(cell(&pick(&|_| true)));
            row.push(cell(&pick(&|x| x.2)));
            row.push(cell(&pick(&|x| !x.2)));
        }
        by_range.row(row);
    }
    s.push_str(&by_range.render());
    Ok(s)
}

//! `gaitclip._gaitclip`: the native half of gaitclip's Python package.
//!
//! It runs the host replay (`gaitclip_host::replay`: the recovered sensor clock, holes
//! bridged or filled, the three step detectors, every length model, the gait parameters) of
//! the firmware's own fixed-point core, `gaitclip`, on a recording given as numpy arrays or as
//! a CSV/MCAP file, and hands back exactly what `gaitclip replay --json` prints, as columns
//! (numpy arrays named as its fields), each event's row in the input beside them, and the
//! summary. There is no second implementation: the Python package (`gaitclip/__init__.py`)
//! only names those columns as gaitmap does.
//!
//! The core runs with the GIL released. Bad input is a Python exception, never a panic:
//! `ValueError` for a shape, a value, a stamp, an option or a malformed file (the file's
//! error names its line and column), `FileNotFoundError` for a path that is not there.

use std::path::{Path, PathBuf};

use gaitclip::length::models::Model;
use gaitclip::pipeline::detectors::Detector;
use gaitclip_host::io::clock::{self, SampleClock};
use gaitclip_host::io::csv_trace::CsvError;
use gaitclip_host::io::mcap_io::McapError;
use gaitclip_host::io::recording::{self, ReadError};
use gaitclip_host::io::trace::{GivenRanges, ImuSample, Ranges, Trace};
use gaitclip_host::io::units::{self, Front, Units};
use gaitclip_host::replay::{self, StrideReport};
use gaitclip_host::stream::{StreamError, Streamed};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// What to replay with.
struct Options {
    detector: Detector,
    model: Model,
    all_models: bool,
}

fn options(detector: &str, model: Option<&str>, all_models: bool) -> PyResult<Options> {
    let d = Detector::from_name(detector).ok_or_else(|| {
        let names: Vec<&str> = Detector::ALL.iter().map(|d| d.name()).collect();
        PyValueError::new_err(format!(
            "detector '{detector}' is not one of {}",
            names.join(", ")
        ))
    })?;
    let m = match model {
        Some(name) => Model::from_name(name).ok_or_else(|| {
            let names: Vec<&str> = Model::ALL.iter().map(|m| m.name()).collect();
            PyValueError::new_err(format!("model '{name}' is not one of {}", names.join(", ")))
        })?,
        None => d.length_model(gaitclip::pipeline::config::DEFAULT_MODEL),
    };
    if d.own_model().is_some_and(|own| m != own || all_models) {
        return Err(PyValueError::new_err(
            "the lu detector's steps are measured by Lu's own chain only: model='lu_fuzzy', without all_models",
        ));
    }
    Ok(Options {
        detector: d,
        model: m,
        all_models,
    })
}

fn ranges_given(acc_range_g: Option<f64>, gyro_range_dps: Option<f64>) -> PyResult<()> {
    for (v, name) in [
        (acc_range_g, "acc_range_g"),
        (gyro_range_dps, "gyro_range_dps"),
    ] {
        if v.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
            return Err(PyValueError::new_err(format!(
                "{name} must be a positive number"
            )));
        }
    }
    Ok(())
}

/// Replays `trace` with the GIL released and hands back its strides as columns (numpy
/// arrays, lists of strings) named as `gaitclip replay --json` names its fields, the events'
/// rows of the input beside them, and the summary as that command's JSON; `row_of` maps a row
/// of the trace to a row of the input.
fn run<'py>(
    py: Python<'py>,
    trace: Trace,
    o: Options,
    row_of: impl Fn(u32) -> u64,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let (strides, summary, clock) = py
        .detach(|| {
            replay::replay_clocked(&trace, Ranges::default(), o.detector, o.model, o.all_models)
        })
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    columns(py, &strides, &summary, &clock, o, row_of)
}

/// The strides' columns and the summary's JSON (see [`run`]).
fn columns<'py>(
    py: Python<'py>,
    strides: &[StrideReport],
    summary: &replay::Summary,
    clock: &SampleClock,
    o: Options,
    row_of: impl Fn(u32) -> u64,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let clock = clock.clone();
    let at = |c: &SampleClock, n: u32| row_of(c.row_of_number(n)) as i64;
    let f = |get: fn(&StrideReport) -> f64| -> Vec<f64> { strides.iter().map(get).collect() };
    let cols = PyDict::new(py);
    let put_f = |name: &str, v: Vec<f64>| cols.set_item(name, v.into_pyarray(py));
    let put_i = |name: &str, v: Vec<i64>| cols.set_item(name, v.into_pyarray(py));
    put_i("index", strides.iter().map(|s| s.index as i64).collect())?;
    for (name, get) in [
        ("start_s", (|s| s.start_s) as fn(&StrideReport) -> f64),
        ("end_s", |s| s.end_s),
        ("length_m", |s| s.length_m),
        ("zupt_m", |s| s.zupt_m),
        ("heel_off_s", |s| s.heel_off_s),
        ("toe_off_s", |s| s.toe_off_s),
        ("heel_strike_s", |s| s.heel_strike_s),
        ("foot_flat_s", |s| s.foot_flat_s),
        ("climb_m", |s| s.climb_m),
        ("stride_time_s", |s| s.stride_time_s),
        ("stance_time_s", |s| s.stance_time_s),
        ("swing_time_s", |s| s.swing_time_s),
        ("stance_pct", |s| s.stance_pct),
        ("swing_pct", |s| s.swing_pct),
        ("gait_velocity_m_s", |s| s.gait_velocity_m_s),
        ("max_sensor_lift_m", |s| s.max_sensor_lift_m),
        ("turning_angle_deg", |s| s.turning_angle_deg),
        ("travel_deg", |s| s.travel_deg),
        ("still_before_s", |s| s.still_before_s),
        ("moving_before_s", |s| s.moving_before_s),
    ] {
        put_f(name, f(get))?;
    }
    put_i(
        "cadence_spm",
        strides.iter().map(|s| s.cadence_spm as i64).collect(),
    )?;
    put_i(
        "swing_deg",
        strides.iter().map(|s| s.swing_deg as i64).collect(),
    )?;
    cols.set_item("model", strides.iter().map(|s| s.model).collect::<Vec<_>>())?;
    cols.set_item(
        "detector",
        strides.iter().map(|s| s.detector).collect::<Vec<_>>(),
    )?;
    cols.set_item("gait", strides.iter().map(|s| s.gait).collect::<Vec<_>>())?;
    cols.set_item(
        "valid",
        strides
            .iter()
            .map(|s| s.valid)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    cols.set_item(
        "flags",
        strides.iter().map(|s| s.flags.clone()).collect::<Vec<_>>(),
    )?;
    if o.all_models {
        for m in Model::ALL {
            let v: Vec<f64> = strides
                .iter()
                .map(|s| {
                    s.lengths_m
                        .as_ref()
                        .and_then(|l| l.get(m.name()).copied())
                        .unwrap_or(f64::NAN)
                })
                .collect();
            put_f(&format!("length_{}", m.name()), v)?;
        }
    }
    // The events as rows of the input; `pre_ic` where the stride before ends at this one's
    // start (NaN where not).
    let ev = |get: fn(&StrideReport) -> u32| -> Vec<i64> {
        strides.iter().map(|s| at(&clock, get(s))).collect()
    };
    put_i("row_start", ev(|s| s.raw.events.start))?;
    put_i("row_end", ev(|s| s.raw.events.end))?;
    put_i("row_heel_off", ev(|s| s.raw.events.heel_off))?;
    put_i("row_toe_off", ev(|s| s.raw.events.toe_off))?;
    put_i("row_heel_strike", ev(|s| s.raw.events.heel_strike))?;
    put_i("row_foot_flat", ev(|s| s.raw.events.foot_flat))?;
    let pre_ic: Vec<f64> = strides
        .iter()
        .enumerate()
        .map(|(k, s)| {
            k.checked_sub(1)
                .map(|j| strides[j].raw.events)
                .filter(|p| p.end == s.raw.events.start)
                .map_or(f64::NAN, |p| at(&clock, p.heel_strike) as f64)
        })
        .collect();
    put_f("row_pre_ic", pre_ic)?;
    let summary =
        serde_json::to_string(summary).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((cols, summary))
}

/// The units named by Python's `acc_unit` and `gyr_unit` (`None`: m/s², rad/s).
fn units_named(acc: Option<&str>, gyr: Option<&str>) -> PyResult<Units> {
    Units::from_names(acc, gyr).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Replays one sensor given as arrays: `t_s` (s; `None`: the rows at `rate_hz`), `acc`
/// (x, y, z: in `acc_unit`, `m/s^2`, `g` or `mg`, gravity included) and `gyr` (x, y, z: in
/// `gyr_unit`, `rad/s` or `deg/s`), in the sensor's axes (any mounting), the units checked as
/// the CLI checks a file's (`gaitclip_host::io::units`). Returns the strides' columns and the
/// summary's JSON.
#[pyfunction]
#[pyo3(signature = (t_s, acc, gyr, gyr_unit, rate_hz, detector, model, all_models, acc_range_g=None, gyro_range_dps=None, acc_unit=None, rate_overrides_stamps=false))]
#[allow(clippy::too_many_arguments)]
fn replay_arrays<'py>(
    py: Python<'py>,
    t_s: Option<PyReadonlyArray1<'py, f64>>,
    acc: [PyReadonlyArray1<'py, f64>; 3],
    gyr: [PyReadonlyArray1<'py, f64>; 3],
    gyr_unit: &str,
    rate_hz: Option<f64>,
    detector: &str,
    model: Option<&str>,
    all_models: bool,
    acc_range_g: Option<f64>,
    gyro_range_dps: Option<f64>,
    acc_unit: Option<&str>,
    rate_overrides_stamps: bool,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let o = options(detector, model, all_models)?;
    ranges_given(acc_range_g, gyro_range_dps)?;
    let declared = units_named(acc_unit, Some(gyr_unit))?;
    let (a, g) = (
        acc.each_ref().map(|v| v.as_array()),
        gyr.each_ref().map(|v| v.as_array()),
    );
    let n = a[0].len();
    if a.iter().chain(g.iter()).any(|v| v.len() != n) {
        return Err(PyValueError::new_err(
            "acc_x … gyr_z must have as many rows each",
        ));
    }
    if n == 0 {
        return Err(PyValueError::new_err("no samples"));
    }
    if rate_hz.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
        return Err(PyValueError::new_err(
            "sampling_rate_hz must be a positive number",
        ));
    }
    let stamps: Vec<f64> = match (&t_s, rate_hz) {
        (Some(t), _) => {
            let t = t.as_array();
            if t.len() != n {
                return Err(PyValueError::new_err(format!(
                    "t_s has {} rows, the sensor {n}",
                    t.len()
                )));
            }
            t.iter().copied().collect()
        }
        (None, Some(r)) => (0..n).map(|i| i as f64 / r).collect(),
        (None, None) => {
            return Err(PyValueError::new_err(
                "without a t_s column, sampling_rate_hz is needed",
            ))
        }
    };
    let mut samples = Vec::with_capacity(n);
    for (i, &t) in stamps.iter().enumerate() {
        let acc = [a[0][i], a[1][i], a[2][i]];
        let gyr = [g[0][i], g[1][i], g[2][i]];
        if !t.is_finite() || acc.iter().chain(gyr.iter()).any(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "row {i}: a value is not a finite number"
            )));
        }
        samples.push(ImuSample {
            t_s: t,
            acc_mps2: acc,
            gyr_radps: gyr,
        });
    }
    units::apply(&mut samples, declared, Front::Python)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    if let (Some(given), true, false) = (rate_hz, t_s.is_some(), rate_overrides_stamps) {
        if let Err(stamps) = recording::rate_agrees(&samples, given) {
            return Err(PyValueError::new_err(format!(
                "sampling_rate_hz={given} is {:+.0} % off the t_s stamps' {stamps:.4} Hz: leave it out to replay on the stamps' clock, or pass rate_overrides_stamps=True if the stamps are the ones that are wrong",
                (given / stamps - 1.0) * 100.0
            )));
        }
    }
    // Re-sent samples are dropped as the file readers drop them; `keep` maps the rows left
    // back to the input's.
    let period = match rate_hz {
        Some(r) => 1.0 / r,
        None => clock::nominal_period(&stamps).unwrap_or(0.0),
    };
    let keep = clock::drop_repeats(&stamps, period).map_err(|e| {
        PyValueError::new_err(format!(
            "row {}: t_s {} goes back from the previous sample's {} by more than half a period",
            e.index, e.t_s, e.previous_s
        ))
    })?;
    let repeated = n - keep.len();
    let samples: Vec<ImuSample> = keep.iter().map(|&i| samples[i]).collect();
    let rate_hz = match rate_hz {
        Some(r) => r,
        None => Trace::rate_from_timestamps(&samples).ok_or_else(|| {
            PyValueError::new_err("the stamps give no rate: pass sampling_rate_hz")
        })?,
    };
    let trace = Trace {
        samples,
        rate_hz,
        repeated,
        given: GivenRanges {
            acc_g: acc_range_g,
            gyro_dps: gyro_range_dps,
        },
    };
    let last = keep.len() - 1;
    run(py, trace, o, |row| keep[(row as usize).min(last)] as u64)
}

/// Replays a recording file: CSV (the datasets' layout: `t_s, acc_*` in m/s², `gyr_*` in
/// rad/s; a `meta.json` beside it gives the rate, ranges and units) or MCAP (told by its
/// magic bytes), as `gaitclip replay` reads it, in `acc_unit`/`gyr_unit` where given (over
/// `meta.json`'s), checked. Returns the strides' columns (rows of the samples kept, a re-sent
/// one dropped) and the summary's JSON.
#[pyfunction]
#[pyo3(signature = (path, rate_hz, detector, model, all_models, acc_range_g=None, gyro_range_dps=None, acc_unit=None, gyr_unit=None, rate_overrides_stamps=false))]
#[allow(clippy::too_many_arguments)]
fn replay_path<'py>(
    py: Python<'py>,
    path: PathBuf,
    rate_hz: Option<f64>,
    detector: &str,
    model: Option<&str>,
    all_models: bool,
    acc_range_g: Option<f64>,
    gyro_range_dps: Option<f64>,
    acc_unit: Option<&str>,
    gyr_unit: Option<&str>,
    rate_overrides_stamps: bool,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    let o = options(detector, model, all_models)?;
    ranges_given(acc_range_g, gyro_range_dps)?;
    let given = units_named(acc_unit, gyr_unit)?;
    let units = recording::declared_units(
        &path,
        acc_unit.map(|_| given.acc),
        gyr_unit.map(|_| given.gyro),
    )
    .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let how = recording::ReadOptions {
        rate_hz,
        rate_overrides_stamps,
        units,
        front: Front::Python,
    };
    // A file (CSV or MCAP) is replayed as a stream, in constant memory
    // (`gaitclip_host::stream`).
    let (strides, summary, clock) = py.detach(|| -> PyResult<_> {
        let mut s = Streamed::open(&path, &how).map_err(read_error)?;
        s.given.acc_g = acc_range_g.or(s.given.acc_g);
        s.given.gyro_dps = gyro_range_dps.or(s.given.gyro_dps);
        let mut strides = Vec::new();
        let (summary, clock) = s
            .replay(Ranges::default(), o.detector, o.model, o.all_models, |r| {
                strides.push(r)
            })
            .map_err(|e| match e {
                StreamError::Read(e) => read_error(e),
                StreamError::Replay(e) => PyValueError::new_err(e.to_string()),
            })?;
        Ok((strides, summary, clock))
    })?;
    columns(py, &strides, &summary, &clock, o, |row| row as u64)
}

fn not_found(path: &Path, source: &std::io::Error) -> PyErr {
    match source.kind() {
        std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(format!("{}: {source}", path.display()))
        }
        _ => PyValueError::new_err(format!("{}: {source}", path.display())),
    }
}

/// A reading error as Python's: a file not found as `FileNotFoundError`.
fn read_error(e: ReadError) -> PyErr {
    match &e {
        ReadError::Csv(CsvError::Io { path, source })
        | ReadError::Mcap(McapError::Io { path, source }) => not_found(path, source),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// The detector and model names the core knows, and the default model.
#[pyfunction]
fn names() -> (Vec<&'static str>, Vec<&'static str>, &'static str) {
    (
        Detector::ALL.iter().map(|d| d.name()).collect(),
        Model::ALL.iter().map(|m| m.name()).collect(),
        gaitclip::pipeline::config::DEFAULT_MODEL.name(),
    )
}

/// The module.
#[pymodule]
fn _gaitclip(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(replay_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(replay_path, m)?)?;
    m.add_function(wrap_pyfunction!(names, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("LOW_RATE_HZ", replay::LOW_RATE_HZ)?;
    Ok(())
}

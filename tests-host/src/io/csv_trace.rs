//! Reading and writing traces as CSV in the layout of `../shared/datasets`:
//! header `t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z`, m/s² and rad/s.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::io::trace::{ImuSample, Trace};
use crate::io::units::{self, Front, Units};

/// The columns, in the order the datasets write them.
pub const COLUMNS: [&str; 7] = ["t_s", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z"];

/// What went wrong reading a CSV trace. Every variant names the file; cell errors also the
/// 1-based line and column.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A required column is missing from the header.
    #[error("{path}: line 1: missing column `{column}` (header has: {header})")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column.
        column: &'static str,
        /// The header as read.
        header: String,
    },
    /// A cell is not a finite number.
    #[error("{path}:{line}:{col}: column `{column}`: `{text}` is not a finite number")]
    BadNumber {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// 1-based column number.
        col: usize,
        /// Column name.
        column: &'static str,
        /// The cell text.
        text: String,
    },
    /// A timestamp goes back by more than half a period: not a re-sent sample (those are
    /// dropped and counted), a broken or shuffled recording.
    #[error(
        "{path}:{line}:{col}: column `t_s`: {t_s} goes back from the previous sample's {previous_s} by more than half a period"
    )]
    TimeGoesBack {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// 1-based column number of `t_s`.
        col: usize,
        /// The time on this line, s.
        t_s: f64,
        /// The time on the line before, s.
        previous_s: f64,
    },
    /// A row is structurally broken (wrong field count, bad UTF-8 …).
    #[error("{path}:{line}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// The parser's message.
        message: String,
    },
    /// The file has a header but no samples.
    #[error("{path}: no samples")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The values cannot be in the units declared for them ([`crate::io::units`]).
    #[error("{path}: {unit}")]
    Units {
        /// The file.
        path: PathBuf,
        /// What the values look like, and how to declare it (in the message, not a cause
        /// of its own: said once).
        unit: units::UnitError,
    },
    /// `meta.json` beside the file exists but is not usable.
    #[error("{path}: {message}")]
    Meta {
        /// The meta.json file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Reads a CSV trace. The nominal rate comes from `rate_hz` if given, else from a
/// `meta.json` beside the file (`sample_rate_hz`), else from the stamps
/// ([`crate::io::clock::nominal_period`]). Re-sent samples (a stamp equal to the one before, or
/// earlier by less than half a period) are dropped and counted in [`Trace::repeated`]. The
/// values are in the units of `meta.json`'s `units` (the datasets' m/s² and rad/s without
/// one), converted and checked ([`units::check`]).
pub fn read(path: &Path, rate_hz: Option<f64>) -> Result<Trace, CsvError> {
    read_in(path, rate_hz, None, Front::CommandLine)
}

/// [`read`], the values in `units` where given (over `meta.json`'s); a unit that fails the
/// check says how to declare another at `front`.
pub fn read_in(
    path: &Path,
    rate_hz: Option<f64>,
    units: Option<Units>,
    front: Front,
) -> Result<Trace, CsvError> {
    let text = fs::read(path).map_err(|source| CsvError::Io {
        path: path.to_owned(),
        source,
    })?;
    let rate_hz = match rate_hz {
        Some(r) => Some(r),
        None => meta_rate(path)?,
    };
    let units = match units {
        Some(u) => u,
        None => meta_units(path)?,
    };
    let rows = parse_rows(path, &text)?;
    let (mut samples, repeated) = rows.without_repeats(path, rate_hz)?;
    units::apply(&mut samples, units, front).map_err(|unit| CsvError::Units {
        path: path.to_owned(),
        unit,
    })?;
    let rate_hz = match rate_hz {
        Some(r) => r,
        None => Trace::rate_from_timestamps(&samples).ok_or_else(|| CsvError::Empty {
            path: path.to_owned(),
        })?,
    };
    Ok(Trace {
        samples,
        rate_hz,
        repeated,
        given: meta_ranges(path)?,
    })
}

/// The `meta.json` beside a CSV file, parsed, with its path; `None` where there is none.
fn meta_json(csv: &Path) -> Result<Option<(PathBuf, serde_json::Value)>, CsvError> {
    let meta = csv.with_file_name("meta.json");
    let Ok(text) = fs::read_to_string(&meta) else {
        return Ok(None);
    };
    let v = serde_json::from_str(&text).map_err(|e| CsvError::Meta {
        path: meta.clone(),
        message: e.to_string(),
    })?;
    Ok(Some((meta, v)))
}

/// A positive number `name` of a `meta.json`, where it gives one.
fn positive(meta: &Path, v: &serde_json::Value, name: &str) -> Result<Option<f64>, CsvError> {
    match v.get(name) {
        None => Ok(None),
        Some(r) => r
            .as_f64()
            .filter(|r| *r > 0.0)
            .map(Some)
            .ok_or(CsvError::Meta {
                path: meta.to_owned(),
                message: format!("{name} is not a positive number: {r}"),
            }),
    }
}

/// The units of a `meta.json` beside the file (`"units": {"acc": "g", "gyr": "deg/s"}`; a
/// sensor not named is in the datasets' m/s² or rad/s).
pub fn meta_units(csv: &Path) -> Result<Units, CsvError> {
    let Some((meta, v)) = meta_json(csv)? else {
        return Ok(Units::default());
    };
    let name = |sensor: &str| match v.get("units").and_then(|u| u.get(sensor)) {
        None => Ok(None),
        Some(n) => n.as_str().map(Some).ok_or(CsvError::Meta {
            path: meta.clone(),
            message: format!("units.{sensor} is not a string: {n}"),
        }),
    };
    Units::from_names(name("acc")?, name("gyr")?).map_err(|e| CsvError::Meta {
        path: meta.clone(),
        message: e.to_string(),
    })
}

/// The nominal ranges `acc_range_g` and `gyro_range_dps` of a `meta.json` beside the file,
/// where it gives them.
pub(crate) fn meta_ranges(csv: &Path) -> Result<crate::io::trace::GivenRanges, CsvError> {
    let Some((meta, v)) = meta_json(csv)? else {
        return Ok(Default::default());
    };
    Ok(crate::io::trace::GivenRanges {
        acc_g: positive(&meta, &v, "acc_range_g")?,
        gyro_dps: positive(&meta, &v, "gyro_range_dps")?,
    })
}

/// The `sample_rate_hz` of a `meta.json` beside the file, where it gives one.
pub(crate) fn meta_rate(csv: &Path) -> Result<Option<f64>, CsvError> {
    match meta_json(csv)? {
        None => Ok(None),
        Some((meta, v)) => positive(&meta, &v, "sample_rate_hz"),
    }
}

/// Parses CSV bytes, dropping re-sent samples at the rate the stamps suggest; `path` is
/// only used in error messages.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Vec<ImuSample>, CsvError> {
    Ok(parse_rows(path, bytes)?.without_repeats(path, None)?.0)
}

/// Samples as parsed, with the line each came from.
struct Rows {
    samples: Vec<ImuSample>,
    lines: Vec<u64>,
    /// 1-based column of `t_s`.
    t_col: usize,
}

impl Rows {
    /// The samples without the re-sent ones, and how many those were.
    fn without_repeats(
        self,
        path: &Path,
        rate_hz: Option<f64>,
    ) -> Result<(Vec<ImuSample>, usize), CsvError> {
        Trace::drop_repeats(self.samples, rate_hz).map_err(|e| CsvError::TimeGoesBack {
            path: path.to_owned(),
            line: self.lines[e.index],
            col: self.t_col,
            t_s: e.t_s,
            previous_s: e.previous_s,
        })
    }
}

fn parse_rows(path: &Path, bytes: &[u8]) -> Result<Rows, CsvError> {
    let mut out = Vec::new();
    let mut lines = Vec::new();
    let t_col = parse_each(path, bytes, |sample, line| {
        lines.push(line);
        out.push(sample);
        Ok(())
    })?;
    Ok(Rows {
        samples: out,
        lines,
        t_col,
    })
}

/// Parses the CSV `reader` (the file `path`, for the errors) row by row, handing each sample
/// and its 1-based line to `row` as it is read; returns the 1-based column of `t_s`. What
/// [`parse`] and a recording read as a stream ([`crate::stream`]) both read with.
pub fn parse_each(
    path: &Path,
    reader: impl std::io::Read,
    mut row: impl FnMut(ImuSample, u64) -> Result<(), CsvError>,
) -> Result<usize, CsvError> {
    // Fields are trimmed here (`str::trim`, what csv's `Trim::All` does to a string record
    // after its ASCII pass): csv's trim builds a new record per row, a tenth of a long
    // recording's parse in allocations.
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(reader);
    let malformed = |e: csv::Error| CsvError::Malformed {
        path: path.to_owned(),
        line: e.position().map_or(0, |p| p.line()),
        message: e.to_string(),
    };
    let header = rdr.headers().map_err(malformed)?.clone();
    let mut idx = [0usize; 7];
    for (slot, name) in idx.iter_mut().zip(COLUMNS) {
        *slot = header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or_else(|| CsvError::MissingColumn {
                path: path.to_owned(),
                column: name,
                header: header.iter().map(str::trim).collect::<Vec<_>>().join(","),
            })?;
    }
    let mut rec = csv::StringRecord::new();
    let mut any = false;
    loop {
        match rdr.read_record(&mut rec) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(malformed(e)),
        }
        let line = rec.position().map_or(0, |p| p.line());
        let mut v = [0f64; 7];
        for (k, (&i, name)) in idx.iter().zip(COLUMNS).enumerate() {
            let text = rec.get(i).unwrap_or("").trim();
            v[k] = text
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| CsvError::BadNumber {
                    path: path.to_owned(),
                    line,
                    col: i + 1,
                    column: name,
                    text: text.to_owned(),
                })?;
        }
        any = true;
        row(
            ImuSample {
                t_s: v[0],
                acc_mps2: [v[1], v[2], v[3]],
                gyr_radps: [v[4], v[5], v[6]],
            },
            line,
        )?;
    }
    if !any {
        return Err(CsvError::Empty {
            path: path.to_owned(),
        });
    }
    Ok(idx[0] + 1)
}

/// Writes a trace as CSV. Values are printed in Rust's shortest round-trip form, so reading
/// the file back gives the same `f64`s and the same counts.
pub fn write(mut w: impl Write, samples: &[ImuSample]) -> std::io::Result<()> {
    writeln!(w, "{}", COLUMNS.join(","))?;
    for s in samples {
        writeln!(
            w,
            "{:.6},{},{},{},{},{},{}",
            s.t_s,
            s.acc_mps2[0],
            s.acc_mps2[1],
            s.acc_mps2[2],
            s.gyr_radps[0],
            s.gyr_radps[1],
            s.gyr_radps[2]
        )?;
    }
    Ok(())
}

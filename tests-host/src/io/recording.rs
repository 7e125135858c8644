//! Opening a recording whatever its name says: MCAP by its magic bytes, CSV otherwise, its
//! values in the units declared ([`crate::io::units`]).

use std::io::Read;
use std::path::Path;

use crate::io::csv_trace::{self, CsvError};
use crate::io::mcap_io::{self, McapError};
use crate::io::trace::Trace;
use crate::io::units::{AccUnit, Front, GyroUnit, Units};

/// The bytes every MCAP file starts with (the MCAP specification's magic).
pub const MCAP_MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// How far a rate given by hand may be from the stamps' before it is a contradiction: host
/// clocks drift by a few % and stay within it; a wrong rate (100 Hz for 204.8) does not.
pub const RATE_DISAGREES: f64 = 0.10;

/// What went wrong opening a recording: the reader's own error, or a rate given by hand
/// that the stamps contradict.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// Read as CSV.
    #[error(transparent)]
    Csv(#[from] CsvError),
    /// Read as MCAP.
    #[error(transparent)]
    Mcap(#[from] McapError),
    /// The rate given differs from the stamps' by more than [`RATE_DISAGREES`].
    #[error(
        "{path}: the rate given, {given_hz} Hz, is {pct:+.0} % off the stamps' {stamps_hz:.4} Hz: leave the rate out to replay on the stamps' clock, or {how} if the stamps are the ones that are wrong",
        path = path.display(),
        pct = (given_hz / stamps_hz - 1.0) * 100.0
    )]
    RateContradicts {
        /// The file.
        path: std::path::PathBuf,
        /// The rate given, Hz.
        given_hz: f64,
        /// The stamps' nominal rate, Hz ([`crate::io::clock::nominal_period`]).
        stamps_hz: f64,
        /// How to say the rate wins, at the front end used.
        how: &'static str,
    },
}

/// How a recording is to be read.
#[derive(Clone, Copy, Debug, Default)]
pub struct ReadOptions {
    /// The rate given by hand, Hz (else `meta.json`'s, else the stamps').
    pub rate_hz: Option<f64>,
    /// The rate given wins over stamps that contradict it (`--rate-overrides-stamps`).
    pub rate_overrides_stamps: bool,
    /// The values' units (else `meta.json`'s, else m/s² and rad/s).
    pub units: Option<Units>,
    /// Where the user declares units and rates (for the errors' advice).
    pub front: Front,
}

/// Whether `path` holds MCAP: its first bytes are [`MCAP_MAGIC`], or (a file too short or
/// unreadable to tell, or a git-LFS pointer standing in for it) its name ends in `.mcap`.
/// An MCAP file named `.csv` is read as MCAP; an un-fetched `.mcap` is named as a pointer by
/// the MCAP reader instead of failing as a CSV file without its columns.
pub fn is_mcap(path: &Path) -> bool {
    let mut head = [0u8; 8];
    let read = std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head));
    let named_mcap = || {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
    };
    match read {
        Ok(()) => &head == MCAP_MAGIC || (&head == b"version " && named_mcap()),
        Err(_) => named_mcap(),
    }
}

/// Reads a recording (CSV or MCAP, told by [`is_mcap`]) as `o` says: its values converted
/// and checked ([`crate::io::units`]); a rate given by hand checked against the stamps'.
pub fn read(path: &Path, o: &ReadOptions) -> Result<Trace, ReadError> {
    let trace = if is_mcap(path) {
        mcap_io::read_in(path, o.rate_hz, o.units, o.front)?
    } else {
        csv_trace::read_in(path, o.rate_hz, o.units, o.front)?
    };
    if let (Some(given_hz), false) = (o.rate_hz, o.rate_overrides_stamps) {
        if let Err(stamps_hz) = rate_agrees(&trace.samples, given_hz) {
            return Err(ReadError::RateContradicts {
                path: path.to_owned(),
                given_hz,
                stamps_hz,
                how: match o.front {
                    Front::CommandLine => "pass --rate-overrides-stamps",
                    Front::Python => "pass rate_overrides_stamps=True",
                },
            });
        }
    }
    Ok(trace)
}

/// `Err(the stamps' rate)` where `given_hz` is more than [`RATE_DISAGREES`] off the rate of
/// the samples' stamps; `Ok` where they agree or the stamps give none.
pub fn rate_agrees(samples: &[crate::io::trace::ImuSample], given_hz: f64) -> Result<(), f64> {
    match Trace::rate_from_timestamps(samples) {
        Some(stamps_hz) if (given_hz / stamps_hz - 1.0).abs() > RATE_DISAGREES => Err(stamps_hz),
        _ => Ok(()),
    }
}

/// The units of `path`'s values where the caller names one or both (`None` for both: the
/// file's own, `meta.json`'s or the datasets'): a sensor not named keeps `meta.json`'s unit
/// (an MCAP file has none: m/s² and rad/s).
pub fn declared_units(
    path: &Path,
    acc: Option<AccUnit>,
    gyro: Option<GyroUnit>,
) -> Result<Option<Units>, CsvError> {
    if acc.is_none() && gyro.is_none() {
        return Ok(None);
    }
    let meta = if is_mcap(path) {
        Units::default()
    } else {
        csv_trace::meta_units(path)?
    };
    Ok(Some(Units {
        acc: acc.unwrap_or(meta.acc),
        gyro: gyro.unwrap_or(meta.gyro),
    }))
}

//! A recording (CSV or MCAP) replayed in constant memory: a week at 100 Hz is 60 M samples,
//! and holding it (≈ 160 bytes a sample in the replay that reads it whole) would take 10 GB.
//!
//! **How.** The file is parsed once, row by row, into a spool (64 bytes a row: the stamp, the
//! six values, the line (CSV) or message index (MCAP) for the errors): in memory up to
//! [`MEMORY_SPOOL_BYTES`], on disk past it, in a file without a name that goes when the
//! replay ends, however the process ends (a `| head -1` ends it by SIGPIPE). An MCAP file is read twice for that, one record at a time
//! ([`crate::io::mcap_io::visit_records`]: its chunks' record lengths checked, then its
//! records decoded), as the reader that reads it whole does. Every step
//! that looks at the whole recording then reads the spool again from the start, in order,
//! keeping only what it needs, and the last pass feeds the core and hands each stride out
//! as the pipeline reports it. What each step keeps:
//!
//! | step | passes | kept |
//! |---|---|---|
//! | re-sent samples dropped ([`crate::io::clock::RepeatFilter`]) | every pass, on the fly | the last stamp |
//! | the nominal rate from the stamps, where none is given ([`crate::io::clock::nominal_period_of`]) | 1 + 4 + 1 | 65 536 counters: the median is an exact radix select |
//! | units ([`crate::io::units::check_of`]) | 2 + 4 + 4 | 65 536 counters (the quantiles the same way) |
//! | clock: the period refined, holes found, fitted ([`crate::io::clock::SampleClock::recover_of`]) | 1–4 + 2 per round (≤ 6) + 1 | the holes (16 bytes each), at most 65 536 fit points (1 MiB: one per 64 rows, coarser past 4.19 M rows), a window of 64 rows |
//! | holes placed in bursts ([`crate::io::clock::SampleClock::place_holes_of`]) | 1 | a window of 128 rows |
//! | rails ([`crate::io::rails::learn_counted_of`]) | 3 | per axis and side a few numbers |
//! | the core | 1 | the pipeline, the refused movements (a few per minute of not walking) |
//!
//! Every step runs the code the whole-recording replay runs ([`crate::replay`], the same
//! functions over a slice), with the same arithmetic in the same order: the output is
//! byte-identical (a test replays every shared CSV recording both ways, a sample of them
//! written as MCAP, the MCAP conformance files, and recordings with every fault the readers
//! handle or refuse). What grows with the recording is what it
//! holds: its holes (16 bytes each; `ipol_gait_events`' lossy link loses 2 % of its packets in
//! holes of 1–11) and the movements the step check refuses (a few per minute of not
//! walking). A week at 100 Hz of walks (60 M samples) peaks at about 14 MiB
//! (`tests-host/cost.sh`, docs/cost.md). A replay that writes the samples back out
//! (`--mcap-out`) still reads the recording whole.

use std::cell::RefCell;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use gaitclip::length::models::Model;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::sensor::rate::SampleRate;

use crate::io::clock::{nominal_period_of, RepeatFilter, SampleClock};
use crate::io::csv_trace::{self, CsvError};
use crate::io::mcap_io::{self, ImuMessages, McapError};
use crate::io::rails::{self, RailsReport};
use crate::io::recording::{self, ReadError, ReadOptions, RATE_DISAGREES};
use crate::io::trace::{GivenRanges, ImuSample, Ranges};
use crate::io::units::{self, Front, Units};
use crate::replay::{self, Preparation, ReplayError, StrideReport, StrideTally, Summary};

/// Bytes of a row in the spool: the stamp, six values and the line, eight bytes each.
pub const ROW_BYTES: usize = 64;

/// What a streamed replay can fail with: reading the recording, or preparing it.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// Reading (as [`crate::io::recording::read`] would fail).
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Preparing (as [`crate::replay::prepare`] would fail).
    #[error(transparent)]
    Replay(#[from] ReplayError),
}

/// A spool this small stays in memory, bytes (131 072 rows: 22 min at 100 Hz, 2.7 min at
/// 800 Hz); a longer recording's goes to disk, where it is read back in every pass. On a
/// short recording the file's creation and its passes' reads cost more than the replay (a
/// 39 s walk: 15 ms against 9 ms read whole); the memory a replay holds stays bounded either
/// way.
pub const MEMORY_SPOOL_BYTES: usize = 8 << 20;

/// A recording's rows in memory or on disk, to be read as often as needed; the file goes with
/// it.
pub struct Spool {
    store: Store,
    rows: usize,
    t_col: usize,
    source: PathBuf,
    /// The recording is MCAP (its errors are MCAP's).
    mcap: bool,
    /// A read of the spool that failed (the disk, not the recording): said at the end.
    failed: RefCell<Option<std::io::Error>>,
}

/// Where a spool's rows are.
enum Store {
    /// Up to [`MEMORY_SPOOL_BYTES`].
    Memory(Vec<u8>),
    /// A file in the temporary folder without a name ([`tempfile::tempfile`]): gone when
    /// its handle closes, however the process ends.
    Disk(File),
}

/// Writes a spool's rows: into memory, then, past [`MEMORY_SPOOL_BYTES`], all of them into
/// its file.
struct SpoolWriter {
    memory: Vec<u8>,
    disk: Option<BufWriter<File>>,
}

impl SpoolWriter {
    fn new() -> SpoolWriter {
        SpoolWriter {
            memory: Vec::new(),
            disk: None,
        }
    }

    /// Where a spool's file goes, for its errors (the file has no name).
    fn folder() -> PathBuf {
        std::env::temp_dir()
    }

    /// One row: the sample and its line (or index).
    fn write_row(&mut self, s: &ImuSample, line: u64) -> std::io::Result<()> {
        let mut b = [0u8; ROW_BYTES];
        let v = [
            s.t_s,
            s.acc_mps2[0],
            s.acc_mps2[1],
            s.acc_mps2[2],
            s.gyr_radps[0],
            s.gyr_radps[1],
            s.gyr_radps[2],
        ];
        for (k, x) in v.iter().enumerate() {
            b[8 * k..8 * k + 8].copy_from_slice(&x.to_le_bytes());
        }
        b[56..].copy_from_slice(&line.to_le_bytes());
        if self.disk.is_none() && self.memory.len() + ROW_BYTES > MEMORY_SPOOL_BYTES {
            let mut out = BufWriter::with_capacity(1 << 20, tempfile::tempfile()?);
            out.write_all(&std::mem::take(&mut self.memory))?;
            self.disk = Some(out);
        }
        match self.disk.as_mut() {
            Some(out) => out.write_all(&b),
            None => {
                self.memory.extend_from_slice(&b);
                Ok(())
            }
        }
    }

    /// The rows written, flushed to the file if they went there.
    fn finish(self) -> std::io::Result<Store> {
        match self.disk {
            Some(out) => Ok(Store::Disk(out.into_inner().map_err(|e| e.into_error())?)),
            None => Ok(Store::Memory(self.memory)),
        }
    }
}

/// A row of the spool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpooledRow {
    /// The sample as read (the file's units).
    pub sample: ImuSample,
    /// Its 1-based line in a CSV file; its 0-based index among an MCAP file's IMU
    /// messages.
    pub line: u64,
}

impl Spool {
    fn of(path: &Path, mcap: bool, store: Store, rows: usize, t_col: usize) -> Spool {
        Spool {
            store,
            rows,
            t_col,
            source: path.to_owned(),
            mcap,
            failed: RefCell::new(None),
        }
    }

    /// Parses the CSV file `path` into a spool in the temporary folder
    /// ([`std::env::temp_dir`]), with the errors [`csv_trace::read`] gives.
    pub fn of_csv(path: &Path) -> Result<Spool, CsvError> {
        let io = |source| CsvError::Io {
            path: path.to_owned(),
            source,
        };
        // A first read says what reading the whole file would (a folder: "Is a directory").
        let mut input = BufReader::with_capacity(1 << 20, File::open(path).map_err(io)?);
        std::io::BufRead::fill_buf(&mut input).map_err(io)?;
        let mut out = SpoolWriter::new();
        let spool_io = |source| CsvError::Io {
            path: SpoolWriter::folder(),
            source,
        };
        let mut rows = 0usize;
        let t_col = csv_trace::parse_each(path, input, |s, line| {
            rows += 1;
            out.write_row(&s, line).map_err(spool_io)
        })?;
        let store = out.finish().map_err(spool_io)?;
        Ok(Spool::of(path, false, store, rows, t_col))
    }

    /// Decodes the MCAP file `path` into a spool (its IMU channel's messages, in file
    /// order) with the errors [`mcap_io::decode`] gives before it drops re-sent samples,
    /// reading the file twice and holding one record at a time; the IMU channel's topic.
    pub fn of_mcap(path: &Path) -> Result<(Spool, String), McapError> {
        let io = |source| McapError::Io {
            path: path.to_owned(),
            source,
        };
        // A first read says what reading the whole file would (a folder: "Is a directory").
        let mut first = BufReader::new(File::open(path).map_err(io)?);
        std::io::BufRead::fill_buf(&mut first).map_err(io)?;
        let len = first.get_ref().metadata().map_err(io)?.len();
        drop(first);
        let mut out = SpoolWriter::new();
        let spool_io = |source| McapError::Io {
            path: SpoolWriter::folder(),
            source,
        };
        let mut imu = ImuMessages::new(path);
        let mut rows = 0usize;
        // The whole-file reader reads every record before it decodes a message, so an error
        // in a record later in the file wins over a message that does not decode: the first
        // such message's error is kept until the walk ends.
        let mut bad_message = None;
        let open = || {
            File::open(path)
                .map(|f| BufReader::with_capacity(1 << 20, f))
                .map_err(io)
        };
        mcap_io::visit_records(path, &open, len, |r| {
            if bad_message.is_some() {
                return Ok(());
            }
            match imu.take(r, rows) {
                Ok(Some(s)) => {
                    out.write_row(&s, rows as u64).map_err(spool_io)?;
                    rows += 1;
                }
                Ok(None) => {}
                Err(e) => bad_message = Some(e),
            }
            Ok(())
        })?;
        if let Some(e) = bad_message {
            return Err(e);
        }
        if rows == 0 {
            return Err(imu.no_imu_channel());
        }
        let store = out.finish().map_err(spool_io)?;
        Ok((
            Spool::of(path, true, store, rows, 1),
            imu.topic().to_owned(),
        ))
    }

    /// Rows in the spool.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The rows, in order, read again from the start.
    pub fn read(&self) -> SpoolRows<'_> {
        let reader = match &self.store {
            Store::Memory(rows) => Some(Rows::Memory(rows)),
            Store::Disk(file) => Some(Rows::Disk(BufReader::with_capacity(
                1 << 20,
                FileAt { file, at: 0 },
            ))),
        };
        SpoolRows {
            spool: self,
            reader,
            left: self.rows,
        }
    }

    /// The error a read of the spool met, if one did (as an error of the recording's file).
    fn failure(&self) -> Option<ReadError> {
        let path = self.source.clone();
        self.failed
            .borrow_mut()
            .take()
            .map(|source| match self.mcap {
                true => McapError::Io { path, source }.into(),
                false => CsvError::Io { path, source }.into(),
            })
    }
}

/// A pass over a spool's rows: the bytes left in memory, or the file.
enum Rows<'a> {
    Memory(&'a [u8]),
    Disk(BufReader<FileAt<'a>>),
}

/// A file read from `at` on, by position: passes over one file handle, each with its own
/// place (a cloned handle would share one).
struct FileAt<'a> {
    file: &'a File,
    at: u64,
}

impl Read for FileAt<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        #[cfg(unix)]
        let n = std::os::unix::fs::FileExt::read_at(self.file, buf, self.at)?;
        #[cfg(windows)]
        let n = std::os::windows::fs::FileExt::seek_read(self.file, buf, self.at)?;
        self.at += n as u64;
        Ok(n)
    }
}

impl Read for Rows<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Rows::Memory(rows) => rows.read(buf),
            Rows::Disk(file) => file.read(buf),
        }
    }
}

impl BufRead for Rows<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        match self {
            Rows::Memory(rows) => Ok(rows),
            Rows::Disk(file) => file.fill_buf(),
        }
    }

    fn consume(&mut self, n: usize) {
        match self {
            Rows::Memory(rows) => rows.consume(n),
            Rows::Disk(file) => file.consume(n),
        }
    }
}

/// The rows of a [`Spool`], in order.
pub struct SpoolRows<'a> {
    spool: &'a Spool,
    reader: Option<Rows<'a>>,
    left: usize,
}

impl Iterator for SpoolRows<'_> {
    type Item = SpooledRow;

    fn next(&mut self) -> Option<SpooledRow> {
        if self.left == 0 {
            return None;
        }
        let r = self.reader.as_mut()?;
        // The row from the buffer where it lies there whole (always, but after a short
        // read): a copy through `read_exact` per row was a tenth of a long replay's time.
        let row = match r.fill_buf() {
            Ok(buf) if buf.len() >= ROW_BYTES => {
                let row = SpooledRow::decode(&buf[..ROW_BYTES]);
                r.consume(ROW_BYTES);
                Ok(row)
            }
            Ok(_) => {
                let mut b = [0u8; ROW_BYTES];
                r.read_exact(&mut b).map(|()| SpooledRow::decode(&b))
            }
            Err(e) => Err(e),
        };
        match row {
            Ok(row) => {
                self.left -= 1;
                Some(row)
            }
            Err(e) => {
                self.spool.failed.borrow_mut().get_or_insert(e);
                self.reader = None;
                None
            }
        }
    }
}

impl SpooledRow {
    /// The row of `b`, [`ROW_BYTES`] long.
    fn decode(b: &[u8]) -> SpooledRow {
        let word = |k: usize| -> [u8; 8] { b[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]) };
        let f = |k: usize| f64::from_le_bytes(word(k));
        SpooledRow {
            sample: ImuSample {
                t_s: f(0),
                acc_mps2: [f(1), f(2), f(3)],
                gyr_radps: [f(4), f(5), f(6)],
            },
            line: u64::from_le_bytes(word(7)),
        }
    }
}

/// A CSV recording read as [`crate::io::recording::read`] reads it, kept on disk: its rows
/// without the re-sent ones, in SI units, as often as needed ([`Streamed::samples`]).
pub struct Streamed {
    spool: Spool,
    /// Re-sent samples are judged at this period.
    repeat_period_s: f64,
    /// Accelerometer and gyro values times these are SI.
    to_si: (f64, f64),
    /// Samples kept.
    kept: usize,
    /// Re-sent samples dropped.
    repeated: usize,
    /// The nominal rate, Hz (given, `meta.json`'s or the stamps').
    pub rate_hz: f64,
    /// The ranges the sensor was set to, where known.
    pub given: GivenRanges,
}

impl Streamed {
    /// Reads the recording `path` (CSV, or MCAP told by [`recording::is_mcap`]) as `o` says,
    /// with [`crate::io::recording::read`]'s checks and errors.
    pub fn open(path: &Path, o: &ReadOptions) -> Result<Streamed, ReadError> {
        let mcap = recording::is_mcap(path);
        // An MCAP file has no `meta.json`: its rate is the one given or the stamps', its
        // values m/s² and rad/s unless declared otherwise.
        let rate_given = match (o.rate_hz, mcap) {
            (Some(r), _) => Some(r),
            (None, true) => None,
            (None, false) => csv_trace::meta_rate(path)?,
        };
        let declared = match (o.units, mcap) {
            (Some(u), _) => u,
            (None, true) => Units::default(),
            (None, false) => csv_trace::meta_units(path)?,
        };
        let (spool, topic) = if mcap {
            let (spool, topic) = Spool::of_mcap(path)?;
            (spool, Some(topic))
        } else {
            (Spool::of_csv(path)?, None)
        };
        // Re-sent samples: at the rate known, else at the stamps' (as `Trace::drop_repeats`).
        let raw_stamps = || spool.read().map(|r| r.sample.t_s);
        let repeat_period_s = match rate_given {
            Some(r) if r > 0.0 => 1.0 / r,
            _ => nominal_period_of(&raw_stamps, spool.rows()).unwrap_or(0.0),
        };
        let mut filter = RepeatFilter::new(repeat_period_s);
        let mut kept = 0usize;
        for (i, r) in spool.read().enumerate() {
            match filter.keeps(i, r.sample.t_s) {
                Ok(true) => kept += 1,
                Ok(false) => {}
                Err(e) => {
                    return Err(match &topic {
                        Some(topic) => {
                            mcap_io::time_goes_back(path, topic, e.index, e.t_s, e.previous_s)
                                .into()
                        }
                        None => CsvError::TimeGoesBack {
                            path: path.to_owned(),
                            line: r.line,
                            col: spool.t_col,
                            t_s: e.t_s,
                            previous_s: e.previous_s,
                        }
                        .into(),
                    })
                }
            }
        }
        let mut s = Streamed {
            repeated: spool.rows() - kept,
            spool,
            repeat_period_s,
            to_si: (declared.acc.mps2(), declared.gyro.radps()),
            kept,
            rate_hz: 0.0,
            given: GivenRanges::default(),
        };
        if let Some(e) = s.spool.failure() {
            return Err(e);
        }
        units::check_of(&|| s.samples(), s.kept, declared, o.front).map_err(|unit| match mcap {
            true => ReadError::from(McapError::Units {
                path: path.to_owned(),
                unit,
            }),
            false => CsvError::Units {
                path: path.to_owned(),
                unit,
            }
            .into(),
        })?;
        let stamps_hz = |s: &Streamed| {
            nominal_period_of(&|| s.samples().map(|x| x.t_s), s.kept).map(|p| 1.0 / p)
        };
        s.rate_hz = match (rate_given, mcap) {
            (Some(r), _) => r,
            // As `mcap_io::decode`: no rate the stamps can give is 0 Hz, which the replay
            // refuses.
            (None, true) => stamps_hz(&s).unwrap_or(0.0),
            (None, false) => stamps_hz(&s).ok_or_else(|| CsvError::Empty {
                path: path.to_owned(),
            })?,
        };
        if !mcap {
            s.given = csv_trace::meta_ranges(path)?;
        }
        if let (Some(given_hz), false) = (o.rate_hz, o.rate_overrides_stamps) {
            if let Some(stamps_hz) =
                stamps_hz(&s).filter(|h| (given_hz / h - 1.0).abs() > RATE_DISAGREES)
            {
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
        if let Some(e) = s.spool.failure() {
            return Err(e);
        }
        Ok(s)
    }

    /// The samples kept (re-sent ones dropped), in SI units, in order, read again.
    pub fn samples(&self) -> impl Iterator<Item = ImuSample> + '_ {
        let mut filter = RepeatFilter::new(self.repeat_period_s);
        let (ka, kg) = self.to_si;
        self.spool
            .read()
            .enumerate()
            .filter(move |(i, r)| filter.keeps(*i, r.sample.t_s).unwrap_or(false))
            .map(move |(_, r)| {
                let mut s = r.sample;
                s.acc_mps2 = s.acc_mps2.map(|v| v * ka);
                s.gyr_radps = s.gyr_radps.map(|v| v * kg);
                s
            })
    }

    /// Samples kept.
    pub fn len(&self) -> usize {
        self.kept
    }

    /// Whether none was (a spool always holds one at least).
    pub fn is_empty(&self) -> bool {
        self.kept == 0
    }

    /// Replays the recording through the core as [`crate::replay::replay_clocked`] does,
    /// each stride handed to `stride` as the core reports it; the summary and the sample
    /// clock at the end.
    pub fn replay(
        &self,
        ranges: Ranges,
        detector: Detector,
        model: Model,
        all_models: bool,
        mut stride: impl FnMut(StrideReport),
    ) -> Result<(Summary, SampleClock), StreamError> {
        // `prepare`'s own pass over re-sent samples drops none: the kept stamps increase.
        let n = self.kept;
        let stamps = || self.samples().map(|s| s.t_s);
        let mut clock =
            SampleClock::recover_of(&stamps, n, Some(self.rate_hz)).ok_or(ReplayError::Empty)?;
        let mhz = (clock.rate_hz() * 1000.0).round();
        let rate = SampleRate::from_millihertz(mhz.clamp(0.0, u32::MAX as f64) as u32)
            .ok_or(ReplayError::Rate(clock.rate_hz()))?;
        let convert = ranges.converter();
        let counts = || self.samples().map(move |s| convert(&s));
        let rails: RailsReport =
            rails::learn_counted_of(&|| self.samples(), counts(), ranges, self.given);
        clock.place_holes_of(
            self.samples()
                .map(|s| (s.t_s, convert(&s).gyro.map(|v| v as f64))),
        );
        let mut config = Config::new(rate, ranges.accel.scale(), ranges.gyro.scale());
        config.rails = rails.rails;
        config.model = model;
        config.detector = detector;
        let mut tally = StrideTally::default();
        let run = replay::core_run_each(counts(), &clock.holes, config, |s, stats| {
            tally.add(&s);
            let mut r = StrideReport {
                stats,
                ..replay::report(s, config, &|n| clock.t_s(n))
            };
            if all_models && detector != Detector::PeakValley {
                replay::add_all_models(&mut r, config, rate);
            }
            stride(r);
        });
        if let Some(e) = self.spool.failure() {
            return Err(e.into());
        }
        let summary = Preparation {
            read: (self.kept + self.repeated, self.repeated),
            clock: &clock,
            rails: &rails,
            nominal_hz: self.rate_hz,
            rate,
        }
        .summary(&run, &tally);
        Ok((summary, clock))
    }
}

//! MCAP traces: IMU samples in gaitclip's own JSON schema or as ROS 2 `sensor_msgs/msg/Imu`
//! (CDR), and writing a trace together with its strides so both open in Foxglove.

use std::collections::BTreeMap;
use std::fs;
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::io::trace::{ImuSample, Trace};
use crate::io::units::{self, Front, Units};
use crate::replay::StrideReport;

/// Schema name of gaitclip's own IMU messages (JSON).
pub const IMU_SCHEMA: &str = "gaitclip.ImuSample";
/// Schema name of gaitclip's stride messages (JSON).
pub const STRIDE_SCHEMA: &str = "gaitclip.Stride";
/// Schema name of ROS 2 IMU messages.
pub const ROS2_IMU_SCHEMA: &str = "sensor_msgs/msg/Imu";
/// Topic gaitclip writes samples to.
pub const IMU_TOPIC: &str = "/imu";
/// Topic gaitclip writes strides to.
pub const STRIDE_TOPIC: &str = "/strides";
/// Schema name of the replay's summary (JSON, [`crate::replay::Summary`]).
pub const SUMMARY_SCHEMA: &str = "gaitclip.ReplaySummary";
/// Topic of the summary: one message at the end.
pub const SUMMARY_TOPIC: &str = "/summary";

const IMU_JSON_SCHEMA: &str = r#"{"type":"object","title":"gaitclip.ImuSample","properties":{"t_s":{"type":"number","description":"time, s"},"acc":{"type":"array","items":{"type":"number"},"description":"specific force x,y,z, m/s^2, sensor axes"},"gyr":{"type":"array","items":{"type":"number"},"description":"angular rate x,y,z, rad/s"}}}"#;
const STRIDE_JSON_SCHEMA: &str = r#"{"type":"object","title":"gaitclip.Stride","properties":{"index":{"type":"integer"},"start_s":{"type":"number"},"end_s":{"type":"number"},"length_m":{"type":"number"},"heel_off_s":{"type":"number"},"toe_off_s":{"type":"number"},"heel_strike_s":{"type":"number"},"foot_flat_s":{"type":"number"},"climb_m":{"type":"number"},"stride_time_s":{"type":"number"},"stance_time_s":{"type":"number"},"swing_time_s":{"type":"number"},"stance_pct":{"type":"number"},"swing_pct":{"type":"number"},"gait_velocity_m_s":{"type":"number"},"cadence_spm":{"type":"integer"},"max_sensor_lift_m":{"type":"number"},"turning_angle_deg":{"type":"number"},"gait":{"type":"string","enum":["walking","running","unknown"]},"valid":{"type":"boolean"},"flags":{"type":"array","items":{"type":"string"}}}}"#;

/// gaitclip's IMU message.
#[derive(Serialize, Deserialize)]
struct ImuJson {
    t_s: f64,
    acc: [f64; 3],
    gyr: [f64; 3],
}

/// What went wrong with an MCAP trace.
#[derive(Debug, thiserror::Error)]
pub enum McapError {
    /// Reading or writing the file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
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
    /// The file is not valid MCAP.
    #[error("{path}: not a readable MCAP file: {source}")]
    Format {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        source: mcap::McapError,
    },
    /// A record's fields do not fit it.
    #[error(
        "{path}: record with opcode {opcode:#04x}: {what} runs past the record or is not UTF-8"
    )]
    BadRecord {
        /// The file.
        path: PathBuf,
        /// The record's opcode.
        opcode: u8,
        /// The field.
        what: String,
    },
    /// The file is a git-LFS pointer: the recording itself was never fetched.
    #[error("{path}: a git-LFS pointer ({size} bytes of MCAP not fetched, {oid}), not an MCAP file: run `git lfs pull` in the repository it came from")]
    LfsPointer {
        /// The file.
        path: PathBuf,
        /// The object id the pointer names.
        oid: String,
        /// Size of the real file, bytes, as the pointer says.
        size: String,
    },
    /// No channel carries IMU samples.
    #[error("{path}: no IMU channel (schema `{IMU_SCHEMA}` or `{ROS2_IMU_SCHEMA}` with CDR); channels seen: {seen}")]
    NoImuChannel {
        /// The file.
        path: PathBuf,
        /// `topic (schema, encoding)` of each channel.
        seen: String,
    },
    /// A message on the IMU channel does not decode.
    #[error("{path}: message {index} on `{topic}`: {message}")]
    BadMessage {
        /// The file.
        path: PathBuf,
        /// 0-based index among the IMU messages.
        index: usize,
        /// The topic.
        topic: String,
        /// What is wrong.
        message: String,
    },
    /// Writing failed.
    #[error("writing MCAP: {0}")]
    Write(mcap::McapError),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum ImuKind {
    Json,
    Ros2Cdr,
}

fn imu_kind(schema: &str, message_encoding: &str) -> Option<ImuKind> {
    match (schema, message_encoding) {
        (IMU_SCHEMA, "json") => Some(ImuKind::Json),
        (ROS2_IMU_SCHEMA, "cdr") => Some(ImuKind::Ros2Cdr),
        _ => None,
    }
}

/// The largest record (or decompressed chunk) the reader accepts, bytes: far above any IMU
/// trace's chunks, far below what would exhaust a host's memory.
pub const MAX_RECORD_BYTES: usize = 256 << 20;

/// A schema, channel or message record as a streamed reader sees it (chunks opened, the
/// summary section included): what the MCAP conformance files list.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum McapRecord {
    /// A schema.
    Schema {
        /// Schema id.
        id: u16,
        /// Name.
        name: String,
        /// Encoding of the schema data.
        encoding: String,
        /// The schema itself.
        data: Vec<u8>,
    },
    /// A channel.
    Channel {
        /// Channel id.
        id: u16,
        /// Its schema (0: none).
        schema_id: u16,
        /// Topic.
        topic: String,
        /// Encoding of its messages.
        message_encoding: String,
        /// User metadata.
        metadata: BTreeMap<String, String>,
    },
    /// A message.
    Message {
        /// Its channel.
        channel_id: u16,
        /// Sequence number.
        sequence: u32,
        /// Log time, ns.
        log_time: u64,
        /// Publish time, ns.
        publish_time: u64,
        /// Payload.
        data: Vec<u8>,
    },
}

/// Reads every schema, channel and message record of an MCAP file's bytes, in file order;
/// `path` is only for error messages.
pub fn read_records(path: &Path, bytes: &[u8]) -> Result<Vec<McapRecord>, McapError> {
    let mut out = Vec::new();
    visit_records(path, &|| Ok(bytes), bytes.len() as u64, |r| {
        out.push(r);
        Ok(())
    })?;
    Ok(out)
}

/// The git-LFS pointer's first line: a file that starts with it was never fetched.
const LFS: &[u8] = b"version https://git-lfs.github.com/spec/v1\n";

/// Every schema, channel and message record of an MCAP file to `each`, in file order,
/// without holding the file: `open` gives its bytes from the start (read twice: once to
/// check the chunks' record lengths, once to read the records), `len` is their length.
/// `each`'s error stops the walk and is returned. The same checks and errors as
/// [`read_records`], which is this on bytes in memory.
pub fn visit_records<'a, R: Read + 'a>(
    path: &Path,
    open: &dyn Fn() -> Result<R, McapError>,
    len: u64,
    mut each: impl FnMut(McapRecord) -> Result<(), McapError>,
) -> Result<(), McapError> {
    let io = |source| McapError::Io {
        path: path.to_owned(),
        source,
    };
    let mut input = open()?;
    let mut head = Vec::with_capacity(LFS.len());
    (&mut input)
        .take(LFS.len() as u64)
        .read_to_end(&mut head)
        .map_err(io)?;
    if head == LFS {
        // A pointer is a few lines of text; read no more than a page of it.
        let mut rest = Vec::new();
        input.take(4096).read_to_end(&mut rest).map_err(io)?;
        let text = String::from_utf8_lossy(&rest);
        let field = |k: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(k))
                .unwrap_or("?")
                .trim()
                .to_owned()
        };
        return Err(McapError::LfsPointer {
            path: path.to_owned(),
            oid: field("oid "),
            size: field("size "),
        });
    }
    drop(input);
    check_uncompressed_chunks(path, open()?, len)?;
    let fmt = |source| McapError::Format {
        path: path.to_owned(),
        source,
    };
    // The `mcap` crate's sans-io reader, fed from the file in pieces of at most a MiB, with a
    // bound on record sizes: a chunk header may claim any uncompressed size, and the reader
    // allocates what it claims (found by fuzzing: 2⁵⁶ bytes aborts the process).
    let mut reader = mcap::sans_io::LinearReader::new_with_options(
        mcap::sans_io::LinearReaderOptions::default().with_record_length_limit(MAX_RECORD_BYTES),
    );
    let mut input = open()?;
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event.map_err(fmt)? {
            mcap::sans_io::LinearReadEvent::ReadRequest(need) => {
                let buf = reader.insert(need.min(1 << 20));
                let n = read_some(&mut input, buf).map_err(io)?;
                reader.notify_read(n);
                continue;
            }
            mcap::sans_io::LinearReadEvent::Record { data, opcode } => (opcode, data),
        };
        // Schema, channel and message records are decoded here, every length prefix checked
        // against the record: the `mcap` crate's parser reserves whatever a string's prefix
        // claims (found by fuzzing: 4 GiB for a header's library name). Other records carry
        // nothing a trace needs and are skipped.
        let bad = |what: &str| McapError::BadRecord {
            path: path.to_owned(),
            opcode,
            what: what.to_owned(),
        };
        let record = match opcode {
            mcap::records::op::SCHEMA => {
                let mut f = Fields(data);
                McapRecord::Schema {
                    id: f.u16().ok_or_else(|| bad("schema id"))?,
                    name: f.string().ok_or_else(|| bad("schema name"))?,
                    encoding: f.string().ok_or_else(|| bad("schema encoding"))?,
                    data: f.bytes().ok_or_else(|| bad("schema data"))?.to_vec(),
                }
            }
            mcap::records::op::CHANNEL => {
                let mut f = Fields(data);
                McapRecord::Channel {
                    id: f.u16().ok_or_else(|| bad("channel id"))?,
                    schema_id: f.u16().ok_or_else(|| bad("channel schema id"))?,
                    topic: f.string().ok_or_else(|| bad("channel topic"))?,
                    message_encoding: f.string().ok_or_else(|| bad("message encoding"))?,
                    metadata: f.map().ok_or_else(|| bad("channel metadata"))?,
                }
            }
            mcap::records::op::MESSAGE => {
                let mut f = Fields(data);
                McapRecord::Message {
                    channel_id: f.u16().ok_or_else(|| bad("message channel id"))?,
                    sequence: f.u32().ok_or_else(|| bad("message sequence"))?,
                    log_time: f.u64().ok_or_else(|| bad("message log time"))?,
                    publish_time: f.u64().ok_or_else(|| bad("message publish time"))?,
                    data: f.0.to_vec(),
                }
            }
            _ => continue,
        };
        each(record)?;
    }
    Ok(())
}

/// Fills as much of `buf` as `r` gives before its end (a short read is not the end).
fn read_some(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// The fields of an MCAP record, little-endian, read front to back; `None` when a field or
/// a length prefix runs past the record.
struct Fields<'a>(&'a [u8]);

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.0.len() {
            return None;
        }
        let (head, tail) = self.0.split_at(n);
        self.0 = tail;
        Some(head)
    }
    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.take(2)?.try_into().ok()?))
    }
    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }
    /// A `uint32` length and that many bytes.
    fn bytes(&mut self) -> Option<&'a [u8]> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    fn string(&mut self) -> Option<String> {
        String::from_utf8(self.bytes()?.to_vec()).ok()
    }
    /// A map of strings: a `uint32` byte length, then key-value pairs filling it.
    fn map(&mut self) -> Option<BTreeMap<String, String>> {
        let mut inner = Fields(self.bytes()?);
        let mut m = BTreeMap::new();
        while !inner.0.is_empty() {
            let k = inner.string()?;
            let v = inner.string()?;
            m.insert(k, v);
        }
        Some(m)
    }
}

/// Walks the file's top-level records and, inside every uncompressed chunk, the records'
/// lengths: the `mcap` crate's reader subtracts a record's length from what is left of the
/// chunk without checking it (found by fuzzing: an overflow panic in `linear_reader.rs`).
/// Whatever else is wrong with the file is left to that reader to report.
fn check_uncompressed_chunks(path: &Path, mut file: impl Read, len: u64) -> Result<(), McapError> {
    const CHUNK: u8 = 0x06;
    let io = |source| McapError::Io {
        path: path.to_owned(),
        source,
    };
    let bad = || McapError::BadRecord {
        path: path.to_owned(),
        opcode: CHUNK,
        what: "a record inside the chunk".to_owned(),
    };
    // Past the magic; each record an opcode, a length and its body.
    let mut left = len.saturating_sub(8);
    std::io::copy(&mut (&mut file).take(8), &mut std::io::sink()).map_err(io)?;
    while left > 8 {
        let mut header = [0u8; 9];
        file.read_exact(&mut header).map_err(io)?;
        left -= 9;
        let op = header[0];
        let record_len = u64::from_le_bytes(header[1..].try_into().unwrap_or([0; 8]));
        // A record running past the end of the file is read as far as it goes: the reader
        // streams a chunk's records before it knows the chunk is cut short.
        let n = record_len.min(left);
        left -= n;
        if op != CHUNK {
            std::io::copy(&mut (&mut file).take(n), &mut std::io::sink()).map_err(io)?;
            continue;
        }
        let mut body = Vec::new();
        (&mut file).take(n).read_to_end(&mut body).map_err(io)?;
        let mut chunk = Fields(&body);
        let header = (chunk.u64(), chunk.u64(), chunk.u64(), chunk.u32());
        let (Some(compression), Some(records_len)) = (chunk.bytes(), chunk.u64()) else {
            continue;
        };
        if !compression.is_empty() || header.3.is_none() {
            continue;
        }
        // Every record inside must fit in what the chunk declares is left.
        let mut declared = records_len;
        let mut inner = chunk;
        while declared > 0 {
            let (Some(_), Some(len)) = (inner.take(1), inner.u64()) else {
                break;
            };
            let whole = len
                .checked_add(9)
                .filter(|&w| w <= declared)
                .ok_or_else(bad)?;
            declared -= whole;
            let Some(_) = usize::try_from(len).ok().and_then(|n| inner.take(n)) else {
                break;
            };
        }
    }
    Ok(())
}

/// Reads the IMU samples of the first IMU channel (the first to carry a message) of an
/// MCAP file. The rate is `rate_hz` if given, else the stamps' ([`crate::io::clock::nominal_period`]).
/// Both schemas carry m/s² and rad/s (gaitclip's by its schema, ROS 2's by REP 103); the
/// values are checked in them ([`units::check`]).
pub fn read(path: &Path, rate_hz: Option<f64>) -> Result<Trace, McapError> {
    read_in(path, rate_hz, None, Front::CommandLine)
}

/// [`read`], the values in `units` where given (a recorder that wrote °/s or g into an SI
/// schema); a unit that fails the check says how to declare another at `front`.
pub fn read_in(
    path: &Path,
    rate_hz: Option<f64>,
    units: Option<Units>,
    front: Front,
) -> Result<Trace, McapError> {
    let bytes = fs::read(path).map_err(|source| McapError::Io {
        path: path.to_owned(),
        source,
    })?;
    let mut trace = decode(path, &bytes, rate_hz)?;
    units::apply(&mut trace.samples, units.unwrap_or_default(), front).map_err(|unit| {
        McapError::Units {
            path: path.to_owned(),
            unit,
        }
    })?;
    Ok(trace)
}

/// [`read`] on bytes already in memory; `path` is only for error messages.
pub fn decode(path: &Path, bytes: &[u8], rate_hz: Option<f64>) -> Result<Trace, McapError> {
    let records = read_records(path, bytes)?;
    let mut imu = ImuMessages::new(path);
    let mut samples: Vec<ImuSample> = Vec::new();
    for r in records {
        if let Some(s) = imu.take(r, samples.len())? {
            samples.push(s);
        }
    }
    if samples.is_empty() {
        return Err(imu.no_imu_channel());
    }
    let (samples, repeated) = Trace::drop_repeats(samples, rate_hz)
        .map_err(|e| time_goes_back(path, imu.topic(), e.index, e.t_s, e.previous_s))?;
    let rate_hz = rate_hz
        .or_else(|| Trace::rate_from_timestamps(&samples))
        .unwrap_or(0.0);
    Ok(Trace {
        samples,
        rate_hz,
        repeated,
        given: Default::default(),
    })
}

/// The error of the IMU message `index` on `topic` of the file `path`, whose stamp `t_s`
/// goes back from the previous one's by more than half a period
/// ([`crate::io::clock::TimeGoesBack`]).
pub fn time_goes_back(
    path: &Path,
    topic: &str,
    index: usize,
    t_s: f64,
    previous_s: f64,
) -> McapError {
    McapError::BadMessage {
        path: path.to_owned(),
        index,
        topic: topic.to_owned(),
        message: format!(
            "time {t_s} s goes back from the previous message's {previous_s} s by more than half a period"
        ),
    }
}

/// The IMU samples among an MCAP file's records, one record at a time: the schemas and
/// channels seen so far, and the IMU channel chosen (the first to carry a message). What
/// [`decode`] and the streamed replay (`crate::stream`) read a file with.
pub struct ImuMessages<'p> {
    path: &'p Path,
    /// Schema name by schema id.
    schemas: BTreeMap<u16, String>,
    /// (topic, schema id, encoding) by channel id.
    channels: BTreeMap<u16, (String, u16, String)>,
    chosen: Option<(u16, ImuKind)>,
}

impl<'p> ImuMessages<'p> {
    /// Nothing seen yet in the file `path` (for the errors).
    pub fn new(path: &'p Path) -> Self {
        ImuMessages {
            path,
            schemas: BTreeMap::new(),
            channels: BTreeMap::new(),
            chosen: None,
        }
    }

    /// The next record: the IMU sample it carries, if it is a message on the IMU channel
    /// (`index` the number of samples before it, for the errors).
    pub fn take(&mut self, r: McapRecord, index: usize) -> Result<Option<ImuSample>, McapError> {
        match r {
            McapRecord::Schema { id, name, .. } => {
                self.schemas.entry(id).or_insert(name);
                Ok(None)
            }
            McapRecord::Channel {
                id,
                schema_id,
                topic,
                message_encoding,
                ..
            } => {
                self.channels
                    .entry(id)
                    .or_insert((topic, schema_id, message_encoding));
                Ok(None)
            }
            McapRecord::Message {
                channel_id,
                log_time,
                data,
                ..
            } => {
                let Some((topic, schema_id, encoding)) = self.channels.get(&channel_id) else {
                    return Ok(None);
                };
                if self.chosen.is_none() {
                    let schema = self.schemas.get(schema_id).map_or("", String::as_str);
                    self.chosen = imu_kind(schema, encoding).map(|k| (channel_id, k));
                }
                let Some((id, kind)) = self.chosen else {
                    return Ok(None);
                };
                if channel_id != id {
                    return Ok(None);
                }
                let bad = |message: String| McapError::BadMessage {
                    path: self.path.to_owned(),
                    index,
                    topic: topic.clone(),
                    message,
                };
                let s = match kind {
                    ImuKind::Json => {
                        let j: ImuJson =
                            serde_json::from_slice(&data).map_err(|e| bad(e.to_string()))?;
                        ImuSample {
                            t_s: j.t_s,
                            acc_mps2: j.acc,
                            gyr_radps: j.gyr,
                        }
                    }
                    ImuKind::Ros2Cdr => {
                        let mut s = decode_ros2_imu(&data).map_err(bad)?;
                        if s.t_s == 0.0 {
                            s.t_s = log_time as f64 * 1e-9;
                        }
                        s
                    }
                };
                if !(s.t_s.is_finite()
                    && s.acc_mps2.iter().chain(&s.gyr_radps).all(|v| v.is_finite()))
                {
                    return Err(bad("non-finite value".into()));
                }
                Ok(Some(s))
            }
        }
    }

    /// The error of a file whose records held no IMU sample: the channels it has.
    pub fn no_imu_channel(&self) -> McapError {
        let seen = if self.channels.is_empty() {
            "none".to_owned()
        } else {
            self.channels
                .values()
                .map(|(t, sid, e)| {
                    let s = self.schemas.get(sid).map_or("no schema", String::as_str);
                    format!("{t} ({s}, {e})")
                })
                .collect::<Vec<_>>()
                .join(", ")
        };
        McapError::NoImuChannel {
            path: self.path.to_owned(),
            seen,
        }
    }

    /// The IMU channel's topic ("" before one is chosen).
    pub fn topic(&self) -> &str {
        self.chosen
            .and_then(|(id, _)| self.channels.get(&id))
            .map_or("", |c| c.0.as_str())
    }
}

/// Decodes a CDR-encoded ROS 2 `sensor_msgs/msg/Imu`: header stamp, frame id, orientation
/// and covariances are skipped except the stamp; angular velocity and linear acceleration
/// are read. Both little- and big-endian CDR are accepted.
pub fn decode_ros2_imu(data: &[u8]) -> Result<ImuSample, String> {
    let mut c = Cdr::new(data)?;
    let sec = c.u32()? as i32;
    let nanosec = c.u32()?;
    let len = c.u32()? as usize;
    c.skip(len)?; // frame_id, with its NUL
    let mut f = |n: usize| -> Result<Vec<f64>, String> { (0..n).map(|_| c.f64()).collect() };
    let _orientation = f(4)?;
    let _orientation_cov = f(9)?;
    let w = f(3)?;
    let _w_cov = f(9)?;
    let a = f(3)?;
    Ok(ImuSample {
        t_s: sec as f64 + nanosec as f64 * 1e-9,
        acc_mps2: [a[0], a[1], a[2]],
        gyr_radps: [w[0], w[1], w[2]],
    })
}

/// Encodes a ROS 2 `sensor_msgs/msg/Imu` as little-endian CDR (orientation unknown:
/// covariance[0] = −1 as REP 145 says).
pub fn encode_ros2_imu(s: &ImuSample, frame_id: &str) -> Vec<u8> {
    let mut b = vec![0x00, 0x01, 0x00, 0x00];
    let sec = s.t_s.floor();
    b.extend_from_slice(&(sec as i32).to_le_bytes());
    b.extend_from_slice(&(((s.t_s - sec) * 1e9).round() as u32).to_le_bytes());
    b.extend_from_slice(&(frame_id.len() as u32 + 1).to_le_bytes());
    b.extend_from_slice(frame_id.as_bytes());
    b.push(0);
    let put = |b: &mut Vec<u8>, v: f64| {
        while !(b.len() - 4).is_multiple_of(8) {
            b.push(0);
        }
        b.extend_from_slice(&v.to_le_bytes());
    };
    for v in [0.0, 0.0, 0.0, 1.0] {
        put(&mut b, v);
    }
    for k in 0..9 {
        put(&mut b, if k == 0 { -1.0 } else { 0.0 });
    }
    for v in s.gyr_radps {
        put(&mut b, v);
    }
    for _ in 0..9 {
        put(&mut b, 0.0);
    }
    for v in s.acc_mps2 {
        put(&mut b, v);
    }
    for _ in 0..9 {
        put(&mut b, 0.0);
    }
    b
}

struct Cdr<'a> {
    body: &'a [u8],
    pos: usize,
    little: bool,
}

impl<'a> Cdr<'a> {
    fn new(data: &'a [u8]) -> Result<Self, String> {
        let little = match data.get(..2) {
            Some([0x00, 0x01]) | Some([0x00, 0x03]) => true,
            Some([0x00, 0x00]) | Some([0x00, 0x02]) => false,
            _ => return Err("not a CDR encapsulation header".into()),
        };
        Ok(Cdr {
            body: &data[4.min(data.len())..],
            pos: 0,
            little,
        })
    }
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        self.pos = self.pos.div_ceil(N) * N;
        let s = self
            .body
            .get(self.pos..self.pos + N)
            .ok_or_else(|| format!("truncated at byte {}", self.pos + 4))?;
        self.pos += N;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        if !self.little {
            a.reverse();
        }
        Ok(a)
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take::<4>()?))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take::<8>()?))
    }
    fn skip(&mut self, n: usize) -> Result<(), String> {
        if self.pos + n > self.body.len() {
            return Err(format!("string runs past the end (length {n})"));
        }
        self.pos += n;
        Ok(())
    }
}

fn ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

/// Writes `samples` on [`IMU_TOPIC`], one message per stride on [`STRIDE_TOPIC`] and, when
/// given, the replay's summary on [`SUMMARY_TOPIC`] (stamped at the last sample).
pub fn write<W: Write + Seek>(
    w: W,
    samples: &[ImuSample],
    strides: &[StrideReport],
    summary: Option<&crate::replay::Summary>,
) -> Result<(), McapError> {
    let e = McapError::Write;
    let mut out = mcap::WriteOptions::new()
        .library("gaitclip")
        .create(w)
        .map_err(e)?;
    let meta = BTreeMap::new();
    let imu_schema = out
        .add_schema(IMU_SCHEMA, "jsonschema", IMU_JSON_SCHEMA.as_bytes())
        .map_err(e)?;
    let imu = out
        .add_channel(imu_schema, IMU_TOPIC, "json", &meta)
        .map_err(e)?;
    let stride_schema = out
        .add_schema(STRIDE_SCHEMA, "jsonschema", STRIDE_JSON_SCHEMA.as_bytes())
        .map_err(e)?;
    let st = out
        .add_channel(stride_schema, STRIDE_TOPIC, "json", &meta)
        .map_err(e)?;
    for (i, s) in samples.iter().enumerate() {
        let data = serde_json::to_vec(&ImuJson {
            t_s: s.t_s,
            acc: s.acc_mps2,
            gyr: s.gyr_radps,
        })
        .map_err(|x| McapError::Write(mcap::McapError::Io(x.into())))?;
        let h = mcap::records::MessageHeader {
            channel_id: imu,
            sequence: i as u32,
            log_time: ns(s.t_s),
            publish_time: ns(s.t_s),
        };
        out.write_to_known_channel(&h, &data).map_err(e)?;
    }
    for s in strides {
        let data =
            serde_json::to_vec(s).map_err(|x| McapError::Write(mcap::McapError::Io(x.into())))?;
        let h = mcap::records::MessageHeader {
            channel_id: st,
            sequence: s.index,
            log_time: ns(s.end_s),
            publish_time: ns(s.end_s),
        };
        out.write_to_known_channel(&h, &data).map_err(e)?;
    }
    if let Some(summary) = summary {
        let schema = out
            .add_schema(
                SUMMARY_SCHEMA,
                "jsonschema",
                br#"{"type":"object","title":"gaitclip.ReplaySummary"}"#,
            )
            .map_err(e)?;
        let ch = out
            .add_channel(schema, SUMMARY_TOPIC, "json", &meta)
            .map_err(e)?;
        let data = serde_json::to_vec(summary)
            .map_err(|x| McapError::Write(mcap::McapError::Io(x.into())))?;
        let t = samples.last().map_or(0, |s| ns(s.t_s));
        let h = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: t,
            publish_time: t,
        };
        out.write_to_known_channel(&h, &data).map_err(e)?;
    }
    out.finish().map_err(e)?;
    Ok(())
}

//! A CSV recording replayed as a stream ([`gaitclip_host::stream`], constant memory) gives
//! what the replay that reads it whole gives, to the byte: every shared recording, and
//! recordings with every fault the readers handle (re-sent and late samples, holes, a
//! host's bursts, units, rates) or refuse (with the same error).

use std::path::{Path, PathBuf};

use gaitclip::length::models::Model;
use gaitclip::pipeline::config::DEFAULT_MODEL;
use gaitclip::pipeline::detectors::Detector;
use gaitclip_host::io::datasets::root_or_skip;
use gaitclip_host::io::mcap_io;
use gaitclip_host::io::recording::{self, ReadOptions};
use gaitclip_host::io::trace::{ImuSample, Ranges};
use gaitclip_host::io::units::{AccUnit, Front, GyroUnit, Units};
use gaitclip_host::replay;
use gaitclip_host::stream::{StreamError, Streamed};

/// Both replays of `path` as `o` reads it: the strides' and the summary's JSON lines, or the
/// error's message.
fn both(path: &Path, o: &ReadOptions, detector: Detector, model: Model) -> [String; 2] {
    let whole = match recording::read(path, o) {
        Err(e) => format!("error: {e}"),
        Ok(t) => match replay::replay_summarised(&t, Ranges::default(), detector, model, true) {
            Err(e) => format!("error: {e}"),
            Ok((strides, summary)) => lines(&strides, &summary),
        },
    };
    let streamed = match Streamed::open(path, o) {
        Err(e) => format!("error: {e}"),
        Ok(s) => {
            let mut strides = Vec::new();
            match s.replay(Ranges::default(), detector, model, true, |r| {
                strides.push(r)
            }) {
                Err(StreamError::Read(e)) => format!("error: {e}"),
                Err(StreamError::Replay(e)) => format!("error: {e}"),
                Ok((summary, _)) => lines(&strides, &summary),
            }
        }
    };
    [whole, streamed]
}

fn lines(strides: &[replay::StrideReport], summary: &replay::Summary) -> String {
    let mut out: Vec<String> = strides
        .iter()
        .map(|s| serde_json::to_string(s).unwrap())
        .collect();
    out.push(serde_json::to_string(summary).unwrap());
    out.join("\n")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gaitclip-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The recordings under `dir`, sorted: every CSV file but the datasets' truth and index
/// tables.
fn recordings_under(dir: &Path) -> Vec<PathBuf> {
    let mut csvs: Vec<PathBuf> = Vec::new();
    let mut stack = vec![dir.to_owned()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() {
                stack.push(p);
            } else if name.ends_with(".csv")
                && !name.ends_with(".reference.csv")
                && !["strides.csv", "events.csv", "trials.csv", "labels.csv"]
                    .contains(&name.as_str())
            {
                csvs.push(p);
            }
        }
    }
    csvs.sort();
    csvs
}

/// A CSV file's rows as they stand (stamp and six values, no checks), or `None` if it has
/// none or is not there.
fn raw_rows(path: &Path) -> Option<Vec<ImuSample>> {
    let text = std::fs::read_to_string(path).ok()?;
    let rows: Vec<ImuSample> = text
        .lines()
        .skip(1)
        .filter_map(|l| {
            let v: Vec<f64> = l
                .split(',')
                .map(|c| c.trim().parse().ok())
                .collect::<Option<_>>()?;
            (v.len() >= 7).then(|| ImuSample {
                t_s: v[0],
                acc_mps2: [v[1], v[2], v[3]],
                gyr_radps: [v[4], v[5], v[6]],
            })
        })
        .collect();
    (!rows.is_empty()).then_some(rows)
}

/// `rows` as an MCAP file of gaitclip's IMU messages at `path`.
fn write_mcap(path: &Path, rows: &[ImuSample]) {
    let f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    mcap_io::write(f, rows, &[], None).unwrap();
}

#[test]
fn shared_recordings_written_as_mcap_stream_to_the_same_bytes() {
    let Some(root) = root_or_skip("shared_recordings_written_as_mcap_stream_to_the_same_bytes")
    else {
        return;
    };
    // Every dataset's first recordings, each up to 200 000 samples (the courses' 800 Hz
    // recordings run to millions: as MCAP, JSON messages of 150 bytes each).
    let d = scratch("stream-mcap");
    let mut written = 0;
    let mut datasets: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    datasets.sort();
    for dataset in &datasets {
        let csvs = recordings_under(dataset);
        let mut here = 0;
        for p in &csvs {
            if here == 3 {
                break;
            }
            // The recording as the whole reader reads it (its units, `meta.json`'s rate),
            // written as MCAP in SI units with that rate given.
            let Ok(t) = recording::read(p, &ReadOptions::default()) else {
                continue;
            };
            if t.samples.len() > 200_000 {
                continue;
            }
            let m = d.join(format!("{written}.mcap"));
            write_mcap(&m, &t.samples);
            let o = ReadOptions {
                rate_hz: Some(t.rate_hz),
                ..ReadOptions::default()
            };
            let [whole, streamed] = both(&m, &o, Detector::Cycle, DEFAULT_MODEL);
            assert!(!whole.starts_with("error"), "{}: {whole}", p.display());
            assert!(
                whole == streamed,
                "{} as MCAP: streamed differs",
                p.display()
            );
            here += 1;
            written += 1;
        }
    }
    assert!(written >= 12, "{written} recordings written as MCAP");
    eprintln!("{written} recordings written as MCAP streamed to the same bytes");
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn every_shared_recording_streams_to_the_same_bytes() {
    let Some(root) = root_or_skip("every_shared_recording_streams_to_the_same_bytes") else {
        return;
    };
    let csvs = recordings_under(&root);
    assert!(csvs.len() >= 300, "{} recordings", csvs.len());
    for p in &csvs {
        let [whole, streamed] = both(p, &ReadOptions::default(), Detector::Cycle, DEFAULT_MODEL);
        assert!(whole == streamed, "{}: streamed differs", p.display());
    }
    eprintln!("{} recordings streamed to the same bytes", csvs.len());
}

#[test]
fn faults_stream_to_the_same_bytes_and_errors() {
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.csv");
    let text = std::fs::read_to_string(&demo).unwrap();
    let (header, rows): (&str, Vec<&str>) = {
        let mut l = text.lines();
        (l.next().unwrap(), l.collect())
    };
    let d = scratch("stream-faults");
    let write = |name: &str, rows: &[String]| {
        let p = d.join(name);
        std::fs::write(&p, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
        p
    };
    let owned: Vec<String> = rows.iter().map(|r| r.to_string()).collect();
    let restamp = |rows: &[String], f: &dyn Fn(usize, f64) -> f64| -> Vec<String> {
        rows.iter()
            .enumerate()
            .map(|(i, r)| {
                let (t, rest) = r.split_once(',').unwrap();
                format!("{},{rest}", f(i, t.parse::<f64>().unwrap()))
            })
            .collect()
    };
    let mut cases: Vec<(PathBuf, ReadOptions)> = Vec::new();
    let plain = ReadOptions::default();
    // As recorded; with the rate taken from the stamps (no meta.json beside it).
    cases.push((write("plain.csv", &owned), plain));
    // Re-sent samples (a repeated row, one a little early) and late stamps.
    let mut resent = owned.clone();
    resent.insert(400, owned[399].clone());
    resent.insert(900, restamp(&owned[899..900], &|_, t| t - 0.001)[0].clone());
    let resent = restamp(&resent, &|i, t| if i % 97 == 5 { t + 0.0031 } else { t });
    cases.push((write("resent.csv", &resent), plain));
    // Holes: one sample, ten, a second; a host's bursts around one.
    let mut holes = owned.clone();
    holes.drain(3000..3200);
    holes.drain(2000..2010);
    holes.remove(1000);
    // A host's bursts: eight rows stamped microseconds apart when the last of them came,
    // with three samples lost inside one.
    let mut burst_rows = holes.clone();
    burst_rows.drain(1520..1523);
    let last_of_burst: Vec<f64> = burst_rows
        .iter()
        .map(|r| r.split_once(',').unwrap().0.parse::<f64>().unwrap())
        .collect();
    let bursty = restamp(&burst_rows, &|i, t| {
        if (1480..1560).contains(&i) {
            let end = (i / 8) * 8 + 7;
            last_of_burst[end] + (i - (i / 8) * 8) as f64 * 1e-6
        } else {
            t
        }
    });
    cases.push((write("holes.csv", &holes), plain));
    cases.push((write("bursts.csv", &bursty), plain));
    // A rate given: right, contradicted, contradicted but to win.
    let given = |hz: f64, wins: bool| ReadOptions {
        rate_hz: Some(hz),
        rate_overrides_stamps: wins,
        ..plain
    };
    cases.push((d.join("plain.csv"), given(200.0, false)));
    cases.push((d.join("plain.csv"), given(100.0, false)));
    cases.push((d.join("plain.csv"), given(100.0, true)));
    // Units: the values in g declared as m/s² (refused, naming g), and declared as g.
    let in_g: Vec<String> = owned
        .iter()
        .map(|r| {
            let v: Vec<f64> = r.split(',').map(|c| c.parse().unwrap()).collect();
            let mut c: Vec<String> = vec![v[0].to_string()];
            c.extend(v[1..4].iter().map(|a| (a / 9.80665).to_string()));
            c.extend(v[4..].iter().map(|g| g.to_string()));
            c.join(",")
        })
        .collect();
    let g = write("in_g.csv", &in_g);
    cases.push((g.clone(), plain));
    cases.push((
        g,
        ReadOptions {
            units: Some(Units {
                acc: AccUnit::G,
                gyro: GyroUnit::RadiansPerSecond,
            }),
            front: Front::Python,
            ..plain
        },
    ));
    // Refused: a stamp going back, a cell that is not a number, no samples, no file.
    let mut back = owned.clone();
    back.swap(500, 700);
    cases.push((write("back.csv", &back), plain));
    let mut bad = owned.clone();
    bad[42] = bad[42].replacen(',', ",x", 1);
    cases.push((write("bad.csv", &bad), plain));
    cases.push((write("empty.csv", &[]), plain));
    cases.push((d.join("missing.csv"), plain));
    // The same as MCAP (gaitclip's JSON IMU messages, stamps and values as the rows hold
    // them), with the same options; and what only MCAP can get wrong.
    let mut mcap_cases: Vec<(PathBuf, ReadOptions)> = Vec::new();
    for (p, o) in &cases {
        if let Some(rows) = raw_rows(p) {
            let m = p.with_extension("mcap");
            write_mcap(&m, &rows);
            mcap_cases.push((m, *o));
        }
    }
    let mut non_finite = raw_rows(&d.join("plain.csv")).unwrap();
    non_finite[77].gyr_radps[1] = f64::NAN;
    let nan = d.join("nan.mcap");
    write_mcap(&nan, &non_finite);
    mcap_cases.push((nan, plain));
    let good = std::fs::read(d.join("plain.mcap")).unwrap();
    for (name, bytes) in [
        // Cut in the middle of a message (no summary, no footer).
        ("cut.mcap", good[..good.len() / 2].to_vec()),
        // A git-LFS pointer where the recording should be.
        (
            "pointer.mcap",
            b"version https://git-lfs.github.com/spec/v1\noid sha256:abc\nsize 1234\n".to_vec(),
        ),
        // The magic alone.
        ("magic.mcap", good[..8].to_vec()),
    ] {
        let m = d.join(name);
        std::fs::write(&m, bytes).unwrap();
        mcap_cases.push((m, plain));
    }
    let mut data_dir = d.join("folder.mcap");
    std::fs::create_dir_all(&data_dir).unwrap();
    mcap_cases.push((data_dir.clone(), plain));
    data_dir.push("missing.mcap");
    mcap_cases.push((data_dir, plain));
    // The MCAP conformance files (none carries IMU messages: each one's error, both ways).
    let conformance =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/mcap-conformance");
    let mut stack = vec![conformance];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "mcap") {
                mcap_cases.push((p, plain));
            }
        }
    }
    mcap_cases.sort_by(|a, b| a.0.cmp(&b.0));
    eprintln!("{} MCAP cases", mcap_cases.len());
    cases.extend(mcap_cases);
    for (p, o) in &cases {
        for (det, model) in [
            (Detector::Cycle, DEFAULT_MODEL),
            (Detector::Stance, DEFAULT_MODEL),
        ] {
            let [whole, streamed] = both(p, o, det, model);
            let last = whole.lines().last().unwrap_or("");
            eprintln!(
                "{} {det:?}: {}",
                p.file_name().unwrap().to_string_lossy(),
                &last[..last.len().min(150)]
            );
            assert!(
                whole == streamed,
                "{} ({o:?}, {det:?}):\nwhole:    {}\nstreamed: {}",
                p.display(),
                whole.lines().last().unwrap_or(""),
                streamed.lines().last().unwrap_or("")
            );
        }
    }
    // An un-fetched `.mcap` is named as the pointer it is, both ways.
    let [whole, streamed] = both(
        &d.join("pointer.mcap"),
        &plain,
        Detector::Cycle,
        DEFAULT_MODEL,
    );
    assert!(
        whole.contains("a git-LFS pointer") && whole == streamed,
        "{whole}"
    );
    let _ = std::fs::remove_dir_all(d);
}

/// A recording too long for the spool in memory ([`gaitclip_host::stream::MEMORY_SPOOL_BYTES`])
/// goes to its file part-way through: two of the shared courses end to end (146 k rows at
/// 800 Hz), as CSV and as MCAP, stream to the bytes the whole replay gives.
#[test]
fn a_recording_past_the_memory_spool_streams_to_the_same_bytes() {
    let Some(root) = root_or_skip("a_recording_past_the_memory_spool_streams_to_the_same_bytes")
    else {
        return;
    };
    let courses = recordings_under(&root.join("esangeni_course"));
    let mut rows: Vec<ImuSample> = Vec::new();
    for p in courses.iter().take(2) {
        let t = recording::read(p, &ReadOptions::default()).unwrap();
        // The second course's stamps go on from the first's, a period apart.
        let shift = rows
            .last()
            .map_or(0.0, |l| l.t_s + 1.0 / t.rate_hz - t.samples[0].t_s);
        rows.extend(t.samples.iter().map(|s| ImuSample {
            t_s: s.t_s + shift,
            ..*s
        }));
    }
    let past = gaitclip_host::stream::MEMORY_SPOOL_BYTES / gaitclip_host::stream::ROW_BYTES;
    assert!(
        rows.len() > past,
        "{} rows, the memory spool holds {past}",
        rows.len()
    );
    let d = scratch("stream-long");
    let csv = d.join("long.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&csv).unwrap());
    gaitclip_host::io::csv_trace::write(&mut f, &rows).unwrap();
    drop(f);
    let mcap = d.join("long.mcap");
    write_mcap(&mcap, &rows);
    let o = ReadOptions {
        rate_hz: Some(800.0),
        ..ReadOptions::default()
    };
    for p in [&csv, &mcap] {
        let [whole, streamed] = both(p, &o, Detector::Cycle, DEFAULT_MODEL);
        assert!(!whole.starts_with("error"), "{}: {whole}", p.display());
        assert!(whole.lines().count() > 100, "{}: {whole}", p.display());
        assert!(whole == streamed, "{}: streamed differs", p.display());
    }
    let _ = std::fs::remove_dir_all(d);
}

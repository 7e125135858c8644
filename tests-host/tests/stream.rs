//! A CSV recording replayed as a stream ([`gaitclip_host::stream`], constant memory) gives
//! what the replay that reads it whole gives, to the byte: every shared recording, and
//! recordings with every fault the readers handle (re-sent and late samples, holes, a
//! host's bursts, units, rates) or refuse (with the same error).

use std::path::{Path, PathBuf};

use gaitclip::length::models::Model;
use gaitclip::pipeline::config::DEFAULT_MODEL;
use gaitclip::pipeline::detectors::Detector;
use gaitclip_host::io::datasets::root_or_skip;
use gaitclip_host::io::recording::{self, ReadOptions};
use gaitclip_host::io::trace::Ranges;
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

#[test]
fn every_shared_recording_streams_to_the_same_bytes() {
    let Some(root) = root_or_skip("every_shared_recording_streams_to_the_same_bytes") else {
        return;
    };
    let mut csvs: Vec<PathBuf> = Vec::new();
    let mut stack = vec![root.clone()];
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
    let _ = std::fs::remove_dir_all(d);
}

//! Wrong units are refused, not replayed into a wrong distance: the simulated demo walk (our
//! own fixture) written with its accelerometer in g, in mg, its gyro in °/s, each refused with
//! the unit it looks like and the flag that says so, and replayed to the same strides once
//! the unit is declared (flag or `meta.json`). An MCAP file named `.csv` is read as MCAP; an
//! error's cause is printed once.

use crate::common;

use std::path::{Path, PathBuf};

use common::{fixture, gaitclip, scratch};

fn demo() -> PathBuf {
    fixture("demo_walk.csv")
}

/// The demo walk with its accelerometer values times `acc` and its gyro's times `gyr`.
fn rescaled(dir: &Path, acc: f64, gyr: f64) -> PathBuf {
    let text = std::fs::read_to_string(demo()).unwrap();
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        if i == 0 {
            out += line;
        } else {
            let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            out += &format!("{}", v[0]);
            for (k, x) in v[1..].iter().enumerate() {
                out += &format!(",{}", x * if k < 3 { acc } else { gyr });
            }
        }
        out.push('\n');
    }
    let p = dir.join("walk.csv");
    std::fs::write(&p, out).unwrap();
    p
}

/// The summary line: strides, distance, samples, clock.
fn summary(stdout: &str) -> String {
    stdout
        .lines()
        .find(|l| l.starts_with("summary:"))
        .unwrap_or_else(|| panic!("no summary in {stdout}"))
        .to_owned()
}

#[test]
fn an_accelerometer_in_g_is_refused_until_declared() {
    let (code, good, err) = gaitclip(&["replay", demo().to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let d = scratch("units-g");
    let p = rescaled(&d, 1.0 / 9.80665, 1.0);
    let (code, _, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("looks like g") || err.contains("look like g"),
        "{err}"
    );
    assert!(err.contains("--acc-unit g"), "{err}");
    // Declared by the flag, or by a meta.json beside it: the demo walk's strides again.
    let (code, out, err) = gaitclip(&["replay", p.to_str().unwrap(), "--acc-unit", "g"]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(summary(&out), summary(&good));
    std::fs::write(d.join("meta.json"), r#"{"units": {"acc": "g"}}"#).unwrap();
    let (code, out, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(summary(&out), summary(&good));
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn milli_g_and_a_gyro_in_degrees_are_named() {
    let d = scratch("units-mg");
    let p = rescaled(&d, 1000.0 / 9.80665, 1.0);
    let (code, _, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("--acc-unit mg"), "{err}");
    let d2 = scratch("units-dps");
    let p = rescaled(&d2, 1.0, 180.0 / std::f64::consts::PI);
    let (code, _, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("--gyr-unit deg/s"), "{err}");
    let (code, out, err) = gaitclip(&["replay", p.to_str().unwrap(), "--gyr-unit", "deg/s"]);
    assert_eq!(code, Some(0), "{err}");
    let (_, good, _) = gaitclip(&["replay", demo().to_str().unwrap()]);
    assert_eq!(summary(&out), summary(&good));
    // rad/s declared as °/s: the foot steps but the gyro barely turns.
    let (code, _, err) = gaitclip(&["replay", demo().to_str().unwrap(), "--gyr-unit", "deg/s"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("--gyr-unit rad/s"), "{err}");
    // A unit that does not exist is a usage error naming the ones that do.
    let (code, _, err) = gaitclip(&["replay", demo().to_str().unwrap(), "--acc-unit", "ft/s^2"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("m/s^2, g, mg"), "{err}");
    let _ = std::fs::remove_dir_all(d);
    let _ = std::fs::remove_dir_all(d2);
}

#[test]
fn an_mcap_named_csv_is_read_as_mcap() {
    let d = scratch("units-mcap");
    let mcap = d.join("walk.mcap");
    let (code, good, err) = gaitclip(&[
        "replay",
        demo().to_str().unwrap(),
        "--mcap-out",
        mcap.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let renamed = d.join("walk.csv");
    std::fs::rename(&mcap, &renamed).unwrap();
    let (code, out, err) = gaitclip(&["replay", renamed.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(
        out.lines().filter(|l| l.starts_with("stride")).count(),
        good.lines().filter(|l| l.starts_with("stride")).count()
    );
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn a_cause_is_printed_once() {
    let d = scratch("units-dir");
    let (code, _, err) = gaitclip(&["replay", d.to_str().unwrap()]);
    assert_eq!(code, Some(66), "{err}");
    assert_eq!(err.matches("Is a directory").count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn the_text_line_labels_its_phases_and_shows_flags() {
    let (code, out, err) = gaitclip(&["replay", demo().to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let strides: Vec<&str> = out.lines().filter(|l| l.starts_with("stride")).collect();
    assert!(strides.len() > 10);
    for l in &strides {
        for label in [
            "stance ",
            "swing ",
            "phases: flat ",
            "push-off ",
            "landing ",
        ] {
            assert!(l.contains(label), "{l}");
        }
    }
    // The demo walk's turn: its strides carry the `turn` flag, shown though they are valid.
    let (_, json, _) = gaitclip(&["replay", demo().to_str().unwrap(), "--json"]);
    let flagged_valid = json
        .lines()
        .filter(|l| l.starts_with("{\"index\""))
        .filter(|l| l.contains("\"valid\":true") && !l.contains("\"flags\":[]"))
        .count();
    let shown = strides.iter().filter(|l| l.contains("  flags ")).count();
    assert_eq!(shown, flagged_valid, "{out}");
}

/// The demo walk with its stamps times `k` (ms for 1000) or rounded to `decimals`.
fn restamped(dir: &Path, k: f64, decimals: usize) -> PathBuf {
    let text = std::fs::read_to_string(demo()).unwrap();
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        match (i, line.split_once(',')) {
            (0, _) | (_, None) => out += line,
            (_, Some((t, rest))) => {
                let t: f64 = t.parse().unwrap();
                out += &format!("{:.*},{rest}", decimals, t * k);
            }
        }
        out.push('\n');
    }
    let p = dir.join("walk.csv");
    std::fs::write(&p, out).unwrap();
    p
}

#[test]
fn contradictions_in_the_clock_are_caught() {
    let demo = demo();
    // A rate the stamps contradict: refused, unless it is to win.
    let (code, _, err) = gaitclip(&["replay", demo.to_str().unwrap(), "--rate", "100"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("--rate-overrides-stamps"), "{err}");
    let (code, _, err) = gaitclip(&[
        "replay",
        demo.to_str().unwrap(),
        "--rate",
        "100",
        "--rate-overrides-stamps",
    ]);
    assert_eq!(code, Some(0), "{err}");
    // A host clock a few % off is the caller's to give.
    let (code, _, err) = gaitclip(&["replay", demo.to_str().unwrap(), "--rate", "196"]);
    assert_eq!(code, Some(0), "{err}");
    // Stamps in ms: the hint.
    let d = scratch("units-ms");
    let p = restamped(&d, 1000.0, 3);
    let (code, _, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("are the stamps in milliseconds?"), "{err}");
    // Stamps rounded to 0.1 ms at an odd rate: the rate is the sensor's, no false ppm.
    let d2 = scratch("units-rounded");
    let p = restamped(&d2, 200.0 / 204.8, 4);
    let (code, out, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let line = summary(&out);
    let after = |key: &str| -> f64 {
        let at = line
            .find(key)
            .unwrap_or_else(|| panic!("no {key} in {line}"))
            + key.len();
        line[at..]
            .split([' ', ','])
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let nominal = after("(nominal ");
    assert!((nominal - 204.8).abs() < 0.05, "{line}");
    let ppm = after("Hz, ");
    assert!(ppm.abs() < 100.0, "{line}");
    let _ = std::fs::remove_dir_all(d);
    let _ = std::fs::remove_dir_all(d2);
}

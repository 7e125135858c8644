//! What a user sees when an input is wrong: the `gaitclip` command names the file, line and
//! column or the channels it saw, and its exit status tells bad input (65), an unreadable
//! file (66) and an unwritable output (74) from internal errors (70).

use std::path::PathBuf;
use std::process::Command;

use crate::common;

/// `gaitclip args`: its exit status and what it said on stderr.
fn gaitclip(args: &[&str]) -> (Option<i32>, String) {
    let (code, _, stderr) = common::gaitclip(args);
    (code, stderr)
}

fn tmp(name: &str, bytes: &[u8]) -> PathBuf {
    let p = std::env::temp_dir().join(format!("gaitclip-cli-{}-{name}", std::process::id()));
    std::fs::write(&p, bytes).unwrap();
    p
}

const HEADER: &str = "t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n";

#[test]
fn a_malformed_csv_cell_is_bad_input_named_by_line_and_column() {
    let p = tmp(
        "cell.csv",
        format!("{HEADER}0,0,0,9.8,0,0,0\n0.005,0,0,9.8,0,x,0\n").as_bytes(),
    );
    let (code, err) = gaitclip(&["replay", p.to_str().unwrap(), "--rate", "200"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("bad input"), "{err}");
    assert!(
        err.contains(&format!("{}:3:6: column `gyr_y`: `x`", p.display())),
        "{err}"
    );
    let _ = std::fs::remove_file(p);
}

#[test]
fn a_missing_column_is_bad_input_and_named() {
    let p = tmp(
        "col.csv",
        b"t_s,acc_x,acc_y,acc_z,gyr_x,gyr_z\n0,0,0,9.8,0,0\n",
    );
    let (code, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("missing column `gyr_y`"), "{err}");
    let _ = std::fs::remove_file(p);
}

#[test]
fn time_going_back_is_bad_input_with_its_line() {
    let p = tmp(
        "time.csv",
        format!("{HEADER}0,0,0,9.8,0,0,0\n0.005,0,0,9.8,0,0,0\n0.010,0,0,9.8,0,0,0\n0.001,0,0,9.8,0,0,0\n")
            .as_bytes(),
    );
    let (code, err) = gaitclip(&["replay", p.to_str().unwrap(), "--rate", "200"]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains(&format!(
            "{}:5:1: column `t_s`: 0.001 goes back from the previous sample's 0.01",
            p.display()
        )),
        "{err}"
    );
    let _ = std::fs::remove_file(p);
}

/// A re-sent sample (the same stamp again) is dropped, counted and reported in the summary,
/// in text and in JSON; the replay goes on.
#[test]
fn a_repeated_sample_is_dropped_and_reported() {
    let mut text = String::from(HEADER);
    for i in 0..400 {
        text += &format!("{},0,0,9.80665,0,0,0\n", i as f64 * 0.005);
        if i == 100 {
            text += &format!("{},0.1,0,9.80665,0,0,0\n", i as f64 * 0.005);
        }
    }
    let p = tmp("repeat.csv", text.as_bytes());
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(["replay", p.to_str().unwrap(), "--rate", "200"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or("");
    assert!(
        last.starts_with("summary:") && last.contains("401 samples read, 1 repeated dropped"),
        "{stdout}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(["replay", p.to_str().unwrap(), "--rate", "200", "--json"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    assert_eq!(v["summary"]["repeated_dropped"], 1, "{stdout}");
    assert_eq!(v["summary"]["samples_read"], 401, "{stdout}");
    let _ = std::fs::remove_file(p);
}

#[test]
fn a_missing_file_is_no_input() {
    let (code, err) = gaitclip(&["replay", "/nonexistent/walk.csv"]);
    assert_eq!(code, Some(66), "{err}");
    assert!(err.contains("/nonexistent/walk.csv"), "{err}");
}

#[test]
fn an_mcap_without_imu_lists_its_channels() {
    let mut w = mcap::Writer::new(std::io::Cursor::new(Vec::new())).unwrap();
    let schema = w.add_schema("foo.Gps", "jsonschema", b"{}").unwrap();
    let ch = w
        .add_channel(schema, "/gps", "json", &Default::default())
        .unwrap();
    let h = mcap::records::MessageHeader {
        channel_id: ch,
        sequence: 0,
        log_time: 0,
        publish_time: 0,
    };
    w.write_to_known_channel(&h, b"{}").unwrap();
    w.finish().unwrap();
    let p = tmp("gps.mcap", &w.into_inner().into_inner());
    let (code, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(err.contains("channels seen: /gps (foo.Gps, json)"), "{err}");
    let _ = std::fs::remove_file(p);
}

#[test]
fn an_unwritable_output_is_cant_write() {
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.csv");
    let (code, err) = gaitclip(&[
        "replay",
        demo.to_str().unwrap(),
        "--mcap-out",
        "/nonexistent/dir/out.mcap",
    ]);
    assert_eq!(code, Some(74), "{err}");
    assert!(err.contains("/nonexistent/dir/out.mcap"), "{err}");
}

#[test]
fn a_bad_command_line_is_usage() {
    let (code, _) = gaitclip(&["replay", "--no-such-flag"]);
    assert_eq!(code, Some(2));
}

#[test]
fn a_range_that_is_not_positive_is_a_usage_error() {
    let p = tmp(
        "range.csv",
        format!("{HEADER}0,0,0,9.8,0,0,0\n0.005,0,0,9.8,0,0,0\n").as_bytes(),
    );
    for (flag, v) in [("--acc-range-g", "0"), ("--gyro-range-dps", "-5")] {
        let arg = format!("{flag}={v}");
        let (code, err) = gaitclip(&["replay", p.to_str().unwrap(), &arg]);
        assert_eq!(code, Some(2), "{err}");
        assert!(err.contains(flag), "{err}");
    }
    let _ = std::fs::remove_file(p);
}

#[test]
fn a_replay_below_100_hz_warns_and_runs() {
    let rows: String = (0..400)
        .map(|i| format!("{},0,0,9.8,0,0,0\n", i as f64 / 60.0))
        .collect();
    let p = tmp("slow.csv", format!("{HEADER}{rows}").as_bytes());
    let (code, err) = gaitclip(&["replay", p.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("warning") && err.contains("below 100 Hz"),
        "{err}"
    );
    let _ = std::fs::remove_file(p);
}

//! docs/host-tool.md's list of JSON fields is generated from `replay::STRIDE_FIELDS`; this
//! holds that list to what `replay --json` writes: every field, in its order, nothing else.

use std::process::Command;

use gaitclip_host::replay::STRIDE_FIELDS;

#[test]
fn the_documented_fields_are_the_ones_written_in_order() {
    let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/demo_walk.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(["replay", demo, "--json", "--all-models"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let line = text.lines().next().unwrap();
    let record: serde_json::Map<String, serde_json::Value> = serde_json::from_str(line).unwrap();
    let names: Vec<&str> = STRIDE_FIELDS
        .iter()
        .map(|(n, _)| *n)
        .filter(|n| *n != "rejected")
        .collect();
    let mut written: Vec<&str> = record.keys().map(String::as_str).collect();
    let mut documented = names.clone();
    written.sort_unstable();
    documented.sort_unstable();
    assert_eq!(written, documented, "documented vs written");
    // In the order written.
    let at: Vec<usize> = names
        .iter()
        .map(|n| line.find(&format!("\"{n}\":")).unwrap())
        .collect();
    assert!(
        at.windows(2).all(|w| w[0] < w[1]),
        "{names:?} out of order in {line}"
    );
}

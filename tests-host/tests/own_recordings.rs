//! `gaitclip eval` on a folder of one's own, made from scratch as docs/host-tool.md makes it:
//! the simulated demo walk (our own fixture) and its truth, no `meta.json`. It is scored, the
//! shipped models are scored out of sample, leave-one-dataset-out says why it is not run;
//! folders that cannot be scored are the user's errors (65, 66), never "internal".

use crate::common;

use common::{fixture, gaitclip, scratch};

/// docs/host-tool.md's `awk`: the truth's strides in `strides.csv`'s columns.
fn strides_csv(truth: &str) -> String {
    let mut out = String::from("trial,start_idx,end_idx,length_m,flag,tc_idx,ic_idx\n");
    for line in truth.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        out += &format!(
            "walk,{},{},{},{},{},{}\n",
            c[1], c[5], c[6], c[8], c[3], c[4]
        );
    }
    out
}

#[test]
fn a_folder_made_from_scratch_is_scored() {
    let d = scratch("own-myrec");
    std::fs::copy(fixture("demo_walk.csv"), d.join("walk.csv")).unwrap();
    let truth = std::fs::read_to_string(fixture("demo_walk.truth.csv")).unwrap();
    std::fs::write(d.join("strides.csv"), strides_csv(&truth)).unwrap();
    let (code, out, err) = gaitclip(&["eval", d.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let name = d.file_name().unwrap().to_str().unwrap();
    // The folder's truth named, with its reference strides.
    let row = out
        .lines()
        .find(|l| l.starts_with(&format!("| {name} ")))
        .unwrap_or_else(|| panic!("no row for {name}:\n{out}"));
    assert!(
        row.contains("| 23 ") && row.contains("strides.csv"),
        "{row}"
    );
    assert!(
        out.contains("Leave-one-dataset-out needs both training datasets"),
        "{out}"
    );
    assert!(!out.contains("Best leave-one-dataset-out"), "{out}");
    assert!(out.contains("the firmware ships"), "{out}");
    let _ = std::fs::remove_dir_all(d);
}

#[test]
fn a_folder_without_truth_is_described_and_a_folder_without_recordings_is_bad_input() {
    let d = scratch("own-bare");
    std::fs::copy(fixture("demo_walk.csv"), d.join("walk.csv")).unwrap();
    let (code, out, err) = gaitclip(&["eval", d.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("no truth"), "{out}");
    let empty = scratch("own-empty");
    let (code, _, err) = gaitclip(&["eval", empty.to_str().unwrap()]);
    assert_eq!(code, Some(65), "{err}");
    assert!(
        err.contains("bad input") && err.contains("no recordings"),
        "{err}"
    );
    let (code, _, err) = gaitclip(&["eval", "/nonexistent/gaitclip-folder"]);
    assert_eq!(code, Some(66), "{err}");
    assert!(!err.contains("internal error"), "{err}");
    let _ = std::fs::remove_dir_all(d);
    let _ = std::fs::remove_dir_all(empty);
}

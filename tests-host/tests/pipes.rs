//! A closed pipe ends the command quietly: `gaitclip … | head -1` exits by SIGPIPE, as `cat`
//! does (status 141 in a shell), never by a panic in `println!` (status 101 and a backtrace).
//!
//! Every subcommand's help, and the subcommands that print from a recording of our own in
//! seconds (`replay`, `energy`, `eval` on a folder of ours), are run with their output closed
//! before they write (deterministic: every write meets the closed pipe) and through a real
//! `head -1`. The other dataset reports print only after their minutes of work on the shared
//! datasets; the same first line of `main` covers them.

use std::io::{BufRead, BufReader};
use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};

const SIGPIPE: i32 = 13;

fn demo() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/demo_walk.csv").to_owned()
}

/// The subcommands `gaitclip --help` lists.
fn subcommands() -> Vec<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .arg("--help")
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    text.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect()
}

/// `gaitclip args` started with its standard output and error piped.
fn spawn(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Runs `gaitclip args` with its standard output a pipe whose reading end was closed before
/// it started (deterministic: its first write meets the closed pipe); returns the status and
/// what it wrote to standard error.
fn closed(args: &[&str]) -> (std::process::ExitStatus, String) {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(args)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `gaitclip args`, reads its first line as `head -1` does and closes the pipe.
fn head_1(args: &[&str]) -> (String, std::process::ExitStatus, String) {
    let mut child = spawn(args);
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (
        line,
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_quiet(args: &[&str], status: std::process::ExitStatus, err: &str) {
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(
        status.success() || status.signal() == Some(SIGPIPE),
        "{args:?}: {status:?} {err}"
    );
}

#[test]
fn every_subcommand_is_listed_here() {
    // A new subcommand must say how it meets a closed pipe: add it to the runs below or to
    // the dataset reports.
    let known = [
        "replay",
        "pod",
        "eval",
        "gait",
        "train",
        "cost",
        "energy",
        "wake",
        "holes",
        "zupt-sweep",
        "bias",
        "events",
        "clipping",
        "sprint",
        "rates",
        "running",
        "constraints",
        "course",
        "flags",
        "daily",
        "docs",
        "simulate",
    ];
    assert_eq!(subcommands(), known);
}

#[test]
fn every_help_ends_by_sigpipe_on_a_closed_pipe() {
    let mut runs: Vec<Vec<String>> = vec![vec!["--help".into()], vec!["--version".into()]];
    for c in subcommands() {
        runs.push(vec![c.clone(), "--help".into()]);
        runs.push(vec!["help".into(), c]);
    }
    for args in &runs {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (status, err) = closed(&args);
        assert_eq!(status.signal(), Some(SIGPIPE), "{args:?}: {status:?} {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn output_into_a_closed_pipe_ends_by_sigpipe_without_a_panic() {
    let demo = demo();
    // A dataset report too: `eval` on a folder of our own (the demo walk, no truth).
    let folder = std::env::temp_dir().join(format!("gaitclip-pipes-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::copy(&demo, folder.join("walk.csv")).unwrap();
    let folder_arg = folder.to_str().unwrap().to_owned();
    let runs: [&[&str]; 7] = [
        &["eval", &folder_arg],
        &["replay", &demo],
        &["replay", &demo, "--json"],
        &["replay", &demo, "--detector", "stance", "--all-models"],
        &["energy", "--m4", "9000", "--m0", "24000"],
        &["replay", &demo, "--detector", "lu", "--model", "lu_fuzzy"],
        &["sprint"],
    ];
    for args in runs {
        let (status, err) = closed(args);
        assert_eq!(status.signal(), Some(SIGPIPE), "{args:?}: {status:?} {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
        // Through `head -1`: the first line, then quiet.
        let (line, status, err) = head_1(args);
        assert!(!line.is_empty(), "{args:?}");
        assert_quiet(args, status, &err);
    }
    let _ = std::fs::remove_dir_all(folder);
}

/// The shell's own pipe, as the issue met it: `gaitclip replay … | head -1`, status 0 from the
/// pipe and 0 or 141 from gaitclip.
#[test]
fn a_shell_pipe_into_head_is_quiet() {
    let script = format!(
        "'{}' replay '{}' | head -1; echo \"status ${{PIPESTATUS[0]}}\"",
        env!("CARGO_BIN_EXE_gaitclip"),
        demo()
    );
    let out = Command::new("bash").args(["-c", &script]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(text.starts_with("stride "), "{text}");
    assert!(
        text.contains("status 0\n") || text.contains("status 141\n"),
        "{text} {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// A replay ended by SIGPIPE leaves nothing in the temporary folder: its spool on disk has no
/// name. A recording longer than the spool held in memory (the demo walk 22 times over,
/// 139 k rows) replayed into a closed pipe with its own `TMPDIR`, which must be empty after.
/// (A named spool, deleted by its destructor, stayed there: a signal runs no destructor.)
#[test]
fn a_replay_ended_by_sigpipe_leaves_no_spool() {
    use gaitclip_host::io::csv_trace;
    use gaitclip_host::io::trace::ImuSample;
    use gaitclip_host::stream::{MEMORY_SPOOL_BYTES, ROW_BYTES};

    let walk = csv_trace::read(std::path::Path::new(&demo()), None).unwrap();
    let period = 1.0 / walk.rate_hz;
    let mut rows: Vec<ImuSample> = Vec::new();
    for _ in 0..22 {
        let shift = rows
            .last()
            .map_or(0.0, |l| l.t_s + period - walk.samples[0].t_s);
        rows.extend(walk.samples.iter().map(|s| ImuSample {
            t_s: s.t_s + shift,
            ..*s
        }));
    }
    assert!(
        rows.len() > MEMORY_SPOOL_BYTES / ROW_BYTES,
        "{} rows",
        rows.len()
    );
    let dir = std::env::temp_dir().join(format!("gaitclip-pipes-spool-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let long = dir.join("long.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&long).unwrap());
    csv_trace::write(&mut f, &rows).unwrap();
    drop(f);
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_gaitclip"))
        .args(["replay", long.to_str().unwrap()])
        .env("TMPDIR", &tmp)
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.signal(), Some(SIGPIPE), "{:?} {err}", out.status);
    let left: Vec<_> = std::fs::read_dir(&tmp)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
    let _ = std::fs::remove_dir_all(dir);
}

//! Replays the fuzz targets' seed corpus and every input that ever crashed one
//! (`fuzz/corpus/<target>/`, `fuzz/regressions/<target>/`) through the same bodies the fuzzer
//! runs (`gaitclip_host::fuzzing`): the test command keeps each fixed crash fixed.

use std::path::PathBuf;

use gaitclip_host::fuzzing::TARGETS;

#[test]
fn corpus_and_regressions_pass_every_target() {
    let fuzz = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    for (name, body) in TARGETS {
        let mut seeds = 0;
        for dir in ["corpus", "regressions"] {
            let d = fuzz.join(dir).join(name);
            let mut files: Vec<PathBuf> = std::fs::read_dir(&d)
                .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
                .map(|e| e.unwrap().path())
                .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != ".gitkeep"))
                .collect();
            files.sort();
            for f in files {
                let data = std::fs::read(&f).unwrap();
                if std::panic::catch_unwind(|| body(&data)).is_err() {
                    panic!("{name} fails on {}", f.display());
                }
                seeds += 1;
            }
        }
        assert!(seeds > 0, "{name}: no seed corpus");
        eprintln!("{name}: {seeds} inputs pass");
    }
}

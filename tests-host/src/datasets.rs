//! Locating `../shared/datasets` (third-party recordings, never copied into the repository).

use std::path::PathBuf;

/// The datasets folder beside the repository, if present.
pub fn root() -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/datasets");
    p.is_dir().then_some(p)
}

/// For tests: the datasets folder, or `None` after printing that the test was skipped.
/// In CI (`CI=true`) a missing folder is a failure, not a skip.
pub fn root_or_skip(test: &str) -> Option<PathBuf> {
    match root() {
        Some(p) => Some(p),
        None if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("{test}: ../shared/datasets is missing in CI")
        }
        None => {
            eprintln!("SKIPPED {test}: ../shared/datasets is not present");
            None
        }
    }
}

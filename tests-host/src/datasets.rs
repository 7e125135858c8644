//! Locating `../shared/datasets` (third-party recordings, never copied into the repository).

use std::path::PathBuf;

/// The datasets folder beside the repository, if present.
pub fn root() -> Option<PathBuf> {
    shared("datasets")
}

/// The folder `../shared/<name>` beside the repository, if present.
pub fn shared(name: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared")
        .join(name);
    p.is_dir().then_some(p)
}

/// For tests: the datasets folder, or `None` after printing that the test was skipped.
/// In CI (`CI=true`) a missing folder is a failure, not a skip.
pub fn root_or_skip(test: &str) -> Option<PathBuf> {
    shared_or_skip("datasets", test)
}

/// For tests: the folder `../shared/<name>`, or `None` after printing that the test was
/// skipped. In CI (`CI=true`) a missing folder is a failure, not a skip.
pub fn shared_or_skip(name: &str, test: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared")
        .join(name);
    match p.is_dir() {
        true => Some(p),
        false if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("{test}: ../shared/{name} is missing in CI")
        }
        false => {
            eprintln!("SKIPPED {test}: ../shared/{name} is not present");
            None
        }
    }
}

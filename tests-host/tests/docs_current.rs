//! Every measured table of `docs/` is what its command prints now (`gaitclip docs`): a
//! change that moves a figure fails here until the docs are regenerated.

use gaitclip_host::eval::docs;
use gaitclip_host::io::datasets::root_or_skip;

#[test]
fn generated_docs_are_current() {
    let Some(root) = root_or_skip("generated_docs_are_current") else {
        return;
    };
    let exe = std::path::Path::new(env!("CARGO_BIN_EXE_gaitclip"));
    let pages = docs::regenerate(&docs::docs_dir(), &root, exe).unwrap();
    assert!(!pages.is_empty());
    let stale: Vec<String> = pages
        .iter()
        .filter(|p| !p.stale.is_empty())
        .map(|p| format!("{}: {}", p.path.display(), p.stale.join(", ")))
        .collect();
    assert!(
        stale.is_empty(),
        "stale generated blocks (run `cargo run --release -- docs` in tests-host/): {stale:?}"
    );
}

//! Progress on long work (`eval`, `train`, `cost`): a bar on standard error where it is a
//! terminal, nothing in a pipe, a file or CI, so that tables and logs stay clean.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `steps` steps labelled `what`, drawn only where standard error is a terminal
/// and `CI` is not set.
pub fn bar(steps: u64, what: &str) -> ProgressBar {
    let shown = std::io::stderr().is_terminal() && std::env::var_os("CI").is_none();
    let target = if shown {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(steps), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} {msg} (about {eta} left)",
    ) {
        bar.set_style(style);
    }
    bar.set_prefix(what.to_owned());
    bar
}

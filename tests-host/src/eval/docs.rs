//! `gaitclip docs`: the measured tables of `docs/`, written by the tools that measure them.
//!
//! A page marks each generated block:
//!
//! ```text
//! <!-- generated: gaitclip clipping -->
//! …whatever the command prints…
//! <!-- end generated -->
//! ```
//!
//! A marker names either one of the in-process reports ([`GENERATORS`]) or a whole command
//! line of the `gaitclip` binary (one of [`COMMANDS`], e.g. `<!-- generated: gaitclip eval
//! gaitmap_walk pyshoe_vicon -->`), whose words that name a dataset folder are read as that
//! folder under the datasets root; the block is what the command prints on stdout.
//!
//! `gaitclip docs` runs every marked command on `../shared/datasets` and writes its output
//! between the markers; `gaitclip docs --check` writes nothing and fails naming every block
//! whose text differs, which `tests/docs_current.rs` runs in the test command. Re-measuring
//! is a command, not an edit. Only deterministic measurements are generated (counts, errors,
//! instruction counts), never a time.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// What prints one block, from the datasets folder.
pub type Generator = fn(&Path) -> Result<String>;

/// The commands a page may mark, and what prints their block.
pub const GENERATORS: &[(&str, Generator)] = &[
    ("clipping", crate::eval::clip_sweep::report),
    ("rates", crate::eval::rate_sweep::report),
    ("running", crate::eval::running::report),
    ("constraints", crate::eval::constraints::report),
    ("course", crate::eval::course::report),
    ("flags", crate::eval::flag_costs::report),
    ("bias", crate::eval::bias::report),
    ("sprint", crate::eval::sprint_sim::report),
    ("json-fields", crate::replay::fields_report),
];

/// The subcommands of the `gaitclip` binary a marker may run as a whole command line: the
/// ones that print deterministic Markdown (no time, no machine figure).
pub const COMMANDS: &[&str] = &[
    "eval",
    "gait",
    "holes",
    "wake",
    "zupt-sweep",
    "energy",
    "events",
    "daily",
];

const OPEN: &str = "<!-- generated: gaitclip ";
const CLOSE: &str = "<!-- end generated -->";

/// One page whose generated blocks were (or would be) rewritten.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Page {
    /// The page.
    pub path: PathBuf,
    /// Its text with every block regenerated.
    pub text: String,
    /// The blocks whose text changed.
    pub stale: Vec<String>,
}

/// `text` with every generated block replaced by its command's output, and the names of the
/// blocks that changed. `run` prints a named block.
pub fn regenerate_text(
    text: &str,
    mut run: impl FnMut(&str) -> Result<String>,
) -> Result<(String, Vec<String>)> {
    let mut out = String::with_capacity(text.len());
    let mut stale = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find(OPEN) {
        let (before, from) = rest.split_at(at);
        out.push_str(before);
        let line_end = from
            .find('\n')
            .context("a generated block's marker ends the file")?;
        let marker = &from[..line_end];
        let name = marker
            .strip_prefix(OPEN)
            .and_then(|m| m.strip_suffix("-->"))
            .map(str::trim)
            .with_context(|| format!("malformed marker `{marker}`"))?;
        let body_start = line_end + 1;
        let Some(close) = from[body_start..].find(CLOSE) else {
            bail!("block `{name}` has no `{CLOSE}`");
        };
        let old = &from[body_start..body_start + close];
        let mut new = run(name).with_context(|| format!("gaitclip {name}"))?;
        if !new.ends_with('\n') {
            new.push('\n');
        }
        if old != new {
            stale.push(name.to_string());
        }
        out.push_str(marker);
        out.push('\n');
        out.push_str(&new);
        out.push_str(CLOSE);
        rest = &from[body_start + close + CLOSE.len()..];
    }
    out.push_str(rest);
    Ok((out, stale))
}

/// Every page of `docs` (`*.md`) regenerated from the datasets under `datasets`; `exe` is
/// the `gaitclip` binary that runs the command-line blocks. The blocks are independent
/// measurements: each distinct one is run once, side by side on the machine's cores
/// ([`run_side_by_side`]), the longest (`eval`) first.
pub fn regenerate(docs: &Path, datasets: &Path, exe: &Path) -> Result<Vec<Page>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(docs)
        .with_context(|| format!("{}", docs.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    paths.sort();
    let mut texts = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for path in paths {
        let text = std::fs::read_to_string(&path).with_context(|| format!("{}", path.display()))?;
        regenerate_text(&text, |name| {
            if !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
            Ok(String::new())
        })?;
        texts.push((path, text));
    }
    // The slowest first, so that it does not start last.
    names.sort_by_key(|n| !n.starts_with("eval"));
    let outputs = run_side_by_side(&names, |name| block(name, datasets, exe));
    let mut pages = Vec::new();
    for (path, text) in texts {
        let (text, stale) = regenerate_text(&text, |name| {
            let k = names
                .iter()
                .position(|n| n == name)
                .context("a block not run")?;
            match &outputs[k] {
                Ok(out) => Ok(out.clone()),
                Err(e) => bail!("{e:#}"),
            }
        })?;
        pages.push(Page { path, text, stale });
    }
    Ok(pages)
}

/// `run` on every item of `items`, on as many threads as the machine has cores, each taking
/// the next item when it is done; the results in the order of `items`.
pub fn run_side_by_side<T: Sync, R: Send>(
    items: &[T],
    run: impl Fn(&T) -> Result<R> + Sync,
) -> Vec<Result<R>> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let done: std::sync::Mutex<Vec<(usize, Result<R>)>> = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(item) = items.get(k) else {
                    break;
                };
                let r = run(item);
                done.lock().unwrap_or_else(|e| e.into_inner()).push((k, r));
            });
        }
    });
    let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
    done.sort_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// What the marker `name` prints.
fn block(name: &str, datasets: &Path, exe: &Path) -> Result<String> {
    if let Some((_, f)) = GENERATORS.iter().find(|(n, _)| *n == name) {
        return f(datasets);
    }
    let words = command_line(name, datasets)?;
    let out = std::process::Command::new(exe)
        .args(&words)
        .output()
        .with_context(|| format!("running {}", exe.display()))?;
    if !out.status.success() {
        bail!(
            "`gaitclip {name}` failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    String::from_utf8(out.stdout).context("the command printed non-UTF-8")
}

/// The arguments of the command-line marker `name`, datasets resolved under `datasets`.
pub fn command_line(name: &str, datasets: &Path) -> Result<Vec<String>> {
    let words: Vec<&str> = name.split_whitespace().collect();
    let Some(cmd) = words.first().filter(|c| COMMANDS.contains(c)) else {
        bail!(
            "no generator `{name}` (known: {:?}, or a command line of {:?})",
            names(),
            COMMANDS
        );
    };
    let mut out = vec![cmd.to_string()];
    for w in &words[1..] {
        let folder = datasets.join(w);
        if !w.starts_with('-') && folder.is_dir() {
            out.push(folder.display().to_string());
        } else {
            out.push(w.to_string());
        }
    }
    Ok(out)
}

/// The generator names.
pub fn names() -> Vec<&'static str> {
    GENERATORS.iter().map(|(n, _)| *n).collect()
}

/// The repository's `docs/` folder.
pub fn docs_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_line_marker_names_datasets_by_folder() {
        let root = std::env::temp_dir().join("gaitclip-docs-test");
        std::fs::create_dir_all(root.join("walk")).unwrap();
        assert_eq!(
            command_line("eval walk --rotate 2", &root).unwrap(),
            vec![
                "eval".to_string(),
                root.join("walk").display().to_string(),
                "--rotate".into(),
                "2".into()
            ]
        );
        assert!(command_line("replay walk", &root).is_err());
        assert!(command_line("", &root).is_err());
    }

    #[test]
    fn a_block_is_replaced_and_reported_stale_only_when_it_differs() {
        let page = "# t\n<!-- generated: gaitclip x -->\nold\n<!-- end generated -->\ntail\n";
        let (text, stale) = regenerate_text(page, |_| Ok("new".into())).unwrap();
        assert_eq!(
            text,
            "# t\n<!-- generated: gaitclip x -->\nnew\n<!-- end generated -->\ntail\n"
        );
        assert_eq!(stale, vec!["x".to_string()]);
        let (again, stale) = regenerate_text(&text, |_| Ok("new\n".into())).unwrap();
        assert_eq!(again, text);
        assert!(stale.is_empty());
        assert!(
            regenerate_text("<!-- generated: gaitclip x -->\nno end", |_| Ok(
                String::new()
            ))
            .is_err()
        );
    }
}

//! The import graph of the crates, read from their sources: no file imports one that
//! (directly or through others) imports it back, and in the core no stage imports a later
//! one (the order of `src/lib.rs`'s layout table).
//!
//! A file's imports are the `crate::…` paths in its code outside comments and outside its
//! `#[cfg(test)] mod tests` (a test may reach anything): `use` lines, with their braces
//! expanded, and paths written inline. Each path is resolved to the longest module prefix
//! that is a file of the crate.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The core's top-level modules in the order the chain runs: a module may import only from
/// those before it (or its own folder).
const CORE_ORDER: [&str; 8] = [
    "fixed", "sensor", "signal", "record", "detect", "length", "gait", "pipeline",
];

type Graph = BTreeMap<String, BTreeSet<String>>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            // Binaries are leaves: nothing imports them.
            if p.file_name().is_some_and(|n| n != "bin") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `detect/cycle.rs` → `detect::cycle`, `detect/mod.rs` → `detect`; `None` for the root.
fn module_of(root: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(root).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|c| c.to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|l| l == "mod") {
        parts.pop();
    }
    let m = parts.join("::");
    (m != "lib" && !m.is_empty()).then_some(m)
}

/// The code of a file without comments and without its unit tests.
fn code_of(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => text,
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every `crate::a::b::…` path in `code`, `use` braces expanded.
fn crate_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        let before = rest[..i].chars().last();
        rest = &rest[i + "crate::".len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        expand("", rest, &mut out);
    }
    out
}

/// Reads one path (or brace tree) at the start of `s`, prefixed by `prefix`.
fn expand(prefix: &str, s: &str, out: &mut Vec<String>) {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(s.len());
    let head = s[..end].trim_end_matches(':');
    let path = match (prefix.is_empty(), head.is_empty()) {
        (true, _) => head.to_string(),
        (false, true) => prefix.to_string(),
        (false, false) => format!("{prefix}::{head}"),
    };
    if s[end..].starts_with('{') {
        // A brace list: split at top-level commas.
        let inner = &s[end + 1..];
        let (mut depth, mut start) = (0usize, 0usize);
        for (j, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    item(&path, &inner[start..j], out);
                    return;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    item(&path, &inner[start..j], out);
                    start = j + 1;
                }
                _ => {}
            }
        }
    } else if !path.is_empty() {
        out.push(path);
    }
}

fn item(prefix: &str, s: &str, out: &mut Vec<String>) {
    let s = s.trim();
    if s == "self" || s.is_empty() {
        out.push(prefix.to_string());
    } else {
        expand(prefix, s, out);
    }
}

/// The graph of the crate whose `lib.rs` is in `root`.
fn graph(root: &Path) -> Graph {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    let modules: BTreeMap<String, PathBuf> = files
        .iter()
        .filter_map(|f| module_of(root, f).map(|m| (m, f.clone())))
        .collect();
    let resolve = |p: &str| -> Option<String> {
        let parts: Vec<&str> = p.split("::").collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|m| modules.contains_key(m))
    };
    modules
        .iter()
        .map(|(m, f)| {
            let code = code_of(&std::fs::read_to_string(f).unwrap());
            let deps = crate_paths(&code)
                .iter()
                .filter_map(|p| resolve(p))
                .filter(|d| d != m)
                .collect();
            (m.clone(), deps)
        })
        .collect()
}

/// The strongly connected components with more than one module (Tarjan).
fn circles(g: &Graph) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let n = t.index.len();
        t.index.insert(v, n);
        t.low.insert(v, n);
        t.stack.push(v);
        for w in t.g.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.stack.contains(&w) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

#[test]
fn the_reader_sees_uses_braces_and_inline_paths() {
    let code = code_of(
        "use crate::a::{b, c::{d, e}, self};\n// use crate::z;\nfn f() { crate::x::y(); }\n\
         #[cfg(test)]\nmod tests { use crate::t; }",
    );
    let mut p = crate_paths(&code);
    p.sort();
    assert_eq!(p, ["a", "a::b", "a::c::d", "a::c::e", "x::y"]);
    let g: Graph = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec!["a"]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(circles(&g), [["a", "b", "c"]]);
}

#[test]
fn no_crate_has_an_import_circle() {
    for root in [
        "src",
        "drivers/mpu6050/src",
        "boards/common/src",
        "tests-host/src",
    ] {
        let g = graph(&repo().join(root));
        assert!(g.len() > 5, "{root}: only {} modules read", g.len());
        assert_eq!(
            circles(&g),
            Vec::<Vec<String>>::new(),
            "{root}: files importing each other in a loop"
        );
    }
}

#[test]
fn no_core_stage_imports_a_later_one() {
    let g = graph(&repo().join("src"));
    let rank = |m: &str| {
        CORE_ORDER
            .iter()
            .position(|t| *t == m.split("::").next().unwrap())
    };
    let mut later = Vec::new();
    for (m, deps) in &g {
        let Some(rm) = rank(m) else {
            panic!("{m}: a top-level module not in CORE_ORDER")
        };
        for d in deps {
            if rank(d).is_some_and(|rd| rd > rm) {
                later.push(format!("{m} → {d}"));
            }
        }
    }
    assert!(later.is_empty(), "imports of a later stage: {later:?}");
}

/// The core does not know which sensor it has: it names only the seam's crate
/// (`gaitclip_imu`, the sample and the scales), in `sensor/`, and no driver crate anywhere;
/// the seam and every driver know nothing of gaitclip's core.
#[test]
fn the_core_names_the_sensor_seam_and_no_driver() {
    let src = repo().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let named = |needle: &str| {
        let mut v: Vec<String> = files
            .iter()
            .filter(|f| code_of(&std::fs::read_to_string(f).unwrap()).contains(needle))
            .map(|f| f.strip_prefix(&src).unwrap().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        named("gaitclip_imu"),
        ["sensor/sample.rs", "sensor/units.rs"]
    );
    let drivers: Vec<String> = std::fs::read_dir(repo().join("drivers"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|d| d != "imu")
        .collect();
    assert!(drivers.iter().any(|d| d == "mpu6050"), "{drivers:?}");
    for d in &drivers {
        let krate = format!("gaitclip_{}", d.replace('-', "_"));
        assert_eq!(
            named(&krate),
            Vec::<String>::new(),
            "the core names {krate}"
        );
    }
    let manifest = std::fs::read_to_string(repo().join("Cargo.toml")).unwrap();
    let deps = manifest
        .split("[dependencies]")
        .nth(1)
        .and_then(|t| t.split("\n[").next())
        .unwrap();
    assert!(deps.contains("gaitclip-imu"));
    for d in &drivers {
        assert!(
            !deps.contains(&format!("gaitclip-{d}")),
            "the core depends on {d}"
        );
    }
    for d in drivers.iter().map(String::as_str).chain(["imu"]) {
        let mut driver = Vec::new();
        rust_files(&repo().join("drivers").join(d).join("src"), &mut driver);
        assert!(!driver.is_empty(), "drivers/{d}");
        for f in driver {
            let code = code_of(&std::fs::read_to_string(&f).unwrap());
            assert!(!code.contains("gaitclip::"), "{}", f.display());
        }
    }
}

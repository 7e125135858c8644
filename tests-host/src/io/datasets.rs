//! The datasets of `../shared/datasets` (third-party recordings, never copied into the
//! repository): locating them, and loading each one's trials and reference strides.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use crate::io::clock::SampleClock;

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

/// Times of a reference's events, s, where the dataset gives them (they override the
/// rows when mapped to sample numbers).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReferenceTimes {
    /// Start of the interval holding the stride's movement.
    pub start_s: Option<f64>,
    /// Its end.
    pub end_s: Option<f64>,
    /// Toe-off.
    pub toe_off_s: Option<f64>,
    /// Heel-strike ending the swing.
    pub heel_strike_s: Option<f64>,
    /// Heel-strike that began the stride's ground contact.
    pub prev_heel_strike_s: Option<f64>,
}

/// One reference stride (rows of the trial's CSV; [`Reference::in_numbers`] maps them to the
/// sensor clock's sample numbers).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Interval that contains the stride's movement.
    pub start: u32,
    /// End of that interval.
    pub end: u32,
    /// Not clean straight walking: neither counted nor missed.
    pub flagged: bool,
    /// Toe-off, where labelled.
    pub toe_off: Option<u32>,
    /// Heel-strike ending the swing, where labelled.
    pub heel_strike: Option<u32>,
    /// Heel-strike that began the stride's ground contact, where labelled.
    pub prev_heel_strike: Option<u32>,
    /// Reference stride length, m, where the dataset has one.
    pub length_m: Option<f64>,
    /// Event times, where the dataset gives them.
    pub times: ReferenceTimes,
}

impl Reference {
    /// The reference in sample numbers of `clock`: events given as times go to the nearest
    /// number, the others from their rows.
    pub fn in_numbers(&self, clock: &SampleClock) -> Reference {
        let row = |r: u32| clock.number_of_row(r as usize);
        let event = |t: Option<f64>, r: Option<u32>| match t {
            Some(t) => Some(clock.number_at(t)),
            None => r.map(row),
        };
        Reference {
            start: event(self.times.start_s, Some(self.start)).unwrap_or(0),
            end: event(self.times.end_s, Some(self.end)).unwrap_or(0),
            toe_off: event(self.times.toe_off_s, self.toe_off),
            heel_strike: event(self.times.heel_strike_s, self.heel_strike),
            prev_heel_strike: event(self.times.prev_heel_strike_s, self.prev_heel_strike),
            ..*self
        }
    }
}

/// One recording and its ground truth.
#[derive(Clone, Debug)]
pub struct Trial {
    /// Name as the dataset gives it.
    pub name: String,
    /// The trial's CSV.
    pub csv: PathBuf,
    /// Reference strides.
    pub references: Vec<Reference>,
    /// Labelled part of the recording, rows `[from, to)`.
    pub span: (u32, u32),
    /// The same bounds as times, s, where the dataset gives them (they override the rows).
    pub span_s: Option<(f64, f64)>,
    /// A part of the span whose steps are not labelled one by one, s (`ipol_gait_events`'
    /// U-turn): detections lying mostly inside it are not scored.
    pub unscored_s: Option<(f64, f64)>,
    /// Per-sample stance label, where the dataset has one.
    pub stance: Option<Vec<bool>>,
    /// Per-sample Vicon foot position, m (`pyshoe_vicon`'s `<trial>.reference.csv`: x, y
    /// horizontal, z up); NaN where the marker was lost.
    pub positions: Option<Vec<[f64; 3]>>,
    /// The walker's height, m, where the dataset gives it.
    pub height_m: Option<f64>,
    /// Distance walked over `span`, m, where the dataset gives it (not per stride).
    pub distance_m: Option<f64>,
}

/// A dataset folder.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// Folder name (`gaitmap_walk`, …).
    pub name: String,
    /// Nominal sample rate, Hz.
    pub rate_hz: f64,
    /// Its trials.
    pub trials: Vec<Trial>,
}

/// What a folder's `meta.json` may say (all optional: a folder of one's own needs none).
#[derive(Deserialize, Default)]
struct Meta {
    name: Option<String>,
    sample_rate_hz: Option<f64>,
}

/// A dataset folder that cannot be scored: the context of its error (a user's input, not
/// gaitclip's fault).
#[derive(Debug, thiserror::Error)]
#[error("dataset folder {0}")]
pub struct DatasetError(pub PathBuf);

/// The files of a dataset folder that are not recordings: its truth and its own tables.
const NOT_RECORDINGS: [&str; 5] = [
    "strides.csv",
    "events.csv",
    "trials.csv",
    ".reference.csv",
    ".truth.csv",
];

/// The truth a folder holds, by its files, and what it scores.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Truth {
    /// `strides.csv`: each stride's `start_idx`, `end_idx`, `length_m` and `flag` (`tc_idx`,
    /// `ic_idx`, `pre_ic_idx` where known), by `trial`: detection, events, phases, lengths.
    Strides,
    /// `events.csv` (each step's `toe_off_idx`/`_s`, `heel_strike_idx`/`_s`, `foot`, `step`,
    /// `in_uturn`) and `trials.csv` (each walk's span, U-turn, `distance_m`, `height_m`):
    /// detection, events, walked distance.
    Events,
    /// Recordings only: replayed and described, nothing scored.
    None,
}

impl Truth {
    /// What the folder's truth scores, for the tables' readers.
    pub const fn scores(self) -> &'static str {
        match self {
            Truth::Strides => "strides.csv: detection, events, phases, stride lengths",
            Truth::Events => "events.csv + trials.csv: detection, events, walked distance",
            Truth::None => {
                "no truth (add strides.csv, or events.csv and trials.csv): recordings as read only"
            }
        }
    }
}

fn read_rows(path: &Path) -> Result<Vec<BTreeMap<String, String>>> {
    let mut r = csv::Reader::from_path(path).with_context(|| format!("{}", path.display()))?;
    let mut out = Vec::new();
    for row in r.deserialize() {
        out.push(row.with_context(|| format!("{}", path.display()))?);
    }
    Ok(out)
}

fn field<'a>(row: &'a BTreeMap<String, String>, k: &str, path: &Path) -> Result<&'a str> {
    row.get(k)
        .map(String::as_str)
        .with_context(|| format!("{}: no column `{k}`", path.display()))
}

fn index(row: &BTreeMap<String, String>, k: &str, path: &Path) -> Result<u32> {
    let v = field(row, k, path)?;
    v.trim()
        .parse()
        .with_context(|| format!("{}: `{k}` = {v:?} is not an index", path.display()))
}

/// Loads a dataset folder: one of `../shared/datasets` (its layout is described there) or
/// one of the user's own in the same layout, with or without `meta.json` (the name is then
/// the folder's, the rate the stamps'). Its truth is told by its files ([`Truth`]). A folder
/// that cannot be read is an error in the [`DatasetError`] context.
pub fn load(dir: &Path) -> Result<Dataset> {
    load_folder(dir).with_context(|| DatasetError(dir.to_owned()))
}

/// The truth `dir` holds, by its files.
pub fn truth_of(dir: &Path) -> Truth {
    if dir.join("strides.csv").is_file() {
        Truth::Strides
    } else if dir.join("events.csv").is_file() && dir.join("trials.csv").is_file() {
        Truth::Events
    } else {
        Truth::None
    }
}

fn load_folder(dir: &Path) -> Result<Dataset> {
    if !dir.exists() {
        return Err(std::io::Error::new(std::io::ErrorKind::NotFound, "no such folder").into());
    }
    if !dir.is_dir() {
        bail!("not a folder");
    }
    let meta_path = dir.join("meta.json");
    let meta: Meta = match std::fs::read(&meta_path) {
        Ok(bytes) => {
            serde_json::from_slice(&bytes).with_context(|| format!("{}", meta_path.display()))?
        }
        Err(_) => Meta::default(),
    };
    let name = match meta.name {
        Some(n) => n,
        None => dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "recordings".to_owned()),
    };
    let trials = match truth_of(dir) {
        Truth::Strides => load_strides(dir, &name)?,
        Truth::Events => load_ipol(dir)?,
        Truth::None => load_unlabelled(dir)?,
    };
    let Some(first) = trials.first() else {
        bail!("no recordings (`<trial>.csv` in the datasets' layout: t_s, acc_x … gyr_z)");
    };
    let rate_hz = match meta.sample_rate_hz {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => bail!(
            "{}: sample_rate_hz {r} is not a positive number",
            meta_path.display()
        ),
        None => crate::io::csv_trace::read(&first.csv, None)?.rate_hz,
    };
    Ok(Dataset {
        name,
        rate_hz,
        trials,
    })
}

fn load_strides(dir: &Path, name: &str) -> Result<Vec<Trial>> {
    let path = dir.join("strides.csv");
    let mut by_trial: BTreeMap<String, Vec<Reference>> = BTreeMap::new();
    for row in read_rows(&path)? {
        let opt = |k: &str| -> Result<Option<u32>> {
            match row.get(k) {
                Some(_) => index(&row, k, &path).map(Some),
                None => Ok(None),
            }
        };
        let r = Reference {
            start: index(&row, "start_idx", &path)?,
            end: index(&row, "end_idx", &path)?,
            flagged: !field(&row, "flag", &path)?.trim().is_empty(),
            toe_off: opt("tc_idx")?,
            heel_strike: opt("ic_idx")?,
            prev_heel_strike: opt("pre_ic_idx")?,
            length_m: Some(
                field(&row, "length_m", &path)?
                    .trim()
                    .parse()
                    .with_context(|| format!("{}: length_m is not a number", path.display()))?,
            ),
            times: ReferenceTimes::default(),
        };
        by_trial
            .entry(field(&row, "trial", &path)?.to_string())
            .or_default()
            .push(r);
    }
    let mut trials = Vec::new();
    for (trial, references) in by_trial {
        let span = (
            references.iter().map(|r| r.start).min().unwrap_or(0),
            references.iter().map(|r| r.end).max().unwrap_or(0),
        );
        let (stance, positions) = if name == "pyshoe_vicon" {
            let p = dir.join(format!("{trial}.reference.csv"));
            let (mut v, mut pos) = (Vec::new(), Vec::new());
            for (line, row) in read_rows(&p)?.iter().enumerate() {
                v.push(field(row, "stance_vicon", &p)?.trim() == "1");
                let mut xyz = [f64::NAN; 3];
                for (x, k) in xyz.iter_mut().zip(["pos_x_m", "pos_y_m", "pos_z_m"]) {
                    let f = field(row, k, &p)?.trim();
                    *x = if f.is_empty() || f.eq_ignore_ascii_case("nan") {
                        f64::NAN
                    } else {
                        f.parse().with_context(|| {
                            format!(
                                "{}:{}: `{k}` = {f:?} is not a number",
                                p.display(),
                                line + 2
                            )
                        })?
                    };
                }
                pos.push(xyz);
            }
            (Some(v), Some(pos))
        } else {
            (None, None)
        };
        trials.push(Trial {
            csv: dir.join(format!("{trial}.csv")),
            name: trial,
            references,
            span,
            span_s: None,
            stance,
            positions,
            unscored_s: None,
            height_m: None,
            distance_m: None,
        });
    }
    Ok(trials)
}

/// A dataset without per-stride truth (`esangeni_run`, a folder of one's own): every
/// `<trial>.csv` of the folder but its tables, whole, with no references.
fn load_unlabelled(dir: &Path) -> Result<Vec<Trial>> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .with_context(|| format!("{}", dir.display()))?
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            if NOT_RECORDINGS.iter().any(|x| n.ends_with(x)) {
                return None;
            }
            n.strip_suffix(".csv").map(str::to_owned)
        })
        .collect();
    names.sort();
    Ok(names
        .into_iter()
        .map(|trial| Trial {
            csv: dir.join(format!("{trial}.csv")),
            name: trial,
            references: Vec::new(),
            span: (0, u32::MAX),
            span_s: None,
            stance: None,
            positions: None,
            unscored_s: None,
            height_m: None,
            distance_m: None,
        })
        .collect())
}

fn load_ipol(dir: &Path) -> Result<Vec<Trial>> {
    let tpath = dir.join("trials.csv");
    let mut spans = BTreeMap::new();
    let number = |row: &BTreeMap<String, String>, k: &str| -> Result<f64> {
        let v = field(row, k, &tpath)?;
        v.trim()
            .parse()
            .with_context(|| format!("{}: `{k}` = {v:?} is not a number", tpath.display()))
    };
    for row in read_rows(&tpath)? {
        spans.insert(
            field(&row, "trial", &tpath)?.to_string(),
            (
                (
                    index(&row, "walk_start_idx", &tpath)?,
                    index(&row, "walk_end_idx", &tpath)?,
                ),
                (number(&row, "walk_start_s")?, number(&row, "walk_end_s")?),
                (number(&row, "uturn_start_s")?, number(&row, "uturn_end_s")?),
                // Some subjects' heights are not given: left empty.
                match field(&row, "height_m", &tpath)?.trim() {
                    "" => None,
                    _ => Some(number(&row, "height_m")?),
                },
                number(&row, "distance_m")?,
            ),
        );
    }
    let epath = dir.join("events.csv");
    let mut by_trial: BTreeMap<(String, String), Vec<(u32, Reference)>> = BTreeMap::new();
    let seconds = |row: &BTreeMap<String, String>, k: &str| -> Result<f64> {
        let v = field(row, k, &epath)?;
        v.trim()
            .parse()
            .with_context(|| format!("{}: `{k}` = {v:?} is not a number", epath.display()))
    };
    for row in read_rows(&epath)? {
        let to = index(&row, "toe_off_idx", &epath)?;
        let hs = index(&row, "heel_strike_idx", &epath)?;
        let r = Reference {
            start: to,
            end: hs,
            flagged: field(&row, "in_uturn", &epath)?.trim() == "True",
            toe_off: Some(to),
            heel_strike: Some(hs),
            prev_heel_strike: None,
            length_m: None,
            times: {
                let (to_s, hs_s) = (seconds(&row, "toe_off_s")?, seconds(&row, "heel_strike_s")?);
                ReferenceTimes {
                    start_s: Some(to_s),
                    end_s: Some(hs_s),
                    toe_off_s: Some(to_s),
                    heel_strike_s: Some(hs_s),
                    prev_heel_strike_s: None,
                }
            },
        };
        let key = (
            field(&row, "trial", &epath)?.to_string(),
            field(&row, "foot", &epath)?.to_string(),
        );
        by_trial
            .entry(key)
            .or_default()
            .push((index(&row, "step", &epath)?, r));
    }
    let mut trials = Vec::new();
    for ((trial, foot), mut steps) in by_trial {
        steps.sort_by_key(|s| s.0);
        let mut references: Vec<Reference> = steps.into_iter().map(|s| s.1).collect();
        for k in 1..references.len() {
            references[k].prev_heel_strike = references[k - 1].heel_strike;
            references[k].times.prev_heel_strike_s = references[k - 1].times.heel_strike_s;
        }
        let (span, span_s, uturn_s, height, distance) = *spans
            .get(&trial)
            .with_context(|| format!("{}: no trial {trial}", tpath.display()))?;
        trials.push(Trial {
            csv: dir.join(format!("{trial}_{foot}.csv")),
            name: format!("{trial}_{foot}"),
            references,
            // The rows are the left foot's: the right foot's file has its own holes.
            span,
            span_s: Some(span_s),
            unscored_s: Some(uturn_s),
            stance: None,
            positions: None,
            height_m: height,
            distance_m: Some(distance),
        });
    }
    Ok(trials)
}

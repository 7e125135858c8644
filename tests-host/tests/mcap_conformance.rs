//! The official MCAP conformance inputs (`../shared/mcap-conformance`, 416 files, each with
//! the records a streamed reader must see as JSON): gaitclip's reader either yields exactly
//! the expected schemas, channels and messages, in order, or rejects the file with an error
//! naming it; never a panic, never a hang (each file gets a time budget).
//!
//! Where a `.mcap` is a git-LFS pointer rather than the file (as in a clone made without
//! git-lfs), the reader must say so, and the expectations are checked on a re-encoding
//! instead: the JSON's records written by the `mcap` crate's writer with the file's features
//! (chunks, indexes, statistics, repeated schemas and channels, summary offsets, attachments,
//! metadata), read back by gaitclip's reader.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use gaitclip_host::io::mcap_io::{read_records, McapError, McapRecord};
use serde_json::Value;

/// A file that takes longer than this to read counts as a hang.
const BUDGET: Duration = Duration::from_secs(20);

fn field<'a>(fields: &'a [Value], name: &str) -> &'a Value {
    fields
        .iter()
        .find(|f| f[0] == name)
        .map(|f| &f[1])
        .unwrap_or_else(|| panic!("no field {name} in {fields:?}"))
}

fn num<T: std::str::FromStr>(fields: &[Value], name: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    field(fields, name).as_str().unwrap().parse().unwrap()
}

fn text(fields: &[Value], name: &str) -> String {
    field(fields, name).as_str().unwrap().to_owned()
}

fn bytes(fields: &[Value], name: &str) -> Vec<u8> {
    field(fields, name)
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_str().unwrap().parse().unwrap())
        .collect()
}

fn map(fields: &[Value], name: &str) -> BTreeMap<String, String> {
    field(fields, name)
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_str().unwrap().to_owned()))
        .collect()
}

/// Every record of a conformance JSON as (type, fields).
fn json_records(json: &Path) -> Vec<(String, Vec<Value>)> {
    let v: Value = serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap();
    v["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["type"].as_str().unwrap().to_owned(),
                r["fields"].as_array().unwrap().clone(),
            )
        })
        .collect()
}

/// The schema, channel and message records the JSON expects, in order.
fn expected(records: &[(String, Vec<Value>)]) -> Vec<McapRecord> {
    records
        .iter()
        .filter_map(|(ty, f)| match ty.as_str() {
            "Schema" => Some(McapRecord::Schema {
                id: num(f, "id"),
                name: text(f, "name"),
                encoding: text(f, "encoding"),
                data: bytes(f, "data"),
            }),
            "Channel" => Some(McapRecord::Channel {
                id: num(f, "id"),
                schema_id: num(f, "schema_id"),
                topic: text(f, "topic"),
                message_encoding: text(f, "message_encoding"),
                metadata: map(f, "metadata"),
            }),
            "Message" => Some(McapRecord::Message {
                channel_id: num(f, "channel_id"),
                sequence: num(f, "sequence"),
                log_time: num(f, "log_time"),
                publish_time: num(f, "publish_time"),
                data: bytes(f, "data"),
            }),
            _ => None,
        })
        .collect()
}

/// The JSON's data-section records written with the features its file name lists.
fn reencode(name: &str, records: &[(String, Vec<Value>)]) -> Vec<u8> {
    let features: Vec<&str> = name.split('-').skip(1).collect();
    let has = |f: &str| features.contains(&f);
    let opts = mcap::WriteOptions::new()
        .library("")
        .profile("")
        .compression(None)
        .use_chunks(has("ch"))
        .emit_message_indexes(has("mx"))
        .emit_chunk_indexes(has("chx"))
        .emit_statistics(has("st"))
        .emit_summary_offsets(has("sum"))
        .emit_attachment_indexes(has("ax"))
        .emit_metadata_indexes(has("mdx"))
        .repeat_schemas(has("rsh"))
        .repeat_channels(has("rch"));
    let mut w = opts.create(Cursor::new(Vec::new())).unwrap();
    // Records after DataEnd are the summary, which the writer makes itself.
    let data_section = records.iter().take_while(|(ty, _)| ty != "DataEnd");
    for (ty, f) in data_section {
        match ty.as_str() {
            "Schema" => {
                w.add_schema_with_id(
                    num(f, "id"),
                    &text(f, "name"),
                    &text(f, "encoding"),
                    &bytes(f, "data"),
                )
                .unwrap();
            }
            "Channel" => {
                w.add_channel_with_id(
                    num(f, "id"),
                    num(f, "schema_id"),
                    &text(f, "topic"),
                    &text(f, "message_encoding"),
                    &map(f, "metadata"),
                )
                .unwrap();
            }
            "Message" => {
                let h = mcap::records::MessageHeader {
                    channel_id: num(f, "channel_id"),
                    sequence: num(f, "sequence"),
                    log_time: num(f, "log_time"),
                    publish_time: num(f, "publish_time"),
                };
                w.write_to_known_channel(&h, &bytes(f, "data")).unwrap();
            }
            "Attachment" => w
                .attach(&mcap::Attachment {
                    log_time: num(f, "log_time"),
                    create_time: num(f, "create_time"),
                    name: text(f, "name"),
                    media_type: text(f, "media_type"),
                    data: bytes(f, "data").into(),
                })
                .unwrap(),
            "Metadata" => w
                .write_metadata(&mcap::records::Metadata {
                    name: text(f, "name"),
                    metadata: map(f, "metadata"),
                })
                .unwrap(),
            _ => {}
        }
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// Reads `bytes` on a thread of its own, so that a panic is reported with the file's name
/// and a hang is caught by [`BUDGET`].
fn read_guarded(path: &Path, bytes: Vec<u8>) -> Result<Vec<McapRecord>, String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_owned();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| read_records(&p, &bytes));
        let _ = tx.send(r);
    });
    match rx.recv_timeout(BUDGET) {
        Ok(Ok(Ok(records))) => Ok(records),
        Ok(Ok(Err(e))) => Err(classify(path, e)),
        Ok(Err(_)) => panic!("{}: the reader panicked", path.display()),
        Err(_) => panic!("{}: the reader took longer than {BUDGET:?}", path.display()),
    }
}

fn classify(path: &Path, e: McapError) -> String {
    let msg = e.to_string();
    assert!(
        msg.starts_with(&path.display().to_string()),
        "an error must name its file: {msg}"
    );
    msg
}

#[test]
fn conformance_files_are_read_exactly_or_rejected_clearly() {
    let Some(root) =
        gaitclip_host::io::datasets::shared_or_skip("mcap-conformance", "mcap_conformance")
    else {
        return;
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .flat_map(|d| std::fs::read_dir(d.unwrap().path()).into_iter().flatten())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 416, "the conformance set has 416 files");
    let (mut exact, mut rejected, mut pointers, mut reencoded) = (0, Vec::new(), 0, 0);
    for path in &files {
        let records = json_records(&path.with_extension("json"));
        let want = expected(&records);
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        match read_guarded(path, std::fs::read(path).unwrap()) {
            Ok(got) => {
                assert_eq!(got, want, "{}", path.display());
                exact += 1;
            }
            Err(msg) if msg.contains("a git-LFS pointer") => {
                pointers += 1;
                let again = Path::new("re-encoded").join(&name);
                let got = read_guarded(&again, reencode(&name, &records))
                    .unwrap_or_else(|e| panic!("{name}: re-encoding not read: {e}"));
                assert_eq!(got, want, "{name} (re-encoded)");
                reencoded += 1;
            }
            Err(msg) => rejected.push(msg),
        }
    }
    eprintln!(
        "MCAP conformance: {} files: {exact} read exactly, {} rejected with an error, \
         {pointers} are git-LFS pointers (named as such; their {reencoded} re-encodings read exactly)",
        files.len(),
        rejected.len()
    );
    for r in &rejected {
        eprintln!("  rejected: {r}");
    }
    assert_eq!(exact + rejected.len() + pointers, files.len());
}

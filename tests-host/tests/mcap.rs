//! MCAP: what gaitclip writes reads back with the same strides; ROS 2 Imu (CDR) is read;
//! files without an IMU channel are rejected with the channels listed.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::PathBuf;

use gaitclip_host::io::csv_trace;
use gaitclip_host::io::mcap_io::{self, encode_ros2_imu, McapError, ROS2_IMU_SCHEMA};
use gaitclip_host::io::trace::Ranges;
use gaitclip_host::replay::replay;

fn demo() -> gaitclip_host::io::trace::Trace {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.csv");
    csv_trace::read(&p, None).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("gaitclip-mcap-{}-{name}", std::process::id()))
}

#[test]
fn written_mcap_replays_to_the_same_strides() {
    let trace = demo();
    let strides = replay(&trace, Ranges::default()).unwrap();
    let path = tmp("roundtrip.mcap");
    mcap_io::write(
        std::fs::File::create(&path).unwrap(),
        &trace.samples,
        &strides,
        None,
    )
    .unwrap();
    let back = mcap_io::read(&path, None).unwrap();
    assert_eq!(back.samples, trace.samples);
    assert!((back.rate_hz - 200.0).abs() < 1e-6);
    assert_eq!(replay(&back, Ranges::default()).unwrap(), strides);
    // The stride channel is there too, one message per stride.
    let bytes = std::fs::read(&path).unwrap();
    let n = mcap::MessageStream::new(&bytes)
        .unwrap()
        .filter(|m| m.as_ref().unwrap().channel.topic == mcap_io::STRIDE_TOPIC)
        .count();
    assert_eq!(n, strides.len());
    let _ = std::fs::remove_file(path);
}

#[test]
fn ros2_imu_cdr_is_read() {
    let trace = demo();
    let path = tmp("ros2.mcap");
    {
        let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
        let schema = w
            .add_schema(ROS2_IMU_SCHEMA, "ros2msg", b"# sensor_msgs/msg/Imu")
            .unwrap();
        let ch = w
            .add_channel(schema, "/imu/data", "cdr", &BTreeMap::new())
            .unwrap();
        for (i, s) in trace.samples.iter().enumerate() {
            let data = encode_ros2_imu(s, "left_foot");
            let h = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i as u32,
                log_time: (s.t_s * 1e9) as u64,
                publish_time: (s.t_s * 1e9) as u64,
            };
            w.write_to_known_channel(&h, &data).unwrap();
        }
        w.finish().unwrap();
        std::fs::write(&path, w.into_inner().into_inner()).unwrap();
    }
    let back = mcap_io::read(&path, None).unwrap();
    assert_eq!(back.samples.len(), trace.samples.len());
    for (a, b) in back.samples.iter().zip(&trace.samples) {
        assert!((a.t_s - b.t_s).abs() < 1e-9);
        assert_eq!(a.acc_mps2, b.acc_mps2);
        assert_eq!(a.gyr_radps, b.gyr_radps);
    }
    let strides_a = replay(&back, Ranges::default()).unwrap();
    let strides_b = replay(&trace, Ranges::default()).unwrap();
    assert_eq!(strides_a.len(), strides_b.len());
    for (a, b) in strides_a.iter().zip(&strides_b) {
        assert_eq!(a.raw, b.raw);
    }
    let _ = std::fs::remove_file(path);
}

#[test]
fn big_endian_cdr_decodes_too() {
    let s = demo().samples[100];
    let le = encode_ros2_imu(&s, "x");
    // Re-encode as big endian by hand: header 00 00, then each aligned field byte-swapped.
    let mut be = vec![0x00, 0x00, 0x00, 0x00];
    let body = &le[4..];
    be.extend(body[0..4].iter().rev());
    be.extend(body[4..8].iter().rev());
    be.extend(body[8..12].iter().rev());
    be.extend_from_slice(&body[12..14]); // "x\0"
    be.extend_from_slice(&body[14..16]); // padding to 8
    for chunk in body[16..].chunks(8) {
        be.extend(chunk.iter().rev());
    }
    let d = mcap_io::decode_ros2_imu(&be).unwrap();
    assert_eq!(d.acc_mps2, s.acc_mps2);
    assert_eq!(d.gyr_radps, s.gyr_radps);
    assert!(mcap_io::decode_ros2_imu(&be[..40])
        .unwrap_err()
        .contains("truncated"));
}

#[test]
fn mcap_without_imu_lists_the_channels_it_saw() {
    let path = tmp("noimu.mcap");
    {
        let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
        let schema = w.add_schema("foo.Bar", "jsonschema", b"{}").unwrap();
        let ch = w
            .add_channel(schema, "/gps", "json", &BTreeMap::new())
            .unwrap();
        let h = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        };
        w.write_to_known_channel(&h, b"{}").unwrap();
        w.finish().unwrap();
        std::fs::write(&path, w.into_inner().into_inner()).unwrap();
    }
    let e = mcap_io::read(&path, None).unwrap_err();
    assert!(matches!(e, McapError::NoImuChannel { .. }));
    let msg = e.to_string();
    assert!(msg.contains("/gps (foo.Bar, json)"), "{msg}");
    let _ = std::fs::remove_file(path);
}

#[test]
fn not_an_mcap_is_a_clear_error() {
    let path = tmp("bad.mcap");
    std::fs::write(&path, b"t_s,acc_x\n0,1\n").unwrap();
    let msg = mcap_io::read(&path, None).unwrap_err().to_string();
    assert!(msg.contains("not a readable MCAP file"), "{msg}");
    assert!(msg.contains("bad.mcap"), "{msg}");
    let _ = std::fs::remove_file(path);
}

#[test]
fn a_git_lfs_pointer_says_so() {
    let path = tmp("pointer.mcap");
    std::fs::write(
        &path,
        b"version https://git-lfs.github.com/spec/v1\noid sha256:45cb\nsize 362\n",
    )
    .unwrap();
    let e = mcap_io::read(&path, None).unwrap_err();
    assert!(matches!(e, McapError::LfsPointer { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains(
            "pointer.mcap: a git-LFS pointer (362 bytes of MCAP not fetched, sha256:45cb)"
        ),
        "{msg}"
    );
    assert!(msg.contains("git lfs pull"), "{msg}");
    let _ = std::fs::remove_file(path);
}

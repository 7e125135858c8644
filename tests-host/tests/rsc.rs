//! The Running Speed and Cadence encodings (`boards/common/src/rsc.rs`), byte for byte: the
//! layout of the Bluetooth SIG's RSC Service 1.0 (§3.1 RSC Measurement, §3.2 RSC Feature,
//! §3.4 SC Control Point), the test vector of Nordic's decoder, and a decoder written here in
//! the field order of Nordic's `RunningSpeedAndCadenceMeasurementDataCallback`
//! (NordicSemiconductor/Android-BLE-Library, ble-common/…/callback/rsc/): flags u8; speed
//! u16 / 256 m/s; cadence u8; stride length u16 cm if flags & 0x01; total distance u32 dm if
//! flags & 0x02; running if flags & 0x04.

use gaitclip::record::gait::{Gait, GaitParameters};
use gaitclip::record::stride::{Stride, StrideEvents, StrideFlags};
use gaitclip::sensor::rate::SampleRate;
use gaitclip_board::rsc::{self, ControlPointRefusal, FootPod, Measurement};

/// What Nordic's decoder reads from a notification: running, speed m/s, cadence, stride
/// length cm, total distance dm; `None` when it would report invalid data (too short).
type Decoded = (bool, f32, u8, Option<u16>, Option<u32>);

fn nordic_decode(d: &[u8]) -> Option<Decoded> {
    if d.len() < 4 {
        return None;
    }
    let flags = d[0];
    let (stride_present, total_present, running) =
        (flags & 0x01 != 0, flags & 0x02 != 0, flags & 0x04 != 0);
    let speed = u16::from_le_bytes([d[1], d[2]]) as f32 / 256.0;
    let cadence = d[3];
    if d.len() < 4 + if stride_present { 2 } else { 0 } + if total_present { 4 } else { 0 } {
        return None;
    }
    let mut offset = 4;
    let stride = stride_present.then(|| {
        offset += 2;
        u16::from_le_bytes([d[offset - 2], d[offset - 1]])
    });
    let total =
        total_present.then(|| u32::from_le_bytes(d[offset..offset + 4].try_into().unwrap()));
    Some((running, speed, cadence, stride, total))
}

fn encode(m: &Measurement) -> Vec<u8> {
    let mut buf = [0u8; rsc::MAX_MEASUREMENT_LEN];
    let n = m.encode(&mut buf);
    buf[..n].to_vec()
}

#[test]
fn measurement_matches_nordics_test_vector() {
    // Nordic's RunningSpeedAndCadenceMeasurementDataCallbackTest: flags 0x07, speed 3 m/s,
    // cadence 18, stride 86 cm, total 0xF0000001 dm, in 10 bytes.
    let m = Measurement {
        speed_256ths_m_s: 3 * 256,
        cadence_per_min: 18,
        stride_length_cm: Some(86),
        total_distance_dm: Some(0xF000_0001),
        running: true,
    };
    let bytes = encode(&m);
    assert_eq!(
        bytes,
        [0x07, 0x00, 0x03, 18, 86, 0x00, 0x01, 0x00, 0x00, 0xF0]
    );
    assert_eq!(
        nordic_decode(&bytes),
        Some((true, 3.0, 18, Some(86), Some(0xF000_0001)))
    );
    // Nordic rejects a notification whose flags promise more than it carries.
    assert_eq!(nordic_decode(&bytes[..9]), None);
}

fn stride(length_mm: u32, gait: Gait, flags: u16) -> Stride {
    let mut s = Stride {
        events: StrideEvents {
            start: 0,
            heel_off: 40,
            toe_off: 60,
            heel_strike: 140,
            foot_flat: 160,
            end: 220,
        },
        length_mm,
        flags: StrideFlags(flags),
        ..Stride::default()
    };
    s.gait = GaitParameters::of(
        &s,
        None,
        gaitclip::sensor::rate::SampleRate::from_hz(200).unwrap(),
    );
    s.gait.gait = gait;
    s
}

#[test]
fn stride_to_notification_field_by_field() {
    let mut pod = FootPod::new();
    // 1.40 m in 1.1 s: 1.273 m/s = 325.8/256, 109 steps/min of both feet, 55 contacts of the
    // sensor's foot per minute (RSCS's cadence).
    let s = stride(1400, Gait::Walking, 0);
    let m = pod.stride(&s, 5000);
    assert_eq!(s.gait.gait_velocity_mm_s, 1273);
    assert_eq!(m.speed_256ths_m_s, 326);
    assert_eq!(s.gait.cadence_spm, 109);
    assert_eq!(m.cadence_per_min, 55);
    assert_eq!(m.stride_length_cm, Some(140));
    assert_eq!(m.total_distance_dm, Some(14));
    let bytes = encode(&m);
    assert_eq!(bytes, [0x03, 0x46, 0x01, 55, 140, 0, 14, 0, 0, 0]);
    let (running, speed, cadence, cm, dm) = nordic_decode(&bytes).unwrap();
    assert!(!running);
    assert!((speed - 1.273).abs() < 1.0 / 256.0);
    assert_eq!((cadence, cm, dm), (55, Some(140), Some(14)));

    // Running sets bit 2; the distance keeps adding up, in dm of the mm total.
    let m = pod.stride(&stride(2650, Gait::Running, 0), 5700);
    assert_eq!(encode(&m)[0], 0x07);
    assert_eq!(m.total_distance_dm, Some(40));
    // A gap stride has no length: no stride-length field, nothing added.
    let m = pod.stride(&stride(0, Gait::Unknown, StrideFlags::GAP), 6400);
    let bytes = encode(&m);
    assert_eq!(bytes.len(), 8);
    assert_eq!(bytes[0], 0x02);
    assert_eq!(nordic_decode(&bytes).unwrap().3, None);
    assert_eq!(pod.total_distance_dm(), 40);
    // A gap stride of two cycles, estimated: its length adds to the total but is not one
    // stride's, and its cadence (from the two cycles' time) is not the walker's: the last
    // stride's is repeated.
    let flags = StrideFlags::GAP | StrideFlags::ESTIMATED | StrideFlags::SEVERAL_CYCLES;
    let mut two = stride(2 * 2650, Gait::Unknown, flags);
    two.events.end *= 2;
    two.gait = GaitParameters::of(&two, None, SampleRate::from_hz(200).unwrap());
    let m = pod.stride(&two, 8600);
    assert_eq!(m.stride_length_cm, None);
    assert_eq!(m.cadence_per_min, 55);
    assert_eq!(two.gait.cadence_spm.div_ceil(2), 28);
    assert_eq!(m.total_distance_dm, Some(40 + 53));
}

#[test]
fn speed_and_cadence_saturate() {
    let mut s = stride(6000, Gait::Running, 0);
    s.gait.gait_velocity_mm_s = u16::MAX;
    s.gait.cadence_spm = 600;
    let m = Measurement::of_stride(&s, u32::MAX);
    assert_eq!(m.speed_256ths_m_s, 16_777);
    assert_eq!(m.cadence_per_min, 255);
    assert_eq!(&encode(&m)[6..], &[0xFF; 4]);
}

#[test]
fn standing_notifications_about_once_a_second() {
    let mut pod = FootPod::new();
    // Nothing walked yet: standing from the start.
    assert_eq!(pod.standing_due(0), Some(Measurement::standing(0)));
    assert_eq!(pod.standing_due(500), None);
    assert_eq!(
        encode(&pod.standing_due(1000).unwrap()),
        [0x02, 0, 0, 0, 0, 0, 0, 0]
    );
    pod.stride(&stride(1300, Gait::Walking, 0), 10_000);
    // Walking: no speed-0 notification between strides.
    for t in [10_500, 11_000, 11_999] {
        assert_eq!(pod.standing_due(t), None, "{t}");
    }
    let m = pod.standing_due(12_000).unwrap();
    assert_eq!((m.speed_256ths_m_s, m.total_distance_dm), (0, Some(13)));
    assert_eq!(pod.standing_due(12_900), None);
    assert!(pod.standing_due(13_000).is_some());
    // Across the u32 wrap of the millisecond clock.
    pod.stride(&stride(1300, Gait::Walking, 0), u32::MAX - 500);
    assert_eq!(pod.standing_due(1000), None);
    assert!(pod.standing_due(1500).is_some());
}

#[test]
fn feature_and_location() {
    // Stride length, total distance, walking/running: bits 0–2, little endian.
    assert_eq!(rsc::feature(), [0x07, 0x00]);
    assert_eq!(rsc::SENSOR_LOCATION_TOP_OF_SHOE, 1);
    assert_eq!(rsc::APPEARANCE_ON_SHOE, (0x011 << 6) | 0x02);
}

#[test]
fn control_point_state_machine() {
    let mut pod = FootPod::new();
    pod.stride(&stride(1400, Gait::Walking, 0), 0);
    // Indications off: refused at the ATT level, nothing changes.
    assert_eq!(
        pod.control_point(&[0x01, 0x10, 0x27, 0, 0], false),
        Err(ControlPointRefusal::CccdImproperlyConfigured)
    );
    assert_eq!(
        ControlPointRefusal::CccdImproperlyConfigured.att_error(),
        0x81
    );
    assert_eq!(pod.total_distance_dm(), 14);
    // Set Cumulative Value: 10 000 dm = 1 km.
    assert_eq!(
        pod.control_point(&[0x01, 0x10, 0x27, 0, 0], true),
        Ok([0x10, 0x01, 0x01])
    );
    assert_eq!(pod.total_distance_dm(), 10_000);
    // Until the response is indicated, a second write is a procedure in progress.
    assert_eq!(
        pod.control_point(&[0x01, 0, 0, 0, 0], true),
        Err(ControlPointRefusal::ProcedureAlreadyInProgress)
    );
    assert_eq!(
        ControlPointRefusal::ProcedureAlreadyInProgress.att_error(),
        0x80
    );
    pod.indication_done();
    // The total goes on from the value set.
    pod.stride(&stride(1400, Gait::Walking, 0), 1100);
    assert_eq!(pod.total_distance_dm(), 10_014);
    // Other op codes: calibration, sensor location, supported locations, unknown.
    for op in [0x02, 0x03, 0x04, 0x7F, 0x10] {
        assert_eq!(pod.control_point(&[op, 1], true), Ok([0x10, op, 0x02]));
        pod.indication_done();
    }
    // A Set Cumulative Value without its 4-byte parameter.
    for bad in [&[0x01][..], &[0x01, 1, 2, 3]] {
        assert_eq!(pod.control_point(bad, true), Ok([0x10, 0x01, 0x03]));
        pod.indication_done();
    }
    // Longer than any procedure's 5 bytes: refused at the ATT level, as an empty write.
    assert_eq!(
        pod.control_point(&[0x01, 1, 2, 3, 4, 5], true),
        Err(ControlPointRefusal::TooLong)
    );
    assert_eq!(ControlPointRefusal::TooLong.att_error(), 0x0D);
    assert_eq!(
        pod.total_distance_dm(),
        10_014,
        "invalid writes change nothing"
    );
    assert_eq!(
        pod.control_point(&[], true),
        Err(ControlPointRefusal::Empty)
    );
    // The response decodes in Nordic's SpeedAndCadenceControlPointDataCallback order:
    // [0x10, request op code, result]; its test vector for success is [0x10, 0x01, 0x01].
    let r = pod.control_point(&[0x01, 0, 0, 0, 0], true).unwrap();
    assert_eq!(r, [0x10, 0x01, 0x01]);
    assert_eq!(pod.total_distance_dm(), 0);
}

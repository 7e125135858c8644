//! The foot pod's GATT table (`boards/common/src/rsc_gatt.rs`), built with trouble-host on
//! the host, without a controller, and read back attribute by attribute: the services and
//! characteristics a watch looks for, their properties, and the values a central reads.

use gaitclip_board::rsc;
use gaitclip_board::rsc_gatt::{self, battery_percent, FootPodServer, PodLink};
use trouble_host::prelude::*;

/// Every attribute: (handle, UUID, value as read), in handle order.
fn attributes(server: &FootPodServer<'_>) -> Vec<(u16, Uuid, Vec<u8>)> {
    let table = server.table();
    (1..=table.len() as u16)
        .filter_map(|h| {
            let uuid = table.uuid(h)?;
            let mut buf = [0u8; 64];
            let n = table.read(h, 0, &mut buf).unwrap_or(0);
            Some((h, uuid, buf[..n].to_vec()))
        })
        .collect()
}

fn u16_uuid(v: u16) -> Uuid {
    Uuid::new_short(v)
}

/// The declaration attribute (0x2803) of a characteristic: properties, value handle, UUID.
fn declaration_of(attrs: &[(u16, Uuid, Vec<u8>)], uuid: u16) -> (u8, u16) {
    attrs
        .iter()
        .filter(|a| a.1 == u16_uuid(0x2803))
        .map(|a| (a.2[0], u16::from_le_bytes([a.2[1], a.2[2]]), &a.2[3..]))
        .find(|d| d.2 == uuid.to_le_bytes())
        .map(|d| (d.0, d.1))
        .unwrap_or_else(|| panic!("no characteristic {uuid:#06x}"))
}

fn value_at(attrs: &[(u16, Uuid, Vec<u8>)], handle: u16) -> Vec<u8> {
    attrs.iter().find(|a| a.0 == handle).unwrap().2.clone()
}

const READ: u8 = 0x02;
const WRITE: u8 = 0x08;
const NOTIFY: u8 = 0x10;
const INDICATE: u8 = 0x20;

#[test]
fn gatt_table_reads_back() {
    let server = FootPodServer::new_with_config(GapConfig::Peripheral(PeripheralConfig {
        name: rsc_gatt::DEVICE_NAME,
        appearance: &appearance::running_walking_sensor::ON_SHOE_RUNNING_WALKING_SENSOR,
    }))
    .unwrap();
    let attrs = attributes(&server);

    // Primary services (0x2800) in order: GAP, GATT, RSC, Battery, Device Information.
    let services: Vec<Vec<u8>> = attrs
        .iter()
        .filter(|a| a.1 == u16_uuid(0x2800))
        .map(|a| a.2.clone())
        .collect();
    for s in [rsc::SERVICE_UUID, 0x180F, 0x180A] {
        assert!(
            services.contains(&s.to_le_bytes().to_vec()),
            "service {s:#06x}"
        );
    }

    // RSC Measurement: notify only, with its CCCD.
    let (props, h) = declaration_of(&attrs, rsc::MEASUREMENT_UUID);
    assert_eq!(props, NOTIFY);
    assert_eq!(
        attrs.iter().find(|a| a.0 == h + 1).unwrap().1,
        u16_uuid(0x2902)
    );
    // RSC Feature: read, stride length + total distance + walking/running.
    let (props, h) = declaration_of(&attrs, rsc::FEATURE_UUID);
    assert_eq!(props, READ);
    assert_eq!(value_at(&attrs, h), [0x07, 0x00]);
    // Sensor Location: top of shoe.
    let (props, h) = declaration_of(&attrs, rsc::SENSOR_LOCATION_UUID);
    assert_eq!(props, READ);
    assert_eq!(value_at(&attrs, h), [1]);
    // SC Control Point: write and indicate, with a CCCD.
    let (props, h) = declaration_of(&attrs, rsc::CONTROL_POINT_UUID);
    assert_eq!(props, WRITE | INDICATE);
    assert_eq!(
        attrs.iter().find(|a| a.0 == h + 1).unwrap().1,
        u16_uuid(0x2902)
    );
    assert_eq!(
        server.rsc.control_point.cccd_handle().map(|c| c.handle()),
        Some(h + 1)
    );
    // Battery level: read + notify, 100 % until measured.
    let (props, h) = declaration_of(&attrs, 0x2A19);
    assert_eq!(props, READ | NOTIFY);
    assert_eq!(value_at(&attrs, h), [100]);
    // Device Information strings.
    let (_, h) = declaration_of(&attrs, 0x2A29);
    assert_eq!(value_at(&attrs, h), b"gaitclip");
    let (_, h) = declaration_of(&attrs, 0x2A26);
    assert_eq!(value_at(&attrs, h), env!("CARGO_PKG_VERSION").as_bytes());
    // GAP: the name and the appearance 0x0442.
    let (_, h) = declaration_of(&attrs, 0x2A00);
    assert_eq!(value_at(&attrs, h), b"gaitclip");
    let (_, h) = declaration_of(&attrs, 0x2A01);
    assert_eq!(value_at(&attrs, h), rsc::APPEARANCE_ON_SHOE.to_le_bytes());
}

/// Walks AD structures: (type, data).
fn ad_structures(d: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < d.len() {
        let len = d[i] as usize;
        assert!(len > 0 && i + 1 + len <= d.len(), "malformed AD at {i}");
        out.push((d[i + 1], d[i + 2..i + 1 + len].to_vec()));
        i += 1 + len;
    }
    out
}

#[test]
fn advertising_data_names_the_rsc_service() {
    let mut buf = [0u8; 31];
    let n = rsc_gatt::advertising_data(&mut buf).unwrap();
    let ad = ad_structures(&buf[..n]);
    // Flags: LE general discoverable, BR/EDR not supported.
    assert!(ad.contains(&(0x01, vec![0x06])));
    // Complete list of 16-bit services: RSC first.
    let services = ad.iter().find(|a| a.0 == 0x03).expect("16-bit services");
    assert_eq!(&services.1[..2], &[0x14, 0x18]);
    assert!(ad.contains(&(0x19, vec![0x42, 0x04])), "appearance 0x0442");
    assert!(ad.contains(&(0x09, b"gaitclip".to_vec())));
}

#[test]
fn strides_count_without_a_central() {
    let link = PodLink::new();
    let mut s = gaitclip::record::stride::Stride {
        events: gaitclip::record::stride::StrideEvents {
            end: 220,
            ..gaitclip::record::stride::StrideEvents::default()
        },
        length_mm: 1400,
        ..Default::default()
    };
    s.gait.gait_velocity_mm_s = 1273;
    // Nobody drains the queue: the first QUEUED_MEASUREMENTS are queued, the rest counted,
    // and every stride's length is in the total.
    for i in 0..10 {
        link.stride(&s, i * 1100);
    }
    assert_eq!(link.total_distance_dm(), 140);
    assert_eq!(
        link.counters(),
        (0, 10 - rsc_gatt::QUEUED_MEASUREMENTS as u32, 0)
    );
}

#[test]
fn battery_percent_over_the_supply_window() {
    assert_eq!(battery_percent(3300), 100);
    assert_eq!(battery_percent(3000), 100);
    assert_eq!(battery_percent(2375), 0);
    assert_eq!(battery_percent(1800), 0);
    assert_eq!(battery_percent(2688), 50);
}

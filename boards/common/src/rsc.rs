//! The Bluetooth Running Speed and Cadence service (RSC, 0x1814) of a foot pod: what its
//! characteristics carry, byte for byte, and the foot pod's state (total distance, the SC
//! Control Point, when to say the wearer stands still). Pure `no_std`, no radio: the BLE
//! firmware (`rsc_gatt`, feature `ble`) sends what these functions encode, and the host tests
//! check them against the layout of the Bluetooth SIG's *Running Speed and Cadence Service*
//! 1.0 (§3.1–3.4) and against the field order of Nordic's decoder
//! (`RunningSpeedAndCadenceMeasurementDataCallback` of the Android BLE library).
//!
//! **RSC Measurement** (0x2A53, notify), little endian:
//!
//! | bytes | field | unit | from the stride |
//! |---|---|---|---|
//! | 1 | flags: bit 0 stride length present, bit 1 total distance present, bit 2 running | | [`Gait::Running`] sets bit 2 |
//! | 2 | instantaneous speed | 1/256 m/s | [`gaitclip::record::gait::GaitParameters::gait_velocity_mm_s`] |
//! | 1 | instantaneous cadence | 1/min: the sensor's foot's contacts, strides per minute | half [`gaitclip::record::gait::GaitParameters::cadence_spm`], rounded (saturated at 255); a stride of several cycles repeats the last one's |
//! | 2 | instantaneous stride length (if bit 0) | cm | [`Stride::length_mm`], for a stride that counts in the distance (measured, or estimated) and is one stride (not [`StrideFlags::SEVERAL_CYCLES`]: its length is the cycles', and counts in the total distance only) |
//! | 4 | total distance (if bit 1) | dm | [`FootPod::total_distance_dm`] |
//!
//! **Cadence and stride, as RSCS 1.0 defines them**: "the cadence represents the number of
//! times per minute the foot with the sensor hits the ground" and "the stride length
//! represents the distance between two successive contacts of the same foot to the ground"
//! (RSCS v1.0, 2012-08-07, §2 and the RSC Measurement characteristic). Both are per stride of
//! the instrumented foot: the cadence sent is strides per minute, half the steps per minute
//! of both feet ([`gaitclip::record::gait::GaitParameters::cadence_spm`]) that the logs and the
//! JSON give. Consumers differ in what they make of it: the interoperability table of docs/bluetooth.md.

use gaitclip::record::gait::Gait;
use gaitclip::record::stride::{Stride, StrideFlags};

/// The service.
pub const SERVICE_UUID: u16 = 0x1814;
/// RSC Measurement (notify).
pub const MEASUREMENT_UUID: u16 = 0x2A53;
/// RSC Feature (read).
pub const FEATURE_UUID: u16 = 0x2A54;
/// Sensor Location (read).
pub const SENSOR_LOCATION_UUID: u16 = 0x2A5D;
/// SC Control Point (write, indicate).
pub const CONTROL_POINT_UUID: u16 = 0x2A55;
/// GAP appearance: Running Walking Sensor, on-shoe (category 0x011, subcategory 0x02).
pub const APPEARANCE_ON_SHOE: u16 = 0x0442;
/// Sensor Location: top of shoe.
pub const SENSOR_LOCATION_TOP_OF_SHOE: u8 = 1;

/// RSC Feature bit: instantaneous stride length measured.
pub const FEATURE_STRIDE_LENGTH: u16 = 1 << 0;
/// RSC Feature bit: total distance measured.
pub const FEATURE_TOTAL_DISTANCE: u16 = 1 << 1;
/// RSC Feature bit: walking or running status.
pub const FEATURE_WALKING_OR_RUNNING: u16 = 1 << 2;
/// What gaitclip measures (no calibration procedure, one sensor location).
pub const FEATURES: u16 =
    FEATURE_STRIDE_LENGTH | FEATURE_TOTAL_DISTANCE | FEATURE_WALKING_OR_RUNNING;

/// Measurement flag: stride length present.
pub const FLAG_STRIDE_LENGTH: u8 = 1 << 0;
/// Measurement flag: total distance present.
pub const FLAG_TOTAL_DISTANCE: u8 = 1 << 1;
/// Measurement flag: running (clear: walking).
pub const FLAG_RUNNING: u8 = 1 << 2;

/// Longest RSC Measurement: flags, speed, cadence, stride length, total distance.
pub const MAX_MEASUREMENT_LEN: usize = 10;

/// SC Control Point op code: Set Cumulative Value (total distance, u32 dm).
pub const OP_SET_CUMULATIVE_VALUE: u8 = 0x01;
/// SC Control Point op code of a response.
pub const OP_RESPONSE: u8 = 0x10;
/// Response value: success.
pub const RESULT_SUCCESS: u8 = 0x01;
/// Response value: op code not supported.
pub const RESULT_NOT_SUPPORTED: u8 = 0x02;
/// Response value: invalid parameter.
pub const RESULT_INVALID_PARAMETER: u8 = 0x03;

/// Time without a stride after which the wearer is standing, ms: longer than the slowest
/// walking stride (≈ 1.6 s).
pub const STANDING_AFTER_MS: u32 = 2000;
/// Interval of the speed-0 notifications while standing, ms.
pub const STANDING_EVERY_MS: u32 = 1000;

/// One RSC Measurement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measurement {
    /// Instantaneous speed, 1/256 m/s.
    pub speed_256ths_m_s: u16,
    /// Instantaneous cadence, 1/min: contacts of the sensor's foot (strides) per minute.
    pub cadence_per_min: u8,
    /// Instantaneous stride length, cm (absent for a stride without a length).
    pub stride_length_cm: Option<u16>,
    /// Total distance, dm.
    pub total_distance_dm: Option<u32>,
    /// Running (a flight phase) rather than walking.
    pub running: bool,
}

impl Measurement {
    /// The measurement of `stride`, with the total distance after it.
    pub fn of_stride(stride: &Stride, total_distance_dm: u32) -> Self {
        let g = &stride.gait;
        let has_length = stride.flags.counts_distance()
            && stride.length_mm > 0
            && !stride.flags.has(StrideFlags::SEVERAL_CYCLES);
        Measurement {
            // mm/s · 256/1000, rounded: at most 65 535 mm/s → 16 777 < 2¹⁶.
            speed_256ths_m_s: ((g.gait_velocity_mm_s as u32 * 256 + 500) / 1000) as u16,
            // Steps of both feet to the sensor's foot's contacts: half, rounded.
            cadence_per_min: g.cadence_spm.div_ceil(2).min(u8::MAX as u16) as u8,
            stride_length_cm: has_length
                .then(|| ((stride.length_mm + 5) / 10).min(u16::MAX as u32) as u16),
            total_distance_dm: Some(total_distance_dm),
            running: g.gait == Gait::Running,
        }
    }

    /// Standing still: speed and cadence 0, the total distance.
    pub const fn standing(total_distance_dm: u32) -> Self {
        Measurement {
            speed_256ths_m_s: 0,
            cadence_per_min: 0,
            stride_length_cm: None,
            total_distance_dm: Some(total_distance_dm),
            running: false,
        }
    }

    /// The characteristic's value: `buf[..n]` for the `n` returned.
    pub fn encode(&self, buf: &mut [u8; MAX_MEASUREMENT_LEN]) -> usize {
        let mut flags = 0;
        if self.stride_length_cm.is_some() {
            flags |= FLAG_STRIDE_LENGTH;
        }
        if self.total_distance_dm.is_some() {
            flags |= FLAG_TOTAL_DISTANCE;
        }
        if self.running {
            flags |= FLAG_RUNNING;
        }
        buf[0] = flags;
        buf[1..3].copy_from_slice(&self.speed_256ths_m_s.to_le_bytes());
        buf[3] = self.cadence_per_min;
        let mut n = 4;
        if let Some(cm) = self.stride_length_cm {
            buf[n..n + 2].copy_from_slice(&cm.to_le_bytes());
            n += 2;
        }
        if let Some(dm) = self.total_distance_dm {
            buf[n..n + 4].copy_from_slice(&dm.to_le_bytes());
            n += 4;
        }
        n
    }
}

/// The RSC Feature characteristic's value.
pub const fn feature() -> [u8; 2] {
    FEATURES.to_le_bytes()
}

/// Why a write to the SC Control Point is refused at the ATT level (RSCS §3.4.2; the codes
/// are the profile's ATT application errors and the core's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlPointRefusal {
    /// A procedure's indication is not confirmed yet (ATT error 0x80).
    ProcedureAlreadyInProgress,
    /// The client has not enabled indications (ATT error 0x81).
    CccdImproperlyConfigured,
    /// An empty write: no op code (ATT error 0x0D, invalid attribute value length).
    Empty,
    /// A write longer than any procedure's ([`CONTROL_POINT_MAX_LEN`]; ATT error 0x0D).
    TooLong,
}

/// The longest SC Control Point write: Set Cumulative Value, op code and a `u32`.
pub const CONTROL_POINT_MAX_LEN: usize = 5;

impl ControlPointRefusal {
    /// The ATT error code.
    pub const fn att_error(self) -> u8 {
        match self {
            ControlPointRefusal::ProcedureAlreadyInProgress => 0x80,
            ControlPointRefusal::CccdImproperlyConfigured => 0x81,
            ControlPointRefusal::Empty | ControlPointRefusal::TooLong => 0x0D,
        }
    }
}

/// The foot pod: total distance, the SC Control Point's procedure, and when to notify.
///
/// The total counts every stride the pipeline measures, connected or not: a watch that
/// connects later reads the distance walked since power-up (or since it set the value).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FootPod {
    /// Distance, mm (the unit the strides carry; RSC's dm is derived).
    total_mm: u64,
    /// When the last stride was reported, ms.
    last_stride_ms: Option<u32>,
    /// When the last measurement (stride or standing) was due, ms.
    last_notified_ms: Option<u32>,
    /// A control-point response is waiting for its indication's confirmation.
    procedure_pending: bool,
    /// The cadence of the last stride of one cycle, 1/min: what a stride of several cycles
    /// (whose duration is theirs) reports.
    last_cadence_per_min: u8,
}

impl Default for FootPod {
    fn default() -> Self {
        Self::new()
    }
}

impl FootPod {
    /// A pod that has walked nowhere.
    pub const fn new() -> Self {
        FootPod {
            total_mm: 0,
            last_stride_ms: None,
            last_notified_ms: None,
            procedure_pending: false,
            last_cadence_per_min: 0,
        }
    }

    /// Total distance, dm, as RSC carries it (wraps at 2³² dm = 429 497 km).
    pub const fn total_distance_dm(&self) -> u32 {
        (self.total_mm / 100) as u32
    }

    /// A stride at `now_ms`: adds its length when it has one (measured, or estimated where
    /// it could not be measured), and returns its measurement.
    pub fn stride(&mut self, stride: &Stride, now_ms: u32) -> Measurement {
        if stride.flags.counts_distance() {
            self.total_mm = self.total_mm.saturating_add(stride.length_mm as u64);
        }
        self.last_stride_ms = Some(now_ms);
        self.last_notified_ms = Some(now_ms);
        let mut m = Measurement::of_stride(stride, self.total_distance_dm());
        if stride.flags.has(StrideFlags::SEVERAL_CYCLES) {
            m.cadence_per_min = self.last_cadence_per_min;
        } else {
            self.last_cadence_per_min = m.cadence_per_min;
        }
        m
    }

    /// Called about every [`STANDING_EVERY_MS`]: the speed-0 measurement when no stride came
    /// for [`STANDING_AFTER_MS`] and none was due for [`STANDING_EVERY_MS`]. Times wrap
    /// (49.7 days of `u32` ms).
    pub fn standing_due(&mut self, now_ms: u32) -> Option<Measurement> {
        let since = |t: Option<u32>| t.map_or(u32::MAX, |t| now_ms.wrapping_sub(t));
        if since(self.last_stride_ms) < STANDING_AFTER_MS
            || since(self.last_notified_ms) < STANDING_EVERY_MS
        {
            return None;
        }
        self.last_notified_ms = Some(now_ms);
        Some(Measurement::standing(self.total_distance_dm()))
    }

    /// A write of `value` to the SC Control Point, with the client's indications enabled or
    /// not: the response to indicate (`[0x10, op code, result]`), or the ATT error to refuse
    /// the write with. Until [`FootPod::indication_done`], further writes are refused as a
    /// procedure in progress.
    pub fn control_point(
        &mut self,
        value: &[u8],
        indications_enabled: bool,
    ) -> Result<[u8; 3], ControlPointRefusal> {
        if !indications_enabled {
            return Err(ControlPointRefusal::CccdImproperlyConfigured);
        }
        if self.procedure_pending {
            return Err(ControlPointRefusal::ProcedureAlreadyInProgress);
        }
        if value.len() > CONTROL_POINT_MAX_LEN {
            return Err(ControlPointRefusal::TooLong);
        }
        let (&op, parameter) = value.split_first().ok_or(ControlPointRefusal::Empty)?;
        let result = match op {
            OP_SET_CUMULATIVE_VALUE => match <[u8; 4]>::try_from(parameter) {
                Ok(dm) => {
                    self.total_mm = u32::from_le_bytes(dm) as u64 * 100;
                    RESULT_SUCCESS
                }
                Err(_) => RESULT_INVALID_PARAMETER,
            },
            // Start Sensor Calibration, Update Sensor Location, Request Supported Sensor
            // Locations (RSC Feature says neither is supported), and anything else.
            _ => RESULT_NOT_SUPPORTED,
        };
        self.procedure_pending = true;
        Ok([OP_RESPONSE, op, result])
    }

    /// A control-point response is waiting for its indication's confirmation.
    pub const fn procedure_pending(&self) -> bool {
        self.procedure_pending
    }

    /// The control-point response was indicated (confirmed, or the link is gone): the next
    /// procedure may start.
    pub fn indication_done(&mut self) {
        self.procedure_pending = false;
    }
}

//! The bodies of the fuzz targets (`tests-host/fuzz/fuzz_targets/`), here so that the test
//! command replays their seed corpus and every crash ever found (`tests/fuzz_corpus.rs`)
//! through exactly the code the fuzzer ran. Each one panics when an invariant breaks.

use std::path::Path;

use gaitclip::length::estimate::MAX_CYCLES;
use gaitclip::length::models::Model;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::{StrideFlags, MAX_STRIDE_MM};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip_mpu6050::{AccelRange, GyroRange};

use crate::io::trace::{Ranges, Trace};
use crate::replay::{replay, StrideReport};
use crate::{io::csv_trace, io::mcap_io};

/// A fuzz target's body: panics when an invariant breaks.
pub type Target = fn(&[u8]);

/// The fuzz targets, by the name of their file in `fuzz/fuzz_targets/`.
pub const TARGETS: [(&str, Target); 3] = [
    ("csv_reader", csv_reader),
    ("mcap_reader", mcap_reader),
    ("core_pipeline", core_pipeline),
];

/// Arbitrary bytes as a CSV trace: an error, or samples that are finite with increasing
/// time, which then replay through the core (rate from the file, else 200 Hz).
pub fn csv_reader(data: &[u8]) {
    let Ok(samples) = csv_trace::parse(Path::new("fuzz.csv"), data) else {
        return;
    };
    check_trace(Trace {
        rate_hz: Trace::rate_from_timestamps(&samples).unwrap_or(200.0),
        samples,
        repeated: 0,
        given: Default::default(),
    });
}

/// Arbitrary bytes as an MCAP trace (gaitclip's JSON samples or ROS 2 Imu in CDR), and as
/// one CDR Imu message: an error, or finite samples with increasing time that replay.
pub fn mcap_reader(data: &[u8]) {
    // One message on its own: any bytes decode or fail, never panic.
    let _ = mcap_io::decode_ros2_imu(data);
    if let Ok(t) = mcap_io::decode(Path::new("fuzz.mcap"), data, None) {
        check_trace(t);
    }
}

fn check_trace(t: Trace) {
    for w in t.samples.windows(2) {
        assert!(w[1].t_s > w[0].t_s, "time must increase: {w:?}");
    }
    for s in &t.samples {
        assert!(s.t_s.is_finite() && s.acc_mps2.iter().chain(&s.gyr_radps).all(|v| v.is_finite()));
    }
    // A rate outside the core's range or time that cannot be replayed is a typed error.
    if let Ok(strides) = replay(&t, Ranges::default()) {
        check_reports(&strides);
    }
}

fn check_reports(strides: &[StrideReport]) {
    for s in strides {
        // One stride's length at most; an estimate of a stride that lasted several cycles
        // is theirs.
        let most_mm = match s.flags.contains(&"estimated") {
            true => MAX_CYCLES * MAX_STRIDE_MM,
            false => MAX_STRIDE_MM,
        };
        assert!(
            s.length_m.is_finite() && s.length_m <= most_mm as f64 / 1000.0,
            "{s:?}"
        );
        assert!(
            s.start_s <= s.heel_off_s && s.heel_off_s <= s.end_s,
            "{s:?}"
        );
    }
}

/// Arbitrary bytes as a run of the core: byte 0 picks the rate (100–1020 Hz in steps of
/// 4), byte 1 the detector (high bit: peak-valley) and the length model; then 13-byte
/// records: a control byte (≥ 0xF0: a gap of `(c & 0x0F) × 37` samples before the sample)
/// and six big-endian i16 (accel, gyro).
/// Every stride must be well formed: events in order, inside what was fed, lengths bounded,
/// none across a gap with a length.
pub fn core_pipeline(data: &[u8]) {
    let [rate_b, model_b, rest @ ..] = data else {
        return;
    };
    let Some(rate) = SampleRate::from_hz(100 + 4 * *rate_b as u32) else {
        return;
    };
    let mut config = Config::new(rate, AccelRange::G16.scale(), GyroRange::Dps2000.scale());
    // The high bit picks the detector, the rest the model.
    config.model = Model::ALL[(*model_b & 0x7F) as usize % Model::ALL.len()];
    if *model_b & 0x80 != 0 {
        config.detector = Detector::PeakValley;
    }
    let mut p = Pipeline::new(config);
    let mut strides = Vec::new();
    for rec in rest.chunks_exact(13) {
        if rec[0] >= 0xF0 {
            strides.extend(p.gap((rec[0] & 0x0F) as u32 * 37));
        }
        let v = |k: usize| i16::from_be_bytes([rec[1 + 2 * k], rec[2 + 2 * k]]);
        let s = RawSample {
            accel: [v(0), v(1), v(2)],
            gyro: [v(3), v(4), v(5)],
            temp: 0,
        };
        strides.extend(p.process(&s));
    }
    strides.extend(std::iter::from_fn(|| p.finish()));
    for (k, s) in strides.iter().enumerate() {
        assert!(
            s.events.start <= s.events.heel_off && s.events.heel_off <= s.events.toe_off,
            "{s:?}"
        );
        assert!(
            s.events.toe_off <= s.events.heel_strike && s.events.heel_strike <= s.events.end,
            "{s:?}"
        );
        assert!(
            s.events.start < s.events.end && s.events.end <= p.next_index(),
            "{s:?}"
        );
        let most_mm = match s.flags.has(StrideFlags::ESTIMATED) {
            true => MAX_CYCLES * MAX_STRIDE_MM,
            false => MAX_STRIDE_MM,
        };
        assert!(s.length_mm <= most_mm, "{s:?}");
        // Nothing measured across a gap: the length is the estimate, or none.
        assert!(
            !s.flags.has(StrideFlags::GAP)
                || s.flags.has(StrideFlags::ESTIMATED)
                || s.length_mm == 0,
            "{s:?}"
        );
        assert_eq!(s.index as usize, k);
    }
}

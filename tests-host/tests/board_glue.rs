//! The board glue shared by every firmware, on the host: the sampler's retries, restarts and
//! gap accounting over a bus that fails, the serial line protocol, and the start-up reports.

use embedded_hal::i2c::{ErrorType, I2c, Operation};
use embedded_hal_mock::eh1::delay::NoopDelay;
use gaitclip::pipeline::Pipeline;
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip_board::{imu_sampler, replay_mpu6050, serial_line, startup};
use gaitclip_mpu6050::blocking::{Mpu6050, Mpu6050Source};
use gaitclip_mpu6050::{AccelRange, GyroRange};
use gaitclip_mpu6050::{Address, Config, OutputRate};
use imu_sampler::{BusRecovery, Counters, ImuSampler, Item, ReadMode};
use replay_mpu6050::{ReplayBusError, ReplayMpu6050};

fn trace() -> &'static [u8] {
    std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.mpu6050"),
    )
    .unwrap()
    .leak()
}

/// The emulated sensor behind a bus whose transactions number `fail` (from 1) are NACKed.
struct FlakyBus {
    inner: ReplayMpu6050,
    fail: std::ops::Range<usize>,
    transactions: usize,
    recoveries: usize,
}

impl ErrorType for FlakyBus {
    type Error = ReplayBusError;
}

impl I2c for FlakyBus {
    fn transaction(&mut self, address: u8, ops: &mut [Operation<'_>]) -> Result<(), Self::Error> {
        self.transactions += 1;
        if self.fail.contains(&self.transactions) {
            return Err(ReplayBusError::NoDevice);
        }
        self.inner.transaction(address, ops)
    }
}

impl BusRecovery for FlakyBus {
    fn recover_bus(&mut self) -> bool {
        self.recoveries += 1;
        true
    }
}

/// Runs `pulses` data-ready interrupts; returns the items and the counters.
fn run(fail: std::ops::Range<usize>, pulses: usize) -> (Vec<Item>, Counters) {
    let bus = FlakyBus {
        inner: ReplayMpu6050::new(0x68, trace(), &[]),
        fail,
        transactions: 0,
        recoveries: 0,
    };
    let config = Config::new(OutputRate::from_hz(200).unwrap());
    let Ok(mut s) = ImuSampler::start(
        Mpu6050Source::new(Mpu6050::new(bus, Address::Ad0Low), config),
        NoopDelay,
        ReadMode::PerSample,
    ) else {
        panic!("the sensor starts");
    };
    let mut items = Vec::new();
    for _ in 0..pulses {
        s.on_data_ready(&mut |i| {
            items.push(i);
            true
        });
    }
    (items, s.counters())
}

fn samples(items: &[Item]) -> Vec<RawSample> {
    items
        .iter()
        .filter_map(|i| match i {
            Item::Sample(s) => Some(*s),
            Item::Gap(_) | Item::Asleep | Item::Woke(_) => None,
        })
        .collect()
}

/// Transactions of `start` (probe, reset, four settings, two interrupt registers).
const START_TRANSACTIONS: usize = 9;

#[test]
fn a_failed_read_is_retried_and_nothing_is_lost() {
    let (items, c) = run(START_TRANSACTIONS + 5..START_TRANSACTIONS + 6, 50);
    assert_eq!(c.bus_errors, 1);
    assert_eq!(c.lost_samples, 0);
    assert_eq!(c.restarts, 0);
    let got = samples(&items);
    let bytes = trace();
    let want: Vec<RawSample> = (0..50)
        .map(|n| {
            gaitclip_mpu6050::sample::from_be_bytes(bytes[n * 14..n * 14 + 14].try_into().unwrap())
        })
        .collect();
    assert_eq!(got, want);
}

#[test]
fn a_sensor_that_stops_answering_is_restarted_and_the_hole_is_a_gap() {
    // Transactions 20..60 fail: ten good reads, then an outage long enough for a restart
    // (which itself fails until the sensor answers again), then reads resume.
    let (items, c) = run(START_TRANSACTIONS + 11..START_TRANSACTIONS + 51, 100);
    let delivered = samples(&items).len() as u32;
    let gaps: u32 = items
        .iter()
        .map(|i| match i {
            Item::Gap(n) => *n,
            Item::Sample(_) | Item::Asleep | Item::Woke(_) => 0,
        })
        .sum();
    // Restarts were attempted (bus recovered, set-up tried) while it did not answer; this
    // emulated sensor keeps its settings, so reads resume without a completed restart.
    assert!(c.recoveries >= 1, "{c:?}");
    assert!(c.bus_errors >= 40, "{c:?}");
    assert!(gaps > 0, "the outage is reported as a gap");
    assert_eq!(gaps, c.lost_samples);
    // Every data-ready period is either a sample or part of a gap.
    assert_eq!(delivered + gaps, 100, "{c:?}");
    // The gap comes before the first sample after the outage, in order.
    let first_gap = items
        .iter()
        .position(|i| matches!(i, Item::Gap(_)))
        .unwrap();
    assert_eq!(first_gap, 10);
}

#[test]
fn a_full_queue_becomes_a_gap_not_a_silent_loss() {
    let bus = FlakyBus {
        inner: ReplayMpu6050::new(0x68, trace(), &[]),
        fail: 0..0,
        transactions: 0,
        recoveries: 0,
    };
    let Ok(mut s) = ImuSampler::start(
        Mpu6050Source::new(
            Mpu6050::new(bus, Address::Ad0Low),
            Config::new(OutputRate::from_hz(200).unwrap()),
        ),
        NoopDelay,
        ReadMode::PerSample,
    ) else {
        panic!("the sensor starts");
    };
    let mut items = Vec::new();
    for k in 0..30 {
        // The queue refuses pulses 10..15.
        s.on_data_ready(&mut |i| {
            if (10..15).contains(&k) {
                return false;
            }
            items.push(i);
            true
        });
    }
    let c = s.counters();
    assert_eq!(c.overruns, 5);
    assert_eq!(c.lost_samples, 5);
    assert_eq!(items[10], Item::Gap(5));
    assert_eq!(samples(&items).len(), 25);
}

#[test]
fn serial_stride_line_parses_back() {
    let rate = SampleRate::from_hz(200).unwrap();
    let mut stride = gaitclip::record::stride::Stride {
        index: 7,
        events: gaitclip::record::stride::StrideEvents {
            start: 1000,
            heel_off: 1084,
            toe_off: 1114,
            heel_strike: 1190,
            end: 1221,
            ..gaitclip::record::stride::StrideEvents::default()
        },
        length_mm: 1362,
        climb_mm: -3,
        ..Default::default()
    };
    stride.flags.0 = gaitclip::record::stride::StrideFlags::FROM_REST;
    stride.max_sensor_lift_mm = 131;
    stride.turning_angle_cdeg = -215;
    stride.swing_deg = 62;
    stride.between = gaitclip::record::stride::Between {
        still_ms: 1500,
        moving_ms: 250,
    };
    stride.gait = gaitclip::record::gait::GaitParameters::of(&stride, None, rate);
    let mut line = String::new();
    serial_line::stride(&mut line, rate, &stride).unwrap();
    assert!(line.len() <= serial_line::MAX_LINE);
    let body = line.strip_suffix("\r\n").expect("CRLF ending");
    let cells: Vec<&str> = body.split(',').collect();
    let header: Vec<&str> = serial_line::HEADER.split(',').collect();
    assert_eq!(cells.len(), header.len());
    let gait_at = header.iter().position(|h| *h == "gait").unwrap();
    assert_eq!(
        cells[gait_at], "unknown",
        "a stride from rest is not one cycle"
    );
    let f: Vec<i64> = cells
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != gait_at)
        .map(|(_, v)| v.parse().unwrap())
        .collect();
    assert_eq!(
        f,
        vec![
            7, 5000, 1362, 1105, 420, 150, 380, 155, -3, 4, 1, 725, 380, 656, 1233, 109, 131, -215,
            62, 1500, 250
        ]
    );
    // Stance and swing times add up to the stride time.
    assert_eq!(f[11] + f[12], f[3]);
    // The phases add up to the stride.
    assert_eq!(f[4] + f[5] + f[6] + f[7], f[3]);

    let mut status = String::new();
    let c = Counters {
        bus_errors: u32::MAX,
        restarts: u32::MAX,
        recoveries: u32::MAX,
        fifo_overflows: u32::MAX,
        silences: u32::MAX,
        overruns: u32::MAX,
        lost_samples: u32::MAX,
        sleeps: u32::MAX,
        slept_periods: u32::MAX,
    };
    serial_line::status(
        &mut status,
        u32::MAX,
        (u32::MAX, u64::MAX, u32::MAX),
        &[u32::MAX; 6],
        (
            &gaitclip::detect::step_check::Rejected {
                by_reason: [u32::MAX; 4],
                unchecked: u32::MAX,
            },
            &gaitclip::pipeline::BetweenTotals {
                still_ms: u64::MAX,
                moving_ms: u64::MAX,
            },
        ),
        &c,
    )
    .unwrap();
    assert!(status.len() <= serial_line::MAX_LINE, "{}", status.len());
    assert!(status.starts_with("# status "));
}

#[test]
fn startup_nags_until_still_then_reports_bias_and_heading() {
    let counts = gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap();
    let rate = SampleRate::from_hz(200).unwrap();
    let cfg = gaitclip::pipeline::config::Config::new(
        rate,
        AccelRange::G16.scale(),
        GyroRange::Dps2000.scale(),
    );
    let mut p = Pipeline::new(cfg);
    let mut st = startup::Startup::new(rate, GyroRange::Dps2000.scale());
    let mut events = Vec::new();
    for s in &counts {
        p.process(s);
        if let Some(e) = st.update(&p) {
            events.push(e);
        }
    }
    assert!(matches!(
        events.first(),
        Some(startup::StartupEvent::HoldStill { waited_ms: 5 })
    ));
    let still = events
        .iter()
        .find_map(|e| match e {
            startup::StartupEvent::Still {
                gyro_bias_mdps,
                gravity_mg,
                plausible,
            } => Some((*gyro_bias_mdps, *gravity_mg, *plausible)),
            _ => None,
        })
        .expect("a rest is found");
    assert!(still.2, "{still:?}");
    assert!((still.1 - 1000).abs() < 50, "{still:?}");
    assert_eq!(events.last(), Some(&startup::StartupEvent::HeadingKnown));
    assert!(st.done());
}

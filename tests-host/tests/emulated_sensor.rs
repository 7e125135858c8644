//! The emulated MPU6050 of the QEMU board, driven by the real driver on the host: it serves
//! the fixture sample by sample and ends with the trace.

use embedded_hal_mock::eh1::delay::NoopDelay;
use gaitclip_board::replay_mpu6050;
use gaitclip_mpu6050::blocking::Mpu6050;
use gaitclip_mpu6050::{Address, Config, Error, OutputRate};
use replay_mpu6050::{ReplayBusError, ReplayMpu6050};

#[test]
fn driver_reads_the_trace_through_the_emulated_bus() {
    let bytes: &'static [u8] = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/demo_walk.mpu6050"),
    )
    .unwrap()
    .leak();
    let mut imu = Mpu6050::new(ReplayMpu6050::new(0x68, bytes, &[]), Address::Ad0Low)
        .init(
            &mut NoopDelay,
            &Config::new(OutputRate::from_hz(200).unwrap()),
        )
        .unwrap();
    let mut n = 0;
    loop {
        match imu.read_sample() {
            Ok(s) => {
                let want = gaitclip_mpu6050::sample::from_be_bytes(
                    bytes[n * 14..n * 14 + 14].try_into().unwrap(),
                );
                assert_eq!(s, want);
                n += 1;
            }
            Err(Error::Bus(ReplayBusError::Exhausted)) => break,
            Err(e) => panic!("{e:?}"),
        }
    }
    assert_eq!(n, bytes.len() / 14);
}

#[test]
fn wrong_address_does_not_answer() {
    let mut imu = Mpu6050::new(ReplayMpu6050::new(0x68, &[], &[]), Address::Ad0High);
    assert_eq!(
        imu.probe().unwrap_err(),
        Error::Bus(ReplayBusError::NoDevice)
    );
}

/// The stored sprint's FIFO words (`fixtures/sprint_40g.lsm6dsv320x`) and how they were
/// recorded, for the emulated LSM6DSV320X.
fn sprint_fifo() -> (&'static [u8], gaitclip_board::replay_lsm6dsv320x::Recorded) {
    use gaitclip_host::sim::sprint::{LSM_ACCEL, LSM_GYRO, LSM_HIGH_G, LSM_WORDS_PER_SAMPLE};
    use gaitclip_lsm6dsv320x::{HighGOdr, Odr};
    let bytes: &'static [u8] = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/sprint_40g.lsm6dsv320x"),
    )
    .unwrap()
    .leak();
    let recorded = gaitclip_board::replay_lsm6dsv320x::Recorded {
        odr_field: Odr::Hz240.field(),
        fs_xl: LSM_ACCEL.field(),
        fs_g: LSM_GYRO.field(),
        high_g_ctrl: LSM_HIGH_G.field() | (HighGOdr::Hz960.field() << 3),
        words_per_period: LSM_WORDS_PER_SAMPLE,
    };
    (bytes, recorded)
}

/// The emulated LSM6DSV320X of the QEMU board, driven by the real driver on the host: it
/// fills its FIFO a period per tick only as configured, the driver reads the words in order,
/// and words left beyond the FIFO's capacity are an overrun the driver reports after emptying
/// the FIFO, with the part's clock still counting.
#[test]
fn the_emulated_lsm6dsv320x_serves_its_fifo_and_overruns_as_the_part_does() {
    use gaitclip_board::replay_lsm6dsv320x::ReplayLsm6dsv320x;
    use gaitclip_lsm6dsv320x::blocking::Lsm6dsv320x;
    use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag, WORD_BYTES};
    use gaitclip_lsm6dsv320x::{Address as LsmAddress, Config as LsmConfig, Odr};

    let (bytes, recorded) = sprint_fifo();
    let word =
        |i: usize| FifoWord::from_bytes(bytes[i * WORD_BYTES..][..WORD_BYTES].try_into().unwrap());
    let blank = FifoWord {
        tag: Tag::Other(0),
        slot: 0,
        data: [0; 3],
    };

    // Configured otherwise (500 °/s): the FIFO stays empty however long it runs.
    let other = LsmConfig {
        gyro: gaitclip_lsm6dsv320x::GyroRange::Dps500,
        ..LsmConfig::new(Odr::Hz240)
    };
    let mut imu = Lsm6dsv320x::new(
        ReplayLsm6dsv320x::new(0x6A, bytes, recorded),
        LsmAddress::Sa0Low,
    )
    .init(&mut NoopDelay, &other)
    .unwrap();
    imu.bus_mut().tick();
    assert_eq!(imu.read_fifo(&mut [blank; 8]), Ok(0));

    // As recorded: eight periods, 48 words, the recording's first, in order.
    let mut imu = Lsm6dsv320x::new(
        ReplayLsm6dsv320x::new(0x6A, bytes, recorded),
        LsmAddress::Sa0Low,
    )
    .init(&mut NoopDelay, &LsmConfig::new(Odr::Hz240))
    .unwrap();
    for _ in 0..8 {
        imu.bus_mut().tick();
    }
    let status = imu.read_fifo_status().unwrap();
    assert_eq!(status.words, 48);
    assert!(status.watermark && !status.overrun);
    let mut out = [blank; 64];
    assert_eq!(imu.read_fifo(&mut out), Ok(48));
    assert!((0..48).all(|i| out[i] == word(i)));
    assert_eq!(
        out[..6].iter().map(|w| w.tag).collect::<Vec<_>>(),
        [
            Tag::HighG,
            Tag::HighG,
            Tag::HighG,
            Tag::HighG,
            Tag::Accel,
            Tag::Gyro
        ]
    );

    // Left unread past the FIFO's 658 words (110 periods of 6): an overrun, the FIFO
    // emptied, the clock still counting; then words flow again from where the part is.
    for _ in 0..120 {
        imu.bus_mut().tick();
    }
    assert_eq!(
        imu.read_fifo(&mut out),
        Err(gaitclip_lsm6dsv320x::Error::FifoOverflow)
    );
    assert_eq!(imu.read_fifo(&mut out), Ok(0));
    assert_eq!(imu.bus_mut().ticked(), 128);
    imu.bus_mut().tick();
    assert_eq!(imu.read_fifo(&mut out), Ok(6));
    assert_eq!(out[0], word(128 * 6));
}

/// The emulated LSM6DSV320X behind a bus whose transactions number `fail` (from 1) are
/// NACKed.
struct FlakyLsm {
    inner: gaitclip_board::replay_lsm6dsv320x::ReplayLsm6dsv320x,
    fail: Vec<usize>,
    transactions: usize,
}

impl embedded_hal::i2c::ErrorType for FlakyLsm {
    type Error = gaitclip_board::replay_lsm6dsv320x::ReplayBusError;
}

impl embedded_hal::i2c::I2c for FlakyLsm {
    fn transaction(
        &mut self,
        address: u8,
        ops: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        self.transactions += 1;
        if self.fail.contains(&self.transactions) {
            return Err(gaitclip_board::replay_lsm6dsv320x::ReplayBusError::NoDevice);
        }
        self.inner.transaction(address, ops)
    }
}

impl gaitclip_board::imu_sampler::BusRecovery for FlakyLsm {
    fn recover_bus(&mut self) -> bool {
        false
    }
}

/// What the live boards' sampler hands on from the emulated LSM6DSV320X, pulsed at every
/// watermark as INT1 would be, with the transactions `fail` NACKed; and its counters.
fn lsm_live(
    fail: Vec<usize>,
) -> (
    Vec<gaitclip_board::imu_sampler::Item>,
    gaitclip_board::imu_sampler::Counters,
    usize,
) {
    use gaitclip_board::imu_sampler::ImuSampler;
    use gaitclip_board::live_settings::lsm6dsv320x as settings;
    use gaitclip_board::replay_lsm6dsv320x::ReplayLsm6dsv320x;
    use gaitclip_lsm6dsv320x::blocking::{Lsm6dsv320x, Lsm6dsv320xSource};

    let (bytes, recorded) = sprint_fifo();
    let bus = FlakyLsm {
        inner: ReplayLsm6dsv320x::new(0x6A, bytes, recorded),
        fail,
        transactions: 0,
    };
    let source = Lsm6dsv320xSource::new(Lsm6dsv320x::new(bus, settings::ADDRESS), settings::SENSOR);
    let Ok(mut sampler) = ImuSampler::start(source, NoopDelay, settings::MODE) else {
        panic!("the part starts");
    };
    let watermark = settings::SENSOR.watermark_words as usize;
    let mut items = Vec::new();
    let mut pulses = 0;
    loop {
        let Some(part) = sampler.bus_mut() else {
            panic!("the part is on the bus between calls");
        };
        if part.inner.remaining() == 0 {
            break;
        }
        part.inner.tick();
        // INT1 rises when the FIFO reaches its watermark (a level: one edge per crossing).
        if part.inner.waiting() == watermark {
            pulses += 1;
            sampler.on_data_ready(&mut |item| {
                items.push(item);
                true
            });
        }
    }
    (items, sampler.counters(), pulses)
}

#[test]
fn the_live_sampler_reads_the_lsm6dsv320x_at_its_watermark_and_merges_as_the_replay_does() {
    use gaitclip_board::imu_sampler::Item;
    use gaitclip_board::live_settings::lsm6dsv320x as settings;
    use gaitclip_lsm6dsv320x::fifo::{FifoWord, WORD_BYTES};
    use gaitclip_lsm6dsv320x::merge::Assembler;

    let (bytes, _) = sprint_fifo();
    // What the QEMU replay firmware and the host replay assemble from the same words.
    let mut assembler = Assembler::new(settings::DUAL);
    let expected: Vec<_> = bytes
        .chunks_exact(WORD_BYTES)
        .filter_map(|w| assembler.push(FifoWord::from_bytes(w.try_into().unwrap())))
        .collect();
    assert!(
        assembler.high_g_axes() > 0,
        "the sprint reaches the high-g channel"
    );

    let (items, counters, pulses) = lsm_live(Vec::new());
    let samples: Vec<_> = items
        .iter()
        .map(|i| match i {
            Item::Sample(s) => *s,
            other => panic!("only samples on a clean bus, got {other:?}"),
        })
        .collect();
    // Every watermark read to the end: all but the periods after the last watermark and
    // the one still being assembled.
    let periods_per_watermark = settings::SENSOR.watermark_periods() as usize;
    assert!(pulses > 100, "{pulses} watermarks");
    assert!(samples.len() + periods_per_watermark + 1 >= expected.len());
    assert_eq!(samples[..], expected[..samples.len()]);
    assert_eq!(counters, gaitclip_board::imu_sampler::Counters::ZERO);

    // A NACKed FIFO read in the middle of a burst (after samples were completed) and one
    // at its start: each counted and retried, not a sample lost or repeated.
    let (flaky, counters, _) = lsm_live(vec![200, 203, 5_000]);
    let flaky: Vec<_> = flaky
        .iter()
        .map(|i| match i {
            Item::Sample(s) => *s,
            other => panic!("a retried read loses nothing, got {other:?}"),
        })
        .collect();
    let first_difference = flaky.iter().zip(&samples).position(|(a, b)| a != b);
    assert_eq!(
        (flaky.len(), first_difference),
        (samples.len(), None),
        "{counters:?}"
    );
    assert_eq!(counters.bus_errors, 3);
    assert_eq!(counters.lost_samples, 0);
}

#[test]
fn the_live_sampler_sends_the_lsm6dsv320x_to_its_wait_for_motion_and_back() {
    use gaitclip_board::imu_sampler::{ImuSampler, Item};
    use gaitclip_board::live_settings::lsm6dsv320x as settings;
    use gaitclip_board::replay_lsm6dsv320x::ReplayLsm6dsv320x;
    use gaitclip_board::sleep::SleepPolicy;
    use gaitclip_lsm6dsv320x::blocking::{Lsm6dsv320x, Lsm6dsv320xSource};

    let (bytes, recorded) = sprint_fifo();
    let part = ReplayLsm6dsv320x::new(0x6A, bytes, recorded);
    let source =
        Lsm6dsv320xSource::new(Lsm6dsv320x::new(part, settings::ADDRESS), settings::SENSOR);
    let Ok(mut s) = ImuSampler::start(source, NoopDelay, settings::MODE) else {
        panic!("the part starts");
    };
    let watermark = settings::SENSOR.watermark_words as usize;
    let mut items = Vec::new();
    let run = |s: &mut ImuSampler<Lsm6dsv320xSource<ReplayLsm6dsv320x>, NoopDelay>,
               periods: usize,
               items: &mut Vec<Item>| {
        for _ in 0..periods {
            let part = s.bus_mut().unwrap();
            part.tick();
            if part.waiting() == watermark {
                s.on_data_ready(&mut |item| {
                    items.push(item);
                    true
                });
            }
        }
    };
    run(&mut s, 80, &mut items);
    let read = s.samples_read();
    assert!(read >= 70, "{read} samples in 80 periods");
    s.request_sleep(read + 1, settings::SLEEP.wake);
    run(&mut s, 16, &mut items);
    assert!(s.asleep(), "asleep after the requested sample");
    assert_eq!(items.last(), Some(&Item::Asleep));
    // Asleep, the FIFO is off: ticks bring nothing and INT1 stays quiet.
    let before = items.len();
    run(&mut s, 48, &mut items);
    assert_eq!(items.len(), before);

    let settle = SleepPolicy::settle_samples(settings::RATE, &settings::SLEEP);
    assert_eq!(settle, 19, "80 ms at 240 Hz");
    s.on_motion(48, settle, &mut |item| {
        items.push(item);
        true
    });
    assert!(!s.asleep());
    run(&mut s, 80, &mut items);
    let after: Vec<_> = items[before..].to_vec();
    // The unsampled periods and the gyro's settling, declared once, then samples again.
    assert!(
        matches!(after.first(), Some(Item::Woke(n)) if *n == 48 + settle),
        "{:?}",
        after.first()
    );
    assert!(after[1..].iter().all(|i| matches!(i, Item::Sample(_))));
    assert!(after.len() > 40, "{} items after waking", after.len());
    let c = s.counters();
    assert_eq!((c.sleeps, c.bus_errors, c.lost_samples), (1, 0, 0));
}

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

/// The emulated LSM6DSV320X of the QEMU board, driven by the real driver on the host: it
/// fills its FIFO a period per tick only as configured, the driver reads the words in order,
/// and words left beyond the FIFO's capacity are an overrun the driver reports after emptying
/// the FIFO, with the part's clock still counting.
#[test]
fn the_emulated_lsm6dsv320x_serves_its_fifo_and_overruns_as_the_part_does() {
    use gaitclip_board::replay_lsm6dsv320x::{Recorded, ReplayLsm6dsv320x};
    use gaitclip_host::sim::sprint::{LSM_ACCEL, LSM_GYRO, LSM_HIGH_G, LSM_WORDS_PER_SAMPLE};
    use gaitclip_lsm6dsv320x::blocking::Lsm6dsv320x;
    use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag, WORD_BYTES};
    use gaitclip_lsm6dsv320x::{Address as LsmAddress, Config as LsmConfig, HighGOdr, Odr};

    let bytes: &'static [u8] = std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/sprint_40g.lsm6dsv320x"),
    )
    .unwrap()
    .leak();
    let recorded = Recorded {
        odr_field: Odr::Hz240.field(),
        fs_xl: LSM_ACCEL.field(),
        fs_g: LSM_GYRO.field(),
        high_g_ctrl: LSM_HIGH_G.field() | (HighGOdr::Hz960.field() << 3),
        words_per_period: LSM_WORDS_PER_SAMPLE,
    };
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

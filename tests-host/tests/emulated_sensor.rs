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

//! The async driver against a mocked bus: the same transactions as the blocking driver's
//! tests (`tests/blocking.rs`), awaited. `block_on` stands in for the board's executor.

mod bus;
use bus::*;

use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as T};
use futures_executor::block_on;
use gaitclip_mpu6050::asynch::Mpu6050;
use gaitclip_mpu6050::mode::{MotionWake, Sampling};
use gaitclip_mpu6050::{
    AccelRange, Address, Config, Error, MotionThreshold, MotionThresholdUnit, MotionWakeConfig,
    OutputRate, RawSample, WakeRate,
};

fn rate_200() -> Config {
    Config::new(OutputRate::from_hz(200).unwrap())
}

/// A driver brought to sampling by `init` at 200 Hz (its transactions first), then `rest`.
async fn sampling(rest: &[T]) -> (Mock, Mpu6050<Mock, Sampling>) {
    let mut all = init_transactions(ADDR, 4, 2, 3, 3);
    all.extend_from_slice(rest);
    let bus = Mock::new(&all);
    let imu = Mpu6050::new(bus.clone(), Address::Ad0Low)
        .init(&mut NoopDelay, &rate_200())
        .await
        .unwrap();
    (bus, imu)
}

fn wake() -> MotionWakeConfig {
    MotionWakeConfig {
        rate: WakeRate::Hz5,
        threshold: MotionThreshold::from_mg(64, MotionThresholdUnit::Mg32).unwrap(),
        duration_ms: 2,
    }
}

#[test]
fn init_at_ad0_high_with_1khz() {
    block_on(async {
        let mut bus = Mock::new(&init_transactions(0x69, 0, 1, 3, 3));
        let config = Config::new(OutputRate::from_hz(1000).unwrap());
        let _imu = Mpu6050::new(bus.clone(), Address::Ad0High)
            .init(&mut NoopDelay, &config)
            .await
            .unwrap();
        bus.done();
    });
}

#[test]
fn wrong_device_hands_the_driver_back() {
    block_on(async {
        let mut bus = Mock::new(&[T::write_read(ADDR, vec![WHO_AM_I], vec![0x70])]);
        let e = Mpu6050::new(bus.clone(), Address::Ad0Low)
            .init(&mut NoopDelay, &rate_200())
            .await
            .unwrap_err();
        assert_eq!(e.error, Error::WrongDevice(0x70));
        let _bus = e.dev.release();
        bus.done();
    });
}

#[test]
fn burst_read_and_bus_error() {
    block_on(async {
        let regs = vec![
            0x08, 0x00, 0xF8, 0x00, 0, 1, 0xF3, 0x30, 0x7F, 0xFF, 0x80, 0, 0x12, 0x34,
        ];
        let (mut bus, mut imu) = sampling(&[
            T::write_read(ADDR, vec![ACCEL_XOUT_H], regs),
            T::write_read(ADDR, vec![ACCEL_XOUT_H], vec![0; 14]).with_error(ErrorKind::Other),
        ])
        .await;
        assert_eq!(
            imu.read_sample().await.unwrap(),
            RawSample {
                accel: [2048, -2048, 1],
                gyro: [32767, -32768, 0x1234],
                temp: -3280
            }
        );
        assert_eq!(
            imu.read_sample().await.unwrap_err(),
            Error::Bus(ErrorKind::Other)
        );
        bus.done();
    });
}

#[test]
fn fifo_enable_read_and_overflow() {
    block_on(async {
        let one = vec![0, 1, 0, 2, 0, 3, 0, 4, 0, 5, 0, 6, 0, 7];
        let (mut bus, mut imu) = sampling(&[
            T::write(ADDR, vec![USER_CTRL, 0x04]),
            T::write(ADDR, vec![FIFO_EN, 0xF8]),
            T::write(ADDR, vec![USER_CTRL, 0x40]),
            T::write(ADDR, vec![INT_PIN_CFG, 0x00]),
            T::write(ADDR, vec![INT_ENABLE, 0x01]),
            T::write_read(ADDR, vec![INT_STATUS], vec![0x01]),
            T::write_read(ADDR, vec![FIFO_COUNT_H], vec![0x00, 14]),
            T::write_read(ADDR, vec![FIFO_R_W], one),
            T::write_read(ADDR, vec![INT_STATUS], vec![0x10]),
            T::write(ADDR, vec![USER_CTRL, 0x44]),
            T::write_read(ADDR, vec![INT_STATUS], vec![0x00]),
            T::write_read(ADDR, vec![FIFO_COUNT_H], vec![0x04, 0x00]),
            T::write(ADDR, vec![USER_CTRL, 0x44]),
        ])
        .await;
        imu.enable_fifo().await.unwrap();
        imu.enable_data_ready_pulse().await.unwrap();
        let mut out = [RawSample::default(); 4];
        assert_eq!(imu.read_fifo(&mut out).await.unwrap(), 1);
        assert_eq!(out[0].gyro, [5, 6, 7]);
        assert_eq!(imu.read_fifo(&mut out).await, Err(Error::FifoOverflow));
        // A full FIFO (1 024 bytes) has overflowed even before INT_STATUS says so.
        assert_eq!(imu.read_fifo(&mut out).await, Err(Error::FifoOverflow));
        bus.done();
    });
}

#[test]
fn motion_wait_and_back() {
    block_on(async {
        let mut script = enter_transactions(2, 0x18);
        script.extend([
            T::write_read(ADDR, vec![INT_STATUS], vec![0x40]),
            T::write(ADDR, vec![PWR_MGMT_1, 0x01]),
            T::write(ADDR, vec![PWR_MGMT_2, 0x00]),
            T::write(ADDR, vec![ACCEL_CONFIG, 0x18]),
            T::write(ADDR, vec![INT_ENABLE, 0x00]),
            T::write_read(ADDR, vec![INT_STATUS], vec![0x00]),
            T::write(ADDR, vec![INT_PIN_CFG, 0x30]),
            T::write(ADDR, vec![INT_ENABLE, 0x11]),
        ]);
        let (mut bus, imu) = sampling(&script).await;
        let mut waiting: Mpu6050<_, MotionWake> = imu
            .enter_motion_wake(&wake(), AccelRange::G16)
            .await
            .unwrap();
        assert!(waiting.read_interrupt_status().await.unwrap().motion());
        let mut imu = waiting.leave_motion_wake(&rate_200()).await.unwrap();
        imu.enable_data_ready_interrupt().await.unwrap();
        bus.done();
    });
}

#[test]
fn a_threshold_the_part_does_not_keep_leaves_it_sampling() {
    block_on(async {
        let (mut bus, imu) = sampling(&[
            T::write(ADDR, vec![INT_ENABLE, 0x00]),
            T::write(ADDR, vec![USER_CTRL, 0x00]),
            T::write(ADDR, vec![FIFO_EN, 0x00]),
            T::write(ADDR, vec![ACCEL_CONFIG, 0x18 | 0x01]),
            T::write(ADDR, vec![MOT_THR, 2]),
            T::write_read(ADDR, vec![MOT_THR], vec![1]),
        ])
        .await;
        let e = imu
            .enter_motion_wake(&wake(), AccelRange::G16)
            .await
            .unwrap_err();
        assert_eq!(e.error, Error::Verify(MOT_THR, 2, 1));
        let _still_sampling: Mpu6050<_, Sampling> = e.dev;
        bus.done();
    });
}

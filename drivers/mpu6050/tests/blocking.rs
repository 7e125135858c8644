//! The blocking driver against a mocked bus. Every expected transaction is spelled out, and
//! the register addresses are written here from the register map, not imported from the
//! driver. `tests/asynch.rs` runs the async driver against the same transactions.

use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as T};
use gaitclip_mpu6050::blocking::Mpu6050;
use gaitclip_mpu6050::mode::{MotionWake, Sampling};
mod bus;
use bus::*;

use gaitclip_mpu6050::{
    AccelRange, Address, Config, Error, GyroRange, MotionThreshold, MotionThresholdUnit,
    MotionWakeConfig, OutputRate, RawSample, WakeRate,
};

/// A driver brought to sampling by `init` at 200 Hz (its transactions first), then `rest`.
fn sampling(rest: &[T]) -> (Mock, Mpu6050<Mock, Sampling>) {
    let mut all = init_transactions(ADDR, 4, 2, 3, 3);
    all.extend_from_slice(rest);
    let bus = Mock::new(&all);
    let imu = Mpu6050::new(bus.clone(), Address::Ad0Low)
        .init(
            &mut NoopDelay,
            &Config::new(OutputRate::from_hz(200).unwrap()),
        )
        .unwrap();
    (bus, imu)
}

#[test]
fn init_200hz_defaults_to_16g_2000dps() {
    let mut bus = Mock::new(&init_transactions(ADDR, 4, 2, 3, 3));
    let imu = Mpu6050::new(bus.clone(), Address::Ad0Low);
    let config = Config::new(OutputRate::from_hz(200).unwrap());
    assert_eq!(config.accel, AccelRange::G16);
    assert_eq!(config.gyro, GyroRange::Dps2000);
    let _sampling: Mpu6050<_, Sampling> = imu.init(&mut NoopDelay, &config).unwrap();
    bus.done();
}

#[test]
fn init_at_ad0_high_with_other_ranges_and_1khz() {
    let mut bus = Mock::new(&init_transactions(0x69, 0, 1, 1, 2));
    let imu = Mpu6050::new(bus.clone(), Address::Ad0High);
    let config = Config {
        rate: OutputRate::from_hz(1000).unwrap(),
        accel: AccelRange::G8,
        gyro: GyroRange::Dps500,
    };
    imu.init(&mut NoopDelay, &config).unwrap();
    bus.done();
}

#[test]
fn output_rates_dividers_and_filters() {
    // (requested Hz, SMPLRT_DIV, exact mHz, DLPF_CFG)
    for (hz, div, mhz, dlpf) in [
        (100, 9, 100_000, 3),
        (200, 4, 200_000, 2),
        (250, 3, 250_000, 2),
        (500, 1, 500_000, 1),
        (1000, 0, 1_000_000, 1),
        (300, 2, 333_333, 2),
    ] {
        let r = OutputRate::from_hz(hz).unwrap();
        assert_eq!(
            (r.divider(), r.hz_x1000(), r.dlpf_cfg()),
            (div, mhz, dlpf),
            "{hz} Hz"
        );
    }
    assert!(OutputRate::from_hz(99).is_none());
    assert!(OutputRate::from_hz(1001).is_none());
}

#[test]
fn lsb_constants_per_range() {
    let a: Vec<u32> = [
        AccelRange::G2,
        AccelRange::G4,
        AccelRange::G8,
        AccelRange::G16,
    ]
    .map(|r| r.lsb_per_g())
    .into();
    assert_eq!(a, [16384, 8192, 4096, 2048]);
    let g: Vec<u32> = [
        GyroRange::Dps250,
        GyroRange::Dps500,
        GyroRange::Dps1000,
        GyroRange::Dps2000,
    ]
    .map(|r| r.lsb_per_dps_x10())
    .into();
    assert_eq!(g, [1310, 655, 328, 164]);
}

#[test]
fn wrong_device_is_reported_and_nothing_is_written() {
    let mut bus = Mock::new(&[T::write_read(ADDR, vec![WHO_AM_I], vec![0x70])]);
    let imu = Mpu6050::new(bus.clone(), Address::Ad0Low);
    let e = imu
        .init(
            &mut NoopDelay,
            &Config::new(OutputRate::from_hz(200).unwrap()),
        )
        .unwrap_err();
    assert_eq!(e.error, Error::WrongDevice(0x70));
    // The driver comes back, still unconfigured, with its bus.
    let _bus = e.dev.release();
    bus.done();
}

#[test]
fn absent_device_is_a_bus_error() {
    let nack = ErrorKind::NoAcknowledge(embedded_hal::i2c::NoAcknowledgeSource::Address);
    let mut bus = Mock::new(&[T::write_read(ADDR, vec![WHO_AM_I], vec![0]).with_error(nack)]);
    let mut imu = Mpu6050::new(bus.clone(), Address::Ad0Low);
    assert_eq!(imu.probe().unwrap_err(), Error::Bus(nack));
    bus.done();
}

#[test]
fn burst_read_decodes_big_endian_accel_temp_gyro() {
    let regs = vec![
        0x08, 0x00, // ax = 2048 (1 g at ±16 g)
        0xF8, 0x00, // ay = −2048
        0x00, 0x01, // az = 1
        0xF3, 0x30, // temp = −3280
        0x7F, 0xFF, // gx = 32767
        0x80, 0x00, // gy = −32768
        0x12, 0x34, // gz = 0x1234
    ];
    let (mut bus, mut imu) = sampling(&[T::write_read(ADDR, vec![ACCEL_XOUT_H], regs.clone())]);
    let s = imu.read_sample().unwrap();
    assert_eq!(
        s,
        RawSample {
            accel: [2048, -2048, 1],
            gyro: [32767, -32768, 0x1234],
            temp: -3280
        }
    );
    assert!(s.is_saturated());
    assert_eq!(gaitclip_mpu6050::sample::to_be_bytes(&s).to_vec(), regs);
    bus.done();
}

#[test]
fn data_ready_interrupt_enable_and_clear() {
    let (mut bus, mut imu) = sampling(&[
        T::write(ADDR, vec![INT_PIN_CFG, 0x30]),
        T::write(ADDR, vec![INT_ENABLE, 0x11]),
        T::write_read(ADDR, vec![INT_STATUS], vec![0x01]),
    ]);
    imu.enable_data_ready_interrupt().unwrap();
    let st = imu.read_interrupt_status().unwrap();
    assert!(st.data_ready() && !st.fifo_overflow());
    bus.done();
}

#[test]
fn fifo_enable_count_and_burst_read() {
    let one = vec![0, 1, 0, 2, 0, 3, 0, 4, 0, 5, 0, 6, 0, 7];
    let two: Vec<u8> = one.iter().map(|b| b * 2).collect();
    let (mut bus, mut imu) = sampling(&[
        T::write(ADDR, vec![USER_CTRL, 0x04]),
        T::write(ADDR, vec![FIFO_EN, 0xF8]),
        T::write(ADDR, vec![USER_CTRL, 0x40]),
        T::write_read(ADDR, vec![INT_STATUS], vec![0x01]),
        T::write_read(ADDR, vec![FIFO_COUNT_H], vec![0x00, 28]),
        T::write_read(ADDR, vec![FIFO_R_W], one),
        T::write_read(ADDR, vec![FIFO_R_W], two),
    ]);
    imu.enable_fifo().unwrap();
    let mut out = [RawSample::default(); 4];
    assert_eq!(imu.read_fifo(&mut out).unwrap(), 2);
    assert_eq!(out[0].accel, [1, 2, 3]);
    assert_eq!(out[0].temp, 4);
    assert_eq!(out[1].gyro, [10, 12, 14]);
    bus.done();
}

#[test]
fn fifo_overflow_resets_and_reports() {
    let (mut bus, mut imu) = sampling(&[
        T::write_read(ADDR, vec![INT_STATUS], vec![0x10]),
        T::write(ADDR, vec![USER_CTRL, 0x44]),
    ]);
    let mut out = [RawSample::default(); 4];
    assert_eq!(imu.read_fifo(&mut out).unwrap_err(), Error::FifoOverflow);
    bus.done();
}

#[test]
fn fifo_partial_sample_is_misaligned() {
    let (mut bus, mut imu) = sampling(&[
        T::write_read(ADDR, vec![INT_STATUS], vec![0x00]),
        T::write_read(ADDR, vec![FIFO_COUNT_H], vec![0x00, 15]),
        T::write(ADDR, vec![USER_CTRL, 0x44]),
    ]);
    let mut out = [RawSample::default(); 4];
    assert_eq!(
        imu.read_fifo(&mut out).unwrap_err(),
        Error::FifoMisaligned(15)
    );
    bus.done();
}

#[test]
fn bus_error_during_read_surfaces_as_bus() {
    let (mut bus, mut imu) = sampling(&[
        T::write_read(ADDR, vec![ACCEL_XOUT_H], vec![0; 14]).with_error(ErrorKind::Other)
    ]);
    assert_eq!(imu.read_sample().unwrap_err(), Error::Bus(ErrorKind::Other));
    bus.done();
}

fn motion_wake(mg: u32, unit: MotionThresholdUnit) -> MotionWakeConfig {
    MotionWakeConfig {
        rate: WakeRate::Hz5,
        threshold: MotionThreshold::from_mg(mg, unit).unwrap(),
        duration_ms: 2,
    }
}

/// Cycle mode with the motion interrupt, register by register (register map rev 4.2 and the
/// product specification rev 3.4): data-ready and FIFO off, ACCEL_CONFIG = ±16 g (3 << 3)
/// with ACCEL_HPF = 1 (5 Hz), MOT_THR written and read back, MOT_DUR, INT latched until
/// read (0x30), INT_ENABLE = MOT_EN (bit 6), PWR_MGMT_2 = LP_WAKE_CTRL 1 (5 Hz) in bits 7:6
/// with STBY_XG/YG/ZG (bits 2:0), PWR_MGMT_1 = CYCLE (bit 5) | TEMP_DIS (bit 3), CLKSEL 0.
#[test]
fn enter_motion_wake_transactions() {
    let wake = motion_wake(64, MotionThresholdUnit::Mg32);
    assert_eq!(wake.threshold.counts(), 2);
    let (mut bus, imu) = sampling(&[
        T::write(ADDR, vec![INT_ENABLE, 0x00]),
        T::write(ADDR, vec![USER_CTRL, 0x00]),
        T::write(ADDR, vec![FIFO_EN, 0x00]),
        T::write(ADDR, vec![ACCEL_CONFIG, 0x18 | 0x01]),
        T::write(ADDR, vec![MOT_THR, 2]),
        T::write_read(ADDR, vec![MOT_THR], vec![2]),
        T::write(ADDR, vec![MOT_DUR, 2]),
        T::write(ADDR, vec![INT_PIN_CFG, 0x30]),
        T::write(ADDR, vec![INT_ENABLE, 0x40]),
        T::write(ADDR, vec![PWR_MGMT_2, 0x40 | 0x07]),
        T::write(ADDR, vec![PWR_MGMT_1, 0x20 | 0x08]),
    ]);
    let _waiting: Mpu6050<_, MotionWake> = imu.enter_motion_wake(&wake, AccelRange::G16).unwrap();
    bus.done();
}

/// A part that does not keep MOT_THR is reported, not trusted to wake the clip.
#[test]
fn motion_threshold_is_read_back() {
    let wake = motion_wake(100, MotionThresholdUnit::Mg2);
    assert_eq!(wake.threshold.counts(), 50);
    let (mut bus, imu) = sampling(&[
        T::write(ADDR, vec![INT_ENABLE, 0x00]),
        T::write(ADDR, vec![USER_CTRL, 0x00]),
        T::write(ADDR, vec![FIFO_EN, 0x00]),
        T::write(ADDR, vec![ACCEL_CONFIG, 0x10 | 0x01]),
        T::write(ADDR, vec![MOT_THR, 50]),
        T::write_read(ADDR, vec![MOT_THR], vec![0]),
        // The driver came back still sampling: it reads on.
        T::write_read(ADDR, vec![ACCEL_XOUT_H], vec![0; 14]),
    ]);
    let e = imu.enter_motion_wake(&wake, AccelRange::G8).unwrap_err();
    assert_eq!(e.error, Error::Verify(MOT_THR, 50, 0));
    let mut imu: Mpu6050<_, Sampling> = e.dev;
    assert_eq!(imu.read_sample().unwrap(), RawSample::default());
    bus.done();
}

/// Back to 6-axis sampling: PLL clock, cycle and TEMP_DIS off (PWR_MGMT_1 = 0x01), no
/// standby, the high-pass filter off, the motion interrupt off and its latch read clear.
#[test]
fn leave_motion_wake_transactions() {
    let wake = motion_wake(64, MotionThresholdUnit::Mg32);
    let mut script = enter_transactions(2, 0x18);
    script.extend([
        T::write(ADDR, vec![PWR_MGMT_1, 0x01]),
        T::write(ADDR, vec![PWR_MGMT_2, 0x00]),
        T::write(ADDR, vec![ACCEL_CONFIG, 0x18]),
        T::write(ADDR, vec![INT_ENABLE, 0x00]),
        T::write_read(ADDR, vec![INT_STATUS], vec![0x40]),
    ]);
    let (mut bus, imu) = sampling(&script);
    let waiting = imu.enter_motion_wake(&wake, AccelRange::G16).unwrap();
    let _sampling: Mpu6050<_, Sampling> = waiting
        .leave_motion_wake(&Config::new(OutputRate::from_hz(200).unwrap()))
        .unwrap();
    bus.done();
}

#[test]
fn wake_rates_and_thresholds() {
    // (rate, LP_WAKE_CTRL, mHz, µA of PS rev 3.4 §6.3)
    for (r, ctrl, mhz, ua) in [
        (WakeRate::Hz1_25, 0, 1250, 10),
        (WakeRate::Hz5, 1, 5000, 20),
        (WakeRate::Hz20, 2, 20_000, 70),
        (WakeRate::Hz40, 3, 40_000, 140),
    ] {
        assert_eq!(
            (r.lp_wake_ctrl(), r.millihertz(), r.supply_ua()),
            (ctrl, mhz, ua)
        );
    }
    use MotionThresholdUnit::{Mg2, Mg32};
    assert_eq!(MotionThreshold::from_mg(0, Mg2), None);
    assert_eq!(
        MotionThreshold::from_mg(1, Mg32),
        None,
        "rounds to 0 counts"
    );
    assert_eq!(MotionThreshold::from_mg(510, Mg2).unwrap().counts(), 255);
    assert_eq!(MotionThreshold::from_mg(512, Mg2), None, "over 255 counts");
    assert_eq!(MotionThreshold::from_mg(8160, Mg32).unwrap().counts(), 255);
    // The same count is 16 times more acceleration in the other unit.
    let t = MotionThreshold::from_mg(96, Mg32).unwrap();
    assert_eq!((t.counts(), t.mg(Mg32), t.mg(Mg2)), (3, 96, 6));
}

/// `init` works from any mode: a part found in its motion wait (after a brown-out of the MCU,
/// say) is reset into sampling.
#[test]
fn init_from_the_motion_wait_resets_into_sampling() {
    let wake = motion_wake(64, MotionThresholdUnit::Mg32);
    let mut script = enter_transactions(2, 0x18);
    script.extend(init_transactions(ADDR, 4, 2, 3, 3));
    let (mut bus, imu) = sampling(&script);
    let waiting = imu.enter_motion_wake(&wake, AccelRange::G16).unwrap();
    let _sampling = waiting
        .init(
            &mut NoopDelay,
            &Config::new(OutputRate::from_hz(200).unwrap()),
        )
        .unwrap();
    bus.done();
}

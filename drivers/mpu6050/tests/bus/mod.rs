//! The bus transactions both drivers' tests expect, written from the register map (RM-MPU-6000A-00
//! rev 4.2), not imported from the driver.

#![allow(dead_code)] // each test file uses its own part of it

use embedded_hal_mock::eh1::i2c::Transaction as T;

pub const ADDR: u8 = 0x68;
pub const SMPLRT_DIV: u8 = 0x19;
pub const CONFIG: u8 = 0x1A;
pub const GYRO_CONFIG: u8 = 0x1B;
pub const ACCEL_CONFIG: u8 = 0x1C;
pub const FIFO_EN: u8 = 0x23;
pub const INT_PIN_CFG: u8 = 0x37;
pub const INT_ENABLE: u8 = 0x38;
pub const INT_STATUS: u8 = 0x3A;
pub const ACCEL_XOUT_H: u8 = 0x3B;
pub const USER_CTRL: u8 = 0x6A;
pub const PWR_MGMT_1: u8 = 0x6B;
pub const FIFO_COUNT_H: u8 = 0x72;
pub const FIFO_R_W: u8 = 0x74;
pub const WHO_AM_I: u8 = 0x75;
pub const MOT_THR: u8 = 0x1F;
pub const MOT_DUR: u8 = 0x20;
pub const PWR_MGMT_2: u8 = 0x6C;

/// `init` at `addr`: WHO_AM_I, reset, PLL clock, SMPLRT_DIV `div`, DLPF_CFG `dlpf`, FS_SEL `fs`, AFS_SEL `afs`.
pub fn init_transactions(addr: u8, div: u8, dlpf: u8, fs: u8, afs: u8) -> Vec<T> {
    vec![
        T::write_read(addr, vec![WHO_AM_I], vec![0x68]),
        T::write(addr, vec![PWR_MGMT_1, 0x80]),
        T::write(addr, vec![PWR_MGMT_1, 0x01]),
        T::write(addr, vec![SMPLRT_DIV, div]),
        T::write(addr, vec![CONFIG, dlpf]),
        T::write(addr, vec![GYRO_CONFIG, fs << 3]),
        T::write(addr, vec![ACCEL_CONFIG, afs << 3]),
    ]
}

/// The transactions of entering the motion wait at 5 Hz (as `enter_motion_wake_transactions`
/// spells out) with MOT_THR `counts` and ACCEL_CONFIG's range bits `afs`.
pub fn enter_transactions(counts: u8, afs: u8) -> Vec<T> {
    vec![
        T::write(ADDR, vec![INT_ENABLE, 0x00]),
        T::write(ADDR, vec![USER_CTRL, 0x00]),
        T::write(ADDR, vec![FIFO_EN, 0x00]),
        T::write(ADDR, vec![ACCEL_CONFIG, afs | 0x01]),
        T::write(ADDR, vec![MOT_THR, counts]),
        T::write_read(ADDR, vec![MOT_THR], vec![counts]),
        T::write(ADDR, vec![MOT_DUR, 2]),
        T::write(ADDR, vec![INT_PIN_CFG, 0x30]),
        T::write(ADDR, vec![INT_ENABLE, 0x40]),
        T::write(ADDR, vec![PWR_MGMT_2, 0x40 | 0x07]),
        T::write(ADDR, vec![PWR_MGMT_1, 0x20 | 0x08]),
    ]
}

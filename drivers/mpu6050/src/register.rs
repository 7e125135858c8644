//! The register map (MPU-6000/6050 Register Map rev. 4.2): addresses, bit flags and the
//! constants of the part.

/// Register addresses (MPU-6000/6050 Register Map, rev. 4.2).
pub mod reg {
    /// Sample-rate divider: rate = gyro output rate / (1 + SMPLRT_DIV).
    pub const SMPLRT_DIV: u8 = 0x19;
    /// DLPF_CFG in bits 2:0.
    pub const CONFIG: u8 = 0x1A;
    /// FS_SEL in bits 4:3.
    pub const GYRO_CONFIG: u8 = 0x1B;
    /// AFS_SEL in bits 4:3.
    pub const ACCEL_CONFIG: u8 = 0x1C;
    /// Which sensor data go into the FIFO.
    pub const FIFO_EN: u8 = 0x23;
    /// INT pin level/latch/clear behaviour.
    pub const INT_PIN_CFG: u8 = 0x37;
    /// Interrupt enables.
    pub const INT_ENABLE: u8 = 0x38;
    /// Interrupt status; reading clears it.
    pub const INT_STATUS: u8 = 0x3A;
    /// First of the 14 data registers (accel, temperature, gyro; big endian).
    pub const ACCEL_XOUT_H: u8 = 0x3B;
    /// FIFO / I2C master / signal-path control.
    pub const USER_CTRL: u8 = 0x6A;
    /// Power management 1: reset, sleep, cycle, temperature disable, clock source.
    pub const PWR_MGMT_1: u8 = 0x6B;
    /// Power management 2: LP_WAKE_CTRL in bits 7:6, per-axis standby in bits 5:0.
    pub const PWR_MGMT_2: u8 = 0x6C;
    /// Motion detection threshold (one count is 2 or 32 mg: [`crate::MotionThresholdUnit`]).
    pub const MOT_THR: u8 = 0x1F;
    /// Motion detection duration, 1 ms per count at the 1 kHz accelerometer rate.
    pub const MOT_DUR: u8 = 0x20;
    /// FIFO byte count, high byte first.
    pub const FIFO_COUNT_H: u8 = 0x72;
    /// FIFO read port.
    pub const FIFO_R_W: u8 = 0x74;
    /// Identity register.
    pub const WHO_AM_I: u8 = 0x75;
}

/// Bit flags of the registers above.
pub mod bits {
    /// PWR_MGMT_1: reset all registers.
    pub const DEVICE_RESET: u8 = 0x80;
    /// PWR_MGMT_1: CLKSEL = 1, PLL with the X gyro as reference (datasheet recommendation).
    pub const CLKSEL_PLL_XGYRO: u8 = 0x01;
    /// FIFO_EN: temperature, gyro x/y/z, accel.
    pub const FIFO_ALL: u8 = 0x80 | 0x40 | 0x20 | 0x10 | 0x08;
    /// USER_CTRL: FIFO enable.
    pub const USER_FIFO_EN: u8 = 0x40;
    /// USER_CTRL: FIFO reset (self-clearing).
    pub const USER_FIFO_RESET: u8 = 0x04;
    /// INT_PIN_CFG: latch INT until cleared, cleared by any read.
    pub const INT_LATCH_ANY_READ_CLEAR: u8 = 0x20 | 0x10;
    /// INT_ENABLE / INT_STATUS: data ready.
    pub const DATA_RDY: u8 = 0x01;
    /// INT_ENABLE / INT_STATUS: FIFO overflow.
    pub const FIFO_OFLOW: u8 = 0x10;
    /// INT_ENABLE / INT_STATUS: motion detected (bit 6).
    pub const MOT: u8 = 0x40;
    /// PWR_MGMT_1: cycle between sleep and one accelerometer sample at LP_WAKE_CTRL's rate.
    pub const CYCLE: u8 = 0x20;
    /// PWR_MGMT_1: temperature sensor off.
    pub const TEMP_DIS: u8 = 0x08;
    /// PWR_MGMT_2: the three gyro axes in standby.
    pub const STBY_GYRO: u8 = 0x04 | 0x02 | 0x01;
    /// ACCEL_CONFIG bits 2:0, ACCEL_HPF = 1: the 5 Hz high-pass filter the motion detector
    /// compares against its threshold (register map rev 3.x; rev 4.2 marks the bits reserved,
    /// and the part still needs a high-pass setting for motion detection to fire).
    pub const ACCEL_HPF_5HZ: u8 = 0x01;
}

/// The value `WHO_AM_I` reads on an MPU6050, whatever the AD0 pin.
pub const WHO_AM_I_VALUE: u8 = 0x68;
/// Size of the on-chip FIFO in bytes.
pub const FIFO_CAPACITY_BYTES: u16 = 1024;
/// Time the part needs after `DEVICE_RESET` before it accepts writes (datasheet: 100 ms).
pub const RESET_DELAY_MS: u32 = 100;

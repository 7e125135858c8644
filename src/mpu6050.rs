//! MPU6050 driver over embedded-hal 1.0 [`I2c`].
//!
//! Covers what gaitclip needs from the part: probing `WHO_AM_I`, reset and configuration for a
//! requested output rate, one-burst sample reads, the data-ready interrupt and the FIFO with
//! overflow detection, and the low-power wait for the first step: the accelerometer alone
//! in cycle mode with the motion interrupt ([`Mpu6050::enter_motion_wake`],
//! [`Mpu6050::leave_motion_wake`]). Every register access is a single `write` or `write_read`, so a bus
//! error surfaces as [`Error::Bus`] and the caller decides whether to retry.
//!
//! ```no_run
//! # fn demo<I: embedded_hal::i2c::I2c, D: embedded_hal::delay::DelayNs>(i2c: I, delay: &mut D)
//! #     -> Result<(), gaitclip::mpu6050::Error<I::Error>> {
//! use gaitclip::mpu6050::{Address, Config, Mpu6050, OutputRate};
//! let mut imu = Mpu6050::new(i2c, Address::Ad0Low);
//! let config = Config::new(OutputRate::from_hz(200).unwrap());
//! imu.init(delay, &config)?;
//! let sample = imu.read_sample()?;
//! # let _ = sample; Ok(()) }
//! ```

use embedded_hal::delay::DelayNs;
use embedded_hal::i2c::I2c;

use crate::sensor::sample::{AccelRange, GyroRange, RawSample, SAMPLE_BYTES};

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
    /// Motion detection threshold (one count is 2 or 32 mg: [`super::MotionThresholdUnit`]).
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

/// I2C address, chosen by the AD0 pin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Address {
    /// AD0 low: 0x68.
    #[default]
    Ad0Low,
    /// AD0 high: 0x69.
    Ad0High,
}

impl Address {
    /// The 7-bit bus address.
    pub const fn bits(self) -> u8 {
        match self {
            Address::Ad0Low => 0x68,
            Address::Ad0High => 0x69,
        }
    }
}

/// Accelerometer wake-up rate in the low-power cycle mode (PWR_MGMT_2 LP_WAKE_CTRL), with the
/// supply current the datasheet gives for it (PS-MPU-6000A-00 rev 3.4, §6.3, "Accelerometer
/// Low Power Mode Current").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WakeRate {
    /// 1.25 Hz, 10 µA.
    Hz1_25,
    /// 5 Hz, 20 µA.
    Hz5,
    /// 20 Hz, 70 µA.
    Hz20,
    /// 40 Hz, 140 µA.
    Hz40,
}

impl WakeRate {
    /// LP_WAKE_CTRL.
    pub const fn lp_wake_ctrl(self) -> u8 {
        match self {
            WakeRate::Hz1_25 => 0,
            WakeRate::Hz5 => 1,
            WakeRate::Hz20 => 2,
            WakeRate::Hz40 => 3,
        }
    }

    /// The rate, mHz.
    pub const fn millihertz(self) -> u32 {
        match self {
            WakeRate::Hz1_25 => 1250,
            WakeRate::Hz5 => 5000,
            WakeRate::Hz20 => 20_000,
            WakeRate::Hz40 => 40_000,
        }
    }

    /// Typical supply current in this mode, µA (datasheet §6.3).
    pub const fn supply_ua(self) -> u32 {
        match self {
            WakeRate::Hz1_25 => 10,
            WakeRate::Hz5 => 20,
            WakeRate::Hz20 => 70,
            WakeRate::Hz40 => 140,
        }
    }
}

/// What one MOT_THR count is worth. The documents disagree: the product specification
/// (PS-MPU-6000A-00 rev 3.4, §6.2, "Intelligence function increment") says 32 mg per LSB,
/// a register-map revision 2 mg. A board says which its parts follow (the threshold is
/// configured in mg, never as a bare count), and [`Mpu6050::enter_motion_wake`] reads the
/// register back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionThresholdUnit {
    /// 2 mg per count (register map rev 4.2).
    Mg2,
    /// 32 mg per count (product specification rev 3.4).
    Mg32,
}

impl MotionThresholdUnit {
    /// mg per count.
    pub const fn mg_per_count(self) -> u32 {
        match self {
            MotionThresholdUnit::Mg2 => 2,
            MotionThresholdUnit::Mg32 => 32,
        }
    }
}

/// A motion-detection threshold: the MOT_THR count for a high-passed acceleration in mg.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionThreshold {
    counts: u8,
}

impl MotionThreshold {
    /// The nearest count to `mg` in `unit` (at least 1): `None` when it does not fit the
    /// register (1..=255 counts: 2–510 mg or 32–8 160 mg) or `mg` is 0.
    pub const fn from_mg(mg: u32, unit: MotionThresholdUnit) -> Option<Self> {
        let per = unit.mg_per_count();
        let counts = (mg + per / 2) / per;
        if mg == 0 || counts == 0 || counts > 255 {
            None
        } else {
            Some(MotionThreshold {
                counts: counts as u8,
            })
        }
    }

    /// The register value.
    pub const fn counts(self) -> u8 {
        self.counts
    }

    /// The threshold in mg, in `unit`.
    pub const fn mg(self, unit: MotionThresholdUnit) -> u32 {
        self.counts as u32 * unit.mg_per_count()
    }
}

/// The low-power wait for motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionWake {
    /// How often the accelerometer wakes to sample.
    pub rate: WakeRate,
    /// The high-passed acceleration that counts as motion.
    pub threshold: MotionThreshold,
    /// How long it must last, ms (MOT_DUR; counted at the accelerometer's 1 kHz).
    pub duration_ms: u8,
}

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<E> {
    /// The bus transaction failed (NACK, arbitration loss, timeout …).
    Bus(E),
    /// `WHO_AM_I` answered this instead of 0x68: another part on the address.
    WrongDevice(u8),
    /// The FIFO overflowed and was reset: samples were lost and the caller must treat the
    /// stream as having a gap.
    FifoOverflow,
    /// The FIFO count is not a whole number of samples: the FIFO was reset.
    FifoMisaligned(u16),
    /// A register read back other than what was written (register, written, read).
    Verify(u8, u8, u8),
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Bus(e)
    }
}

/// An output data rate the part can produce with the DLPF on (1 kHz internal rate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputRate {
    divider: u8,
}

impl OutputRate {
    /// Lowest supported rate: below it a 30 ms heel-strike is only three samples.
    pub const MIN_HZ: u16 = 100;
    /// Highest rate with the DLPF enabled.
    pub const MAX_HZ: u16 = 1000;

    /// The rate closest to `hz` that the part can make (1000 / (1 + divider)); `None` outside
    /// 100–1000 Hz. Check [`OutputRate::hz_x1000`] for the exact rate obtained.
    pub const fn from_hz(hz: u16) -> Option<Self> {
        if hz < Self::MIN_HZ || hz > Self::MAX_HZ {
            return None;
        }
        // Round 1000/hz to the nearest integer divisor.
        let div = (2000 + hz as u32) / (2 * hz as u32);
        Some(OutputRate {
            divider: (div - 1) as u8,
        })
    }

    /// The `SMPLRT_DIV` register value.
    pub const fn divider(self) -> u8 {
        self.divider
    }

    /// The exact output rate in millihertz (1 000 000 / (1 + divider)).
    pub const fn hz_x1000(self) -> u32 {
        1_000_000 / (1 + self.divider as u32)
    }

    /// `DLPF_CFG`: the widest filter whose gyro bandwidth stays at or below Nyquist, so that
    /// the heel-strike transient keeps as much of its edge as the rate can carry.
    pub const fn dlpf_cfg(self) -> u8 {
        let nyquist_hz = self.hz_x1000() / 2000;
        if nyquist_hz >= 188 {
            1 // 188 Hz gyro / 184 Hz accel
        } else if nyquist_hz >= 98 {
            2 // 98 / 94 Hz
        } else if nyquist_hz >= 42 {
            3 // 42 / 44 Hz
        } else {
            4 // 20 / 21 Hz
        }
    }
}

/// Measurement configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Output data rate.
    pub rate: OutputRate,
    /// Accelerometer range (default ±16 g).
    pub accel: AccelRange,
    /// Gyroscope range (default ±2000 °/s).
    pub gyro: GyroRange,
}

impl Config {
    /// `rate` with the default ranges ±16 g and ±2000 °/s.
    pub const fn new(rate: OutputRate) -> Self {
        Config {
            rate,
            accel: AccelRange::G16,
            gyro: GyroRange::Dps2000,
        }
    }
}

/// Interrupt status bits read (and thereby cleared) from `INT_STATUS`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InterruptStatus(pub u8);

impl InterruptStatus {
    /// A new sample is in the data registers.
    pub const fn data_ready(self) -> bool {
        self.0 & bits::DATA_RDY != 0
    }
    /// The FIFO overflowed since the last read.
    pub const fn fifo_overflow(self) -> bool {
        self.0 & bits::FIFO_OFLOW != 0
    }
    /// Motion was detected (the low-power wake).
    pub const fn motion(self) -> bool {
        self.0 & bits::MOT != 0
    }
}

/// An MPU6050 on an I2C bus.
pub struct Mpu6050<I> {
    i2c: I,
    address: u8,
}

impl<I: I2c> Mpu6050<I> {
    /// Wraps the bus; talks to nothing yet.
    pub const fn new(i2c: I, address: Address) -> Self {
        Mpu6050 {
            i2c,
            address: address.bits(),
        }
    }

    /// Gives the bus back.
    pub fn release(self) -> I {
        self.i2c
    }

    /// Reads `WHO_AM_I`; [`Error::WrongDevice`] if it is not an MPU6050.
    pub fn probe(&mut self) -> Result<(), Error<I::Error>> {
        match self.read_reg(reg::WHO_AM_I)? {
            WHO_AM_I_VALUE => Ok(()),
            other => Err(Error::WrongDevice(other)),
        }
    }

    /// Probes, resets, wakes with the gyro PLL clock and applies `config`.
    pub fn init<D: DelayNs>(
        &mut self,
        delay: &mut D,
        config: &Config,
    ) -> Result<(), Error<I::Error>> {
        self.probe()?;
        self.write_reg(reg::PWR_MGMT_1, bits::DEVICE_RESET)?;
        delay.delay_ms(RESET_DELAY_MS);
        self.write_reg(reg::PWR_MGMT_1, bits::CLKSEL_PLL_XGYRO)?;
        self.write_reg(reg::SMPLRT_DIV, config.rate.divider())?;
        self.write_reg(reg::CONFIG, config.rate.dlpf_cfg())?;
        self.write_reg(reg::GYRO_CONFIG, config.gyro.fs_sel() << 3)?;
        self.write_reg(reg::ACCEL_CONFIG, config.accel.afs_sel() << 3)?;
        Ok(())
    }

    /// One burst read of the 14 data registers.
    pub fn read_sample(&mut self) -> Result<RawSample, Error<I::Error>> {
        let mut buf = [0u8; SAMPLE_BYTES];
        self.i2c
            .write_read(self.address, &[reg::ACCEL_XOUT_H], &mut buf)?;
        Ok(RawSample::from_be_bytes(&buf))
    }

    /// Drives INT on data ready (and FIFO overflow), latched until any register read.
    pub fn enable_data_ready_interrupt(&mut self) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::INT_PIN_CFG, bits::INT_LATCH_ANY_READ_CLEAR)?;
        self.write_reg(reg::INT_ENABLE, bits::DATA_RDY | bits::FIFO_OFLOW)
    }

    /// Pulses INT (50 µs, active high) on every data ready, without latching: for reading
    /// the FIFO in bursts, where most pulses are only counted and no register is read to
    /// clear a latch. FIFO overflow is found by [`Mpu6050::read_fifo`] from `INT_STATUS`.
    pub fn enable_data_ready_pulse(&mut self) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::INT_PIN_CFG, 0)?;
        self.write_reg(reg::INT_ENABLE, bits::DATA_RDY)
    }

    /// The bus, for a board to recover it (clock SCL until a stuck slave lets go of SDA).
    /// The driver keeps no state about the bus, so anything done to it is safe here.
    pub fn bus_mut(&mut self) -> &mut I {
        &mut self.i2c
    }

    /// Reads `INT_STATUS`, which clears it and releases the INT pin.
    pub fn read_interrupt_status(&mut self) -> Result<InterruptStatus, Error<I::Error>> {
        Ok(InterruptStatus(self.read_reg(reg::INT_STATUS)?))
    }

    /// Resets and enables the FIFO with accel, temperature and gyro (14 bytes a sample).
    pub fn enable_fifo(&mut self) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::USER_CTRL, bits::USER_FIFO_RESET)?;
        self.write_reg(reg::FIFO_EN, bits::FIFO_ALL)?;
        self.write_reg(reg::USER_CTRL, bits::USER_FIFO_EN)
    }

    /// Bytes waiting in the FIFO.
    pub fn fifo_count(&mut self) -> Result<u16, Error<I::Error>> {
        let mut buf = [0u8; 2];
        self.i2c
            .write_read(self.address, &[reg::FIFO_COUNT_H], &mut buf)?;
        Ok(u16::from_be_bytes(buf))
    }

    /// Reads as many whole samples as are waiting and fit in `out`; returns how many.
    ///
    /// Checks `INT_STATUS` first: after an overflow the oldest samples are gone and the
    /// stream is misaligned, so the FIFO is reset and [`Error::FifoOverflow`] returned; the
    /// caller marks a gap. A count that is not a multiple of 14 is handled the same way.
    pub fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<usize, Error<I::Error>> {
        if self.read_interrupt_status()?.fifo_overflow() {
            self.reset_fifo()?;
            return Err(Error::FifoOverflow);
        }
        let count = self.fifo_count()?;
        if count >= FIFO_CAPACITY_BYTES {
            self.reset_fifo()?;
            return Err(Error::FifoOverflow);
        }
        if count as usize % SAMPLE_BYTES != 0 {
            self.reset_fifo()?;
            return Err(Error::FifoMisaligned(count));
        }
        let n = (count as usize / SAMPLE_BYTES).min(out.len());
        for slot in out.iter_mut().take(n) {
            let mut buf = [0u8; SAMPLE_BYTES];
            self.i2c
                .write_read(self.address, &[reg::FIFO_R_W], &mut buf)?;
            *slot = RawSample::from_be_bytes(&buf);
        }
        Ok(n)
    }

    /// Waits for the first step at a few µA: stops the data-ready interrupt and the FIFO, sets
    /// the accelerometer's 5 Hz high-pass filter (what the motion detector compares) and the
    /// threshold (read back: [`Error::Verify`] if the part did not take it) and duration,
    /// latches INT on motion (a level the MCU cannot miss while it sleeps), puts the gyro in
    /// standby and the temperature sensor off, and cycles the accelerometer at `wake.rate`
    /// on the internal oscillator (the gyro's PLL is off). `accel` is the range kept.
    pub fn enter_motion_wake(
        &mut self,
        wake: &MotionWake,
        accel: AccelRange,
    ) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::INT_ENABLE, 0)?;
        self.write_reg(reg::USER_CTRL, 0)?;
        self.write_reg(reg::FIFO_EN, 0)?;
        self.write_reg(
            reg::ACCEL_CONFIG,
            accel.afs_sel() << 3 | bits::ACCEL_HPF_5HZ,
        )?;
        let counts = wake.threshold.counts();
        self.write_reg(reg::MOT_THR, counts)?;
        let read = self.read_reg(reg::MOT_THR)?;
        if read != counts {
            return Err(Error::Verify(reg::MOT_THR, counts, read));
        }
        self.write_reg(reg::MOT_DUR, wake.duration_ms)?;
        self.write_reg(reg::INT_PIN_CFG, bits::INT_LATCH_ANY_READ_CLEAR)?;
        self.write_reg(reg::INT_ENABLE, bits::MOT)?;
        self.write_reg(
            reg::PWR_MGMT_2,
            wake.rate.lp_wake_ctrl() << 6 | bits::STBY_GYRO,
        )?;
        self.write_reg(reg::PWR_MGMT_1, bits::CYCLE | bits::TEMP_DIS)
    }

    /// Back from [`Mpu6050::enter_motion_wake`] to full 6-axis sampling with `config`'s
    /// ranges: the gyro's PLL clock and the temperature sensor on, cycle off, every axis out
    /// of standby, the high-pass filter off, the motion interrupt off and its latch cleared.
    /// The caller then enables its interrupt and FIFO again, as after [`Mpu6050::init`]; the
    /// gyro needs its start-up time (datasheet §6.1: 30 ms) before its samples settle.
    pub fn leave_motion_wake(&mut self, config: &Config) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::PWR_MGMT_1, bits::CLKSEL_PLL_XGYRO)?;
        self.write_reg(reg::PWR_MGMT_2, 0)?;
        self.write_reg(reg::ACCEL_CONFIG, config.accel.afs_sel() << 3)?;
        self.write_reg(reg::INT_ENABLE, 0)?;
        self.read_interrupt_status()?;
        Ok(())
    }

    fn reset_fifo(&mut self) -> Result<(), Error<I::Error>> {
        self.write_reg(reg::USER_CTRL, bits::USER_FIFO_RESET | bits::USER_FIFO_EN)
    }

    fn read_reg(&mut self, r: u8) -> Result<u8, Error<I::Error>> {
        let mut buf = [0u8];
        self.i2c.write_read(self.address, &[r], &mut buf)?;
        Ok(buf[0])
    }

    fn write_reg(&mut self, r: u8, value: u8) -> Result<(), Error<I::Error>> {
        self.i2c.write(self.address, &[r, value])?;
        Ok(())
    }
}

//! What the part is told: its address, output rate and ranges, and the low-power wait for
//! motion.

use crate::range::{AccelRange, GyroRange};

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
/// configured in mg, never as a bare count), and [`enter_motion_wake`](crate::blocking::Mpu6050::enter_motion_wake) reads the
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
pub struct MotionWakeConfig {
    /// How often the accelerometer wakes to sample.
    pub rate: WakeRate,
    /// The high-passed acceleration that counts as motion.
    pub threshold: MotionThreshold,
    /// How long it must last, ms (MOT_DUR; counted at the accelerometer's 1 kHz).
    pub duration_ms: u8,
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
        self.0 & crate::register::bits::DATA_RDY != 0
    }
    /// The FIFO overflowed since the last read.
    pub const fn fifo_overflow(self) -> bool {
        self.0 & crate::register::bits::FIFO_OFLOW != 0
    }
    /// Motion was detected (the low-power wake).
    pub const fn motion(self) -> bool {
        self.0 & crate::register::bits::MOT != 0
    }
}

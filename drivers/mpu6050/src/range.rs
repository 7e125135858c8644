//! The full-scale ranges and their sensitivities (product specification PS-MPU-6000A-00
//! rev 3.4, §6.1–6.2).

use gaitclip_imu::{AccelScale, GyroScale};

/// Accelerometer full-scale range (register `ACCEL_CONFIG.AFS_SEL`).
///
/// The default is ±16 g: heel strikes of a foot-mounted sensor exceed 8 g.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelRange {
    /// ±2 g, 16384 LSB/g.
    G2,
    /// ±4 g, 8192 LSB/g.
    G4,
    /// ±8 g, 4096 LSB/g.
    G8,
    /// ±16 g, 2048 LSB/g.
    #[default]
    G16,
}

impl AccelRange {
    /// Counts per g (datasheet sensitivity).
    pub const fn lsb_per_g(self) -> u32 {
        16384 >> self.afs_sel()
    }

    /// The scale the pipeline takes this range's counts in.
    pub const fn scale(self) -> AccelScale {
        AccelScale::from_lsb_per_g(self.lsb_per_g())
    }

    /// The range for an `AFS_SEL` field value; `None` above 3.
    pub const fn from_afs_sel(v: u8) -> Option<Self> {
        match v {
            0 => Some(AccelRange::G2),
            1 => Some(AccelRange::G4),
            2 => Some(AccelRange::G8),
            3 => Some(AccelRange::G16),
            _ => None,
        }
    }

    /// The `AFS_SEL` field value (0..=3).
    pub const fn afs_sel(self) -> u8 {
        match self {
            AccelRange::G2 => 0,
            AccelRange::G4 => 1,
            AccelRange::G8 => 2,
            AccelRange::G16 => 3,
        }
    }
}

/// Gyroscope full-scale range (register `GYRO_CONFIG.FS_SEL`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroRange {
    /// ±250 °/s, 131 LSB/(°/s).
    Dps250,
    /// ±500 °/s, 65.5 LSB/(°/s).
    Dps500,
    /// ±1000 °/s, 32.8 LSB/(°/s).
    Dps1000,
    /// ±2000 °/s, 16.4 LSB/(°/s). Swing of a fast walk reaches ~800 °/s, running more.
    #[default]
    Dps2000,
}

impl GyroRange {
    /// Counts per (°/s), times ten, so that every range is an integer (131.0 → 1310).
    pub const fn lsb_per_dps_x10(self) -> u32 {
        match self {
            GyroRange::Dps250 => 1310,
            GyroRange::Dps500 => 655,
            GyroRange::Dps1000 => 328,
            GyroRange::Dps2000 => 164,
        }
    }

    /// The scale the pipeline takes this range's counts in.
    pub const fn scale(self) -> GyroScale {
        GyroScale::from_lsb_per_dps_x10(self.lsb_per_dps_x10())
    }

    /// The range for an `FS_SEL` field value; `None` above 3.
    pub const fn from_fs_sel(v: u8) -> Option<Self> {
        match v {
            0 => Some(GyroRange::Dps250),
            1 => Some(GyroRange::Dps500),
            2 => Some(GyroRange::Dps1000),
            3 => Some(GyroRange::Dps2000),
            _ => None,
        }
    }

    /// The `FS_SEL` field value (0..=3).
    pub const fn fs_sel(self) -> u8 {
        match self {
            GyroRange::Dps250 => 0,
            GyroRange::Dps500 => 1,
            GyroRange::Dps1000 => 2,
            GyroRange::Dps2000 => 3,
        }
    }
}

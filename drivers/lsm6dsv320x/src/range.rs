//! Full-scale ranges of the three channels and their sensitivities.

use gaitclip_imu::{AccelScale, GyroScale};

/// The low-g accelerometer's full-scale range (`CTRL8.FS_XL`, register 0x17 bits 0–1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelRange {
    /// ±2 g, 0.061 mg per count (16 384 per g).
    G2,
    /// ±4 g, 0.122 mg per count (8 192 per g).
    G4,
    /// ±8 g, 0.244 mg per count (4 096 per g).
    G8,
    /// ±16 g, 0.488 mg per count (2 048 per g): the widest, the one a foot needs.
    #[default]
    G16,
}

impl AccelRange {
    /// The range of an `FS_XL` field value.
    pub const fn from_field(field: u8) -> Option<Self> {
        match field {
            0 => Some(AccelRange::G2),
            1 => Some(AccelRange::G4),
            2 => Some(AccelRange::G8),
            3 => Some(AccelRange::G16),
            _ => None,
        }
    }

    /// The `FS_XL` field value.
    pub const fn field(self) -> u8 {
        match self {
            AccelRange::G2 => 0,
            AccelRange::G4 => 1,
            AccelRange::G8 => 2,
            AccelRange::G16 => 3,
        }
    }

    /// Counts per g.
    pub const fn lsb_per_g(self) -> u32 {
        16_384 >> self.field()
    }

    /// The full scale, g.
    pub const fn full_scale_g(self) -> u32 {
        2 << self.field()
    }

    /// The seam's scale of this range's counts.
    pub const fn scale(self) -> AccelScale {
        AccelScale::from_lsb_per_g(self.lsb_per_g())
    }
}

/// The high-g accelerometer's full-scale range (`CTRL1_XL_HG.FS_XL_HG`, register 0x4E
/// bits 0–2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum HighGRange {
    /// ±32 g, 0.976 mg per count (1 024 per g).
    G32,
    /// ±64 g, 1.952 mg per count (512 per g).
    G64,
    /// ±128 g, 3.904 mg per count (256 per g): a sprinting foot's touch-down (up to 70 g at
    /// the heel, Bailey & Harle 2014) with room to spare.
    #[default]
    G128,
    /// ±256 g, 7.808 mg per count (128 per g).
    G256,
    /// ±320 g, 10.417 mg per count (96 per g).
    G320,
}

impl HighGRange {
    /// The range of an `FS_XL_HG` field value.
    pub const fn from_field(field: u8) -> Option<Self> {
        match field {
            0 => Some(HighGRange::G32),
            1 => Some(HighGRange::G64),
            2 => Some(HighGRange::G128),
            3 => Some(HighGRange::G256),
            4 => Some(HighGRange::G320),
            _ => None,
        }
    }

    /// The `FS_XL_HG` field value.
    pub const fn field(self) -> u8 {
        match self {
            HighGRange::G32 => 0,
            HighGRange::G64 => 1,
            HighGRange::G128 => 2,
            HighGRange::G256 => 3,
            HighGRange::G320 => 4,
        }
    }

    /// Counts per g.
    pub const fn lsb_per_g(self) -> u32 {
        match self {
            HighGRange::G320 => 96,
            r => 1_024 >> r.field(),
        }
    }

    /// The full scale, g.
    pub const fn full_scale_g(self) -> u32 {
        match self {
            HighGRange::G320 => 320,
            r => 32 << r.field(),
        }
    }

    /// The seam's scale of this range's counts.
    pub const fn scale(self) -> AccelScale {
        AccelScale::from_lsb_per_g(self.lsb_per_g())
    }
}

/// The gyroscope's full-scale range (`CTRL6.FS_G`, register 0x15 bits 0–3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroRange {
    /// ±250 °/s, 8.75 mdps per count.
    Dps250,
    /// ±500 °/s, 17.5 mdps per count.
    Dps500,
    /// ±1 000 °/s, 35 mdps per count.
    Dps1000,
    /// ±2 000 °/s, 70 mdps per count.
    Dps2000,
    /// ±4 000 °/s, 140 mdps per count: a sprint's toe-off stays in range.
    #[default]
    Dps4000,
}

impl GyroRange {
    /// The range of an `FS_G` field value.
    pub const fn from_field(field: u8) -> Option<Self> {
        match field {
            1 => Some(GyroRange::Dps250),
            2 => Some(GyroRange::Dps500),
            3 => Some(GyroRange::Dps1000),
            4 => Some(GyroRange::Dps2000),
            5 => Some(GyroRange::Dps4000),
            _ => None,
        }
    }

    /// The `FS_G` field value.
    pub const fn field(self) -> u8 {
        match self {
            GyroRange::Dps250 => 1,
            GyroRange::Dps500 => 2,
            GyroRange::Dps1000 => 3,
            GyroRange::Dps2000 => 4,
            GyroRange::Dps4000 => 5,
        }
    }

    /// The full scale, °/s.
    pub const fn full_scale_dps(self) -> u32 {
        125 << self.field()
    }

    /// The seam's scale: one count per 8.75 · 2^(field − 1) mdps, i.e. 4 000 counts per
    /// 35 · 2^(field − 1) °/s (560 °/s at ±4 000, within the seam's 10³).
    pub const fn scale(self) -> GyroScale {
        GyroScale::from_ratio(4_000, 35 << (self.field() - 1))
    }
}

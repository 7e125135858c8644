//! What the caller configures: the bus address, output rates, the FIFO, the motion wake-up.

use crate::merge::DualRange;
use crate::range::{AccelRange, GyroRange, HighGRange};

/// The part's I²C address, set by its SA0 pin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Address {
    /// SA0 to ground: 0x6A.
    Sa0Low,
    /// SA0 to supply: 0x6B.
    Sa0High,
}

impl Address {
    /// The 7-bit address.
    pub const fn bits(self) -> u8 {
        match self {
            Address::Sa0Low => 0x6A,
            Address::Sa0High => 0x6B,
        }
    }
}

/// An output data rate of the low-g accelerometer and the gyroscope (`ODR_XL`, `ODR_G`), and
/// the FIFO's batch rate (`BDR_XL`, `BDR_GY`, the same codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Odr {
    /// 7.5 Hz.
    Hz7_5,
    /// 15 Hz.
    Hz15,
    /// 30 Hz.
    Hz30,
    /// 60 Hz.
    Hz60,
    /// 120 Hz.
    Hz120,
    /// 240 Hz.
    Hz240,
    /// 480 Hz.
    Hz480,
    /// 960 Hz.
    Hz960,
    /// 1 920 Hz.
    Hz1920,
    /// 3 840 Hz.
    Hz3840,
    /// 7 680 Hz.
    Hz7680,
}

impl Odr {
    /// The field value (2 for 7.5 Hz … 12 for 7 680 Hz).
    pub const fn field(self) -> u8 {
        match self {
            Odr::Hz7_5 => 0x2,
            Odr::Hz15 => 0x3,
            Odr::Hz30 => 0x4,
            Odr::Hz60 => 0x5,
            Odr::Hz120 => 0x6,
            Odr::Hz240 => 0x7,
            Odr::Hz480 => 0x8,
            Odr::Hz960 => 0x9,
            Odr::Hz1920 => 0xA,
            Odr::Hz3840 => 0xB,
            Odr::Hz7680 => 0xC,
        }
    }

    /// The rate of `hz` (7 for 7.5 Hz), if it is one.
    pub const fn from_hz(hz: u32) -> Option<Self> {
        match hz {
            7 => Some(Odr::Hz7_5),
            15 => Some(Odr::Hz15),
            30 => Some(Odr::Hz30),
            60 => Some(Odr::Hz60),
            120 => Some(Odr::Hz120),
            240 => Some(Odr::Hz240),
            480 => Some(Odr::Hz480),
            960 => Some(Odr::Hz960),
            1920 => Some(Odr::Hz1920),
            3840 => Some(Odr::Hz3840),
            7680 => Some(Odr::Hz7680),
            _ => None,
        }
    }

    /// The rate, mHz (7.5 Hz doubles from 15 Hz upward).
    pub const fn millihertz(self) -> u32 {
        7_500 << (self.field() - 2)
    }
}

/// An output data rate of the high-g accelerometer (`ODR_XL_HG`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HighGOdr {
    /// 480 Hz.
    Hz480,
    /// 960 Hz.
    Hz960,
    /// 1 920 Hz.
    Hz1920,
    /// 3 840 Hz.
    Hz3840,
    /// 7 680 Hz.
    Hz7680,
}

impl HighGOdr {
    /// The field value (3 for 480 Hz … 7 for 7 680 Hz).
    pub const fn field(self) -> u8 {
        match self {
            HighGOdr::Hz480 => 0x3,
            HighGOdr::Hz960 => 0x4,
            HighGOdr::Hz1920 => 0x5,
            HighGOdr::Hz3840 => 0x6,
            HighGOdr::Hz7680 => 0x7,
        }
    }

    /// The rate, Hz.
    pub const fn hz(self) -> u32 {
        480 << (self.field() - 3)
    }

    /// The rate of `hz`, if it is one.
    pub const fn from_hz(hz: u32) -> Option<Self> {
        match hz {
            480 => Some(HighGOdr::Hz480),
            960 => Some(HighGOdr::Hz960),
            1920 => Some(HighGOdr::Hz1920),
            3840 => Some(HighGOdr::Hz3840),
            7680 => Some(HighGOdr::Hz7680),
            _ => None,
        }
    }
}

/// The high-g channel: its range and rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HighG {
    /// Its range.
    pub range: HighGRange,
    /// Its rate: at least the low-g rate, so that every low-g period holds a high-g sample.
    pub odr: HighGOdr,
}

/// How the part samples, and what the FIFO holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// The low-g accelerometer's and the gyroscope's rate (both high-performance mode), and
    /// their FIFO batch rate.
    pub odr: Odr,
    /// The low-g accelerometer's range.
    pub accel: AccelRange,
    /// The gyroscope's range.
    pub gyro: GyroRange,
    /// The high-g channel, batched in the FIFO beside them; `None`: off.
    pub high_g: Option<HighG>,
    /// Words in the FIFO that raise INT1 (`WTM`), 1–255.
    pub watermark_words: u8,
}

impl Config {
    /// `odr`, ±16 g, ±4 000 °/s, the high-g channel at ±128 g and 960 Hz, a watermark of
    /// 48 words (eight samples of one low-g, one gyroscope and four high-g words).
    pub const fn new(odr: Odr) -> Self {
        Config {
            odr,
            accel: AccelRange::G16,
            gyro: GyroRange::Dps4000,
            high_g: Some(HighG {
                range: HighGRange::G128,
                odr: HighGOdr::Hz960,
            }),
            watermark_words: 48,
        }
    }
    /// FIFO words per low-g period: the accelerometer's, the gyroscope's, and the high-g
    /// channel's samples of the period (its rate over the low-g one, rounded down).
    pub const fn words_per_period(&self) -> u32 {
        2 + match self.high_g {
            Some(h) => h.odr.hz() * 1000 / self.odr.millihertz(),
            None => 0,
        }
    }

    /// Low-g periods the FIFO holds when INT1 rises (at least 1).
    pub const fn watermark_periods(&self) -> u32 {
        let p = self.watermark_words as u32 / self.words_per_period();
        if p == 0 {
            1
        } else {
            p
        }
    }

    /// How a board's sampler reads the part with this configuration: the FIFO whenever
    /// INT1 says it holds [`Config::watermark_periods`] periods (at most 255: the watermark is
    /// at most 255 words).
    pub const fn read_mode(&self) -> gaitclip_imu::source::ReadMode {
        gaitclip_imu::source::ReadMode::Watermark {
            samples: self.watermark_periods() as u8,
        }
    }

    /// The two accelerometers as the FIFO's samples merge them: the high-g channel's range,
    /// or, with it off, ±32 g (the low-g counts rescaled, nothing to merge).
    pub const fn dual_range(&self) -> DualRange {
        DualRange::new(
            self.accel,
            match self.high_g {
                Some(h) => h.range,
                None => HighGRange::G32,
            },
        )
    }
}

/// The FIFO's state (`FIFO_STATUS1`, `FIFO_STATUS2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FifoStatus {
    /// Words waiting (`DIFF_FIFO`, 0–511).
    pub words: u16,
    /// The watermark is reached.
    pub watermark: bool,
    /// The FIFO is full.
    pub full: bool,
    /// Words were overwritten (the overrun flag, or its latched copy since the last read).
    pub overrun: bool,
}

impl FifoStatus {
    /// Decodes the two status bytes.
    pub const fn from_bytes(b: [u8; 2]) -> Self {
        use crate::register::bits;
        FifoStatus {
            words: b[0] as u16 | (((b[1] & bits::DIFF_FIFO_8) as u16) << 8),
            watermark: b[1] & bits::FIFO_WTM_IA != 0,
            full: b[1] & bits::FIFO_FULL_IA != 0,
            overrun: b[1] & (bits::FIFO_OVR_IA | bits::FIFO_OVR_LATCHED) != 0,
        }
    }
}

/// The wait for motion: the low-g accelerometer alone in low-power mode, the gyroscope and
/// the high-g channel off, INT1 latched on the wake-up event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionWakeConfig {
    /// The accelerometer's rate while waiting.
    pub odr: Odr,
    /// `WU_INACT_THS_W`, 0–7: the weight of one threshold count. The LSM6DSV family's
    /// datasheets give 7.8125 mg for 0, doubling to 250 mg for 5 to 7; not checked here
    /// against the LSM6DSV320X's own.
    pub weight_code: u8,
    /// `WK_THS`, 0–63 counts of that weight, on the slope (sample-to-sample change).
    pub threshold_counts: u8,
}

impl MotionWakeConfig {
    /// 15 Hz, weight code 2 (31.25 mg), 3 counts: 94 mg, as near as the part's steps get to
    /// the MPU6050's 96 mg.
    pub const DEFAULT: MotionWakeConfig = MotionWakeConfig {
        odr: Odr::Hz15,
        weight_code: 2,
        threshold_counts: 3,
    };
}

//! One raw MPU6050 sample as it comes off the bus, and the sensor's full-scale ranges.

use crate::sensor::units::{AccelScale, GyroScale};

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
    /// The scale the stages compute in.
    pub const fn scale(self) -> AccelScale {
        AccelScale::from_lsb_per_g(self.lsb_per_g())
    }

    /// Counts per g (datasheet sensitivity).
    pub const fn lsb_per_g(self) -> u32 {
        16384 >> self.afs_sel()
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
    /// The scale the stages compute in.
    pub const fn scale(self) -> GyroScale {
        GyroScale::from_lsb_per_dps_x10(self.lsb_per_dps_x10())
    }

    /// Counts per (°/s), times ten, so that every range is an integer (131.0 → 1310).
    pub const fn lsb_per_dps_x10(self) -> u32 {
        match self {
            GyroRange::Dps250 => 1310,
            GyroRange::Dps500 => 655,
            GyroRange::Dps1000 => 328,
            GyroRange::Dps2000 => 164,
        }
    }

    /// An angular rate in mrad/s as counts of this range, rounded (exact to ±0.5 count
    /// plus 1 ppm for π; any `mrad_per_s` up to 10⁶, 1 000 rad/s).
    pub const fn counts_of_mrad_per_s(self, mrad_per_s: u32) -> u32 {
        self.scale().counts_of_mrad_per_s(mrad_per_s)
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

/// Number of bytes of one sample in the sensor's register layout (0x3B..=0x48) and FIFO.
pub const SAMPLE_BYTES: usize = 14;

/// One sample in raw sensor counts, sensor axes.
///
/// `accel` is specific force (gravity included) in counts of the configured [`AccelRange`],
/// `gyro` angular rate in counts of the configured [`GyroRange`], `temp` the raw temperature
/// register (°C = temp / 340 + 36.53).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct RawSample {
    /// Accelerometer x, y, z in counts.
    pub accel: [i16; 3],
    /// Gyroscope x, y, z in counts.
    pub gyro: [i16; 3],
    /// Temperature register.
    pub temp: i16,
}

impl RawSample {
    /// Decodes the big-endian register block `ACCEL_XOUT_H..=GYRO_ZOUT_L` (also the FIFO
    /// layout when accel, temperature and gyro are enabled).
    pub const fn from_be_bytes(b: &[u8; SAMPLE_BYTES]) -> Self {
        RawSample {
            accel: [word(b, 0), word(b, 1), word(b, 2)],
            temp: word(b, 3),
            gyro: [word(b, 4), word(b, 5), word(b, 6)],
        }
    }

    /// Encodes in the register layout; the inverse of [`RawSample::from_be_bytes`].
    pub const fn to_be_bytes(&self) -> [u8; SAMPLE_BYTES] {
        let words = [
            self.accel[0],
            self.accel[1],
            self.accel[2],
            self.temp,
            self.gyro[0],
            self.gyro[1],
            self.gyro[2],
        ];
        let mut out = [0u8; SAMPLE_BYTES];
        let mut i = 0;
        while i < 7 {
            let [h, l] = words[i].to_be_bytes();
            out[2 * i] = h;
            out[2 * i + 1] = l;
            i += 1;
        }
        out
    }

    /// True if a gyroscope axis sits at a rail of its range.
    pub const fn gyro_saturated(&self) -> bool {
        rail(self.gyro[0]) || rail(self.gyro[1]) || rail(self.gyro[2])
    }

    /// True if an accelerometer axis sits at a rail of its range.
    pub const fn accel_saturated(&self) -> bool {
        rail(self.accel[0]) || rail(self.accel[1]) || rail(self.accel[2])
    }

    /// True if any axis sits at a rail of its range (the true value may be beyond it).
    pub const fn is_saturated(&self) -> bool {
        let mut i = 0;
        while i < 3 {
            if rail(self.accel[i]) || rail(self.gyro[i]) {
                return true;
            }
            i += 1;
        }
        false
    }
}

/// Where one axis clips, in counts: a reading at or beyond `low` or `high` sits at a rail
/// and the true value may lie beyond it.
///
/// The MPU6050's registers saturate at the counts' extremes ([`AxisRails::FULL_SCALE`]), but
/// real parts clip below their nominal range (a ±16 g accelerometer axis at −15.6 g, a
/// ±2000 °/s gyro at ±1 988 °/s), so a replayed recording's rails are learnt from its data
/// or given, axis by axis, and the core is told them ([`Rails`]), never assumes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisRails {
    /// Lowest reading that is not at a rail, less one: readings `<= low` are clipped.
    pub low: i16,
    /// Readings `>= high` are clipped.
    pub high: i16,
}

impl AxisRails {
    /// The counts' own extremes: what the MPU6050's output registers saturate at.
    pub const FULL_SCALE: AxisRails = AxisRails {
        low: i16::MIN,
        high: i16::MAX,
    };

    /// Rails at `low` < 0 < `high`; `None` for rails that do not bracket zero (an axis at
    /// rest reads near zero or near 1 g, never at a rail).
    pub const fn new(low: i16, high: i16) -> Option<Self> {
        if low < 0 && high > 0 {
            Some(AxisRails { low, high })
        } else {
            None
        }
    }

    /// True when `v` sits at (or beyond) a rail.
    pub const fn clipped(self, v: i16) -> bool {
        v >= self.high || v <= self.low
    }

    /// The rail on `v`'s side of zero, counts: the one a clipped run of `v`'s sign sits at.
    pub const fn rail_of(self, v: i32) -> i32 {
        if v >= 0 {
            self.high as i32
        } else {
            self.low as i32
        }
    }

    /// The smaller of the two rails' magnitudes, counts.
    pub const fn min_magnitude(self) -> u32 {
        let lo = (self.low as i32).unsigned_abs();
        let hi = self.high as u32;
        if lo < hi {
            lo
        } else {
            hi
        }
    }
}

/// The rails of every axis of both sensors ([`AxisRails`]), in the counts the pipeline is fed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rails {
    /// Accelerometer x, y, z.
    pub accel: [AxisRails; 3],
    /// Gyroscope x, y, z.
    pub gyro: [AxisRails; 3],
}

impl Rails {
    /// Every axis at the counts' extremes: the MPU6050 as the firmware reads it.
    pub const FULL_SCALE: Rails = Rails {
        accel: [AxisRails::FULL_SCALE; 3],
        gyro: [AxisRails::FULL_SCALE; 3],
    };

    /// True if an accelerometer axis of `s` sits at a rail.
    pub const fn accel_clipped(&self, s: &RawSample) -> bool {
        self.accel[0].clipped(s.accel[0])
            || self.accel[1].clipped(s.accel[1])
            || self.accel[2].clipped(s.accel[2])
    }

    /// True if a gyroscope axis of `s` sits at a rail.
    pub const fn gyro_clipped(&self, s: &RawSample) -> bool {
        self.gyro[0].clipped(s.gyro[0])
            || self.gyro[1].clipped(s.gyro[1])
            || self.gyro[2].clipped(s.gyro[2])
    }

    /// Which axes of `s` sit at a rail: bits 0–2 accelerometer x, y, z, bits 3–5 gyroscope
    /// x, y, z.
    pub const fn clipped_axes(&self, s: &RawSample) -> u8 {
        let mut bits = 0u8;
        let mut k = 0;
        while k < 3 {
            if self.accel[k].clipped(s.accel[k]) {
                bits |= 1 << k;
            }
            if self.gyro[k].clipped(s.gyro[k]) {
                bits |= 1 << (k + 3);
            }
            k += 1;
        }
        bits
    }
}

const fn word(b: &[u8; SAMPLE_BYTES], i: usize) -> i16 {
    i16::from_be_bytes([b[2 * i], b[2 * i + 1]])
}

const fn rail(v: i16) -> bool {
    v == i16::MAX || v == i16::MIN
}

/// Where a sample fed to the tracker comes from: the sensor, or the pipeline's
/// interpolation across a hole of lost samples ([`crate::pipeline::Pipeline::gap`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Origin {
    /// Read from the sensor.
    #[default]
    Measured,
    /// Interpolated across a hole short enough to measure through
    /// ([`crate::pipeline::config::BRIDGE_MAX_MS`]): the stride is [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED).
    Bridged,
    /// Interpolated across a longer hole ([`crate::pipeline::config::FILL_MAX_MS`]), so that the
    /// stride's events outside the hole can still be found: in a movement the stride is a
    /// [`StrideFlags::GAP`](crate::record::stride::StrideFlags::GAP) stride, in a stance only [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED) (a foot at rest
    /// is at rest either side of it).
    Filled,
}

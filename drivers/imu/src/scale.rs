//! The units a sensor's counts are in.

/// An accelerometer's scale: counts per g.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccelScale {
    lsb_per_g: u32,
}

impl AccelScale {
    /// A scale of `lsb_per_g` counts per g (a zero reads as 1).
    pub const fn from_lsb_per_g(lsb_per_g: u32) -> Self {
        AccelScale {
            lsb_per_g: if lsb_per_g == 0 { 1 } else { lsb_per_g },
        }
    }

    /// Counts per g.
    pub const fn lsb_per_g(self) -> u32 {
        self.lsb_per_g
    }
}

/// A gyroscope's scale: `lsb` counts per `dps` °/s, a ratio of two integers.
///
/// InvenSense states its sensitivities in counts per °/s with one decimal (16.4), ST in mdps
/// per count (70, 140): neither is the other's whole number, so the scale is kept as the
/// ratio the datasheet gives, and every stage that converts counts multiplies by `lsb` and
/// divides by `dps` in one step, so that the MPU6050's `164 / 10` gives the same integers as
/// its 16.4 did. Range: `lsb` up to 10⁶ and `dps` up to 10³ keep every stage's products in
/// their integer types; the host tests run every driver's scale through them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GyroScale {
    lsb: u32,
    dps: u32,
}

impl GyroScale {
    /// Largest numerator, counts.
    pub const MAX_LSB: u32 = 1_000_000;
    /// Largest denominator, °/s.
    pub const MAX_DPS: u32 = 1_000;

    /// `lsb` counts per `dps` °/s, each clamped to 1..=[`GyroScale::MAX_LSB`] and
    /// 1..=[`GyroScale::MAX_DPS`].
    pub const fn from_ratio(lsb: u32, dps: u32) -> Self {
        GyroScale {
            lsb: clamp(lsb, Self::MAX_LSB),
            dps: clamp(dps, Self::MAX_DPS),
        }
    }

    /// `lsb_per_dps_x10` / 10 counts per °/s: InvenSense's sensitivities (16.4 → 164).
    pub const fn from_lsb_per_dps_x10(lsb_per_dps_x10: u32) -> Self {
        Self::from_ratio(lsb_per_dps_x10, 10)
    }

    /// One count per `mdps_per_lsb` thousandths of a °/s: ST's sensitivities (70 mdps per
    /// count at ±2 000 °/s is 1 000 counts per 70 °/s).
    pub const fn from_mdps_per_lsb(mdps_per_lsb: u32) -> Self {
        Self::from_ratio(1_000, mdps_per_lsb)
    }

    /// The ratio's numerator: counts.
    pub const fn lsb(self) -> u32 {
        self.lsb
    }

    /// The ratio's denominator: °/s.
    pub const fn dps(self) -> u32 {
        self.dps
    }

    /// Counts per °/s, for the host's f64 references (`lsb / dps`, one rounding).
    pub fn lsb_per_dps(self) -> f64 {
        self.lsb as f64 / self.dps as f64
    }

    /// An angular rate in mrad/s as counts of this scale, rounded (exact to ±0.5 count plus
    /// 1 ppm for π; any `mrad_per_s` up to 10⁶, 1 000 rad/s).
    pub const fn counts_of_mrad_per_s(self, mrad_per_s: u32) -> u32 {
        // counts = mrad/1000 · (180/π) · lsb/dps, π as 3 141 593 / 10⁶.
        let num = mrad_per_s as u128 * self.lsb as u128 * 180 * 1_000_000;
        let den = 3_141_593u128 * 1_000 * self.dps as u128;
        ((num + den / 2) / den) as u32
    }
}

const fn clamp(v: u32, max: u32) -> u32 {
    if v == 0 {
        1
    } else if v > max {
        max
    } else {
        v
    }
}

/// What a driver's configuration says its samples are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scales {
    /// The accelerometer's counts.
    pub accel: AccelScale,
    /// The gyroscope's counts.
    pub gyro: GyroScale,
}

//! One sample in the sensor's counts.

/// One sample in raw sensor counts, sensor axes, whichever part read it.
///
/// `accel` is specific force (gravity included) in counts of an [`crate::AccelScale`],
/// `gyro` angular rate in counts of a [`crate::GyroScale`], `temp` the part's own
/// temperature word (its own scale and offset; the pipeline only carries it through).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct RawSample {
    /// Accelerometer x, y, z in counts.
    pub accel: [i16; 3],
    /// Gyroscope x, y, z in counts.
    pub gyro: [i16; 3],
    /// Temperature word, the part's own scale.
    pub temp: i16,
}

impl RawSample {
    /// True if a gyroscope axis sits at the counts' extremes (`i16::MIN` or `i16::MAX`),
    /// where a part's output register saturates.
    pub const fn gyro_saturated(&self) -> bool {
        extreme(self.gyro[0]) || extreme(self.gyro[1]) || extreme(self.gyro[2])
    }

    /// True if an accelerometer axis sits at the counts' extremes.
    pub const fn accel_saturated(&self) -> bool {
        extreme(self.accel[0]) || extreme(self.accel[1]) || extreme(self.accel[2])
    }

    /// True if any axis sits at the counts' extremes (the true value may be beyond it).
    pub const fn is_saturated(&self) -> bool {
        self.accel_saturated() || self.gyro_saturated()
    }
}

const fn extreme(v: i16) -> bool {
    v == i16::MAX || v == i16::MIN
}

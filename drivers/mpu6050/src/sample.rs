//! One sample as it comes off the bus: the 14 data registers, or one FIFO entry.

/// Number of bytes of one sample in the sensor's register layout (0x3B..=0x48) and FIFO.
pub const SAMPLE_BYTES: usize = 14;

/// One sample in raw sensor counts, sensor axes.
///
/// `accel` is specific force (gravity included) in counts of the configured [`crate::AccelRange`],
/// `gyro` angular rate in counts of the configured [`crate::GyroRange`], `temp` the raw temperature
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

const fn rail(v: i16) -> bool {
    v == i16::MAX || v == i16::MIN
}

const fn word(b: &[u8; SAMPLE_BYTES], i: usize) -> i16 {
    i16::from_be_bytes([b[2 * i], b[2 * i + 1]])
}

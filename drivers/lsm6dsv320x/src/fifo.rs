//! One FIFO word: `FIFO_DATA_OUT_TAG` (register 0x78) and the six bytes after it
//! (`FIFO_DATA_OUT_X_L` … `Z_H`, 0x79–0x7E), read in one burst of [`WORD_BYTES`].

/// Bytes of one FIFO word: the tag and three little-endian 16-bit words.
pub const WORD_BYTES: usize = 7;

/// What a FIFO word holds (`TAG_SENSOR`, the tag byte's bits 3–7), the tags gaitclip reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tag {
    /// Gyroscope, uncompressed (0x01).
    Gyro,
    /// Low-g accelerometer, uncompressed (0x02).
    Accel,
    /// Temperature (0x03).
    Temperature,
    /// Timestamp (0x04).
    Timestamp,
    /// High-g accelerometer (0x1D).
    HighG,
    /// Any other tag (compressed data, sensor hub, embedded functions): skipped.
    Other(u8),
}

impl Tag {
    /// The tag of a `TAG_SENSOR` value.
    pub const fn of(sensor: u8) -> Tag {
        match sensor {
            0x01 => Tag::Gyro,
            0x02 => Tag::Accel,
            0x03 => Tag::Temperature,
            0x04 => Tag::Timestamp,
            0x1D => Tag::HighG,
            other => Tag::Other(other),
        }
    }

    /// The `TAG_SENSOR` value.
    pub const fn sensor(self) -> u8 {
        match self {
            Tag::Gyro => 0x01,
            Tag::Accel => 0x02,
            Tag::Temperature => 0x03,
            Tag::Timestamp => 0x04,
            Tag::HighG => 0x1D,
            Tag::Other(v) => v & 0x1F,
        }
    }
}

/// One decoded FIFO word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FifoWord {
    /// What it holds.
    pub tag: Tag,
    /// `TAG_CNT` (bits 1–2): the time slot, counting 0–3; words of one instant share it.
    pub slot: u8,
    /// X, Y, Z (or the tag's own three words).
    pub data: [i16; 3],
}

impl FifoWord {
    /// Decodes the seven bytes of one word.
    pub const fn from_bytes(b: &[u8; WORD_BYTES]) -> FifoWord {
        FifoWord {
            tag: Tag::of(b[0] >> 3),
            slot: (b[0] >> 1) & 0b11,
            data: [
                i16::from_le_bytes([b[1], b[2]]),
                i16::from_le_bytes([b[3], b[4]]),
                i16::from_le_bytes([b[5], b[6]]),
            ],
        }
    }

    /// Encodes it; the inverse of [`FifoWord::from_bytes`] (the reserved bit 0 is 0).
    pub const fn to_bytes(&self) -> [u8; WORD_BYTES] {
        let [x0, x1] = self.data[0].to_le_bytes();
        let [y0, y1] = self.data[1].to_le_bytes();
        let [z0, z1] = self.data[2].to_le_bytes();
        [
            (self.tag.sensor() << 3) | ((self.slot & 0b11) << 1),
            x0,
            x1,
            y0,
            y1,
            z0,
            z1,
        ]
    }
}

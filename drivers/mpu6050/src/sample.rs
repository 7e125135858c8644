//! One sample as it comes off the bus: the 14 data registers, or one FIFO entry.

/// Number of bytes of one sample in the sensor's register layout (0x3B..=0x48) and FIFO.
pub const SAMPLE_BYTES: usize = 14;

pub use gaitclip_imu::RawSample;

/// Decodes the big-endian register block `ACCEL_XOUT_H..=GYRO_ZOUT_L` (also the FIFO layout
/// when accel, temperature and gyro are enabled): accel x, y, z, temperature (°C = temp / 340
/// + 36.53), gyro x, y, z.
pub const fn from_be_bytes(b: &[u8; SAMPLE_BYTES]) -> RawSample {
    RawSample {
        accel: [word(b, 0), word(b, 1), word(b, 2)],
        temp: word(b, 3),
        gyro: [word(b, 4), word(b, 5), word(b, 6)],
    }
}

/// Encodes in the register layout; the inverse of [`from_be_bytes`].
pub const fn to_be_bytes(s: &RawSample) -> [u8; SAMPLE_BYTES] {
    let words = [
        s.accel[0], s.accel[1], s.accel[2], s.temp, s.gyro[0], s.gyro[1], s.gyro[2],
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

const fn word(b: &[u8; SAMPLE_BYTES], i: usize) -> i16 {
    i16::from_be_bytes([b[2 * i], b[2 * i + 1]])
}

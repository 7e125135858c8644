//! The register map gaitclip uses, as ST's `lsm6dsv320x-rs` 2.x (`src/register/main.rs`)
//! gives it: addresses, field positions, and the part's constants.

/// Register addresses (main bank).
pub mod reg {
    /// FIFO watermark, in words (`WTM[7:0]`).
    pub const FIFO_CTRL1: u8 = 0x07;
    /// Batch data rates: `BDR_XL` bits 0–3, `BDR_GY` bits 4–7.
    pub const FIFO_CTRL3: u8 = 0x09;
    /// `FIFO_MODE` bits 0–2.
    pub const FIFO_CTRL4: u8 = 0x0A;
    /// `XL_HG_BATCH_EN` bit 3: the high-g accelerometer into the FIFO.
    pub const COUNTER_BDR_REG1: u8 = 0x0B;
    /// What INT1 signals.
    pub const INT1_CTRL: u8 = 0x0D;
    /// Device identification, [`crate::WHO_AM_I_VALUE`].
    pub const WHO_AM_I: u8 = 0x0F;
    /// Low-g accelerometer: `ODR_XL` bits 0–3, `OP_MODE_XL` bits 4–6.
    pub const CTRL1: u8 = 0x10;
    /// Gyroscope: `ODR_G` bits 0–3, `OP_MODE_G` bits 4–6.
    pub const CTRL2: u8 = 0x11;
    /// `SW_RESET` bit 0, `IF_INC` bit 2, `BDU` bit 6, `BOOT` bit 7.
    pub const CTRL3: u8 = 0x12;
    /// `FS_G` bits 0–2 (bit 3 reserved, reads 1), `LPF1_G_BW` bits 4–6.
    pub const CTRL6: u8 = 0x15;
    /// `FS_XL` bits 0–1, `HP_LPF2_XL_BW` bits 5–7.
    pub const CTRL8: u8 = 0x17;
    /// `DIFF_FIFO[7:0]`; the next register holds bit 8 and the flags.
    pub const FIFO_STATUS1: u8 = 0x1B;
    /// Every interrupt source; reading it clears latched interrupts.
    pub const ALL_INT_SRC: u8 = 0x1D;
    /// High-g accelerometer: `FS_XL_HG` bits 0–2, `ODR_XL_HG` bits 3–5, `XL_HG_REGOUT_EN`
    /// bit 7.
    pub const CTRL1_XL_HG: u8 = 0x4E;
    /// `INTERRUPTS_ENABLE` bit 7 (wake-up and the other basic interrupts).
    pub const FUNCTIONS_ENABLE: u8 = 0x50;
    /// `XL_INACT_ODR` bits 2–3 (reset value 01), `WU_INACT_THS_W` bits 4–6.
    pub const INACTIVITY_DUR: u8 = 0x54;
    /// `LIR` bit 0 (latched interrupts), `SLOPE_FDS` bit 4.
    pub const TAP_CFG0: u8 = 0x56;
    /// `WK_THS` bits 0–5.
    pub const WAKE_UP_THS: u8 = 0x5B;
    /// `WAKE_DUR` bits 5–6.
    pub const WAKE_UP_DUR: u8 = 0x5C;
    /// Events routed to INT1: `INT1_WU` bit 5.
    pub const MD1_CFG: u8 = 0x5E;
    /// The FIFO's output: the tag byte, then six data bytes to 0x7E.
    pub const FIFO_DATA_OUT_TAG: u8 = 0x78;
}

/// Bit flags and field values.
pub mod bits {
    /// `CTRL3`: software reset (clears itself when done).
    pub const SW_RESET: u8 = 1 << 0;
    /// `CTRL3`: register address auto-increment (reset value 1).
    pub const IF_INC: u8 = 1 << 2;
    /// `CTRL3`: block data update (reset value 1).
    pub const BDU: u8 = 1 << 6;
    /// `CTRL6` bit 3: reserved, reads 1 (ST's driver writes it back as 1).
    pub const CTRL6_RESERVED: u8 = 1 << 3;
    /// `OP_MODE_XL` / `OP_MODE_G`: high-performance (0). The high-g channel runs only with
    /// the low-g one off or in high-performance or high-accuracy mode.
    pub const OP_MODE_HIGH_PERFORMANCE: u8 = 0;
    /// `OP_MODE_XL`: low-power mode 1, two-sample mean (4).
    pub const OP_MODE_XL_LOW_POWER_2_MEAN: u8 = 4;
    /// `OP_MODE_XL`: normal (7), the mode ST's reset procedure powers the accelerometer
    /// down in.
    pub const OP_MODE_XL_NORMAL: u8 = 7;
    /// `OP_MODE_G`: low-power (5), the mode ST's reset procedure powers the gyroscope down
    /// in.
    pub const OP_MODE_G_LOW_POWER: u8 = 5;
    /// `COUNTER_BDR_REG1`: high-g accelerometer batched in the FIFO.
    pub const XL_HG_BATCH_EN: u8 = 1 << 3;
    /// `FIFO_MODE`: bypass (0), the FIFO off and emptied.
    pub const FIFO_MODE_BYPASS: u8 = 0;
    /// `FIFO_MODE`: continuous (6), new words overwrite the oldest when full.
    pub const FIFO_MODE_CONTINUOUS: u8 = 6;
    /// `INT1_CTRL`: FIFO watermark on INT1.
    pub const INT1_FIFO_TH: u8 = 1 << 3;
    /// `INT1_CTRL`: FIFO overrun on INT1.
    pub const INT1_FIFO_OVR: u8 = 1 << 4;
    /// `FIFO_STATUS2`: `DIFF_FIFO` bit 8.
    pub const DIFF_FIFO_8: u8 = 1 << 0;
    /// `FIFO_STATUS2`: overrun since the last read (latched).
    pub const FIFO_OVR_LATCHED: u8 = 1 << 3;
    /// `FIFO_STATUS2`: FIFO full.
    pub const FIFO_FULL_IA: u8 = 1 << 5;
    /// `FIFO_STATUS2`: FIFO overrun.
    pub const FIFO_OVR_IA: u8 = 1 << 6;
    /// `FIFO_STATUS2`: watermark reached.
    pub const FIFO_WTM_IA: u8 = 1 << 7;
    /// `FUNCTIONS_ENABLE`: basic interrupts (wake-up) on.
    pub const INTERRUPTS_ENABLE: u8 = 1 << 7;
    /// `INACTIVITY_DUR`: `XL_INACT_ODR` at its reset value (01), bits 2–3.
    pub const XL_INACT_ODR_RESET: u8 = 0b01 << 2;
    /// `TAP_CFG0`: latched interrupts, cleared by reading `ALL_INT_SRC`.
    pub const LIR: u8 = 1 << 0;
    /// `MD1_CFG`: wake-up on INT1.
    pub const INT1_WU: u8 = 1 << 5;
    /// `ALL_INT_SRC`: wake-up.
    pub const WU_IA: u8 = 1 << 1;
}

/// `WHO_AM_I` of an LSM6DSV320X.
pub const WHO_AM_I_VALUE: u8 = 0x73;

/// Words the FIFO holds: 4.5 KB of 7-byte words (ST: "smart FIFO up to 4.5 KB").
pub const FIFO_CAPACITY_WORDS: u16 = 4608 / 7;

/// How long the software reset is given before `CTRL3` is checked, ms (ST's driver polls
/// `SW_RESET` up to four times, 150 µs apart).
pub const RESET_WAIT_MS: u32 = 1;

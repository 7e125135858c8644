//! An emulated LSM6DSV320X that answers on the I²C bus with a recorded FIFO.
//!
//! As [`crate::replay_mpu6050`] stands in for the MPU6050, this stands in for ST's part at the
//! bus: it implements embedded-hal's `I2c`, keeps a register file, answers `WHO_AM_I` with
//! 0x73, completes a software reset at once (`CTRL3.SW_RESET` reads back clear, the register
//! file at its reset values), and serves `FIFO_STATUS1`/`2` and the FIFO's words
//! (`FIFO_DATA_OUT_TAG` … `Z_H`, seven bytes with the address auto-incremented) from a
//! recording of the part's FIFO stored in flash, in the part's own word layout. Each
//! [`ReplayLsm6dsv320x::tick`] is one low-g sample period: that period's words (its high-g
//! words, then its low-g and gyroscope words) enter the FIFO, if the FIFO is on (continuous
//! mode) and the part is configured as the recording was made ([`ReplayLsm6dsv320x::configured_as`]);
//! in bypass mode the FIFO is empty. Words the reader leaves beyond the FIFO's capacity are
//! overwritten and the overrun flags set, as the part does. The real driver runs unchanged on
//! top of it.
//!
//! Board glue, not core: it is safe code but knows a storage format.

use embedded_hal::i2c::{self, ErrorKind, NoAcknowledgeSource, Operation, SevenBitAddress};
use gaitclip_lsm6dsv320x::fifo::WORD_BYTES;
use gaitclip_lsm6dsv320x::FIFO_CAPACITY_WORDS;

const FIFO_CTRL1: u8 = 0x07;
const FIFO_CTRL4: u8 = 0x0A;
const WHO_AM_I: u8 = 0x0F;
const CTRL1: u8 = 0x10;
const CTRL2: u8 = 0x11;
const CTRL3: u8 = 0x12;
const CTRL6: u8 = 0x15;
const CTRL8: u8 = 0x17;
const FIFO_STATUS1: u8 = 0x1B;
const FIFO_STATUS2: u8 = 0x1C;
const CTRL1_XL_HG: u8 = 0x4E;
const FIFO_DATA_OUT_TAG: u8 = 0x78;
const FIFO_DATA_OUT_Z_H: u8 = 0x7E;
const SW_RESET: u8 = 0x01;
const FIFO_MODE_CONTINUOUS: u8 = 6;

/// How the recording was made: what the firmware must have configured for the emulated part
/// to fill its FIFO.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Recorded {
    /// `ODR_XL` = `ODR_G` (and the batch rates).
    pub odr_field: u8,
    /// `FS_XL`.
    pub fs_xl: u8,
    /// `FS_G`.
    pub fs_g: u8,
    /// `CTRL1_XL_HG`: `FS_XL_HG` | `ODR_XL_HG` << 3.
    pub high_g_ctrl: u8,
    /// FIFO words per low-g period.
    pub words_per_period: usize,
}

/// Why the emulated bus refused a transaction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayBusError {
    /// Nothing answers at that address.
    NoDevice,
}

impl i2c::Error for ReplayBusError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address)
    }
}

/// The emulated part.
pub struct ReplayLsm6dsv320x {
    address: u8,
    fifo: &'static [u8],
    recorded: Recorded,
    regs: [u8; 0x80],
    pointer: u8,
    /// Words of the recording that entered the FIFO.
    produced: usize,
    /// Words of the recording that left it (read, or dropped by bypass or an overrun).
    consumed: usize,
    /// Bytes of the current word already read (the address auto-increments through it).
    byte: usize,
    overrun_latched: bool,
    /// Low-g periods ticked.
    periods: usize,
}

impl ReplayLsm6dsv320x {
    /// A part at `address` whose FIFO will hold `fifo` (seven-byte words, in FIFO order),
    /// recorded as `recorded` says.
    pub const fn new(address: u8, fifo: &'static [u8], recorded: Recorded) -> Self {
        let mut regs = [0u8; 0x80];
        regs[CTRL3 as usize] = 0x44;
        regs[CTRL6 as usize] = 0x08;
        ReplayLsm6dsv320x {
            address,
            fifo,
            recorded,
            regs,
            pointer: 0,
            produced: 0,
            consumed: 0,
            byte: 0,
            overrun_latched: false,
            periods: 0,
        }
    }

    fn words(&self) -> usize {
        self.fifo.len() / WORD_BYTES
    }

    /// Low-g sample periods in the recording.
    pub fn periods(&self) -> usize {
        self.words() / self.recorded.words_per_period.max(1)
    }

    /// Periods ticked so far: the part's own clock, which a board keeps with its timer.
    pub fn ticked(&self) -> usize {
        self.periods
    }

    /// Periods not yet ticked.
    pub fn remaining(&self) -> usize {
        self.periods().saturating_sub(self.periods)
    }

    /// Whether the registers configure the part as the recording was made.
    pub fn configured_as(&self) -> bool {
        let r = &self.regs;
        let odr = self.recorded.odr_field;
        r[CTRL1 as usize] & 0x0F == odr
            && r[CTRL2 as usize] & 0x0F == odr
            && r[CTRL8 as usize] & 0x03 == self.recorded.fs_xl
            && r[CTRL6 as usize] & 0x07 == self.recorded.fs_g
            && r[CTRL1_XL_HG as usize] & 0x3F == self.recorded.high_g_ctrl
    }

    fn fifo_on(&self) -> bool {
        self.regs[FIFO_CTRL4 as usize] & 0x07 == FIFO_MODE_CONTINUOUS && self.configured_as()
    }

    /// One low-g sample period: its words enter the FIFO (when it is on), the oldest
    /// overwritten beyond its capacity.
    pub fn tick(&mut self) {
        if self.remaining() == 0 {
            return;
        }
        self.periods += 1;
        if !self.fifo_on() {
            return;
        }
        self.produced = (self.produced + self.recorded.words_per_period).min(self.words());
        let capacity = FIFO_CAPACITY_WORDS as usize;
        if self.produced - self.consumed > capacity {
            self.consumed = self.produced - capacity;
            self.byte = 0;
            self.overrun_latched = true;
        }
    }

    /// Words waiting in the FIFO.
    pub fn waiting(&self) -> usize {
        self.produced - self.consumed
    }

    fn status(&mut self, second: bool) -> u8 {
        let waiting = self.waiting().min(0x1FF);
        if !second {
            return (waiting & 0xFF) as u8;
        }
        let mut b = (waiting >> 8) as u8 & 0x01;
        if waiting >= self.regs[FIFO_CTRL1 as usize] as usize && waiting > 0 {
            b |= 1 << 7;
        }
        if core::mem::take(&mut self.overrun_latched) {
            b |= (1 << 6) | (1 << 3);
        }
        if self.waiting() >= FIFO_CAPACITY_WORDS as usize {
            b |= 1 << 5;
        }
        b
    }

    fn read_byte(&mut self) -> u8 {
        let r = self.pointer;
        let next = match r {
            FIFO_DATA_OUT_Z_H => FIFO_DATA_OUT_TAG,
            _ => r.wrapping_add(1) & 0x7F,
        };
        self.pointer = next;
        match r {
            WHO_AM_I => 0x73,
            FIFO_STATUS1 => self.status(false),
            FIFO_STATUS2 => self.status(true),
            FIFO_DATA_OUT_TAG..=FIFO_DATA_OUT_Z_H => {
                if self.waiting() == 0 {
                    return 0; // an empty FIFO reads as tag 0 (`FifoEmpty`)
                }
                let b = self.fifo[self.consumed * WORD_BYTES + self.byte];
                self.byte += 1;
                if self.byte == WORD_BYTES {
                    self.byte = 0;
                    self.consumed += 1;
                }
                b
            }
            _ => self.regs[r as usize],
        }
    }

    fn write_byte(&mut self, v: u8) {
        let r = self.pointer;
        self.pointer = r.wrapping_add(1) & 0x7F;
        match r {
            WHO_AM_I | FIFO_STATUS1 | FIFO_STATUS2 => {}
            CTRL3 if v & SW_RESET != 0 => {
                // The reset completes at once: every register at its reset value.
                *self = ReplayLsm6dsv320x {
                    pointer: self.pointer,
                    produced: self.produced,
                    consumed: self.produced,
                    periods: self.periods,
                    ..ReplayLsm6dsv320x::new(self.address, self.fifo, self.recorded)
                };
                self.regs[CTRL3 as usize] = v & !SW_RESET;
            }
            FIFO_CTRL4 => {
                self.regs[r as usize] = v;
                if v & 0x07 != FIFO_MODE_CONTINUOUS {
                    // Bypass (or any mode but continuous here): the FIFO empties.
                    self.consumed = self.produced;
                    self.byte = 0;
                }
            }
            _ => self.regs[r as usize] = v,
        }
    }
}

impl i2c::ErrorType for ReplayLsm6dsv320x {
    type Error = ReplayBusError;
}

impl i2c::I2c<SevenBitAddress> for ReplayLsm6dsv320x {
    fn transaction(
        &mut self,
        address: SevenBitAddress,
        operations: &mut [Operation<'_>],
    ) -> Result<(), Self::Error> {
        if address != self.address {
            return Err(ReplayBusError::NoDevice);
        }
        for op in operations {
            match op {
                Operation::Write(bytes) => {
                    if let Some((&reg, values)) = bytes.split_first() {
                        self.pointer = reg & 0x7F;
                        for &v in values {
                            self.write_byte(v);
                        }
                    }
                }
                Operation::Read(buf) => {
                    for b in buf.iter_mut() {
                        *b = self.read_byte();
                    }
                }
            }
        }
        Ok(())
    }
}

impl crate::imu_sampler::BusRecovery for ReplayLsm6dsv320x {
    /// An emulated bus never sticks: nothing to clock free.
    fn recover_bus(&mut self) -> bool {
        false
    }
}

//! An emulated MPU6050 that answers on the I2C bus with a recorded trace.
//!
//! The emulated board has no sensor, so this stands in for one at the bus: it implements
//! embedded-hal's `I2c`, keeps a register file, answers `WHO_AM_I` with 0x68, accepts the
//! configuration writes, and serves the data registers (0x3B..=0x48) from a trace stored
//! in flash in the sensor's own big-endian register layout. A burst read that ends at
//! `GYRO_ZOUT_L` latches the next sample, as a new conversion would. The real driver runs
//! unchanged on top of it, so everything after the bus read is the code real hardware runs.
//!
//! It can also lose samples, as a sensor whose reads fail for a few periods does (a bus
//! glitch, a brown-out): every read of the data registers that would start a lost run fails,
//! as many times as the sampler tries in those periods, and the run's samples are skipped.
//! The replay firmware uses it to show that the pipeline bridges such holes on the board as
//! the host replay does.
//!
//! Board glue, not core: it is safe code but knows a storage format.

use embedded_hal::i2c::{self, ErrorKind, NoAcknowledgeSource, Operation, SevenBitAddress};

const WHO_AM_I: u8 = 0x75;
const DATA_FIRST: u8 = 0x3B;
const DATA_LAST: u8 = 0x48;
const INT_STATUS: u8 = 0x3A;
const DATA_RDY: u8 = 0x01;
const SAMPLE_BYTES: usize = 14;

/// Bus errors of the emulated sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayBusError {
    /// Nothing answers at that address.
    NoDevice,
    /// The trace has no samples left: the recording is over.
    Exhausted,
    /// The sample of this period is lost (the read is not acknowledged).
    Lost,
}

impl i2c::Error for ReplayBusError {
    fn kind(&self) -> ErrorKind {
        match self {
            ReplayBusError::NoDevice => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address),
            ReplayBusError::Exhausted => ErrorKind::Other,
            ReplayBusError::Lost => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Data),
        }
    }
}

/// Failed read attempts per lost sample period: the sampler's first try and its retries.
const ATTEMPTS_PER_PERIOD: u32 = crate::imu_sampler::RETRIES + 1;

/// The emulated sensor.
pub struct ReplayMpu6050 {
    address: u8,
    trace: &'static [u8],
    /// Byte offset of the current sample in `trace`.
    cursor: usize,
    regs: [u8; 128],
    pointer: u8,
    /// Runs of samples lost, `(first sample, samples)`, in order.
    lost: &'static [(u32, u32)],
    /// The next run of `lost` not yet reached.
    next_lost: usize,
    /// Read attempts still to fail in the run being lost, and its samples.
    failing: (u32, u32),
}

impl ReplayMpu6050 {
    /// A sensor at `address` (0x68 or 0x69) replaying `trace` (a whole number of 14-byte
    /// register blocks; a trailing partial block is ignored) and losing the runs of samples
    /// `lost` (`(first sample, samples)`, sorted, not overlapping).
    pub const fn new(address: u8, trace: &'static [u8], lost: &'static [(u32, u32)]) -> Self {
        let mut regs = [0u8; 128];
        regs[WHO_AM_I as usize] = 0x68;
        ReplayMpu6050 {
            address,
            trace,
            cursor: 0,
            regs,
            pointer: 0,
            lost,
            next_lost: 0,
            failing: (0, 0),
        }
    }

    /// Whether this read of the data registers fails because its sample is lost; the lost
    /// samples are skipped once every attempt for them has failed.
    fn loses_this_read(&mut self) -> bool {
        if self.failing.0 == 0 {
            let sample = (self.cursor / SAMPLE_BYTES) as u32;
            match self.lost.get(self.next_lost) {
                Some(&(first, n)) if first == sample && n > 0 => {
                    self.next_lost += 1;
                    self.failing = (n * ATTEMPTS_PER_PERIOD, n);
                }
                _ => return false,
            }
        }
        self.failing.0 -= 1;
        if self.failing.0 == 0 {
            self.cursor =
                (self.cursor + self.failing.1 as usize * SAMPLE_BYTES).min(self.trace.len());
        }
        true
    }

    /// Samples not yet read.
    pub const fn remaining(&self) -> usize {
        (self.trace.len() - self.cursor) / SAMPLE_BYTES
    }

    fn read_byte(&mut self) -> Result<u8, ReplayBusError> {
        let r = self.pointer;
        self.pointer = self.pointer.wrapping_add(1) & 0x7F;
        match r {
            DATA_FIRST..=DATA_LAST => {
                let off = self.cursor + (r - DATA_FIRST) as usize;
                let byte = match self.trace.get(off) {
                    Some(&b) if self.remaining() > 0 => b,
                    _ => return Err(ReplayBusError::Exhausted),
                };
                if r == DATA_LAST {
                    self.cursor += SAMPLE_BYTES;
                }
                Ok(byte)
            }
            INT_STATUS => Ok(if self.remaining() > 0 { DATA_RDY } else { 0 }),
            _ => Ok(self.regs[r as usize & 0x7F]),
        }
    }
}

impl i2c::ErrorType for ReplayMpu6050 {
    type Error = ReplayBusError;
}

impl i2c::I2c<SevenBitAddress> for ReplayMpu6050 {
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
                            if self.pointer != WHO_AM_I {
                                self.regs[self.pointer as usize] = v;
                            }
                            self.pointer = (self.pointer + 1) & 0x7F;
                        }
                    }
                }
                Operation::Read(buf) => {
                    if self.pointer == DATA_FIRST && self.loses_this_read() {
                        return Err(ReplayBusError::Lost);
                    }
                    for b in buf.iter_mut() {
                        *b = self.read_byte()?;
                    }
                }
            }
        }
        Ok(())
    }
}

impl crate::imu_sampler::BusRecovery for ReplayMpu6050 {
    /// An emulated bus cannot get stuck.
    fn recover_bus(&mut self) -> bool {
        false
    }
}

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
//! It can stand still for longer than the recording does ([`Still`]: a sample served again
//! for a run of periods, a shoe left on the floor), and it has the part's low-power cycle
//! mode: with `PWR_MGMT_1` CYCLE set, [`ReplayMpu6050::wake_tick`] is the accelerometer's
//! wake-up at the `LP_WAKE_CTRL` rate, on the sensor's own clock (periods in multiples of
//! the wake period since power-on, so where the sleep began does not move them). At each
//! wake-up it compares the sample with the one a wake period before ([`motion_between`],
//! a model of the part's high-passed motion test: the difference of two wake-up samples is
//! what a high-pass filter passes of a change within one wake period) and, when an axis
//! moved by more than `MOT_THR` (in the unit the emulated part follows,
//! [`REPLAY_MOTION_UNIT`]), latches `MOT` in `INT_STATUS` and raises INT. Time runs on
//! while the part sleeps: the periods it slept are skipped, as a real shoe's would be.
//!
//! Board glue, not core: it is safe code but knows a storage format.

use embedded_hal::i2c::{self, ErrorKind, NoAcknowledgeSource, Operation, SevenBitAddress};
use gaitclip_mpu6050::MotionThresholdUnit;

const WHO_AM_I: u8 = 0x75;
const DATA_FIRST: u8 = 0x3B;
const DATA_LAST: u8 = 0x48;
const INT_STATUS: u8 = 0x3A;
const INT_ENABLE: u8 = 0x38;
const ACCEL_CONFIG: u8 = 0x1C;
const MOT_THR: u8 = 0x1F;
const PWR_MGMT_1: u8 = 0x6B;
const PWR_MGMT_2: u8 = 0x6C;
const DATA_RDY: u8 = 0x01;
const MOT: u8 = 0x40;
const CYCLE: u8 = 0x20;
const SAMPLE_BYTES: usize = 14;

/// The MOT_THR unit the emulated part follows: the product specification's 32 mg per count
/// (PS-MPU-6000A-00 rev 3.4, §6.2).
pub const REPLAY_MOTION_UNIT: MotionThresholdUnit = MotionThresholdUnit::Mg32;

/// A run of periods in which the emulated sensor serves one sample of the trace again:
/// `(sample, periods)` holds the trace's sample `sample` (an index into the recording) for
/// `periods` periods more before going on with the next.
pub type Still = (u32, u32);

/// Whether a wake-up's accelerometer counts `now` moved from the previous wake-up's `before`
/// by more than `threshold` counts on an axis: the emulated part's motion test (shared with
/// the host model of the sleeping firmware).
pub const fn motion_between(before: [i16; 3], now: [i16; 3], threshold: i32) -> bool {
    let mut k = 0;
    while k < 3 {
        let d = now[k] as i32 - before[k] as i32;
        if d > threshold || -d > threshold {
            return true;
        }
        k += 1;
    }
    false
}

/// The counts of `mg` at the accelerometer range `afs_sel`.
pub const fn mg_to_counts(mg: u32, afs_sel: u8) -> i32 {
    ((mg as i64 * (16_384i64 >> (afs_sel & 3))) / 1000) as i32
}

/// Sample periods per wake-up of the low-power cycle mode for `LP_WAKE_CTRL` = `lp` at a
/// trace rate of `rate_millihertz` (1.25, 5, 20, 40 Hz).
pub const fn periods_per_wake(rate_millihertz: u32, lp: u8) -> u32 {
    let wake_mhz = match lp & 3 {
        0 => 1250,
        1 => 5000,
        2 => 20_000,
        _ => 40_000,
    };
    let p = rate_millihertz / wake_mhz;
    if p == 0 {
        1
    } else {
        p
    }
}

/// What one wake-up of the cycle mode found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WakeTick {
    /// Still: the part sleeps on.
    Still,
    /// Motion: `MOT` latched, INT raised (if the motion interrupt is enabled).
    Motion,
    /// The recording ended while the part slept.
    Ended,
    /// Not in cycle mode: nothing happened.
    Awake,
}

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
    /// The trace's sample rate, mHz (the cycle mode's wake period follows it).
    rate_millihertz: u32,
    /// Period of the next sample, counting the held ones ([`Still`]) and the ones skipped.
    pos: u32,
    /// Runs of periods holding one sample, sorted.
    still: &'static [Still],
    /// `pos` when the part entered its cycle mode.
    cycle_from: u32,
    /// `MOT` latched, until `INT_STATUS` is read.
    motion_latched: bool,
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
    /// `lost` (`(first period, periods)`, sorted, not overlapping).
    pub const fn new(address: u8, trace: &'static [u8], lost: &'static [(u32, u32)]) -> Self {
        Self::with_still(address, trace, 200_000, &[], lost)
    }

    /// [`ReplayMpu6050::new`] for a trace sampled at `rate_millihertz` that also holds still
    /// for the runs `still` (sorted by sample); `lost` counts periods, held ones included.
    pub const fn with_still(
        address: u8,
        trace: &'static [u8],
        rate_millihertz: u32,
        still: &'static [Still],
        lost: &'static [(u32, u32)],
    ) -> Self {
        let mut regs = [0u8; 128];
        regs[WHO_AM_I as usize] = 0x68;
        ReplayMpu6050 {
            address,
            trace,
            rate_millihertz,
            pos: 0,
            still,
            cycle_from: 0,
            motion_latched: false,
            regs,
            pointer: 0,
            lost,
            next_lost: 0,
            failing: (0, 0),
        }
    }

    /// Periods the replay lasts: the trace's samples and the held ones.
    pub const fn periods(&self) -> u32 {
        let mut n = (self.trace.len() / SAMPLE_BYTES) as u32;
        let mut k = 0;
        while k < self.still.len() {
            n = n.saturating_add(self.still[k].1);
            k += 1;
        }
        n
    }

    /// The trace's sample served at period `pos`, if the replay lasts that long.
    pub const fn sample_at(&self, pos: u32) -> Option<usize> {
        let mut p = pos;
        let mut k = 0;
        while k < self.still.len() {
            let (at, extra) = self.still[k];
            if p <= at {
                break;
            }
            if p <= at.saturating_add(extra) {
                p = at;
                break;
            }
            p -= extra;
            k += 1;
        }
        if (p as usize) < self.trace.len() / SAMPLE_BYTES {
            Some(p as usize)
        } else {
            None
        }
    }

    /// The period of the next sample.
    pub const fn position(&self) -> u32 {
        self.pos
    }

    /// Periods since the part entered its cycle mode (what the board's low-power clock
    /// counts while it sleeps).
    pub const fn periods_in_cycle(&self) -> u32 {
        self.pos.saturating_sub(self.cycle_from)
    }

    fn accel_at(&self, pos: u32) -> Option<[i16; 3]> {
        let off = match self.sample_at(pos) {
            Some(i) => i * SAMPLE_BYTES,
            None => return None,
        };
        let t = self.trace;
        let be = |k: usize| i16::from_be_bytes([t[off + 2 * k], t[off + 2 * k + 1]]);
        Some([be(0), be(1), be(2)])
    }

    /// One wake-up of the low-power cycle mode: the first period at or after the next
    /// sample's that is a multiple of the wake period; the samples before it are skipped.
    pub fn wake_tick(&mut self) -> WakeTick {
        if self.regs[PWR_MGMT_1 as usize] & CYCLE == 0 {
            return WakeTick::Awake;
        }
        let period = periods_per_wake(self.rate_millihertz, self.regs[PWR_MGMT_2 as usize] >> 6);
        let t = self.pos.div_ceil(period).saturating_mul(period);
        let (Some(now), Some(before)) = (self.accel_at(t), self.accel_at(t.saturating_sub(period)))
        else {
            self.pos = self.periods();
            return WakeTick::Ended;
        };
        self.pos = t + 1;
        let unit = REPLAY_MOTION_UNIT.mg_per_count();
        let mg = self.regs[MOT_THR as usize] as u32 * unit;
        let threshold = mg_to_counts(mg, self.regs[ACCEL_CONFIG as usize] >> 3);
        let armed = self.regs[INT_ENABLE as usize] & MOT != 0;
        if armed && t >= period && motion_between(before, now, threshold) {
            self.motion_latched = true;
            return WakeTick::Motion;
        }
        WakeTick::Still
    }

    /// Whether this read of the data registers fails because its sample is lost; the lost
    /// samples are skipped once every attempt for them has failed.
    fn loses_this_read(&mut self) -> bool {
        if self.failing.0 == 0 {
            let sample = self.pos;
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
            self.pos = self.pos.saturating_add(self.failing.1).min(self.periods());
        }
        true
    }

    /// Samples not yet read.
    pub const fn remaining(&self) -> usize {
        self.periods().saturating_sub(self.pos) as usize
    }

    fn read_byte(&mut self) -> Result<u8, ReplayBusError> {
        let r = self.pointer;
        self.pointer = self.pointer.wrapping_add(1) & 0x7F;
        match r {
            DATA_FIRST..=DATA_LAST => {
                let byte = match self.sample_at(self.pos) {
                    Some(i) => self.trace[i * SAMPLE_BYTES + (r - DATA_FIRST) as usize],
                    None => return Err(ReplayBusError::Exhausted),
                };
                if r == DATA_LAST {
                    self.pos += 1;
                }
                Ok(byte)
            }
            INT_STATUS => {
                let ready = if self.remaining() > 0 { DATA_RDY } else { 0 };
                let motion = if core::mem::take(&mut self.motion_latched) {
                    MOT
                } else {
                    0
                };
                Ok(ready | motion)
            }
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
                            if self.pointer == PWR_MGMT_1
                                && v & CYCLE != 0
                                && self.regs[PWR_MGMT_1 as usize] & CYCLE == 0
                            {
                                self.cycle_from = self.pos;
                            }
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

//! Every configuration sequence as data: a `const fn` builds the register steps, and the
//! blocking and async drivers only run them ([`crate::blocking`], [`crate::asynch`]), so the
//! two cannot drift apart. The FIFO's bookkeeping is here too, as pure functions.

use crate::register::{bits, reg, FIFO_CAPACITY_BYTES, RESET_DELAY_MS};
use crate::sample::SAMPLE_BYTES;
use crate::settings::{Config, MotionWakeConfig};
use crate::AccelRange;

pub use gaitclip_regbus::Step;

const fn w(reg: u8, value: u8) -> Step {
    Step::Write { reg, value }
}

/// Probes, resets, waits [`RESET_DELAY_MS`], wakes with the gyro PLL clock and applies
/// `config`: rate divider, the widest DLPF under Nyquist, both ranges.
pub const fn init(config: &Config) -> [Step; 8] {
    [
        Step::Identify,
        w(reg::PWR_MGMT_1, bits::DEVICE_RESET),
        Step::WaitMs(RESET_DELAY_MS),
        w(reg::PWR_MGMT_1, bits::CLKSEL_PLL_XGYRO),
        w(reg::SMPLRT_DIV, config.rate.divider()),
        w(reg::CONFIG, config.rate.dlpf_cfg()),
        w(reg::GYRO_CONFIG, config.gyro.fs_sel() << 3),
        w(reg::ACCEL_CONFIG, config.accel.afs_sel() << 3),
    ]
}

/// INT on data ready (and FIFO overflow), latched until any register read.
pub const DATA_READY_INTERRUPT: [Step; 2] = [
    w(reg::INT_PIN_CFG, bits::INT_LATCH_ANY_READ_CLEAR),
    w(reg::INT_ENABLE, bits::DATA_RDY | bits::FIFO_OFLOW),
];

/// INT pulsed (50 µs, active high) on every data ready, without latching: for reading the
/// FIFO in bursts, where most pulses are only counted and no register is read to clear a
/// latch. A FIFO overflow is found from `INT_STATUS` when the FIFO is read.
pub const DATA_READY_PULSE: [Step; 2] =
    [w(reg::INT_PIN_CFG, 0), w(reg::INT_ENABLE, bits::DATA_RDY)];

/// Resets and enables the FIFO with accel, temperature and gyro (14 bytes a sample).
pub const ENABLE_FIFO: [Step; 3] = [
    w(reg::USER_CTRL, bits::USER_FIFO_RESET),
    w(reg::FIFO_EN, bits::FIFO_ALL),
    w(reg::USER_CTRL, bits::USER_FIFO_EN),
];

/// Empties the FIFO and keeps it enabled (after an overflow or a misaligned count).
pub const RESET_FIFO: [Step; 1] = [w(
    reg::USER_CTRL,
    bits::USER_FIFO_RESET | bits::USER_FIFO_EN,
)];

/// The low-power wait for motion: stops the data-ready interrupt and the FIFO, sets the
/// accelerometer's 5 Hz high-pass filter (what the motion detector compares) and the
/// threshold (read back: a part that does not keep it must not be trusted to wake the clip)
/// and duration, latches INT on motion (a level the MCU cannot miss while it sleeps), puts
/// the gyro in standby and the temperature sensor off, and cycles the accelerometer at
/// `wake.rate` on the internal oscillator (the gyro's PLL is off). `accel` is the range kept.
pub const fn enter_motion_wake(wake: &MotionWakeConfig, accel: AccelRange) -> [Step; 11] {
    let counts = wake.threshold.counts();
    [
        w(reg::INT_ENABLE, 0),
        w(reg::USER_CTRL, 0),
        w(reg::FIFO_EN, 0),
        w(
            reg::ACCEL_CONFIG,
            accel.afs_sel() << 3 | bits::ACCEL_HPF_5HZ,
        ),
        w(reg::MOT_THR, counts),
        Step::Check {
            reg: reg::MOT_THR,
            value: counts,
        },
        w(reg::MOT_DUR, wake.duration_ms),
        w(reg::INT_PIN_CFG, bits::INT_LATCH_ANY_READ_CLEAR),
        w(reg::INT_ENABLE, bits::MOT),
        w(
            reg::PWR_MGMT_2,
            wake.rate.lp_wake_ctrl() << 6 | bits::STBY_GYRO,
        ),
        w(reg::PWR_MGMT_1, bits::CYCLE | bits::TEMP_DIS),
    ]
}

/// Back to full 6-axis sampling with `config`'s ranges: the gyro's PLL clock and the
/// temperature sensor on, cycle off, every axis out of standby, the high-pass filter off,
/// the motion interrupt off and its latch cleared. The caller then enables its interrupt and
/// FIFO again, as after [`init`]; the gyro needs its start-up time (datasheet §6.1: 30 ms)
/// before its samples settle.
pub const fn leave_motion_wake(config: &Config) -> [Step; 5] {
    [
        w(reg::PWR_MGMT_1, bits::CLKSEL_PLL_XGYRO),
        w(reg::PWR_MGMT_2, 0),
        w(reg::ACCEL_CONFIG, config.accel.afs_sel() << 3),
        w(reg::INT_ENABLE, 0),
        Step::Read {
            reg: reg::INT_STATUS,
        },
    ]
}

/// What a FIFO byte count says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FifoCount {
    /// This many whole samples wait.
    Samples(usize),
    /// The FIFO is full: the oldest samples are gone and the stream is misaligned.
    Overflow,
    /// Not a whole number of samples.
    Misaligned(u16),
}

/// Reads a `FIFO_COUNT` value: a full FIFO has overflowed (the part stops at
/// [`FIFO_CAPACITY_BYTES`]), a count that is not a multiple of 14 is misaligned.
pub const fn fifo_count(bytes: u16) -> FifoCount {
    if bytes >= FIFO_CAPACITY_BYTES {
        FifoCount::Overflow
    } else if bytes as usize % SAMPLE_BYTES != 0 {
        FifoCount::Misaligned(bytes)
    } else {
        FifoCount::Samples(bytes as usize / SAMPLE_BYTES)
    }
}

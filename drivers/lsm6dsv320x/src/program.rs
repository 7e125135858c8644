//! Every configuration sequence as data: a `const fn` builds the register steps and the
//! driver ([`crate::blocking`], [`crate::asynch`], one source) only runs them, so the tests
//! can read each sequence as the bus sees it.

use crate::register::{bits, reg, RESET_WAIT_MS};
use crate::settings::{Config, MotionWakeConfig};

pub use gaitclip_regbus::Step;

const fn w(reg: u8, value: u8) -> Step {
    Step::Write { reg, value }
}

/// `CTRL1` / `CTRL2`: `odr` in high-performance mode.
const fn sampling_odr(config: &Config) -> u8 {
    config.odr.field() | (bits::OP_MODE_HIGH_PERFORMANCE << 4)
}

/// `CTRL1_XL_HG`: the high-g range and rate, or off.
const fn high_g_ctrl(config: &Config) -> u8 {
    match config.high_g {
        Some(h) => h.range.field() | (h.odr.field() << 3),
        None => 0,
    }
}

/// Probes; powers the three channels down and resets as ST's procedure does (power-down,
/// `SW_RESET`, wait, `SW_RESET` clear); then both ranges, both rates in high-performance
/// mode, and the high-g channel last (it runs only once the low-g one is in
/// high-performance mode).
pub const fn init(config: &Config) -> [Step; 12] {
    [
        Step::Identify,
        w(reg::CTRL1, bits::OP_MODE_XL_NORMAL << 4),
        w(reg::CTRL2, bits::OP_MODE_G_LOW_POWER << 4),
        w(reg::CTRL1_XL_HG, 0),
        w(reg::CTRL3, bits::BDU | bits::IF_INC | bits::SW_RESET),
        Step::WaitMs(RESET_WAIT_MS),
        Step::Check {
            reg: reg::CTRL3,
            value: bits::BDU | bits::IF_INC,
        },
        w(reg::CTRL6, bits::CTRL6_RESERVED | config.gyro.field()),
        w(reg::CTRL8, config.accel.field()),
        w(reg::CTRL1, sampling_odr(config)),
        w(reg::CTRL2, sampling_odr(config)),
        w(reg::CTRL1_XL_HG, high_g_ctrl(config)),
    ]
}

/// Empties the FIFO (bypass), sets the watermark and batch rates (the high-g channel at its
/// own rate when it is on), continuous mode, and the watermark and overrun on INT1.
pub const fn enable_fifo(config: &Config) -> [Step; 6] {
    let bdr = config.odr.field();
    [
        w(reg::FIFO_CTRL4, bits::FIFO_MODE_BYPASS),
        w(reg::FIFO_CTRL1, config.watermark_words),
        w(reg::FIFO_CTRL3, bdr | (bdr << 4)),
        w(
            reg::COUNTER_BDR_REG1,
            if config.high_g.is_some() {
                bits::XL_HG_BATCH_EN
            } else {
                0
            },
        ),
        w(reg::FIFO_CTRL4, bits::FIFO_MODE_CONTINUOUS),
        w(reg::INT1_CTRL, bits::INT1_FIFO_TH | bits::INT1_FIFO_OVR),
    ]
}

/// Empties the FIFO and keeps it on (after an overrun).
pub const RESET_FIFO: [Step; 2] = [
    w(reg::FIFO_CTRL4, bits::FIFO_MODE_BYPASS),
    w(reg::FIFO_CTRL4, bits::FIFO_MODE_CONTINUOUS),
];

/// INT1 quiet, the FIFO off, the high-g channel and the gyroscope off, the low-g
/// accelerometer alone in low-power mode at `wake.odr`, the wake-up threshold, latched
/// interrupts, the basic interrupts on, wake-up on INT1, and a read of `ALL_INT_SRC` to
/// clear anything latched before.
pub const fn enter_motion_wake(wake: &MotionWakeConfig) -> [Step; 12] {
    [
        w(reg::INT1_CTRL, 0),
        w(reg::FIFO_CTRL4, bits::FIFO_MODE_BYPASS),
        w(reg::CTRL1_XL_HG, 0),
        w(reg::CTRL2, 0),
        w(
            reg::CTRL1,
            wake.odr.field() | (bits::OP_MODE_XL_LOW_POWER_2_MEAN << 4),
        ),
        w(
            reg::INACTIVITY_DUR,
            bits::XL_INACT_ODR_RESET | ((wake.weight_code & 0b111) << 4),
        ),
        w(reg::WAKE_UP_THS, wake.threshold_counts & 0x3F),
        w(reg::WAKE_UP_DUR, 0),
        w(reg::TAP_CFG0, bits::LIR),
        w(reg::FUNCTIONS_ENABLE, bits::INTERRUPTS_ENABLE),
        w(reg::MD1_CFG, bits::INT1_WU),
        Step::Read {
            reg: reg::ALL_INT_SRC,
        },
    ]
}

/// Wake-up off INT1, the basic interrupts and the latch off, then `config`'s rates back
/// (low-g and gyroscope before the high-g channel); the FIFO follows ([`enable_fifo`]).
pub const fn leave_motion_wake(config: &Config) -> [Step; 6] {
    [
        w(reg::MD1_CFG, 0),
        w(reg::FUNCTIONS_ENABLE, 0),
        w(reg::TAP_CFG0, 0),
        w(reg::CTRL1, sampling_odr(config)),
        w(reg::CTRL2, sampling_odr(config)),
        w(reg::CTRL1_XL_HG, high_g_ctrl(config)),
    ]
}

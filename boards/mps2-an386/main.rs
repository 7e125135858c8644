//! gaitclip on the emulated board: QEMU `mps2-an386` (Cortex-M4F).
//!
//! TIMER0 stands in for the MPU6050's INT pin, interrupting at the trace's sample rate; the
//! rest is the shared replay firmware (`replay_app`, or `replay_lsm_app` with the
//! `replay-lsm6dsv320x` feature): the real driver reads an emulated
//! sensor that replays a trace from flash, the pipeline runs in the main loop, strides are
//! logged over defmt (semihosting) and QEMU exits with the firmware's status.

#![no_std]
#![no_main]

mod cmsdk_timer;

use gaitclip_board::Steps;

/// The replay firmware: the demo walk through the emulated MPU6050, or with the
/// `replay-lsm6dsv320x` feature the sprint through the emulated LSM6DSV320X's FIFO.
#[cfg(not(feature = "replay-lsm6dsv320x"))]
use gaitclip_board::replay_app as app;
#[cfg(feature = "replay-lsm6dsv320x")]
use gaitclip_board::replay_lsm_app as app;

use cortex_m_rt::{entry, exception};
use defmt_semihosting as _;

use cmsdk_timer::CmsdkTimer;
use gaitclip::pipeline::Pipeline;
use static_cell::ConstStaticCell;

/// The MPS2 core clock, 25 MHz.
const CYCLES_PER_US: u32 = 25;

/// The pipeline, built at compile time into .data: no copy of it ever sits on the stack
/// (moving 8–12 KiB through the stack is more than a 16 KiB part can spare), and the stack
/// holds only what one sample's processing needs.
static PIPELINE: ConstStaticCell<Pipeline<Steps<{ app::MOVEMENT_SAMPLES }>>> = ConstStaticCell::new(
    Pipeline::with_detector(app::CONFIG, Steps::new(&app::CONFIG.detect())),
);

#[entry]
fn main() -> ! {
    app::run::<_, CmsdkTimer>(PIPELINE.take(), "mps2-an386", CYCLES_PER_US)
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    app::on_interrupt::<CmsdkTimer>(irqn);
}

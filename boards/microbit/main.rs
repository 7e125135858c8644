//! gaitclip on the emulated Cortex-M0: QEMU `microbit` (nRF51822, ARMv6-M, no FPU).
//!
//! The nRF51's TIMER0 stands in for the MPU6050's INT pin, interrupting at the trace's sample rate; the
//! rest is the shared replay firmware ([`replay_app`]): the real driver reads an emulated
//! sensor that replays a trace from flash, the pipeline runs in the main loop, strides are
//! logged over defmt (semihosting) and QEMU exits with the firmware's status.

#![no_std]
#![no_main]

mod nrf51_timer;

use gaitclip_board::{replay_app, Steps};

use cortex_m_rt::{entry, exception};
use defmt_semihosting as _;

use gaitclip::pipeline::Pipeline;
use nrf51_timer::Nrf51Timer;
use static_cell::ConstStaticCell;

/// The nRF51 core clock, 16 MHz.
const CYCLES_PER_US: u32 = 16;
/// Movement buffer, samples: 1.12 s at 200 Hz (1.75 KiB), so that the pipeline (≈ 8 KiB,
/// the step check's ledger among it) and the stack fit the nRF51's 16 KiB of RAM; 256 no
/// longer leaves the stack its margin since the ledger came (measured: 8 bytes to spare),
/// 320 overflows into flip-link's guard at the first stride. Walking movements last 0.5–1 s;
/// the demo trace's turns last longer, and their heel-strikes come from the 224 samples kept
/// (the host replay with the same buffer gives the same strides: `firmware_qemu`).
const MOVEMENT_SAMPLES: usize = 224;

/// The pipeline, built at compile time into .data: no copy of it ever sits on the stack
/// (moving 8–12 KiB through the stack is more than a 16 KiB part can spare), and the stack
/// holds only what one sample's processing needs.
static PIPELINE: ConstStaticCell<Pipeline<Steps<MOVEMENT_SAMPLES>>> = ConstStaticCell::new(
    Pipeline::with_detector(replay_app::CONFIG, Steps::new(&replay_app::CONFIG.detect())),
);

#[entry]
fn main() -> ! {
    replay_app::run::<_, Nrf51Timer>(PIPELINE.take(), "microbit", CYCLES_PER_US)
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    replay_app::on_interrupt::<Nrf51Timer>(irqn);
}

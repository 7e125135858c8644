//! gaitclip on the emulated board: QEMU `mps2-an386` (Cortex-M4F).
//!
//! TIMER0 stands in for the MPU6050's INT pin, interrupting at the trace's sample rate; the
//! rest is the shared replay firmware ([`replay_app`]): the real driver reads an emulated
//! sensor that replays a trace from flash, the pipeline runs in the main loop, strides are
//! logged over defmt (semihosting) and QEMU exits with the firmware's status.

#![no_std]
#![no_main]

mod cmsdk_timer;

use gaitclip_board::{replay_app, Steps};

use cortex_m::peripheral::NVIC;
use cortex_m_rt::{entry, exception};
use defmt_semihosting as _;
use gaitclip::stride::MAX_MOVEMENT_SAMPLES;

use cmsdk_timer::{CmsdkTimer, TIMER0_BASE, TIMER0_IRQ};
use gaitclip::pipeline::Pipeline;
use replay_app::{Irq, SampleTimer};
use static_cell::ConstStaticCell;

/// The MPS2 core clock, 25 MHz.
const CYCLES_PER_US: u32 = 25;

impl SampleTimer for CmsdkTimer {
    fn start_periodic(&self, millihertz: u32) {
        CmsdkTimer::start_periodic(self, millihertz);
    }
    fn stop(&self) {
        CmsdkTimer::stop(self);
    }
    fn clear_interrupt(&self) {
        CmsdkTimer::clear_interrupt(self);
    }
}

/// The pipeline, built at compile time into .data: no copy of it ever sits on the stack
/// (moving 8–12 KiB through the stack is more than a 16 KiB part can spare), and the stack
/// holds only what one sample's processing needs.
static PIPELINE: ConstStaticCell<Pipeline<Steps<MAX_MOVEMENT_SAMPLES>>> = ConstStaticCell::new(
    Pipeline::with_detector(replay_app::CONFIG, Steps::new(&replay_app::CONFIG)),
);

#[entry]
fn main() -> ! {
    // Note(unsafe): TIMER0 is driven only through this value, from here and its handler.
    let timer = unsafe { CmsdkTimer::new(TIMER0_BASE) };
    let pipeline = PIPELINE.take();
    replay_app::run(pipeline, "mps2-an386", CYCLES_PER_US, &timer, || {
        // Note(unsafe): the handler only touches state behind `Mutex`es and atomics, so
        // unmasking cannot break a critical section.
        unsafe { NVIC::unmask(Irq(TIMER0_IRQ)) }
    })
}

#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == TIMER0_IRQ as i16 {
        // Note(unsafe): TIMER0 is only acknowledged and stopped here; `main` only started it.
        replay_app::on_timer_interrupt(&unsafe { CmsdkTimer::new(TIMER0_BASE) });
    }
}

//! TIMER0 of the nRF51 (nRF51 Series Reference Manual v3.0 §18), as QEMU's `microbit`
//! machine models it: a 16 MHz timer with a prescaler and compare registers.

use gaitclip_board::registers::Registers;
use gaitclip_board::replay_app::SampleTimer;

/// TIMER0 base address.
pub const TIMER0_BASE: usize = 0x4000_8000;
/// TIMER0's interrupt number.
pub const TIMER0_IRQ: u16 = 8;

const TASKS_START: usize = 0x000;
const TASKS_STOP: usize = 0x004;
const TASKS_CLEAR: usize = 0x00C;
const EVENTS_COMPARE0: usize = 0x140;
const SHORTS: usize = 0x200;
const INTENSET: usize = 0x304;
const MODE: usize = 0x504;
const BITMODE: usize = 0x508;
const PRESCALER: usize = 0x510;
const CC0: usize = 0x540;
/// SHORTS: COMPARE[0] clears the counter, so CC[0] is the period.
const COMPARE0_CLEAR: u32 = 1 << 0;
/// INTENSET: COMPARE[0].
const INT_COMPARE0: u32 = 1 << 16;
/// BITMODE: 32 bit.
const BITMODE_32: u32 = 3;
/// PRESCALER 4: 16 MHz / 2⁴ = 1 MHz, 1 µs per tick.
const PRESCALER_1MHZ: u32 = 4;

/// TIMER0, the sample timer.
pub struct Nrf51Timer(Registers);

impl SampleTimer for Nrf51Timer {
    const IRQ: u16 = TIMER0_IRQ;

    unsafe fn steal() -> Self {
        // Note(unsafe): TIMER0_BASE is TIMER0's register block; `replay_app` drives it
        // through one value at a time, the handler only acknowledging events (the trait's
        // contract).
        Nrf51Timer(unsafe { Registers::new(TIMER0_BASE) })
    }

    /// Periodic COMPARE[0] interrupts at `millihertz` (1 µs resolution).
    fn start_periodic(&self, millihertz: u32) {
        let period_us = (1_000_000_000u64 / millihertz.max(1) as u64).max(1) as u32;
        self.0.write(TASKS_STOP, 1);
        self.0.write(MODE, 0);
        self.0.write(BITMODE, BITMODE_32);
        self.0.write(PRESCALER, PRESCALER_1MHZ);
        self.0.write(CC0, period_us);
        self.0.write(SHORTS, COMPARE0_CLEAR);
        self.0.write(INTENSET, INT_COMPARE0);
        self.0.write(TASKS_CLEAR, 1);
        self.0.write(TASKS_START, 1);
    }

    fn stop(&self) {
        self.0.write(TASKS_STOP, 1);
    }

    /// Acknowledges the COMPARE[0] event.
    fn clear_interrupt(&self) {
        self.0.write(EVENTS_COMPARE0, 0);
    }
}

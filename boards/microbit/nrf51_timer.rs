//! TIMER0 of the nRF51 (nRF51 Series Reference Manual v3.0 §18), as QEMU's `microbit`
//! machine models it: a 16 MHz timer with a prescaler and compare registers.

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

/// One nRF51 timer.
pub struct Nrf51Timer {
    base: usize,
}

impl Nrf51Timer {
    /// The timer at `base`.
    ///
    /// # Safety
    /// `base` must be a TIMER of this device, driven through no other value at the same
    /// time (two values may exist when one only acknowledges events, as the handler does).
    pub const unsafe fn new(base: usize) -> Self {
        Nrf51Timer { base }
    }

    fn write(&self, offset: usize, value: u32) {
        // Note(unsafe): `base + offset` is a register of this timer (see `new`), and a
        // volatile write is how the peripheral is meant to be driven.
        unsafe { core::ptr::write_volatile((self.base + offset) as *mut u32, value) }
    }

    /// Periodic COMPARE[0] interrupts at `millihertz` (1 µs resolution).
    pub fn start_periodic(&self, millihertz: u32) {
        let period_us = (1_000_000_000u64 / millihertz.max(1) as u64).max(1) as u32;
        self.write(TASKS_STOP, 1);
        self.write(MODE, 0);
        self.write(BITMODE, BITMODE_32);
        self.write(PRESCALER, PRESCALER_1MHZ);
        self.write(CC0, period_us);
        self.write(SHORTS, COMPARE0_CLEAR);
        self.write(INTENSET, INT_COMPARE0);
        self.write(TASKS_CLEAR, 1);
        self.write(TASKS_START, 1);
    }

    /// Stops the timer.
    pub fn stop(&self) {
        self.write(TASKS_STOP, 1);
    }

    /// Acknowledges the COMPARE[0] event.
    pub fn clear_interrupt(&self) {
        self.write(EVENTS_COMPARE0, 0);
    }
}

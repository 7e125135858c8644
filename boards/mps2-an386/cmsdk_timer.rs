//! The CMSDK APB timer of the MPS2 FPGA images (ARM DDI 0479C §4.4), as QEMU models it.

use gaitclip_board::registers::Registers;
use gaitclip_board::replay_app::SampleTimer;

/// TIMER0 base address on AN385/AN386.
pub const TIMER0_BASE: usize = 0x4000_0000;
/// TIMER0's interrupt number (external IRQ 8 on AN385/AN386).
pub const TIMER0_IRQ: u16 = 8;
/// The timer's clock: the MPS2 peripheral clock, 25 MHz.
pub const PCLK_HZ: u64 = 25_000_000;

const CTRL: usize = 0x00;
const RELOAD: usize = 0x08;
const VALUE: usize = 0x04;
const INTCLEAR: usize = 0x0C;
const CTRL_ENABLE: u32 = 1 << 0;
const CTRL_IRQ_ENABLE: u32 = 1 << 3;

/// TIMER0, the sample timer.
pub struct CmsdkTimer(Registers);

impl SampleTimer for CmsdkTimer {
    const IRQ: u16 = TIMER0_IRQ;

    unsafe fn steal() -> Self {
        // Note(unsafe): TIMER0_BASE is TIMER0's register block; `replay_app` drives it
        // through one value at a time (the trait's contract).
        CmsdkTimer(unsafe { Registers::new(TIMER0_BASE) })
    }

    /// Starts periodic interrupts at `rate_millihertz` (the period is rounded to whole clock
    /// cycles: 125 000 cycles at 200 Hz, exact).
    fn start_periodic(&self, rate_millihertz: u32) {
        let cycles = (PCLK_HZ * 1000 + rate_millihertz as u64 / 2) / rate_millihertz.max(1) as u64;
        let reload = cycles.saturating_sub(1).min(u32::MAX as u64) as u32;
        self.0.write(CTRL, 0);
        self.0.write(RELOAD, reload);
        self.0.write(VALUE, reload);
        self.0.write(INTCLEAR, 1);
        self.0.write(CTRL, CTRL_ENABLE | CTRL_IRQ_ENABLE);
    }

    fn clear_interrupt(&self) {
        self.0.write(INTCLEAR, 1);
    }

    fn stop(&self) {
        self.0.write(CTRL, 0);
    }
}

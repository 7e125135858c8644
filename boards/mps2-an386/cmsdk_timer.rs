//! The CMSDK APB timer of the MPS2 FPGA images (ARM DDI 0479C §4.4), as QEMU models it.

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

/// One CMSDK timer.
pub struct CmsdkTimer {
    base: usize,
}

impl CmsdkTimer {
    /// The timer at `base`.
    ///
    /// # Safety
    /// `base` must be the address of a CMSDK APB timer that nothing else drives.
    pub const unsafe fn new(base: usize) -> Self {
        CmsdkTimer { base }
    }

    fn write(&self, offset: usize, v: u32) {
        // Note(unsafe): `base` is a CMSDK timer owned by this value (constructor contract);
        // the offsets are its documented 32-bit registers.
        unsafe { core::ptr::write_volatile((self.base + offset) as *mut u32, v) }
    }

    /// Starts periodic interrupts at `rate_millihertz` (the period is rounded to whole clock
    /// cycles: 125 000 cycles at 200 Hz, exact).
    pub fn start_periodic(&self, rate_millihertz: u32) {
        let cycles = (PCLK_HZ * 1000 + rate_millihertz as u64 / 2) / rate_millihertz.max(1) as u64;
        let reload = cycles.saturating_sub(1).min(u32::MAX as u64) as u32;
        self.write(CTRL, 0);
        self.write(RELOAD, reload);
        self.write(VALUE, reload);
        self.write(INTCLEAR, 1);
        self.write(CTRL, CTRL_ENABLE | CTRL_IRQ_ENABLE);
    }

    /// Acknowledges the interrupt.
    pub fn clear_interrupt(&self) {
        self.write(INTCLEAR, 1);
    }

    /// Stops the timer.
    pub fn stop(&self) {
        self.write(CTRL, 0);
    }
}

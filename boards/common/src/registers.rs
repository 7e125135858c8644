//! A block of 32-bit memory-mapped registers: the one place the QEMU boards' timer drivers
//! write to their peripherals.

/// The registers of one peripheral at `base`.
pub struct Registers {
    base: usize,
}

impl Registers {
    /// The peripheral at `base`.
    ///
    /// # Safety
    /// `base` must be the address of a peripheral whose registers are 32-bit words at the
    /// offsets written, driven through no other value in a way that conflicts.
    pub const unsafe fn new(base: usize) -> Self {
        Registers { base }
    }

    /// Writes `value` to the register at `offset`.
    pub fn write(&self, offset: usize, value: u32) {
        // Note(unsafe): `base + offset` is a register of this peripheral (the constructor's
        // contract), and a volatile write is how a peripheral is meant to be driven.
        unsafe { core::ptr::write_volatile((self.base + offset) as *mut u32, value) }
    }
}

//! The stack's high-water mark: cortex-m-rt paints the whole stack region with
//! [`STACK_PAINT_VALUE`] at reset (its `paint-stack` feature); the deepest word no longer
//! painted is as far as the stack ever grew. A measurement, not a bound: it holds for the
//! paths this run took (the QEMU boards replay a whole walk, every stride path included).

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    /// Top of the stack (it grows down from here), from cortex-m-rt's linker script.
    static _stack_start: u32;
    /// Bottom of the stack region (flip-link puts it at the start of RAM).
    static _stack_end: u32;
}

/// Bytes of stack used so far, and the size of the stack region.
pub fn used_and_size() -> (u32, u32) {
    let top = core::ptr::addr_of!(_stack_start) as usize;
    let bottom = core::ptr::addr_of!(_stack_end) as usize;
    let mut p = bottom;
    while p < top {
        // Note(unsafe): `bottom..top` is the stack region the linker script reserves,
        // word aligned and mapped RAM; reading a word of it (painted or in use) is sound.
        if unsafe { core::ptr::read_volatile(p as *const u32) } != STACK_PAINT_VALUE {
            break;
        }
        p += 4;
    }
    ((top - p) as u32, (top - bottom) as u32)
}

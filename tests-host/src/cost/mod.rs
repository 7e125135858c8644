//! What the firmware costs: QEMU runs, instruction counts, sizes, energy.

pub mod energy;
pub mod firmware;
pub mod insn_count;
pub mod qemu;
pub mod report;

//! Host tools for gaitclip: read CSV and MCAP traces, replay them through the same
//! `no_std` core the firmware runs, simulate gait fixtures with ground truth, and run the
//! firmware in QEMU with its defmt log decoded.

pub mod cost;
pub mod eval;
pub mod fuzzing;
pub mod io;
pub mod reference;
pub mod sim;
pub mod train;

pub mod pod;
pub mod progress;
pub mod replay;
pub mod stream;

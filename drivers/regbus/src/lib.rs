//! # gaitclip-regbus — register programs on an I²C bus, blocking and async
//!
//! What gaitclip's sensor drivers (`drivers/<part>/`) share below their register maps: a
//! configuration sequence is data, a list of [`Step`]s a `const fn` builds from the caller's
//! settings, and one runner executes it on the bus ([`blocking::RegisterBus`],
//! [`asynch::RegisterBus`]: one async source, its blocking twin made by `maybe-async-cfg`).
//! A driver is then its register map, its programs and its reads, on top of this; its tests
//! read each program as the bus sees it.
//!
//! - [`Step`]: identify the part, write, check a register back, read and drop, wait;
//! - [`ProgramError`]: what a program can fail on (the bus, another part answering, a
//!   register that does not read back);
//! - [`mode`]: the typestate modes the drivers share (unconfigured, sampling, waiting for
//!   motion), and [`ModeChangeError`], which hands a driver back in its old mode.
//!
//! Every register access is one `write` or `write_read`, so a bus error surfaces at once and
//! the caller decides whether to retry. No heap, no panics, no `unsafe`.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod bus;
mod error;
pub mod mode;
mod program;

pub use bus::{asynch, blocking, NoWait};
pub use error::{ModeChangeError, ProgramError};
pub use program::{Identity, Step};

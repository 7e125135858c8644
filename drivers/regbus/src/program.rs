//! A register program's steps.

/// How a part identifies itself: the value its identification register holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Identity {
    /// The register (`WHO_AM_I`).
    pub reg: u8,
    /// The value it holds.
    pub value: u8,
}

/// One step of a register program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Read the part's identity register: anything but its value is
    /// [`crate::ProgramError::WrongDevice`] and ends the program.
    Identify,
    /// Write `value` to `reg`.
    Write {
        /// Register.
        reg: u8,
        /// Value.
        value: u8,
    },
    /// Read `reg` back: anything but `value` is [`crate::ProgramError::Verify`] and ends the
    /// program.
    Check {
        /// Register.
        reg: u8,
        /// The value it must hold.
        value: u8,
    },
    /// Read `reg` and drop the value (reading a status register clears its latch).
    Read {
        /// Register.
        reg: u8,
    },
    /// Wait this long, ms (the delay the caller passed).
    WaitMs(u32),
}

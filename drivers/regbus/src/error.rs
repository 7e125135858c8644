//! What a register program and a mode change can fail on.

/// A register program's failures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProgramError<E> {
    /// The bus transaction failed (NACK, arbitration loss, timeout …).
    Bus(E),
    /// The identity register answered this instead: another part on the address.
    WrongDevice(u8),
    /// A register read back other than what it must hold (register, expected, read).
    Verify(u8, u8, u8),
}

impl<E> From<E> for ProgramError<E> {
    fn from(e: E) -> Self {
        ProgramError::Bus(e)
    }
}

/// A mode change that failed: why, and the driver back in the mode it was in, to retry the
/// change or reset the part (the part itself may be half-way between the two).
pub struct ModeChangeError<Err, D> {
    /// What failed (the driver's error type).
    pub error: Err,
    /// The driver, in its old mode.
    pub dev: D,
}

impl<Err: core::fmt::Debug, D> core::fmt::Debug for ModeChangeError<Err, D> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ModeChangeError")
            .field("error", &self.error)
            .finish_non_exhaustive()
    }
}

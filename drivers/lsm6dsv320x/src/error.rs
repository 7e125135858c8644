//! What can go wrong.

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<E> {
    /// The bus transaction failed (NACK, arbitration loss, timeout …).
    Bus(E),
    /// `WHO_AM_I` answered this instead of 0x73: another part on the address.
    WrongDevice(u8),
    /// The FIFO overran (words were overwritten) and was emptied: the caller must treat the
    /// stream as having a gap.
    FifoOverflow,
    /// A register read back other than what it must hold (register, expected, read): after
    /// the software reset, `CTRL3` still resetting.
    Verify(u8, u8, u8),
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Bus(e)
    }
}

/// A mode change that failed: why, and the driver back in the mode it was in, to retry the
/// change or reset the part with `init` (the part itself may be half-way between the two).
pub struct ModeChangeError<E, D> {
    /// What failed.
    pub error: Error<E>,
    /// The driver, in its old mode.
    pub dev: D,
}

impl<E: core::fmt::Debug, D> core::fmt::Debug for ModeChangeError<E, D> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ModeChangeError")
            .field("error", &self.error)
            .finish_non_exhaustive()
    }
}

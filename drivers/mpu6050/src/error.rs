//! What can go wrong.

/// Driver errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<E> {
    /// The bus transaction failed (NACK, arbitration loss, timeout …).
    Bus(E),
    /// `WHO_AM_I` answered this instead of 0x68: another part on the address.
    WrongDevice(u8),
    /// The FIFO overflowed and was reset: samples were lost and the caller must treat the
    /// stream as having a gap.
    FifoOverflow,
    /// The FIFO count is not a whole number of samples: the FIFO was reset.
    FifoMisaligned(u16),
    /// A register read back other than what was written (register, written, read).
    Verify(u8, u8, u8),
    /// Asked of the part in a mode that cannot do it: a sample read while it waits for
    /// motion, or a read mode it does not have (the FIFO has no watermark interrupt).
    Mode,
}

impl<E> From<E> for Error<E> {
    fn from(e: E) -> Self {
        Error::Bus(e)
    }
}

impl<E> From<gaitclip_regbus::ProgramError<E>> for Error<E> {
    fn from(e: gaitclip_regbus::ProgramError<E>) -> Self {
        match e {
            gaitclip_regbus::ProgramError::Bus(e) => Error::Bus(e),
            gaitclip_regbus::ProgramError::WrongDevice(v) => Error::WrongDevice(v),
            gaitclip_regbus::ProgramError::Verify(r, w, v) => Error::Verify(r, w, v),
        }
    }
}

/// A mode change that failed: the driver's error, and the driver back in its old mode, to
/// retry the change or reset the part with `init` (the part itself may be half-way).
pub type ModeChangeError<E, D> = gaitclip_regbus::ModeChangeError<Error<E>, D>;

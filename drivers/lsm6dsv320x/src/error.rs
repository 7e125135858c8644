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
    /// Asked of the part in a mode that cannot do it: a FIFO read while it waits for motion,
    /// or a read mode the handle does not offer (it delivers through the FIFO's watermark).
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

/// A mode change that failed: the driver's error, and the driver back in its old mode.
pub type ModeChangeError<E, D> = gaitclip_regbus::ModeChangeError<Error<E>, D>;

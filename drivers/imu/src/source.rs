//! What a board's sampler needs of a part, whichever it is (feature `source`): start it
//! sampling, read one sample or a FIFO burst as [`RawSample`](crate::RawSample)s, send it to its wait for
//! motion and bring it back. Each driver crate implements [`blocking::ImuSource`] and
//! [`asynch::ImuSource`] on a handle that carries its typestate driver in whichever mode it
//! is in; the boards' sampler (`gaitclip-board`'s `imu_sampler`) is written once against
//! these traits, so a third part is a driver crate that implements them, and a board feature
//! that picks it.
//!
//! Written once: `maybe-async-cfg` makes [`blocking`] (on [`embedded_hal`]) and [`asynch`]
//! (each transfer awaited, on [`embedded_hal_async`]) from the same source.

/// How the board learns that samples wait: the part's interrupt pin, as the sampler reads
/// it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadMode {
    /// INT latched on data ready; every pulse reads one sample from the output registers.
    PerSample,
    /// INT pulses on every data ready and is only counted; every `batch` pulses the FIFO is
    /// read in bursts.
    Fifo {
        /// Pulses per FIFO read (at least 1).
        batch: u8,
    },
    /// INT rises when the FIFO holds `samples` sample periods (its watermark); every pulse
    /// reads the FIFO in bursts until it is empty.
    Watermark {
        /// Sample periods the FIFO holds when INT rises (at least 1).
        samples: u8,
    },
}

#[maybe_async_cfg::maybe(
    idents(embedded_hal_async(sync = "embedded_hal", async)),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The trait, `ImuSource`.
pub mod trait_def {
    use embedded_hal_async::delay::DelayNs;

    use super::ReadMode;
    use crate::RawSample;

    /// A part as a board's sampler drives it: a handle owning the driver (and its bus), in
    /// whichever of its modes the last call left it. Every method leaves the handle usable:
    /// a failed mode change keeps the old mode, and [`ImuSource::restart`] always brings the
    /// part back from anything.
    #[allow(async_fn_in_trait)]
    pub trait ImuSource {
        /// The board's bus, for it to recover a stuck bus (clock SCL free).
        type Bus;
        /// The driver's error.
        type Error: core::fmt::Debug;
        /// How the part waits for motion (its thresholds and rate).
        type Wake: Copy;

        /// Resets the part into sampling, from any mode, with the handle's configuration,
        /// and sets its interrupt up for `mode`. A part that cannot deliver samples in
        /// `mode` says so in its error, every time.
        async fn restart<D: DelayNs>(
            &mut self,
            delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error>;

        /// Reads the newest sample from the output registers ([`ReadMode::PerSample`]).
        async fn read_sample(&mut self) -> Result<RawSample, Self::Error>;

        /// Reads the samples waiting in the FIFO, at most `out.len()`, oldest first; how
        /// many were written. Fewer than `out.len()` means the FIFO is (for now) empty.
        async fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<usize, Self::Error>;

        /// Whether `error` is a FIFO overflow: the part lost samples and emptied its FIFO,
        /// so the caller declares a gap instead of retrying.
        fn overflowed(error: &Self::Error) -> bool;

        /// Sends the sampling part to its low-power wait for motion with `wake`.
        async fn enter_motion_wake<D: DelayNs>(
            &mut self,
            delay: &mut D,
            wake: &Self::Wake,
        ) -> Result<(), Self::Error>;

        /// Brings a waiting part back to sampling (the handle's configuration) and sets its
        /// interrupt up for `mode` again; a part already sampling only has its interrupt set
        /// up.
        async fn leave_motion_wake<D: DelayNs>(
            &mut self,
            delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error>;

        /// Whether the part is in its wait for motion.
        fn asleep(&self) -> bool;

        /// The bus; `None` only inside a mode change, which no caller can see.
        fn bus_mut(&mut self) -> Option<&mut Self::Bus>;
    }
}

//! The part as a board's sampler drives it ([`gaitclip_imu::source`]):
//! [`blocking::Lsm6dsv320xSource`] and [`asynch::Lsm6dsv320xSource`], written once
//! (`maybe-async-cfg`).
//!
//! The part only delivers through its FIFO at the watermark
//! ([`ReadMode::Watermark`](gaitclip_imu::source::ReadMode::Watermark)); the handle reads
//! the words, merges the two accelerometers ([`Assembler`](crate::merge::Assembler)) and hands
//! out whole samples. A period's sample is complete once a word of the next period arrives,
//! so each burst holds back the newest period until the next one: one period of latency.
//!
//! [`blocking::Lsm6dsv320xSource`]: crate::blocking::Lsm6dsv320xSource
//! [`asynch::Lsm6dsv320xSource`]: crate::asynch::Lsm6dsv320xSource

/// FIFO words read per transfer loop. Each word completes at most one sample, so a loop never
/// completes more samples than the caller's room when it reads no more words than that.
pub const WORDS_PER_LOOP: usize = 16;

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The handle, `Lsm6dsv320xSource`.
pub mod handle {
    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;
    use gaitclip_imu::source::asynch::ImuSource;
    use gaitclip_imu::source::ReadMode;
    use gaitclip_imu::RawSample;

    use super::WORDS_PER_LOOP;
    use crate::asynch::Lsm6dsv320x;
    use crate::fifo::{FifoWord, Tag};
    use crate::merge::Assembler;
    use crate::mode::{MotionWake, Sampling, Unconfigured};
    use crate::{Config, Error, MotionWakeConfig};

    /// Which mode a driver was in before a reset.
    #[derive(Clone, Copy)]
    enum ModeWas {
        Unconfigured,
        Sampling,
        Waiting,
    }

    /// The typestate driver in whichever mode it is in.
    enum Moded<I> {
        Unconfigured(Lsm6dsv320x<I, Unconfigured>),
        Sampling(Lsm6dsv320x<I, Sampling>),
        Waiting(Lsm6dsv320x<I, MotionWake>),
    }

    /// An LSM6DSV320X with its configuration and the merge of its FIFO, for a board's
    /// sampler ([`ImuSource`]).
    pub struct Lsm6dsv320xSource<I: I2c> {
        /// Always `Some` between calls: taken only while a mode change moves the driver.
        imu: Option<Moded<I>>,
        config: Config,
        assembler: Assembler,
        /// An error met after a burst had completed samples: those are handed out first,
        /// the error at the next call, so neither is lost.
        pending: Option<Error<I::Error>>,
    }

    impl<I: I2c> Lsm6dsv320xSource<I> {
        /// The part on `imu`, to be sampled with `config` (nothing is sent yet).
        pub const fn new(imu: Lsm6dsv320x<I, Unconfigured>, config: Config) -> Self {
            Lsm6dsv320xSource {
                imu: Some(Moded::Unconfigured(imu)),
                config,
                assembler: Assembler::new(config.dual_range()),
                pending: None,
            }
        }

        /// The configuration it samples with.
        pub const fn config(&self) -> &Config {
            &self.config
        }

        /// The merge's counts so far (axes taken from the high-g channel, railed samples
        /// without one, unpaired periods).
        pub const fn assembler(&self) -> &Assembler {
            &self.assembler
        }

        /// A FIFO emptied by the part or a reset: the period being assembled is gone with
        /// it (the caller's gap counts it), the merge's counts stay.
        fn forget_partial(&mut self) {
            self.assembler = self.assembler.restarted();
        }
    }

    impl<I: I2c> ImuSource for Lsm6dsv320xSource<I> {
        type Bus = I;
        type Error = Error<I::Error>;
        type Wake = MotionWakeConfig;

        async fn restart<D: DelayNs>(
            &mut self,
            delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error> {
            // The FIFO at its watermark is the only way this part delivers here.
            if !matches!(mode, ReadMode::Watermark { .. }) {
                return Err(Error::Mode);
            }
            let config = self.config;
            // One `init` (one copy of its work in flash) from whatever mode the part is in;
            // on failure the driver goes back to that mode, as `init` itself hands it back.
            let (unconfigured, was) = match self.imu.take() {
                Some(Moded::Unconfigured(d)) => (d, ModeWas::Unconfigured),
                Some(Moded::Sampling(d)) => (d.into_unconfigured(), ModeWas::Sampling),
                Some(Moded::Waiting(d)) => (d.into_unconfigured(), ModeWas::Waiting),
                None => return Err(Error::Mode),
            };
            let (imu, result) = match unconfigured.init(delay, &config).await {
                Ok(d) => (Moded::Sampling(d), Ok(())),
                Err(e) => (
                    match was {
                        ModeWas::Unconfigured => Moded::Unconfigured(e.dev),
                        ModeWas::Sampling => Moded::Sampling(e.dev.into_mode()),
                        ModeWas::Waiting => Moded::Waiting(e.dev.into_mode()),
                    },
                    Err(e.error),
                ),
            };
            self.imu = Some(imu);
            self.forget_partial();
            // A reset empties the FIFO: an error met before it is moot.
            self.pending = None;
            result
        }

        /// Not on this part: it delivers through its FIFO ([`Error::Mode`]).
        async fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
            Err(Error::Mode)
        }

        async fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<usize, Self::Error> {
            if let Some(e) = self.pending.take() {
                return Err(e);
            }
            let mut words = [FifoWord {
                tag: Tag::Other(0),
                slot: 0,
                data: [0; 3],
            }; WORDS_PER_LOOP];
            let mut done = 0;
            while done < out.len() {
                let room = (out.len() - done).min(WORDS_PER_LOOP);
                let (n, result) = match &mut self.imu {
                    Some(Moded::Sampling(d)) => d.read_fifo_partial(&mut words[..room]).await,
                    _ => (0, Err(Error::Mode)),
                };
                // The words read are out of the FIFO: they are assembled whatever came after.
                for w in &words[..n] {
                    if let Some(s) = self.assembler.push(*w) {
                        // At most one sample per word, and no more words than room.
                        if let Some(slot) = out.get_mut(done) {
                            *slot = s;
                            done += 1;
                        }
                    }
                }
                if let Err(e) = result {
                    if matches!(e, Error::FifoOverflow) {
                        self.forget_partial();
                    }
                    if done == 0 {
                        return Err(e);
                    }
                    self.pending = Some(e);
                    return Ok(done);
                }
                if n < room {
                    break;
                }
            }
            Ok(done)
        }

        fn overflowed(error: &Self::Error) -> bool {
            matches!(error, Error::FifoOverflow)
        }

        async fn enter_motion_wake<D: DelayNs>(
            &mut self,
            delay: &mut D,
            wake: &MotionWakeConfig,
        ) -> Result<(), Self::Error> {
            match self.imu.take() {
                Some(Moded::Sampling(d)) => match d.enter_motion_wake(delay, wake).await {
                    Ok(d) => {
                        self.imu = Some(Moded::Waiting(d));
                        self.forget_partial();
                        Ok(())
                    }
                    Err(e) => {
                        self.imu = Some(Moded::Sampling(e.dev));
                        Err(e.error)
                    }
                },
                other => {
                    self.imu = other;
                    Err(Error::Mode)
                }
            }
        }

        async fn leave_motion_wake<D: DelayNs>(
            &mut self,
            delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error> {
            if !matches!(mode, ReadMode::Watermark { .. }) {
                return Err(Error::Mode);
            }
            match self.imu.take() {
                Some(Moded::Waiting(d)) => match d.leave_motion_wake(delay, &self.config).await {
                    Ok(d) => {
                        self.imu = Some(Moded::Sampling(d));
                        Ok(())
                    }
                    Err(e) => {
                        self.imu = Some(Moded::Waiting(e.dev));
                        Err(e.error)
                    }
                },
                // Already sampling: the FIFO and INT1 came back with it.
                other => {
                    self.imu = other;
                    Ok(())
                }
            }
        }

        fn asleep(&self) -> bool {
            matches!(self.imu, Some(Moded::Waiting(_)))
        }

        fn bus_mut(&mut self) -> Option<&mut I> {
            self.imu.as_mut().map(|m| match m {
                Moded::Unconfigured(d) => d.bus_mut(),
                Moded::Sampling(d) => d.bus_mut(),
                Moded::Waiting(d) => d.bus_mut(),
            })
        }
    }
}

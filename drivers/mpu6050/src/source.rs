//! The part as a board's sampler drives it ([`gaitclip_imu::source`]): [`blocking::Mpu6050Source`]
//! and [`asynch::Mpu6050Source`], written once (`maybe-async-cfg`).
//!
//! [`blocking::Mpu6050Source`]: crate::blocking::Mpu6050Source
//! [`asynch::Mpu6050Source`]: crate::asynch::Mpu6050Source

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The handle, `Mpu6050Source`.
pub mod handle {
    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;
    use gaitclip_imu::source::asynch::ImuSource;
    use gaitclip_imu::source::ReadMode;
    use gaitclip_imu::RawSample;

    use crate::asynch::Mpu6050;
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
        Unconfigured(Mpu6050<I, Unconfigured>),
        Sampling(Mpu6050<I, Sampling>),
        Waiting(Mpu6050<I, MotionWake>),
    }

    /// An MPU6050 with its configuration, for a board's sampler: the driver moves between
    /// its modes inside ([`ImuSource`]).
    pub struct Mpu6050Source<I> {
        /// Always `Some` between calls: taken only while a mode change moves the driver.
        imu: Option<Moded<I>>,
        config: Config,
    }

    impl<I: I2c> Mpu6050Source<I> {
        /// The part on `imu`, to be sampled with `config` (nothing is sent yet).
        pub const fn new(imu: Mpu6050<I, Unconfigured>, config: Config) -> Self {
            Mpu6050Source {
                imu: Some(Moded::Unconfigured(imu)),
                config,
            }
        }

        /// The configuration it samples with.
        pub const fn config(&self) -> &Config {
            &self.config
        }

        async fn enable_interrupt(&mut self, mode: ReadMode) -> Result<(), Error<I::Error>> {
            let Some(Moded::Sampling(d)) = &mut self.imu else {
                return Err(Error::Mode);
            };
            match mode {
                ReadMode::PerSample => d.enable_data_ready_interrupt().await,
                ReadMode::Fifo { .. } => {
                    d.enable_fifo().await?;
                    d.enable_data_ready_pulse().await
                }
                // The MPU6050's FIFO has no watermark interrupt.
                ReadMode::Watermark { .. } => Err(Error::Mode),
            }
        }
    }

    impl<I: I2c> ImuSource for Mpu6050Source<I> {
        type Bus = I;
        type Error = Error<I::Error>;
        type Wake = MotionWakeConfig;

        async fn restart<D: DelayNs>(
            &mut self,
            delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error> {
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
            result?;
            self.enable_interrupt(mode).await
        }

        async fn read_sample(&mut self) -> Result<RawSample, Self::Error> {
            match &mut self.imu {
                Some(Moded::Sampling(d)) => d.read_sample().await,
                _ => Err(Error::Mode),
            }
        }

        async fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<usize, Self::Error> {
            match &mut self.imu {
                Some(Moded::Sampling(d)) => d.read_fifo(out).await,
                _ => Err(Error::Mode),
            }
        }

        fn overflowed(error: &Self::Error) -> bool {
            matches!(error, Error::FifoOverflow | Error::FifoMisaligned(_))
        }

        async fn enter_motion_wake<D: DelayNs>(
            &mut self,
            _delay: &mut D,
            wake: &MotionWakeConfig,
        ) -> Result<(), Self::Error> {
            match self.imu.take() {
                Some(Moded::Sampling(d)) => {
                    match d.enter_motion_wake(wake, self.config.accel).await {
                        Ok(d) => {
                            self.imu = Some(Moded::Waiting(d));
                            Ok(())
                        }
                        Err(e) => {
                            self.imu = Some(Moded::Sampling(e.dev));
                            Err(e.error)
                        }
                    }
                }
                other => {
                    self.imu = other;
                    Err(Error::Mode)
                }
            }
        }

        async fn leave_motion_wake<D: DelayNs>(
            &mut self,
            _delay: &mut D,
            mode: ReadMode,
        ) -> Result<(), Self::Error> {
            match self.imu.take() {
                Some(Moded::Waiting(d)) => match d.leave_motion_wake(&self.config).await {
                    Ok(d) => self.imu = Some(Moded::Sampling(d)),
                    Err(e) => {
                        self.imu = Some(Moded::Waiting(e.dev));
                        return Err(e.error);
                    }
                },
                // Already sampling (a retry after the interrupt's set-up failed).
                other => self.imu = other,
            }
            self.enable_interrupt(mode).await
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

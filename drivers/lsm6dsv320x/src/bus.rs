//! The driver on the bus, written once: `maybe-async-cfg` makes [`blocking`] (on
//! [`embedded_hal::i2c::I2c`]) and [`asynch`] (on [`embedded_hal_async::i2c::I2c`], for an
//! executor that sleeps the core while a transfer runs) from the same source, so the two
//! cannot drift apart.

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The driver, `Lsm6dsv320x<I, Mode>` ([`crate::mode`]).
pub mod driver {
    use core::marker::PhantomData;

    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;

    use gaitclip_regbus::asynch::RegisterBus;
    use gaitclip_regbus::Identity;

    use crate::error::{Error, ModeChangeError};
    use crate::fifo::{FifoWord, WORD_BYTES};
    use crate::mode::{Mode, MotionWake, Sampling, Unconfigured};
    use crate::program::{self, Step};
    use crate::register::{bits, reg, WHO_AM_I_VALUE};
    use crate::settings::{Address, Config, FifoStatus, MotionWakeConfig};

    /// What `WHO_AM_I` holds on this part.
    const IDENTITY: Identity = Identity {
        reg: reg::WHO_AM_I,
        value: WHO_AM_I_VALUE,
    };

    /// An LSM6DSV320X on an I²C bus, in mode `M` ([`crate::mode`]).
    #[derive(Debug)]
    pub struct Lsm6dsv320x<I, M = Sampling> {
        bus: RegisterBus<I>,
        mode: PhantomData<M>,
    }

    impl<I: I2c> Lsm6dsv320x<I, Unconfigured> {
        /// Wraps the bus; talks to nothing yet.
        pub const fn new(i2c: I, address: Address) -> Self {
            Lsm6dsv320x {
                bus: RegisterBus::new(i2c, address.bits()),
                mode: PhantomData,
            }
        }
    }

    impl<I: I2c, M: Mode> Lsm6dsv320x<I, M> {
        /// Gives the bus back.
        pub fn release(self) -> I {
            self.bus.release()
        }

        /// The bus, for a board to recover it. The driver keeps no state about the bus, so
        /// anything done to it is safe here.
        pub fn bus_mut(&mut self) -> &mut I {
            self.bus.bus_mut()
        }

        /// Reads `WHO_AM_I`; [`Error::WrongDevice`] if it is not an LSM6DSV320X.
        pub async fn probe(&mut self) -> Result<(), Error<I::Error>> {
            Ok(self.bus.identify(IDENTITY).await?)
        }

        /// From any mode: probes, resets and applies `config` ([`program::init`]), then turns
        /// the FIFO on ([`program::enable_fifo`]). On failure the driver comes back in its
        /// old mode.
        #[allow(clippy::type_complexity)]
        pub async fn init<D: DelayNs>(
            mut self,
            delay: &mut D,
            config: &Config,
        ) -> Result<Lsm6dsv320x<I, Sampling>, ModeChangeError<I::Error, Self>> {
            match init_bus(&mut self.bus, delay, config).await {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }

        /// Forgets the mode: the driver claims nothing about the part any more.
        pub fn into_unconfigured(self) -> Lsm6dsv320x<I, Unconfigured> {
            self.into_mode()
        }

        pub(crate) fn into_mode<N: Mode>(self) -> Lsm6dsv320x<I, N> {
            Lsm6dsv320x {
                bus: self.bus,
                mode: PhantomData,
            }
        }

        async fn run<D: DelayNs>(
            &mut self,
            steps: &[Step],
            delay: &mut D,
        ) -> Result<(), Error<I::Error>> {
            Ok(self.bus.run(steps, delay, IDENTITY).await?)
        }
    }

    /// [`program::init`] then [`program::enable_fifo`] on the bus, shared by `init` from
    /// every mode (one copy of the programs' work whatever modes a caller resets from).
    #[inline(never)]
    async fn init_bus<I: I2c, D: DelayNs>(
        bus: &mut RegisterBus<I>,
        delay: &mut D,
        config: &Config,
    ) -> Result<(), Error<I::Error>> {
        bus.run(&program::init(config), delay, IDENTITY).await?;
        Ok(bus
            .run(&program::enable_fifo(config), delay, IDENTITY)
            .await?)
    }

    impl<I: I2c> Lsm6dsv320x<I, Sampling> {
        /// Reads `FIFO_STATUS1` and `FIFO_STATUS2` in one transfer.
        pub async fn read_fifo_status(&mut self) -> Result<FifoStatus, Error<I::Error>> {
            let mut b = [0u8; 2];
            self.bus.read(reg::FIFO_STATUS1, &mut b).await?;
            Ok(FifoStatus::from_bytes(b))
        }

        /// Reads one FIFO word: the tag and its six bytes in one transfer.
        pub async fn read_fifo_word(&mut self) -> Result<FifoWord, Error<I::Error>> {
            let mut b = [0u8; WORD_BYTES];
            self.bus.read(reg::FIFO_DATA_OUT_TAG, &mut b).await?;
            Ok(FifoWord::from_bytes(&b))
        }

        /// Reads the words waiting, up to `out.len()`, oldest first; how many. An overrun
        /// empties the FIFO and is [`Error::FifoOverflow`] (the words in it are lost with the
        /// overwritten ones: a gap). Each word is its own transfer: a bus error after some
        /// words were read loses those here; [`Lsm6dsv320x::read_fifo_partial`] keeps them.
        pub async fn read_fifo(&mut self, out: &mut [FifoWord]) -> Result<usize, Error<I::Error>> {
            let (n, result) = self.read_fifo_partial(out).await;
            result.map(|()| n)
        }

        /// [`Lsm6dsv320x::read_fifo`] that keeps what it read before an error: the words read
        /// (in `out[..n]`, already gone from the FIFO) and how the read ended.
        pub async fn read_fifo_partial(
            &mut self,
            out: &mut [FifoWord],
        ) -> (usize, Result<(), Error<I::Error>>) {
            let status = match self.read_fifo_status().await {
                Ok(s) => s,
                Err(e) => return (0, Err(e)),
            };
            if status.overrun {
                let reset = self
                    .bus
                    .run(&program::RESET_FIFO, &mut gaitclip_regbus::NoWait, IDENTITY)
                    .await;
                return (
                    0,
                    Err(match reset {
                        Ok(()) => Error::FifoOverflow,
                        Err(e) => e.into(),
                    }),
                );
            }
            let n = out.len().min(status.words as usize);
            for (k, slot) in out.iter_mut().take(n).enumerate() {
                match self.read_fifo_word().await {
                    Ok(w) => *slot = w,
                    Err(e) => return (k, Err(e)),
                }
            }
            (n, Ok(()))
        }

        /// Into the wait for motion ([`program::enter_motion_wake`]). On failure the driver
        /// comes back sampling.
        #[allow(clippy::type_complexity)]
        pub async fn enter_motion_wake<D: DelayNs>(
            mut self,
            delay: &mut D,
            wake: &MotionWakeConfig,
        ) -> Result<Lsm6dsv320x<I, MotionWake>, ModeChangeError<I::Error, Self>> {
            match self.run(&program::enter_motion_wake(wake), delay).await {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }
    }

    impl<I: I2c> Lsm6dsv320x<I, MotionWake> {
        /// Reads `ALL_INT_SRC` (which clears the latch and releases INT1): whether the
        /// wake-up fired.
        pub async fn read_wake_source(&mut self) -> Result<bool, Error<I::Error>> {
            Ok(self.bus.read_reg(reg::ALL_INT_SRC).await? & bits::WU_IA != 0)
        }

        /// Back to sampling with `config` ([`program::leave_motion_wake`], then
        /// [`program::enable_fifo`]). On failure the driver comes back waiting.
        #[allow(clippy::type_complexity)]
        pub async fn leave_motion_wake<D: DelayNs>(
            mut self,
            delay: &mut D,
            config: &Config,
        ) -> Result<Lsm6dsv320x<I, Sampling>, ModeChangeError<I::Error, Self>> {
            let mut result = self.run(&program::leave_motion_wake(config), delay).await;
            if result.is_ok() {
                result = self.run(&program::enable_fifo(config), delay).await;
            }
            match result {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }
    }
}

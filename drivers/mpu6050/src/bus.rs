//! The driver on the bus, written once: `maybe-async-cfg` makes [`blocking`] (on
//! [`embedded_hal::i2c::I2c`]) and [`asynch`] (on [`embedded_hal_async::i2c::I2c`], each
//! transfer awaited, so an executor such as embassy's sleeps the core while the bytes move)
//! from the same source, so the two cannot drift apart: the same modes, the same register
//! programs, the same reads.

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The driver, `Mpu6050<I, Mode>` ([`crate::mode`]).
pub mod driver {
    use core::marker::PhantomData;

    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;

    use gaitclip_regbus::asynch::RegisterBus;
    use gaitclip_regbus::{Identity, NoWait};

    use crate::error::{Error, ModeChangeError};
    use crate::mode::{Mode, MotionWake, Sampling, Unconfigured};
    use crate::program::{self, FifoCount, Step};
    use crate::register::{reg, WHO_AM_I_VALUE};
    use crate::sample::{RawSample, SAMPLE_BYTES};
    use crate::settings::{Address, Config, InterruptStatus, MotionWakeConfig};
    use crate::AccelRange;

    /// What `WHO_AM_I` holds on this part.
    const IDENTITY: Identity = Identity {
        reg: reg::WHO_AM_I,
        value: WHO_AM_I_VALUE,
    };

    /// An MPU6050 on an I²C bus, in mode `M` ([`crate::mode`]).
    #[derive(Debug)]
    pub struct Mpu6050<I, M = Sampling> {
        bus: RegisterBus<I>,
        mode: PhantomData<M>,
    }

    impl<I: I2c> Mpu6050<I, Unconfigured> {
        /// Wraps the bus; talks to nothing yet.
        pub const fn new(i2c: I, address: Address) -> Self {
            Mpu6050 {
                bus: RegisterBus::new(i2c, address.bits()),
                mode: PhantomData,
            }
        }
    }

    impl<I: I2c, M: Mode> Mpu6050<I, M> {
        /// Gives the bus back.
        pub fn release(self) -> I {
            self.bus.release()
        }

        /// The bus, for a board to recover it (clock SCL until a stuck slave lets go of SDA).
        /// The driver keeps no state about the bus, so anything done to it is safe here.
        pub fn bus_mut(&mut self) -> &mut I {
            self.bus.bus_mut()
        }

        /// Reads `WHO_AM_I`; [`Error::WrongDevice`] if it is not an MPU6050.
        pub async fn probe(&mut self) -> Result<(), Error<I::Error>> {
            Ok(self.bus.identify(IDENTITY).await?)
        }

        /// Reads `INT_STATUS`, which clears it and releases a latched INT pin.
        pub async fn read_interrupt_status(&mut self) -> Result<InterruptStatus, Error<I::Error>> {
            Ok(InterruptStatus(self.bus.read_reg(reg::INT_STATUS).await?))
        }

        /// From any mode: probes, resets, wakes with the gyro PLL clock and applies `config`
        /// ([`program::init`]). On failure the driver comes back in its old mode.
        #[allow(clippy::type_complexity)]
        pub async fn init<D: DelayNs>(
            mut self,
            delay: &mut D,
            config: &Config,
        ) -> Result<Mpu6050<I, Sampling>, ModeChangeError<I::Error, Self>> {
            match init_bus(&mut self.bus, delay, config).await {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }

        /// Forgets the mode: the driver claims nothing about the part any more, and offers only
        /// what is safe in any mode (probing, the interrupt status, `init`). For handing a
        /// driver back whatever mode it reached, as a failed start does.
        pub fn into_unconfigured(self) -> Mpu6050<I, Unconfigured> {
            self.into_mode()
        }

        pub(crate) fn into_mode<N: Mode>(self) -> Mpu6050<I, N> {
            Mpu6050 {
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

    /// [`program::init`] on the bus, shared by `init` from every mode (one copy of the
    /// program's work whatever modes a caller resets from).
    #[inline(never)]
    async fn init_bus<I: I2c, D: DelayNs>(
        bus: &mut RegisterBus<I>,
        delay: &mut D,
        config: &Config,
    ) -> Result<(), Error<I::Error>> {
        Ok(bus.run(&program::init(config), delay, IDENTITY).await?)
    }

    impl<I: I2c> Mpu6050<I, Sampling> {
        /// One burst read of the 14 data registers.
        pub async fn read_sample(&mut self) -> Result<RawSample, Error<I::Error>> {
            let mut buf = [0u8; SAMPLE_BYTES];
            self.bus.read(reg::ACCEL_XOUT_H, &mut buf).await?;
            Ok(crate::sample::from_be_bytes(&buf))
        }

        /// Drives INT on data ready (and FIFO overflow), latched until any register read
        /// ([`program::DATA_READY_INTERRUPT`]).
        pub async fn enable_data_ready_interrupt(&mut self) -> Result<(), Error<I::Error>> {
            self.run(&program::DATA_READY_INTERRUPT, &mut NoWait).await
        }

        /// Pulses INT on every data ready without latching, for FIFO bursts
        /// ([`program::DATA_READY_PULSE`]).
        pub async fn enable_data_ready_pulse(&mut self) -> Result<(), Error<I::Error>> {
            self.run(&program::DATA_READY_PULSE, &mut NoWait).await
        }

        /// Resets and enables the FIFO with accel, temperature and gyro ([`program::ENABLE_FIFO`]).
        pub async fn enable_fifo(&mut self) -> Result<(), Error<I::Error>> {
            self.run(&program::ENABLE_FIFO, &mut NoWait).await
        }

        /// Bytes waiting in the FIFO.
        pub async fn fifo_count(&mut self) -> Result<u16, Error<I::Error>> {
            let mut buf = [0u8; 2];
            self.bus.read(reg::FIFO_COUNT_H, &mut buf).await?;
            Ok(u16::from_be_bytes(buf))
        }

        /// Reads as many whole samples as are waiting and fit in `out`; returns how many.
        ///
        /// Checks `INT_STATUS` first: after an overflow the oldest samples are gone and the
        /// stream is misaligned, so the FIFO is reset and [`Error::FifoOverflow`] returned; the
        /// caller marks a gap. A count that is not a multiple of 14 is handled the same way
        /// ([`program::fifo_count`]).
        pub async fn read_fifo(&mut self, out: &mut [RawSample]) -> Result<usize, Error<I::Error>> {
            let waiting = if self.read_interrupt_status().await?.fifo_overflow() {
                FifoCount::Overflow
            } else {
                program::fifo_count(self.fifo_count().await?)
            };
            let n = match waiting {
                FifoCount::Samples(n) => n.min(out.len()),
                FifoCount::Overflow => {
                    self.run(&program::RESET_FIFO, &mut NoWait).await?;
                    return Err(Error::FifoOverflow);
                }
                FifoCount::Misaligned(bytes) => {
                    self.run(&program::RESET_FIFO, &mut NoWait).await?;
                    return Err(Error::FifoMisaligned(bytes));
                }
            };
            for slot in out.iter_mut().take(n) {
                let mut buf = [0u8; SAMPLE_BYTES];
                self.bus.read(reg::FIFO_R_W, &mut buf).await?;
                *slot = crate::sample::from_be_bytes(&buf);
            }
            Ok(n)
        }

        /// Into the low-power wait for the first step at a few µA ([`program::enter_motion_wake`];
        /// the threshold is read back, [`Error::Verify`] if the part did not take it). `accel` is
        /// the range kept.
        #[allow(clippy::type_complexity)]
        pub async fn enter_motion_wake(
            mut self,
            wake: &MotionWakeConfig,
            accel: AccelRange,
        ) -> Result<Mpu6050<I, MotionWake>, ModeChangeError<I::Error, Self>> {
            match self
                .run(&program::enter_motion_wake(wake, accel), &mut NoWait)
                .await
            {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }
    }

    impl<I: I2c> Mpu6050<I, MotionWake> {
        /// Back to full 6-axis sampling with `config`'s ranges ([`program::leave_motion_wake`]);
        /// the caller then enables its interrupt and FIFO again, as after [`Mpu6050::init`].
        #[allow(clippy::type_complexity)]
        pub async fn leave_motion_wake(
            mut self,
            config: &Config,
        ) -> Result<Mpu6050<I, Sampling>, ModeChangeError<I::Error, Self>> {
            match self
                .run(&program::leave_motion_wake(config), &mut NoWait)
                .await
            {
                Ok(()) => Ok(self.into_mode()),
                Err(error) => Err(ModeChangeError { error, dev: self }),
            }
        }
    }
}

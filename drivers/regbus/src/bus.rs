//! The runner, written once: `maybe-async-cfg` makes [`blocking`] (on
//! [`embedded_hal::i2c::I2c`]) and [`asynch`] (on [`embedded_hal_async::i2c::I2c`]) from the
//! same source.

#[maybe_async_cfg::maybe(
    idents(embedded_hal_async(sync = "embedded_hal", async)),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// A part's address on a bus, and the program runner.
pub mod driver {
    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;

    use crate::error::ProgramError;
    use crate::program::{Identity, Step};

    /// One part at `address` on the bus `I`.
    #[derive(Debug)]
    pub struct RegisterBus<I> {
        i2c: I,
        address: u8,
    }

    impl<I: I2c> RegisterBus<I> {
        /// The part at the 7-bit `address`; talks to nothing yet.
        pub const fn new(i2c: I, address: u8) -> Self {
            RegisterBus { i2c, address }
        }

        /// Its 7-bit address.
        pub const fn address(&self) -> u8 {
            self.address
        }

        /// Gives the bus back.
        pub fn release(self) -> I {
            self.i2c
        }

        /// The bus, for a board to recover it. Nothing is kept about the bus, so anything
        /// done to it is safe here.
        pub fn bus_mut(&mut self) -> &mut I {
            &mut self.i2c
        }

        /// Reads one register.
        pub async fn read_reg(&mut self, reg: u8) -> Result<u8, I::Error> {
            let mut buf = [0u8];
            self.i2c.write_read(self.address, &[reg], &mut buf).await?;
            Ok(buf[0])
        }

        /// Writes one register.
        pub async fn write_reg(&mut self, reg: u8, value: u8) -> Result<(), I::Error> {
            self.i2c.write(self.address, &[reg, value]).await
        }

        /// Reads `buf.len()` bytes from `reg` on, in one transfer (the part increments the
        /// address, or serves a FIFO from it).
        pub async fn read(&mut self, reg: u8, buf: &mut [u8]) -> Result<(), I::Error> {
            self.i2c.write_read(self.address, &[reg], buf).await
        }

        /// Reads the identity register; [`ProgramError::WrongDevice`] if it is not `id`'s.
        pub async fn identify(&mut self, id: Identity) -> Result<(), ProgramError<I::Error>> {
            match self.read_reg(id.reg).await? {
                v if v == id.value => Ok(()),
                other => Err(ProgramError::WrongDevice(other)),
            }
        }

        /// Runs `steps` in order, stopping at the first failure; `id` is what
        /// [`Step::Identify`] expects, `delay` what [`Step::WaitMs`] waits on.
        pub async fn run<D: DelayNs>(
            &mut self,
            steps: &[Step],
            delay: &mut D,
            id: Identity,
        ) -> Result<(), ProgramError<I::Error>> {
            for step in steps {
                match *step {
                    Step::Identify => self.identify(id).await?,
                    Step::Write { reg, value } => self.write_reg(reg, value).await?,
                    Step::Check { reg, value } => {
                        let read = self.read_reg(reg).await?;
                        if read != value {
                            return Err(ProgramError::Verify(reg, value, read));
                        }
                    }
                    Step::Read { reg } => {
                        self.read_reg(reg).await?;
                    }
                    Step::WaitMs(ms) => delay.delay_ms(ms).await,
                }
            }
            Ok(())
        }
    }
}

/// The delay of the programs that have no wait step, for both runners.
pub struct NoWait;

impl embedded_hal::delay::DelayNs for NoWait {
    fn delay_ns(&mut self, _ns: u32) {}
}

impl embedded_hal_async::delay::DelayNs for NoWait {
    async fn delay_ns(&mut self, _ns: u32) {}
}

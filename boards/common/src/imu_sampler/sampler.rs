//! The sampler on the bus, written once: `maybe-async-cfg` makes [`blocking`] (on
//! [`embedded_hal::i2c::I2c`], which the bare-metal boards call from their data-ready
//! interrupt) and [`asynch`] (on [`embedded_hal_async::i2c::I2c`], each transfer and the
//! reset's waits awaited, so an executor such as embassy's sleeps the core while the bytes
//! move instead of spinning in the data-ready task) from the same source. Both report to one
//! ledger (`imu_sampler::ledger`).

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The sampler over the MPU6050's driver: `ImuSampler`.
pub mod driver {
    use embedded_hal_async::delay::DelayNs;
    use embedded_hal_async::i2c::I2c;
    use gaitclip::sensor::sample::RawSample;
    use gaitclip_mpu6050::asynch::Mpu6050;
    use gaitclip_mpu6050::mode::{MotionWake, Sampling, Unconfigured};
    use gaitclip_mpu6050::{self as mpu6050, MotionWakeConfig};

    use crate::imu_sampler::ledger::{Due, Ledger};
    use crate::imu_sampler::{BusRecovery, Counters, Item, ReadMode, FIFO_BURST, RETRIES};

    /// The driver in the mode the sampler last brought it to (the driver's modes are types; the
    /// sampler switches between them at run time).
    enum Sensor<I> {
        Sampling(Mpu6050<I, Sampling>),
        Waiting(Mpu6050<I, MotionWake>),
    }

    impl<I: I2c> Sensor<I> {
        fn bus_mut(&mut self) -> &mut I {
            match self {
                Sensor::Sampling(d) => d.bus_mut(),
                Sensor::Waiting(d) => d.bus_mut(),
            }
        }

        /// Resets the part into sampling from either mode ([`Mpu6050::init`]); on failure the
        /// driver stays in the mode it was.
        async fn init<D: DelayNs>(
            self,
            delay: &mut D,
            config: &mpu6050::Config,
        ) -> (Self, Result<(), mpu6050::Error<I::Error>>) {
            let r = match self {
                Sensor::Sampling(d) => d
                    .init(delay, config)
                    .await
                    .map_err(|e| (Sensor::Sampling(e.dev), e.error)),
                Sensor::Waiting(d) => d
                    .init(delay, config)
                    .await
                    .map_err(|e| (Sensor::Waiting(e.dev), e.error)),
            };
            match r {
                Ok(d) => (Sensor::Sampling(d), Ok(())),
                Err((s, e)) => (s, Err(e)),
            }
        }
    }

    /// The sensor, its settings and the fault bookkeeping, on the bus.
    pub struct ImuSampler<I, D> {
        /// Always `Some` between calls: taken only while a mode change moves the driver.
        imu: Option<Sensor<I>>,
        delay: D,
        config: mpu6050::Config,
        ledger: Ledger,
    }

    impl<I, D> ImuSampler<I, D>
    where
        I: I2c + BusRecovery,
        D: DelayNs,
    {
        /// Initialises the sensor for `config` and its interrupt for `mode`. On error the bus
        /// and delay are handed back with it, for the board to report and retry.
        #[allow(clippy::type_complexity)]
        pub async fn start(
            imu: Mpu6050<I, Unconfigured>,
            mut delay: D,
            config: mpu6050::Config,
            mode: ReadMode,
        ) -> Result<Self, (Mpu6050<I, Unconfigured>, D, mpu6050::Error<I::Error>)> {
            let mut imu = match imu.init(&mut delay, &config).await {
                Ok(imu) => imu,
                Err(e) => return Err((e.dev, delay, e.error)),
            };
            if let Err(e) = enable_interrupt(&mut imu, mode).await {
                return Err((imu.into_unconfigured(), delay, e));
            }
            Ok(ImuSampler {
                imu: Some(Sensor::Sampling(imu)),
                delay,
                config,
                ledger: Ledger::new(mode),
            })
        }

        /// The fault counters.
        pub const fn counters(&self) -> Counters {
            self.ledger.counters()
        }

        /// The data-ready interrupt: reads what is due and hands it to `push` (which returns
        /// `false` when the queue is full); then, if a sleep is due
        /// ([`ImuSampler::request_sleep`]), sends the sensor to its wait for motion. Ignored
        /// while asleep (the board calls [`ImuSampler::on_motion`] for the INT pin then).
        pub async fn on_data_ready(&mut self, push: &mut impl FnMut(Item) -> bool) {
            if self.asleep() {
                return;
            }
            match self.ledger.pulse() {
                Due::Nothing => {}
                Due::Sample => self.read_one(push).await,
                Due::Fifo { bursts } => self.read_fifo(bursts, push).await,
            }
            if let Some(wake) = self.ledger.sleep_due() {
                self.enter_sleep(&wake, push).await;
            }
        }

        /// Samples read and handed on so far (the main loop's count of samples, plus what is
        /// queued and what the queue had no room for).
        pub const fn samples_read(&self) -> u32 {
            self.ledger.samples_read()
        }

        /// Whether the sensor is in its low-power wait for motion.
        pub const fn asleep(&self) -> bool {
            matches!(self.imu, Some(Sensor::Waiting(_)))
        }

        /// Sends the sensor to its low-power wait for motion ([`Mpu6050::enter_motion_wake`])
        /// once `after` samples have been handed on in all ([`ImuSampler::samples_read`]). The main
        /// loop decides on what it has processed, while the interrupt may have read a few more:
        /// it asks for a count ahead of anything the queue can hold, so the sleep falls after
        /// the same sample however far behind it ran (the replay's host model relies on it).
        /// Replaces an earlier request.
        pub fn request_sleep(&mut self, after: u32, wake: MotionWakeConfig) {
            self.ledger.request_sleep(after, wake);
        }

        async fn enter_sleep(
            &mut self,
            wake: &MotionWakeConfig,
            push: &mut impl FnMut(Item) -> bool,
        ) {
            for _ in 0..=RETRIES {
                let entered = match self.imu.take() {
                    Some(Sensor::Sampling(d)) => {
                        match d.enter_motion_wake(wake, self.config.accel).await {
                            Ok(d) => {
                                self.imu = Some(Sensor::Waiting(d));
                                true
                            }
                            Err(e) => {
                                self.imu = Some(Sensor::Sampling(e.dev));
                                false
                            }
                        }
                    }
                    other => {
                        self.imu = other;
                        false
                    }
                };
                if entered {
                    self.ledger.asleep(push);
                    return;
                }
                self.ledger.bus_error();
            }
            // Half configured: set the sensor up again and stay awake; the main loop asks
            // again after another still period.
            self.restart().await;
        }

        /// The INT pin rose while asleep: motion. Back to full sampling
        /// ([`Mpu6050::leave_motion_wake`], then the interrupt and FIFO as at start), dropping the first
        /// `settle` samples (the gyro's start-up, datasheet §6.1: 30 ms); `slept` sample periods
        /// passed while asleep (the board's low-power clock). Both become one [`Item::Woke`]
        /// before the first sample kept. On a bus error the sensor is set up again from reset.
        pub async fn on_motion(
            &mut self,
            slept: u32,
            settle: u32,
            push: &mut impl FnMut(Item) -> bool,
        ) {
            if !self.asleep() {
                return;
            }
            self.ledger.motion(slept, settle);
            let mut resumed = false;
            for _ in 0..=RETRIES {
                if self.resume().await {
                    resumed = true;
                    break;
                }
                self.ledger.bus_error();
            }
            if !resumed {
                self.restart().await;
            }
            self.ledger.resumed(push);
        }

        /// Leaves the motion wait (if still in it: a retry after the interrupt's setup failed
        /// is already sampling) and sets the interrupt up again.
        async fn resume(&mut self) -> bool {
            match self.imu.take() {
                Some(Sensor::Waiting(d)) => match d.leave_motion_wake(&self.config).await {
                    Ok(d) => self.imu = Some(Sensor::Sampling(d)),
                    Err(e) => {
                        self.imu = Some(Sensor::Waiting(e.dev));
                        return false;
                    }
                },
                other => self.imu = other,
            }
            self.enable_interrupt().await
        }

        /// The bus, for a board's emulated sensor (its clock in the low-power wait) and tests;
        /// `None` only inside a mode change, which no caller can see.
        pub fn bus_mut(&mut self) -> Option<&mut I> {
            self.imu.as_mut().map(Sensor::bus_mut)
        }

        /// The board's watchdog found no data-ready pulse for `periods` sample periods: the
        /// sensor was reset or lost power. They become a gap and the sensor is set up again.
        pub async fn on_silence(&mut self, periods: u32, push: &mut impl FnMut(Item) -> bool) {
            if self.asleep() {
                // Silent by design: the sensor only speaks again on motion.
                return;
            }
            self.ledger.silence(periods);
            self.restart().await;
            self.ledger.silence_reported(push);
        }

        async fn read_one(&mut self, push: &mut impl FnMut(Item) -> bool) {
            for _ in 0..=RETRIES {
                let read = match &mut self.imu {
                    Some(Sensor::Sampling(d)) => d.read_sample().await.ok(),
                    // Never here while awake; a read that cannot happen fails like a bus error.
                    _ => None,
                };
                match read {
                    Some(s) => return self.ledger.sample(s, push),
                    None => self.ledger.bus_error(),
                }
            }
            if self.ledger.sample_missed() {
                self.restart().await;
            }
        }

        async fn read_fifo(&mut self, mut bursts: usize, push: &mut impl FnMut(Item) -> bool) {
            let mut buf = [RawSample::default(); FIFO_BURST];
            let mut attempts = 0;
            while bursts > 0 {
                let read = match &mut self.imu {
                    Some(Sensor::Sampling(d)) => d.read_fifo(&mut buf).await.map_err(Some),
                    _ => Err(None),
                };
                match read {
                    Ok(n) => {
                        if !self.ledger.fifo_read(&buf[..n.min(FIFO_BURST)], push) {
                            return;
                        }
                        bursts -= 1;
                    }
                    Err(Some(mpu6050::Error::FifoOverflow | mpu6050::Error::FifoMisaligned(_))) => {
                        return self.ledger.fifo_overflowed();
                    }
                    Err(_) => {
                        self.ledger.bus_error();
                        attempts += 1;
                        if attempts > RETRIES {
                            // The samples stay in the FIFO; the next pulse tries again.
                            if self.ledger.period_failed() {
                                self.restart().await;
                            }
                            return;
                        }
                    }
                }
            }
        }

        /// Recovers the bus and sets the sensor up again; on failure the next failed period
        /// tries again.
        async fn restart(&mut self) {
            let recovered = self.imu.as_mut().is_some_and(|s| s.bus_mut().recover_bus());
            let set_up = self.setup().await;
            self.ledger.restarted(recovered, set_up);
        }

        /// Resets the sensor into sampling (a reset sensor is awake whatever it was doing) and
        /// sets its interrupt up; whether both worked.
        async fn setup(&mut self) -> bool {
            let Some(sensor) = self.imu.take() else {
                return false;
            };
            let (sensor, reset) = sensor.init(&mut self.delay, &self.config).await;
            self.imu = Some(sensor);
            reset.is_ok() && self.enable_interrupt().await
        }

        /// Sets the data-ready interrupt up for the read mode; false if that failed (or the
        /// sensor is not sampling).
        async fn enable_interrupt(&mut self) -> bool {
            match &mut self.imu {
                Some(Sensor::Sampling(d)) => enable_interrupt(d, self.ledger.mode()).await.is_ok(),
                _ => false,
            }
        }
    }

    async fn enable_interrupt<I: I2c>(
        d: &mut Mpu6050<I, Sampling>,
        mode: ReadMode,
    ) -> Result<(), mpu6050::Error<I::Error>> {
        match mode {
            ReadMode::PerSample => d.enable_data_ready_interrupt().await,
            ReadMode::Fifo { .. } => {
                d.enable_fifo().await?;
                d.enable_data_ready_pulse().await
            }
        }
    }
}

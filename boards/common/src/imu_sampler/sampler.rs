//! The sampler on the bus, written once: `maybe-async-cfg` makes [`blocking`] (on
//! [`gaitclip_imu::source::blocking::ImuSource`], which the bare-metal boards call from their
//! data-ready interrupt) and [`asynch`] (on [`gaitclip_imu::source::asynch::ImuSource`], each
//! transfer and the reset's waits awaited, so an executor such as embassy's sleeps the core
//! while the bytes move instead of spinning in the data-ready task) from the same source. Both
//! report to one ledger (`imu_sampler::ledger`). Neither knows which part it drives: the
//! driver crates implement the source traits.

#[maybe_async_cfg::maybe(
    idents(
        embedded_hal_async(sync = "embedded_hal", async),
        asynch(sync = "blocking", async)
    ),
    sync(self = "blocking"),
    async(self = "asynch")
)]
/// The sampler over any part's source: `ImuSampler`.
pub mod driver {
    use embedded_hal_async::delay::DelayNs;
    use gaitclip::sensor::sample::RawSample;
    use gaitclip_imu::source::asynch::ImuSource;

    use crate::imu_sampler::ledger::{Due, Ledger};
    use crate::imu_sampler::{BusRecovery, Counters, Item, ReadMode, FIFO_BURST, RETRIES};

    /// The part, its read mode and the fault bookkeeping, on the bus.
    pub struct ImuSampler<S: ImuSource, D> {
        imu: S,
        delay: D,
        ledger: Ledger<S::Wake>,
    }

    impl<S, D> ImuSampler<S, D>
    where
        S: ImuSource,
        S::Bus: BusRecovery,
        D: DelayNs,
    {
        /// Resets the part into sampling and sets its interrupt up for `mode`. On error the
        /// part and delay are handed back with it, for the board to report and retry.
        #[allow(clippy::type_complexity)]
        pub async fn start(
            mut imu: S,
            mut delay: D,
            mode: ReadMode,
        ) -> Result<Self, (S, D, S::Error)> {
            if let Err(e) = imu.restart(&mut delay, mode).await {
                return Err((imu, delay, e));
            }
            Ok(ImuSampler {
                imu,
                delay,
                ledger: Ledger::new(mode),
            })
        }

        /// The fault counters.
        pub const fn counters(&self) -> Counters {
            self.ledger.counters()
        }

        /// The part's source (for what it counts of its own, such as a merge's).
        pub const fn source(&self) -> &S {
            &self.imu
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
        pub fn asleep(&self) -> bool {
            self.imu.asleep()
        }

        /// Sends the sensor to its low-power wait for motion ([`ImuSource::enter_motion_wake`])
        /// once `after` samples have been handed on in all ([`ImuSampler::samples_read`]). The main
        /// loop decides on what it has processed, while the interrupt may have read a few more:
        /// it asks for a count ahead of anything the queue can hold, so the sleep falls after
        /// the same sample however far behind it ran (the replay's host model relies on it).
        /// Replaces an earlier request.
        pub fn request_sleep(&mut self, after: u32, wake: S::Wake) {
            self.ledger.request_sleep(after, wake);
        }

        async fn enter_sleep(&mut self, wake: &S::Wake, push: &mut impl FnMut(Item) -> bool) {
            for _ in 0..=RETRIES {
                if self
                    .imu
                    .enter_motion_wake(&mut self.delay, wake)
                    .await
                    .is_ok()
                {
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
        /// ([`ImuSource::leave_motion_wake`], with the interrupt and FIFO as at start), dropping
        /// the first `settle` samples (the gyro's start-up: 30 ms on the MPU6050, datasheet
        /// §6.1); `slept` sample periods passed while asleep (the board's low-power clock).
        /// Both become one [`Item::Woke`] before the first sample kept. On a bus error the
        /// sensor is set up again from reset.
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
                let mode = self.ledger.mode();
                if self
                    .imu
                    .leave_motion_wake(&mut self.delay, mode)
                    .await
                    .is_ok()
                {
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

        /// The bus, for a board's emulated sensor (its clock in the low-power wait) and tests;
        /// `None` only inside a mode change, which no caller can see.
        pub fn bus_mut(&mut self) -> Option<&mut S::Bus> {
            self.imu.bus_mut()
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
                match self.imu.read_sample().await {
                    Ok(s) => return self.ledger.sample(s, push),
                    Err(_) => self.ledger.bus_error(),
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
                match self.imu.read_fifo(&mut buf).await {
                    Ok(n) => {
                        if !self.ledger.fifo_read(&buf[..n.min(FIFO_BURST)], push) {
                            return;
                        }
                        bursts -= 1;
                    }
                    Err(e) if S::overflowed(&e) => return self.ledger.fifo_overflowed(),
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
            let recovered = self.imu.bus_mut().is_some_and(|b| b.recover_bus());
            let mode = self.ledger.mode();
            let set_up = self.imu.restart(&mut self.delay, mode).await.is_ok();
            self.ledger.restarted(recovered, set_up);
        }
    }
}

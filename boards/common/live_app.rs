//! The main loop of the boards with a real sensor, and their sensor watchdog.
//!
//! The INT pin's interrupt runs the [`crate::imu_sampler::ImuSampler`] and fills the queue;
//! [`main_loop`] drains it through the pipeline, reports start-up, strides, gaps and a
//! status line every [`STATUS_EVERY_MS`] on defmt and the serial line, and sleeps with
//! `wfi`. A periodic timer drives the [`Watchdog`], which notices a sensor that stopped
//! pulsing (reset, brown-out, loose wire) and has the sampler set it up again.

use core::fmt::Write;

use cortex_m::interrupt as irq;
use gaitclip::pipeline::Pipeline;
use heapless::spsc::Consumer;

use crate::imu_sampler::{Counters, Item};
use crate::startup::Startup;
use crate::stride_log::StrideLog;

/// Interval of the status line.
pub const STATUS_EVERY_MS: u32 = 60_000;
/// Period of the board's watchdog timer.
pub const WATCHDOG_TICK_MS: u32 = 100;
/// Watchdog ticks without a data-ready pulse after which the sensor is declared silent.
pub const SILENT_TICKS: u32 = 3;

/// Finds a sensor that stopped pulsing.
pub struct Watchdog {
    last_pulses: u32,
    quiet_ticks: u32,
}

impl Watchdog {
    /// A watchdog that has seen nothing yet.
    pub const fn new() -> Self {
        Watchdog {
            last_pulses: 0,
            quiet_ticks: 0,
        }
    }

    /// One tick, with the running count of data-ready interrupts. Returns the sample
    /// periods lost when the sensor has been silent for [`SILENT_TICKS`] ticks
    /// (`periods_per_tick` each); the count starts again after that.
    pub fn tick(&mut self, pulses: u32, periods_per_tick: u32) -> Option<u32> {
        if pulses != self.last_pulses {
            self.last_pulses = pulses;
            self.quiet_ticks = 0;
            return None;
        }
        self.quiet_ticks += 1;
        if self.quiet_ticks < SILENT_TICKS {
            return None;
        }
        self.quiet_ticks = 0;
        Some(SILENT_TICKS.saturating_mul(periods_per_tick))
    }
}

impl Default for Watchdog {
    fn default() -> Self {
        Self::new()
    }
}

/// Processes the queue forever. `counters` reads the sampler's fault counters (inside a
/// critical section, as the interrupt owns the sampler).
pub fn main_loop<const M: usize>(
    pipeline: &mut Pipeline<M>,
    consumer: &mut Consumer<'static, Item>,
    log: &mut StrideLog,
    serial: &mut impl Write,
    startup: &mut Startup,
    counters: impl Fn() -> Counters,
    status_every_samples: u32,
) -> ! {
    let mut samples = 0u32;
    let mut next_status = status_every_samples;
    loop {
        while let Some(item) = consumer.dequeue() {
            match item {
                Item::Sample(s) => {
                    samples = samples.wrapping_add(1);
                    let stride = pipeline.process(&s);
                    if let Some(e) = startup.update(pipeline) {
                        log.startup(e, serial);
                    }
                    if let Some(stride) = stride {
                        log.stride(&stride, serial);
                    }
                    if samples == next_status {
                        next_status = next_status.wrapping_add(status_every_samples);
                        log.summary(samples, &counters(), serial);
                    }
                }
                Item::Gap(n) => {
                    log.gap(n, serial);
                    if let Some(stride) = pipeline.gap(n) {
                        log.stride(&stride, serial);
                    }
                }
            }
        }
        // Interrupts are masked while checking the queue so that a sample arriving between
        // the check and `wfi` still wakes the core (WFI wakes on a pending interrupt even
        // with PRIMASK set).
        irq::disable();
        if !consumer.ready() {
            cortex_m::asm::wfi();
        }
        // Note(unsafe): re-enables the interrupts disabled just above; no critical section
        // spans this point.
        unsafe { irq::enable() };
    }
}

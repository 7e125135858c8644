//! What every board reports, on both of its outputs: defmt (RTT with a probe, semihosting in
//! QEMU) and the serial line protocol of [`crate::serial_line`] (any `fmt::Write`; boards
//! without a UART pass [`NoSerial`]).
//!
//! defmt format (one line per stride; the host's bit-exact test parses it):
//! `stride <index> t=<start ms> dur=<ms> len=<mm> climb=<mm> phases=<stance>/<push-off>/<swing>/<heel-strike> ms flags=<bits> idx=<start>,<heel_off>,<toe_off>,<heel_strike>,<end> gait=<…> <gait> swing=<deg> before=<still ms>,<moving ms>`

use core::fmt::Write;

use gaitclip::detect::step_check::Rejected;
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::{BetweenTotals, HoleKind};
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;

use crate::imu_sampler::Counters;
use crate::serial_line;
use crate::sleep::{SleepSettings, WakeFigures};
use crate::startup::StartupEvent;

/// A serial output that discards everything (boards without a UART).
pub struct NoSerial;

impl Write for NoSerial {
    fn write_str(&mut self, _: &str) -> core::fmt::Result {
        Ok(())
    }
}

/// Running totals and the formatting of strides.
pub struct StrideLog {
    rate: SampleRate,
    strides: u32,
    /// Summed length of the strides that count in the distance (measured or estimated).
    distance_mm: u64,
    /// Strides whose length is the estimate ([`gaitclip::length::estimate`]).
    estimated: u32,
}

impl StrideLog {
    /// A log for samples at `rate`.
    pub const fn new(rate: SampleRate) -> Self {
        StrideLog {
            rate,
            strides: 0,
            distance_mm: 0,
            estimated: 0,
        }
    }

    /// The banner of the serial protocol (defmt logs its own): the detector, and the model
    /// behind the lengths ([`Config::length_model`]).
    pub fn banner(&self, board: &str, config: &Config, serial: &mut impl Write) {
        let model = config.length_model();
        defmt::info!(
            "gaitclip {=str} on {=str}: {=u32} mHz, detector {=str}, model {=str}",
            env!("CARGO_PKG_VERSION"),
            board,
            self.rate.millihertz(),
            config.detector.name(),
            model.name()
        );
        let _ = serial_line::banner(serial, board, self.rate, config.detector, model);
    }

    /// Logs one stride.
    pub fn stride(&mut self, s: &Stride, serial: &mut impl Write) {
        let t = s.times_ms(self.rate);
        self.strides += 1;
        if s.flags.counts_distance() {
            self.distance_mm += s.length_mm as u64;
        }
        if s.flags
            .has(gaitclip::record::stride::StrideFlags::ESTIMATED)
        {
            self.estimated += 1;
        }
        defmt::println!(
            "stride {=u32} t={=u32} dur={=u32} len={=u32} climb={=i32} phases={=u32}/{=u32}/{=u32}/{=u32} ms flags={=u16} idx={=u32},{=u32},{=u32},{=u32},{=u32} gait={=u16},{=u16},{=u16},{=u16},{=u16},{=u16},{=i16} {=str} swing={=u16} before={=u32},{=u32}",
            s.index,
            t.start,
            t.duration,
            s.length_mm,
            s.climb_mm,
            t.stance,
            t.push_off,
            t.swing,
            t.heel_strike,
            s.flags.0,
            s.events.start,
            s.events.heel_off,
            s.events.toe_off,
            s.events.heel_strike,
            s.events.end,
            s.gait.stance_time_ms,
            s.gait.swing_time_ms,
            s.gait.stance_permille,
            s.gait.gait_velocity_mm_s,
            s.gait.cadence_spm,
            s.max_sensor_lift_mm,
            s.turning_angle_cdeg,
            s.gait.gait.name(),
            s.swing_deg,
            s.between.still_ms,
            s.between.moving_ms
        );
        let _ = serial_line::stride(serial, self.rate, s);
    }

    /// Reports a step of the start-up calibration.
    pub fn startup(&self, e: StartupEvent, serial: &mut impl Write) {
        match e {
            StartupEvent::HoldStill { waited_ms } => {
                defmt::info!(
                    "hold still: waiting for the clip to rest ({=u32} ms so far)",
                    waited_ms
                );
                let _ = serial_line::comment(
                    serial,
                    format_args!(
                        "hold still: waiting for the clip to rest ({} ms so far)",
                        waited_ms
                    ),
                );
            }
            StartupEvent::Still {
                gyro_bias_mdps: b,
                gravity_mg,
                plausible,
            } => {
                defmt::info!(
                    "still: gyro_bias_mdps={=i32},{=i32},{=i32} gravity_mg={=i32}",
                    b[0],
                    b[1],
                    b[2],
                    gravity_mg
                );
                let _ = serial_line::comment(
                    serial,
                    format_args!(
                        "still: gyro_bias_mdps={},{},{} gravity_mg={}",
                        b[0], b[1], b[2], gravity_mg
                    ),
                );
                if !plausible {
                    defmt::warn!("the sensor reads outside its datasheet tolerance: check the part and its range");
                    let _ = serial_line::comment(
                        serial,
                        format_args!("warning: the sensor reads outside its datasheet tolerance: check the part and its range"),
                    );
                }
            }
            StartupEvent::HeadingKnown => {
                defmt::info!("foot frame known: measuring strides");
                let _ = serial_line::comment(
                    serial,
                    format_args!("foot frame known: measuring strides"),
                );
            }
        }
    }

    /// Reports a gap in the samples.
    pub fn gap(&self, samples: u32, kind: HoleKind, serial: &mut impl Write) {
        let what = match kind {
            HoleKind::Bridged => "bridged: the stride keeps its length (flag 256)",
            HoleKind::Filled => {
                "filled: a stride whose movement it falls in is a gap stride (flag 64), without a length"
            }
            HoleKind::Restart => {
                "detection restarts: the stride in progress is a gap stride (flag 64), without a length"
            }
        };
        defmt::warn!("hole of {=u32} samples {=str}", samples, what);
        let _ = serial_line::comment(serial, format_args!("hole samples={} {}", samples, what));
    }

    /// Reports that the sensor went to its low-power wait for motion, still for
    /// `still_samples` samples.
    pub fn asleep<W: WakeFigures>(
        &self,
        still_samples: u32,
        settings: &SleepSettings<W>,
        serial: &mut impl Write,
    ) {
        let still_ms = self.rate.ms_of_samples(still_samples);
        let wake_mhz = settings.wake.millihertz();
        match settings.wake.supply_ua() {
            Some(ua) => {
                defmt::info!(
                    "sleep: still for {=u32} ms; sensor waits for motion at {=u32} mHz ({=u32} uA), MCU sleeps",
                    still_ms,
                    wake_mhz,
                    ua
                );
                let _ = serial_line::comment(
                    serial,
                    format_args!(
                        "sleep still_ms={} wake_mhz={} sensor_ua={}: waiting for motion",
                        still_ms, wake_mhz, ua
                    ),
                );
            }
            None => {
                defmt::info!(
                    "sleep: still for {=u32} ms; sensor waits for motion at {=u32} mHz, MCU sleeps",
                    still_ms,
                    wake_mhz
                );
                let _ = serial_line::comment(
                    serial,
                    format_args!(
                        "sleep still_ms={} wake_mhz={}: waiting for motion",
                        still_ms, wake_mhz
                    ),
                );
            }
        }
    }

    /// Reports the wake-up on motion: `periods` sample periods were not sampled (asleep,
    /// then the gyro's settling).
    pub fn woke(&self, periods: u32, serial: &mut impl Write) {
        let ms = self.rate.ms_of_samples(periods);
        let what = "detection restarts: a step the wake-up cut into is a gap stride (flag 64)";
        defmt::info!("wake: motion after {=u32} ms unsampled; {=str}", ms, what);
        let _ = serial_line::comment(serial, format_args!("wake unsampled_ms={} {}", ms, what));
    }

    /// Logs the status (periodically, and at the end of a run).
    ///
    /// `clipped`: samples at a rail per axis (accelerometer x, y, z, gyroscope x, y, z;
    /// [`gaitclip::pipeline::Pipeline::clipped_samples`]).
    /// `steps`: the movements the step check refused and the time outside the strides
    /// ([`gaitclip::pipeline::Pipeline::rejected`], [`gaitclip::pipeline::Pipeline::between`]).
    pub fn summary(
        &self,
        samples: u32,
        c: &Counters,
        clipped: &[u32; 6],
        steps: (&Rejected, &BetweenTotals),
        serial: &mut impl Write,
    ) {
        let (rejected, between) = steps;
        defmt::println!(
            "summary strides={=u32} distance_mm={=u64} samples={=u32} overruns={=u32} bus_errors={=u32} restarts={=u32} fifo_overflows={=u32} silences={=u32} lost_samples={=u32} sleeps={=u32} slept_periods={=u32} estimated={=u32} clipped={=u32},{=u32},{=u32},{=u32},{=u32},{=u32} rejected={=u32},{=u32},{=u32},{=u32} still_s={=u64} moving_s={=u64}",
            self.strides,
            self.distance_mm,
            samples,
            c.overruns,
            c.bus_errors,
            c.restarts,
            c.fifo_overflows,
            c.silences,
            c.lost_samples,
            c.sleeps,
            c.slept_periods,
            self.estimated,
            clipped[0],
            clipped[1],
            clipped[2],
            clipped[3],
            clipped[4],
            clipped[5],
            rejected.by_reason[0],
            rejected.by_reason[1],
            rejected.by_reason[2],
            rejected.by_reason[3],
            between.still_ms / 1000,
            between.moving_ms / 1000
        );
        let _ = serial_line::status(
            serial,
            samples,
            (self.strides, self.distance_mm, self.estimated),
            clipped,
            steps,
            c,
        );
    }
}

//! Start-up calibration, as the user sees it.
//!
//! The gait core calibrates itself from the data: the first time the clip has rested for
//! [`gaitclip::detect::foot_frame::FIRST_FRAME_AFTER_MS`] it takes the gyroscope bias and the up axis
//! from that rest, and it learns the forward axis from the first steps. No stride can be
//! measured before that, so the board tells its user what it is waiting for:
//!
//! 1. every [`NAG_EVERY_MS`] until the clip has rested: "hold still";
//! 2. once: the gyroscope bias and gravity it measured, with a warning when either is outside
//!    the MPU6050's datasheet tolerance (zero-rate output ±20 °/s; a gravity reading off by
//!    more than 10 % means a wrong range or a damaged part);
//! 3. once: the forward axis is known, strides will follow.
//!
//! The core keeps refining all of it at every rest; this only reports progress.

use gaitclip::detect::seam::StepDetector;
use gaitclip::pipeline::Pipeline;
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::units::GyroScale;

/// How often to repeat the "hold still" message.
pub const NAG_EVERY_MS: u32 = 2000;
/// MPU6050 gyroscope zero-rate output tolerance, m°/s (datasheet: ±20 °/s).
pub const GYRO_BIAS_LIMIT_MDPS: i32 = 20_000;
/// Largest believable deviation of gravity from 1 g, mg.
pub const GRAVITY_TOLERANCE_MG: i32 = 100;

/// A step of the calibration to report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartupEvent {
    /// Still waiting for a rest, this long since power-up.
    HoldStill {
        /// Time since the first sample, ms.
        waited_ms: u32,
    },
    /// The first rest was measured.
    Still {
        /// Gyroscope bias, m°/s per sensor axis.
        gyro_bias_mdps: [i32; 3],
        /// Gravity as measured, mg.
        gravity_mg: i32,
        /// Both are within the datasheet's tolerance.
        plausible: bool,
    },
    /// The forward axis is known: strides are measured from now on.
    HeadingKnown,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    WaitingForRest,
    WaitingForHeading,
    Done,
}

/// Follows the core's calibration and says what changed.
pub struct Startup {
    rate: SampleRate,
    gyro: GyroScale,
    stage: Stage,
    next_nag: u32,
}

impl Startup {
    /// Progress reporting for samples at `rate` in the gyro range `gyro`.
    pub const fn new(rate: SampleRate, gyro: GyroScale) -> Self {
        Startup {
            rate,
            gyro,
            stage: Stage::WaitingForRest,
            next_nag: 0,
        }
    }

    /// True once the core measures strides.
    pub fn done(&self) -> bool {
        self.stage == Stage::Done
    }

    /// Call after each sample the pipeline took; returns what to report, if anything.
    pub fn update<D: StepDetector>(&mut self, pipeline: &Pipeline<D>) -> Option<StartupEvent> {
        // Called for every sample: once calibrated, nothing more to look at.
        if self.stage == Stage::Done {
            return None;
        }
        let frame = pipeline.foot_frame();
        match self.stage {
            Stage::WaitingForRest => match frame {
                None => {
                    let n = pipeline.next_index();
                    if n >= self.next_nag {
                        self.next_nag = n.saturating_add(self.rate.samples_in_ms(NAG_EVERY_MS));
                        return Some(StartupEvent::HoldStill {
                            waited_ms: self.rate.ms_of_samples(n),
                        });
                    }
                    None
                }
                Some(f) => {
                    self.stage = Stage::WaitingForHeading;
                    // counts · dps/lsb °/s, in m°/s.
                    let (lsb, dps) = (self.gyro.lsb() as i64, self.gyro.dps() as i64);
                    let gyro_bias_mdps = pipeline
                        .gyro_bias()
                        .map(|c| (c as i64 * 1_000 * dps / lsb) as i32);
                    let gravity_mg = (f.gravity() as i64 * 1000
                        / gaitclip::sensor::units::FOOT_LSB_PER_G as i64)
                        as i32;
                    let plausible = gyro_bias_mdps
                        .iter()
                        .all(|b| b.abs() <= GYRO_BIAS_LIMIT_MDPS)
                        && (gravity_mg - 1000).abs() <= GRAVITY_TOLERANCE_MG;
                    Some(StartupEvent::Still {
                        gyro_bias_mdps,
                        gravity_mg,
                        plausible,
                    })
                }
            },
            Stage::WaitingForHeading => match frame {
                Some(f) if f.heading_known() => {
                    self.stage = Stage::Done;
                    Some(StartupEvent::HeadingKnown)
                }
                _ => None,
            },
            Stage::Done => None,
        }
    }
}

//! # gaitclip — stride lengths from a shoe-clip IMU, in fixed point
//!
//! gaitclip turns the raw samples of an IMU clipped to a shoe into one record per
//! stride: when it started, when the heel left the ground, when the toe left it, when the
//! heel struck, when the foot was flat again, and how long the stride was.
//!
//! ## Design
//!
//! **The unit of output is the stride, the unit of work is the sample.** Each sample goes
//! through a fixed chain of stages, in this order, each fed only the records of the stage
//! before it:
//!
//! 1. the driver — a crate of its own per part (`drivers/mpu6050`, …), which turns its
//!    registers or FIFO words into the sensor seam's records ([`gaitclip_imu`]): a
//!    [`sensor::sample::RawSample`] of counts and the scales they are in. Nothing later looks
//!    at a register or knows the part.
//! 2. [`signal::mean_filter`] — a moving average over a power-of-two ring with a running sum.
//! 3. [`detect::foot_frame`] — which way is up (gravity in the rests that the orientation-free
//!    [`detect::rest`] test finds) and which way is forward (the axis the foot pitches about in its
//!    steps); every sample is rotated into that frame by an integer matrix.
//! 4. [`detect::cycle`] — one zero-velocity instant per gait cycle, at every pace: the deepest
//!    minimum of a SHOE-type energy (angular-rate energy plus |f| − g) between two swings,
//!    found relative to the cycle rather than under a fixed threshold, and confirmed by
//!    physics (the integrated attitude's up agrees with gravity, the foot is near flat).
//!    Strides run from instant to instant; the [`detect::zupt`] strapdown integration imposes the
//!    rolling-contact velocity `ω × (h·up)` at each instant, and puts back the tilt a
//!    clipped gyro lost. Huang's [`detect::phases`] splitter gives toe-off and heel-strike, and
//!    [`detect::phase_stats`] sums the movement's acceleration phase by phase.
//! 5. [`detect::stance`] and [`detect::stance_strides`] — Huang's variance + IQR stance detector and its
//!    stance-to-stance segmentation ([`detect::stance_strides::StanceStrides`]), kept selectable as the
//!    paper's method for the side-by-side tables ([`pipeline::detectors::Detector::Stance`]).
//! 6. [`length::features`] — Huang's per-phase features (Table 2) in Q16.
//! 7. [`length::models`] — every paper's stride-length model side by side
//!    ([`length::fuzzy`] for Lu's K, [`length::svr`] for Huang's RBF SVRs), with the
//!    coefficients and support vectors that `gaitclip train` writes into
//!    [`length::trained`]; the pipeline's model fills in the length, and a stride it cannot
//!    measure gets an estimate from its neighbours ([`length::estimate`]).
//! 8. [`gait`] — the gait parameters of each stride (stance, swing, cadence, lift, turning),
//!    the last stage.
//!
//! [`pipeline::Pipeline`] composes them; a board or a host tool only feeds samples and
//! reads strides. Stages 4 and 5 are step detectors behind one seam,
//! [`detect::seam::StepDetector`]: the pipeline is generic over it, so a firmware links only the
//! detector it runs, and the host chooses at run time ([`pipeline::detectors::AnyDetector`]). Besides
//! the cycle detector and Huang's, Lu's [`detect::peak_valley`] detector works on the vertical
//! acceleration (after the [`signal::low_pass`]) and measures its steps with Lu's own chain; the
//! cycle detector is the default, because it alone gives every cycle of a jog its stance.
//!
//! **Units are types where they cross a stage.** The stages take the sensor's scale as
//! [`sensor::units::AccelScale`] and [`sensor::units::GyroScale`] (counts per g, per °/s), not the MPU6050's
//! register enums, and the foot frame hands on [`sensor::units::FootAccel`] (g/2048 in the foot
//! frame), not a bare `[i16; 3]` that a raw gyro reading could be passed as.
//!
//! **Integer on the sample path.** The per-sample work is integer arithmetic with documented
//! scaling ([`fixed`]): Q30 quaternions, counts·2⁸ accelerations, `i64` integrals. The same
//! code therefore gives bit-identical strides on a Cortex-M0 without an FPU, on a Cortex-M4,
//! and on the host that replays recordings; tests compare the two.
//!
//! **Holes are bridged, not measured across.** A lost packet or a FIFO overflow reaches the
//! pipeline as [`pipeline::Pipeline::gap`]: a short hole is interpolated ([`signal::bridge`]) and the
//! stride keeps its length (flagged), a longer one makes the stride across it a gap stride
//! without a length, so that nothing is silently measured across missing samples.
//!
//! **No heap, no panics, bounded state.** Every buffer is a compile-time capacity
//! ([`detect::stance::RING_CAPACITY`], [`detect::seam::DELAY_CAPACITY`],
//! [`detect::seam::MAX_MOVEMENT_SAMPLES`]); a movement longer than its buffer is flagged, never
//! grown. Arithmetic that could overflow on hostile input saturates or is bounded by the
//! capacities.
//!
//! **What the core refuses to know.** Boards, log transports and file formats live outside:
//! `boards/` feeds samples from a sensor or a replayed trace and logs over defmt;
//! `tests-host/` reads CSV and MCAP. The core forbids `unsafe`.
//!
//! **Any mounting.** A clip is mounted however the user mounts it. The foot frame is learnt
//! from the data and re-learnt when the clip moves; the ZUPT integrator levels itself from
//! gravity at every stance and measures horizontal distance, which does not depend on yaw.
//! `gaitclip eval --rotate N` shows the results do not change under random rotations.
//!
//! ## Layout
//!
//! The folders follow the chain, and a module imports only from folders above it in this
//! list (`tests-host/tests/import_graph.rs` checks it from the `use` lines):
//!
//! | folder | what it holds |
//! |---|---|
//! | [`fixed`] | fixed-point arithmetic: Q16/Q30, roots, quaternions, each with its range and error |
//! | [`sensor`] | what a sample is: counts, scales and rails as types, the rate, where a sample came from |
//! | [`signal`] | integer signal processing that knows no gait: mean filter, low-pass, hole bridging |
//! | [`record`] | the records a stride carries out: [`record::stride::Stride`], its flags and events, [`record::gait::GaitParameters`] |
//! | [`detect`] | finding strides: the detector seam and the three detectors with their stages |
//! | [`length`] | measuring them: features, models, SVRs, the generated tables, estimates |
//! | [`gait`] | the gait parameters of a stride |
//! | [`pipeline`] | the configuration, the detector list, and the composition of it all |
//!
//! The core does not know which sensor it has. It depends only on the seam, [`gaitclip_imu`]
//! (the sample in counts, the accelerometer's and gyroscope's scales), which
//! [`sensor::sample`] and [`sensor::units`] re-export; each driver crate provides those
//! records, and no stage calls a driver: the boards do.
//!
//! ## Units
//!
//! Sample indices count from the first sample fed (gaps included). Lengths are in mm.
//! The sample rate ([`sensor::rate::SampleRate`]) is in millihertz so that 204.8 Hz is exact.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

// Alphabetical (rustfmt's order); the chain's order is in the table above.
pub mod detect;
pub mod fixed;
pub mod gait;
pub mod length;
pub mod pipeline;
pub mod record;
pub mod sensor;
pub mod signal;

//! # gaitclip — stride lengths from a shoe-clip IMU, in fixed point
//!
//! gaitclip turns the raw samples of an MPU6050 clipped to a shoe into one record per
//! stride: when it started, when the heel left the ground, when the toe left it, when the
//! heel struck, when the foot was flat again, and how long the stride was.
//!
//! ## Design
//!
//! **The unit of output is the stride, the unit of work is the sample.** Each sample goes
//! through a fixed chain of stages, in this order, each fed only the records of the stage
//! before it:
//!
//! 1. [`mpu6050`] — the driver: one burst read per sample into a [`sample::RawSample`] of
//!    counts. Nothing later looks at a register.
//! 2. [`mean_filter`] — a moving average over a power-of-two ring with a running sum.
//! 3. [`foot_frame`] — which way is up (gravity in the rests that the orientation-free
//!    [`rest`] test finds) and which way is forward (the axis the foot pitches about in its
//!    steps); every sample is rotated into that frame by an integer matrix.
//! 4. [`cycle`] — one zero-velocity instant per gait cycle, at every pace: the deepest
//!    minimum of a SHOE-type energy (angular-rate energy plus |f| − g) between two swings,
//!    found relative to the cycle rather than under a fixed threshold, and confirmed by
//!    physics (the integrated attitude's up agrees with gravity, the foot is near flat).
//!    Strides run from instant to instant; the [`zupt`] strapdown integration imposes the
//!    rolling-contact velocity `ω × (h·up)` at each instant, and puts back the tilt a
//!    clipped gyro lost. Huang's [`phases`] splitter gives toe-off and heel-strike, and
//!    [`phase_stats`] sums the movement's acceleration phase by phase.
//! 5. [`stance`] and [`stride`] — Huang's variance + IQR stance detector and its
//!    stance-to-stance segmentation ([`stride::StanceStrides`]), kept selectable as the
//!    paper's method for the side-by-side tables ([`detector::Detector::Stance`]).
//! 6. [`features`] — Huang's per-phase features (Table 2) in Q16.
//! 7. [`models`] — every paper's stride-length model side by side ([`fuzzy`] for Lu's K,
//!    [`svr`] for Huang's RBF SVRs), with the coefficients and support vectors that
//!    `gaitclip train` writes into [`trained`]; the pipeline's model fills in the length.
//!
//! [`pipeline::Pipeline`] composes them; a board or a host tool only feeds samples and
//! reads strides. Stages 4 and 5 are step detectors behind one seam,
//! [`detector::StepDetector`]: the pipeline is generic over it, so a firmware links only the
//! detector it runs, and the host chooses at run time ([`detector::AnyDetector`]). Besides
//! the cycle detector and Huang's, Lu's [`peak_valley`] detector works on the vertical
//! acceleration (after the [`low_pass`]) and measures its steps with Lu's own chain; the
//! cycle detector is the default, because it alone gives every cycle of a jog its stance.
//!
//! **Units are types where they cross a stage.** The stages take the sensor's scale as
//! [`units::AccelScale`] and [`units::GyroScale`] (counts per g, per °/s), not the MPU6050's
//! register enums, and the foot frame hands on [`units::FootAccel`] (g/2048 in the foot
//! frame), not a bare `[i16; 3]` that a raw gyro reading could be passed as.
//!
//! **Integer on the sample path.** The per-sample work is integer arithmetic with documented
//! scaling ([`fixed`]): Q30 quaternions, counts·2⁸ accelerations, `i64` integrals. The same
//! code therefore gives bit-identical strides on a Cortex-M0 without an FPU, on a Cortex-M4,
//! and on the host that replays recordings; tests compare the two.
//!
//! **Holes are bridged, not measured across.** A lost packet or a FIFO overflow reaches the
//! pipeline as [`pipeline::Pipeline::gap`]: a short hole is interpolated ([`bridge`]) and the
//! stride keeps its length (flagged), a longer one makes the stride across it a gap stride
//! without a length, so that nothing is silently measured across missing samples.
//!
//! **No heap, no panics, bounded state.** Every buffer is a compile-time capacity
//! ([`stance::RING_CAPACITY`], [`pipeline::DELAY_CAPACITY`],
//! [`stride::MAX_MOVEMENT_SAMPLES`]); a movement longer than its buffer is flagged, never
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
//! ## Units
//!
//! Sample indices count from the first sample fed (gaps included). Lengths are in mm.
//! The sample rate ([`rate::SampleRate`]) is in millihertz so that 204.8 Hz is exact.

#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod bridge;
pub mod clipping;
pub mod cycle;
pub mod detector;
pub mod estimate;
pub mod features;
pub mod fixed;
pub mod foot_frame;
pub mod fuzzy;
pub mod gait;
pub mod low_pass;
pub mod mean_filter;
pub mod models;
pub mod mpu6050;
pub mod peak_valley;
pub mod phase_stats;
pub mod phases;
pub mod pipeline;
pub mod rate;
pub mod rest;
pub mod sample;
pub mod stance;
pub mod stride;
pub mod svr;
#[rustfmt::skip] // generated by `gaitclip train`, compared byte for byte by a test
pub mod trained;
pub mod units;
pub mod zupt;

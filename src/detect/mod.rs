//! From samples to strides: the rest test and the foot frame, the seam every step detector
//! plugs into ([`seam`]), the detectors themselves ([`cycle`], [`stance`] with
//! [`stance_strides`], [`peak_valley`]), and what they measure each stride with: the events
//! from the sagittal rate ([`gyro_events`]), Huang's phase splitter ([`phases`],
//! [`phase_stats`]) and the strapdown integration ([`zupt`], with [`clipping`] for what a
//! sensor's rails lost).

pub mod clipping;
pub mod cycle;
pub mod foot_frame;
pub mod gyro_events;
pub mod peak_valley;
pub mod phase_stats;
pub mod phases;
pub mod rest;
pub mod seam;
pub mod stance;
pub mod stance_strides;
pub mod step_check;
pub mod zupt;

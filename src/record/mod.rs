//! The records the stages hand on: the stride ([`stride::Stride`]) and its gait parameters
//! ([`gait::GaitParameters`]). Below every stage, so that detectors write them and the
//! length and gait stages read them without importing each other.

pub mod gait;
pub mod stride;

//! The gait simulator and the fixtures it writes.

pub mod fixtures;
pub mod gait_sim;
pub mod sprint;

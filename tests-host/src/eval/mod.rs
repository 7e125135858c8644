//! Scoring against ground truth, and the tables and pages it writes.

pub mod bias;
pub mod clip_sweep;
pub mod constraints;
pub mod course;
pub mod daily;
pub mod docs;
pub mod event_timing;
pub mod flag_costs;
pub mod gait_eval;
pub mod hole_sweep;
pub mod length_eval;
pub mod markdown;
pub mod matching;
pub mod plot;
pub mod rate_sweep;
pub mod running;
pub mod scoring;
pub mod sprint_sim;
pub mod stats;
pub mod tables;
pub mod wake_eval;
pub mod zupt_sweep;

//! Host tools for gaitclip: read CSV and MCAP traces, replay them through the same
//! `no_std` core the firmware runs, simulate gait fixtures with ground truth, and run the
//! firmware in QEMU with its defmt log decoded.

pub mod clip_sweep;
pub mod clock;
pub mod codegen;
pub mod cost;
pub mod cross_validation;
pub mod csv_trace;
pub mod cycle_ref;
pub mod datasets;
pub mod docs;
pub mod energy;
pub mod eval;
pub mod firmware;
pub mod fit;
pub mod fixtures;
pub mod flag_costs;
pub mod fuzzing;
pub mod gait_eval;
pub mod hole_sweep;
pub mod insn_count;

pub mod length_eval;
pub mod length_ref;
pub mod markdown;
pub mod matching;
pub mod mcap_io;
pub mod peak_valley_ref;
pub mod plot;
pub mod pod;
pub mod qemu;
pub mod rails;
pub mod rate_sweep;
pub mod reference;
pub mod replay;
pub mod resample;
pub mod running;
pub mod sim;
pub mod stats;
pub mod tables;
pub mod trace;
pub mod train;
pub mod training_set;
pub mod wake_eval;
pub mod zupt_sweep;

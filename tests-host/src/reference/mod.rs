//! The f64 references the fixed-point core is checked against.

pub mod cycle_ref;
pub mod length_ref;
pub mod peak_valley_ref;
pub mod stance_chain;

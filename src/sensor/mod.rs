//! What the sensor hands the pipeline: raw samples in counts ([`sample`]), the units the
//! stages compute in ([`units`]), and the sample rate ([`rate`]).

pub mod rate;
pub mod sample;
pub mod units;

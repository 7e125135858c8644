//! Reading recordings: CSV and MCAP, the datasets, the sensor clock, rails, resampling.

pub mod clock;
pub mod csv_trace;
pub mod datasets;
pub mod mcap_io;
pub mod rails;
pub mod recording;
pub mod resample;
pub mod trace;
pub mod units;

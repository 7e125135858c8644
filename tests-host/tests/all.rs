//! The host tools' integration tests, one binary: each file beside this one is a module of it
//! (`autotests = false` in Cargo.toml), kept where it was so that its name and the docs that
//! cite it stay as they are. One binary links the host library and its dependencies once
//! instead of once per file (37 links of the same crates); cargo-nextest still runs every test
//! in a process of its own, so a test cannot see another's state.

mod common;

#[path = "bias.rs"]
mod bias;
#[path = "board_glue.rs"]
mod board_glue;
#[path = "bus_faults.rs"]
mod bus_faults;
#[path = "cli_errors.rs"]
mod cli_errors;
#[path = "clipping.rs"]
mod clipping;
#[path = "clock_recovery.rs"]
mod clock_recovery;
#[path = "cost_counts.rs"]
mod cost_counts;
#[path = "csv_errors.rs"]
mod csv_errors;
#[path = "cycle_reference.rs"]
mod cycle_reference;
#[path = "datasets.rs"]
mod datasets;
#[path = "docs_current.rs"]
mod docs_current;
#[path = "emulated_sensor.rs"]
mod emulated_sensor;
#[path = "estimate.rs"]
mod estimate;
#[path = "event_timing.rs"]
mod event_timing;
#[path = "firmware_qemu.rs"]
mod firmware_qemu;
#[path = "fixed_point.rs"]
mod fixed_point;
#[path = "fixtures.rs"]
mod fixtures;
#[path = "fuzz_corpus.rs"]
mod fuzz_corpus;
#[path = "gait_parameters.rs"]
mod gait_parameters;
#[path = "hole_sweep.rs"]
mod hole_sweep;
#[path = "import_graph.rs"]
mod import_graph;
#[path = "json_fields.rs"]
mod json_fields;
#[path = "lengths.rs"]
mod lengths;
#[path = "mcap.rs"]
mod mcap;
#[path = "mcap_conformance.rs"]
mod mcap_conformance;
#[path = "own_recordings.rs"]
mod own_recordings;
#[path = "peak_valley.rs"]
mod peak_valley;
#[path = "pipeline_props.rs"]
mod pipeline_props;
#[path = "pipes.rs"]
mod pipes;
#[path = "rates_and_running.rs"]
mod rates_and_running;
#[path = "reference_agreement.rs"]
mod reference_agreement;
#[path = "rsc.rs"]
mod rsc;
#[path = "rsc_gatt.rs"]
mod rsc_gatt;
#[path = "sleep_policy.rs"]
mod sleep_policy;
#[path = "sprint.rs"]
mod sprint;
#[path = "stream.rs"]
mod stream;
#[path = "trace_faults.rs"]
mod trace_faults;
#[path = "trained_model.rs"]
mod trained_model;
#[path = "units.rs"]
mod units;

//! Host replay throughput: the whole of `replay` (counts conversion, pipeline, default
//! model) over a real trace, in samples per second. `gaitclip cost` compares it with
//! gaitmap's pipeline on the same trace. Needs ../shared/datasets.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gaitclip_host::cost::report::TRACE;
use gaitclip_host::io::trace::Ranges;
use gaitclip_host::{io::csv_trace, io::datasets, replay};

fn replay_trace(c: &mut Criterion) {
    let Some(root) = datasets::root_or_skip("bench replay") else {
        return;
    };
    let (dataset, trial, rate_hz) = TRACE;
    let path = root.join(dataset).join(format!("{trial}.csv"));
    let trace = csv_trace::read(&path, Some(rate_hz)).expect("the dataset trace reads");
    let mut g = c.benchmark_group("replay");
    g.throughput(Throughput::Elements(trace.samples.len() as u64));
    g.bench_function(format!("{dataset}_{trial}"), |b| {
        b.iter(|| replay::replay(std::hint::black_box(&trace), Ranges::default()))
    });
    g.finish();
}

criterion_group!(benches, replay_trace);
criterion_main!(benches);

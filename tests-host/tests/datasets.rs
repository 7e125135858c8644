//! Real recordings from `../shared/datasets` (skipped with a message when absent; a failure
//! in CI). Issue-2 level checks: the chain finds the strides of a real walk and measures them
//! to within a few percent.

use gaitclip_host::csv_trace;
use gaitclip_host::datasets::root_or_skip;
use gaitclip_host::replay::replay;
use gaitclip_host::trace::Ranges;

#[derive(Debug)]
struct RefStride {
    start_s: f64,
    end_s: f64,
    length_m: f64,
    clean: bool,
}

fn reference(root: &std::path::Path, trial: &str, rate: f64) -> Vec<RefStride> {
    let mut rdr = csv::Reader::from_path(root.join("gaitmap_walk/strides.csv")).unwrap();
    let h = rdr.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|x| x == n).unwrap();
    let (t, s, e, l, f) = (
        col("trial"),
        col("start_idx"),
        col("end_idx"),
        col("length_m"),
        col("flag"),
    );
    rdr.records()
        .map(|r| r.unwrap())
        .filter(|r| &r[t] == trial)
        .map(|r| RefStride {
            start_s: r[s].parse::<f64>().unwrap() / rate,
            end_s: r[e].parse::<f64>().unwrap() / rate,
            length_m: r[l].parse().unwrap(),
            clean: r[f].is_empty(),
        })
        .collect()
}

/// Both feet of the gaitmap walk: every clean reference stride is overlapped by a detected
/// stride of matching length (per-stride error under 12 %), and the summed length of the
/// matched clean strides is within 5 % of the Vicon sum.
#[test]
fn gaitmap_walk_strides_and_lengths() {
    let Some(root) = root_or_skip("gaitmap_walk_strides_and_lengths") else {
        return;
    };
    for trial in ["left", "right"] {
        let trace = csv_trace::read(&root.join(format!("gaitmap_walk/{trial}.csv")), None).unwrap();
        let t0 = trace.samples[0].t_s;
        let got = replay(&trace, Ranges::default()).unwrap();
        let refs = reference(&root, trial, trace.rate_hz);
        let (mut sum_ref, mut sum_got, mut matched) = (0.0, 0.0, 0);
        for r in refs.iter().filter(|r| r.clean) {
            // The detected stride whose span overlaps the reference stride the most.
            let best = got
                .iter()
                .map(|g| {
                    let ov = (g.end_s - t0).min(r.end_s) - (g.start_s - t0).max(r.start_s);
                    (ov, g)
                })
                .filter(|(ov, _)| *ov > 0.0)
                .max_by(|a, b| a.0.total_cmp(&b.0));
            let Some((_, g)) = best else {
                panic!("{trial}: reference stride at {:.2} s not found", r.start_s)
            };
            let rel = (g.length_m - r.length_m).abs() / r.length_m;
            assert!(
                rel < 0.12,
                "{trial}: stride at {:.2} s: {} m vs {} m",
                r.start_s,
                g.length_m,
                r.length_m
            );
            sum_ref += r.length_m;
            sum_got += g.length_m;
            matched += 1;
        }
        let err = (sum_got - sum_ref) / sum_ref;
        eprintln!(
            "{trial}: {matched} clean strides matched, {} detected in all, distance error {:+.2} %",
            got.len(),
            err * 100.0
        );
        assert!(matched >= 20);
        assert!(err.abs() < 0.05, "{trial}: distance error {err}");
    }
}

//! The sample clock recovered from host-clock stamps: real walks of `gaitmap_walk` and
//! `pyshoe_vicon` re-stamped as a PC logging tool stamps them (when a burst of samples
//! reaches the computer: 1–8 samples microseconds apart, then a pause; the sensor clock
//! drifting ±100 ppm against the host's), with and without holes cut in. The replay must
//! find the holes where they were cut and give the same strides as the same samples with
//! their true stamps. Skipped with a message without `../shared/datasets` (a failure in CI).

use gaitclip_host::io::clock::SampleClock;
use gaitclip_host::io::csv_trace;
use gaitclip_host::io::datasets::root_or_skip;
use gaitclip_host::io::trace::{ImuSample, Ranges, Trace};
use gaitclip_host::replay::{replay_summarised, StrideReport, Summary};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The trace on its own recovered clock, with no jitter: the truth to re-stamp.
fn on_its_clock(t: &Trace) -> Trace {
    let stamps: Vec<f64> = t.samples.iter().map(|s| s.t_s).collect();
    let clock = SampleClock::recover(&stamps, Some(t.rate_hz)).unwrap();
    assert!(clock.holes.is_empty());
    let mut out = t.clone();
    for (i, s) in out.samples.iter_mut().enumerate() {
        s.t_s = clock.t_s(i as u32);
    }
    out
}

/// Rows to cut: IPOL-like clusters of 1–3-sample holes (four holes within half a second)
/// and single holes of 1–6 samples, spread over the walk so that some fall in stances and
/// some in swings.
fn holes_to_cut(n: usize, rng: &mut ChaCha8Rng) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut at = 600;
    while at + 400 < n {
        if rng.random_bool(0.5) {
            for _ in 0..4 {
                out.push((at, rng.random_range(1..=3)));
                at += rng.random_range(15..30);
            }
        } else {
            out.push((at, rng.random_range(1..=6)));
        }
        at += rng.random_range(150..400);
    }
    out
}

/// Removes the rows of `holes` (row, length), in the trace's own rows.
fn cut(t: &Trace, holes: &[(usize, usize)]) -> Trace {
    let mut keep = vec![true; t.samples.len()];
    for &(at, len) in holes {
        for k in keep.iter_mut().skip(at).take(len) {
            *k = false;
        }
    }
    let samples = t
        .samples
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(s, _)| *s)
        .collect();
    Trace {
        samples,
        ..t.clone()
    }
}

/// Host arrival stamps: the sensor's times scaled by `1 + drift`, delivered in bursts of
/// 1–8 samples when the burst's last sample is taken plus 0.2–3 ms, the samples of a burst
/// 2 µs apart; with `stalls`, 2 % of the deliveries 10–30 ms later still. No burst spans a
/// row of `breaks` (holes lost between deliveries, where the stamps show them).
fn host_stamped(
    t: &Trace,
    drift: f64,
    breaks: &[usize],
    stalls: bool,
    rng: &mut ChaCha8Rng,
) -> Trace {
    let mut out = t.clone();
    let n = out.samples.len();
    let mut i = 0;
    while i < n {
        let next_break = breaks.iter().copied().find(|&b| b > i).unwrap_or(n);
        let burst = rng.random_range(1..=8).min(n - i).min(next_break - i);
        let last = t.samples[i + burst - 1].t_s * (1.0 + drift);
        let mut deliver = last + rng.random_range(0.0002..0.003);
        if stalls && rng.random_bool(0.02) {
            deliver += rng.random_range(0.010..0.030);
        }
        for k in 0..burst {
            out.samples[i + k].t_s = deliver + k as f64 * 2e-6;
        }
        i += burst;
    }
    // Bursts never overlap: a delivery is never before the one before it.
    for k in 1..n {
        let prev = out.samples[k - 1].t_s;
        if out.samples[k].t_s <= prev {
            out.samples[k].t_s = prev + 2e-6;
        }
    }
    out
}

fn run(t: &Trace) -> (Vec<StrideReport>, Summary) {
    replay_summarised(
        t,
        Ranges::default(),
        gaitclip::pipeline::detectors::Detector::Cycle,
        gaitclip::pipeline::config::DEFAULT_MODEL,
        false,
    )
    .unwrap()
}

/// The length difference of each pair of strides, m, and the events more than a period
/// apart; panics unless the strides match one to one with the same flags (but `bridged`,
/// which moves with a hole placed a row off into the next stride).
fn compare(name: &str, a: &[StrideReport], b: &[StrideReport]) -> (Vec<f64>, usize) {
    assert_eq!(a.len(), b.len(), "{name}: stride counts");
    let strip = |f: &[&'static str]| -> Vec<&'static str> {
        f.iter().copied().filter(|f| *f != "bridged").collect()
    };
    let (mut d, mut off) = (Vec::new(), 0);
    for (x, y) in a.iter().zip(b) {
        assert_eq!(strip(&x.flags), strip(&y.flags), "{name}: {x:?} vs {y:?}");
        for (p, q) in [
            (x.heel_off_s, y.heel_off_s),
            (x.toe_off_s, y.toe_off_s),
            (x.heel_strike_s, y.heel_strike_s),
            (x.end_s, y.end_s),
        ] {
            off += ((p - q).abs() > 1.01 / 200.0) as usize;
        }
        d.push((x.length_m - y.length_m).abs());
    }
    (d, off)
}

/// How holes fall against the host's deliveries.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Holes {
    None,
    /// Lost between deliveries: the stamps show where.
    BetweenDeliveries,
    /// Lost inside a delivery: the stamps show the delivery, the samples the place.
    InsideDeliveries,
}

#[test]
fn host_clock_stamps_give_the_strides_of_the_true_clock() {
    let Some(root) = root_or_skip("host_clock_stamps_give_the_strides_of_the_true_clock") else {
        return;
    };
    let trials = [
        "gaitmap_walk/left",
        "gaitmap_walk/right",
        "pyshoe_vicon/2017-11-22-11-22-03",
        "pyshoe_vicon/2017-11-22-11-25-20",
        "pyshoe_vicon/2017-11-27-11-12-44",
        "pyshoe_vicon/2017-12-15-18-01-18",
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let mut checked = 0;
    // Per kind of hole: holes placed exactly, holes in all, stride length differences (m).
    let mut stats: Vec<(Holes, usize, usize, Vec<f64>, usize)> = [
        Holes::None,
        Holes::BetweenDeliveries,
        Holes::InsideDeliveries,
    ]
    .map(|k| (k, 0, 0, Vec::new(), 0))
    .to_vec();
    for (k, name) in trials.iter().enumerate() {
        let path = root.join(format!("{name}.csv"));
        let truth = on_its_clock(&csv_trace::read(&path, None).unwrap());
        let drift = [100e-6, -100e-6, 37e-6][k % 3];
        for (kind_index, kind) in [
            Holes::None,
            Holes::BetweenDeliveries,
            Holes::InsideDeliveries,
        ]
        .into_iter()
        .enumerate()
        {
            let (clean, holes) = match kind {
                Holes::None => (truth.clone(), Vec::new()),
                _ => {
                    let h = holes_to_cut(truth.samples.len(), &mut rng);
                    (cut(&truth, &h), h)
                }
            };
            // The holes' places in the rows of the cut trace.
            let mut removed = 0;
            let rows: Vec<(usize, u32)> = holes
                .iter()
                .map(|&(at, len)| {
                    let r = (at - removed, len as u32);
                    removed += len;
                    r
                })
                .collect();
            let breaks: Vec<usize> = match kind {
                Holes::BetweenDeliveries => rows.iter().map(|r| r.0).collect(),
                _ => Vec::new(),
            };
            let host = host_stamped(&clean, drift, &breaks, kind == Holes::None, &mut rng);
            // Bursts make the median interval microseconds: without a rate the stamps
            // give it (the median advance per row between deliveries).
            for rate in [Some(truth.rate_hz), None] {
                let host = Trace {
                    rate_hz: rate
                        .unwrap_or_else(|| Trace::rate_from_timestamps(&host.samples).unwrap()),
                    ..host.clone()
                };
                let label = format!("{name} (drift {drift:+e}, {kind:?}, rate {rate:?})");
                let (want, ws) = run(&clean);
                let (got, gs) = run(&host);
                // The drift is found…
                let ppm = (gs.clock_rate_hz / ws.clock_rate_hz - 1.0) * 1e6;
                assert!(
                    (ppm + drift * 1e6).abs() < 10.0,
                    "{label}: clock {ppm:+.1} ppm"
                );
                // …and every hole, whole, where it was cut or within the deliveries that
                // hide it (a delivery is at most 8 rows).
                assert_eq!(
                    (gs.holes, gs.lost_samples),
                    (ws.holes, ws.lost_samples),
                    "{label}"
                );
                let placed = gaitclip_host::replay::prepare(&host, Ranges::default())
                    .unwrap()
                    .clock
                    .holes;
                let st = &mut stats[kind_index];
                for (g, r) in placed.iter().zip(&rows) {
                    assert_eq!(g.missing, r.1, "{label}: {g:?} vs {r:?}");
                    assert!(g.before.abs_diff(r.0) <= 8, "{label}: {g:?} vs {r:?}");
                    st.1 += (g.before == r.0) as usize;
                    st.2 += 1;
                }
                let (d, off) = compare(&label, &want, &got);
                st.3.extend(d);
                st.4 += off;
                checked += 1;
            }
        }
    }
    assert_eq!(checked, trials.len() * 6);
    for (kind, exact, holes, mut diff, events_off) in stats {
        diff.sort_by(f64::total_cmp);
        let mean = diff.iter().sum::<f64>() / diff.len() as f64;
        let p95 = diff[diff.len() * 95 / 100];
        let worst = diff[diff.len() - 1];
        eprintln!(
            "{kind:?}: {exact} of {holes} holes placed exactly; stride length difference mean {:.2} mm, p95 {:.1} mm, worst {:.1} mm over {} strides; {events_off} events more than a period off",
            mean * 1e3,
            p95 * 1e3,
            worst * 1e3,
            diff.len()
        );
        match kind {
            // No hole: the strides of the true clock, to the millimetre.
            Holes::None => assert!(
                worst <= 0.001 + 1e-9 && events_off == 0,
                "{kind:?}: {worst}"
            ),
            // Holes where deliveries break: the stamps place them; a rare one moves into
            // the delivery after it where the rate looks smoother there.
            Holes::BetweenDeliveries => {
                assert!(exact * 100 >= holes * 95, "{kind:?}: {exact} of {holes}");
                assert!(
                    p95 <= 0.001 + 1e-9 && mean <= 0.001,
                    "{kind:?}: {mean} / {p95}"
                );
            }
            // Holes inside a delivery: the stamps cannot place them, the angular rate does
            // for most; one a row off in a fast swing moves that stride by centimetres.
            // Measured with the cycle detector: mean 1.98 mm, p95 14 mm (Huang's stance
            // detector: under 1.5 mm; the rolling-contact velocity at a stance instant
            // takes the rate of the very sample a misplaced hole shifts).
            Holes::InsideDeliveries => {
                assert!(exact * 100 >= holes * 70, "{kind:?}: {exact} of {holes}");
                assert!(mean <= 0.0025, "{kind:?}: mean {mean}");
            }
        }
    }
}

/// The smallest recordings the fit has to work with: a second of samples and a few holes.
#[test]
fn a_short_recording_still_finds_its_holes() {
    let samples: Vec<ImuSample> = (0..200)
        .filter(|i| ![50, 51, 120].contains(i))
        .map(|i| ImuSample {
            t_s: 3.0 + i as f64 / 200.0,
            ..Default::default()
        })
        .collect();
    let stamps: Vec<f64> = samples.iter().map(|s| s.t_s).collect();
    for rate in [Some(200.0), None] {
        let c = SampleClock::recover(&stamps, rate).unwrap();
        assert_eq!(c.holes.len(), 2, "{rate:?}: {:?}", c.holes);
        assert_eq!((c.holes[0].before, c.holes[0].missing), (50, 2));
        assert_eq!((c.holes[1].before, c.holes[1].missing), (118, 1));
        assert!((c.rate_hz() - 200.0).abs() < 1e-6, "{}", c.rate_hz());
        assert!((c.offset_s - 3.0).abs() < 1e-9);
    }
}

//! Property tests of the core on arbitrary input: never a panic (overflow checks are on in
//! tests), state bounded by its constants, and every stride well formed.

use gaitclip::length::estimate::MAX_CYCLES;
use gaitclip::pipeline::config::{Config, BRIDGE_MAX_MS, FILL_MAX_MS};
use gaitclip::pipeline::detectors::AnyDetector;
use gaitclip::pipeline::Pipeline;
use gaitclip::record::stride::{Stride, StrideFlags, MAX_STRIDE_MM};
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use gaitclip_mpu6050::{AccelRange, GyroRange};
use proptest::prelude::*;

fn sample() -> impl Strategy<Value = RawSample> {
    (any::<[i16; 3]>(), any::<[i16; 3]>(), any::<i16>()).prop_map(|(accel, gyro, temp)| RawSample {
        accel,
        gyro,
        temp,
    })
}

/// A foot at rest in some orientation: about 1 g, little rotation.
fn quiet() -> impl Strategy<Value = RawSample> {
    (
        any::<[i8; 3]>(),
        prop::sample::select(vec![[2048i16, 0, 0], [0, -2048, 0], [1200, 1200, -1200]]),
    )
        .prop_map(|(g, a)| RawSample {
            accel: a,
            gyro: g.map(|v| v as i16),
            temp: 0,
        })
}

/// Runs of a repeated sample, alternating rest and motion: still stretches and rails are
/// where stance logic lives.
fn runs() -> impl Strategy<Value = Vec<RawSample>> {
    prop::collection::vec((prop_oneof![sample(), quiet()], 1usize..300), 0..40).prop_map(|v| {
        v.into_iter()
            .flat_map(|(s, n)| std::iter::repeat_n(s, n))
            .collect()
    })
}

/// The demo walk's counts (200 Hz, ±16 g, ±2000 °/s): real strides to cut gaps into.
fn walk() -> Vec<RawSample> {
    gaitclip_host::sim::fixtures::firmware_trace_counts().unwrap()
}

/// Feeds `samples` with a gap of `missing` before each index in `gaps`; checks every stride
/// and returns them.
fn check<const M: usize>(
    samples: &[RawSample],
    rate_hz: u32,
    gaps: &[(usize, u32)],
) -> Vec<Stride> {
    let rate = SampleRate::from_hz(rate_hz).unwrap();
    let mut p = Pipeline::<AnyDetector<M>>::sized(Config::new(
        rate,
        AccelRange::G16.scale(),
        GyroRange::Dps2000.scale(),
    ));
    let mut strides = Vec::new();
    for (i, s) in samples.iter().enumerate() {
        for &(_, missing) in gaps.iter().filter(|g| g.0 == i) {
            strides.extend(p.gap(missing));
        }
        strides.extend(p.process(s));
    }
    strides.extend(std::iter::from_fn(|| p.finish()));
    let buffer_ms = M as u64 * 1000 / rate_hz as u64;
    for (k, s) in strides.iter().enumerate() {
        assert!(
            s.events.start <= s.events.heel_off && s.events.heel_off <= s.events.toe_off,
            "{s:?}"
        );
        assert!(
            s.events.toe_off <= s.events.heel_strike && s.events.heel_strike <= s.events.end,
            "{s:?}"
        );
        assert!(s.events.start < s.events.end, "{s:?}");
        // A gap stride's events after the gap are unknown (set to the gap, which may be its
        // end when the recording stops in it); every other stride ends after heel-strike.
        assert!(
            s.events.heel_strike < s.events.end || s.flags.has(StrideFlags::GAP),
            "{s:?}"
        );
        assert!(s.events.end <= p.next_index(), "{s:?}");
        // One stride's length at most; an estimate of a stride that lasted several cycles
        // (holes swallowed a stance instant) is theirs.
        let most = match s.flags.has(StrideFlags::ESTIMATED) {
            true => MAX_CYCLES * MAX_STRIDE_MM,
            false => MAX_STRIDE_MM,
        };
        assert!(s.length_mm <= most, "{s:?}");
        if s.flags.has(StrideFlags::GAP) {
            // No length measured across a gap: the length is the estimate, or none.
            assert!(!s.flags.valid());
            assert!(
                s.flags.has(StrideFlags::ESTIMATED) || s.length_mm == 0,
                "a gap stride's length is estimated or absent: {s:?}"
            );
        }
        // The movement buffer holds M samples of heel-off to foot-flat; a longer movement is
        // flagged, not grown.
        let moved_ms = (s.events.foot_flat - s.events.heel_off) as u64 * 1000 / rate_hz as u64;
        if moved_ms > buffer_ms + 1 && !s.flags.has(StrideFlags::GAP) {
            assert!(s.flags.has(StrideFlags::TOO_LONG), "{s:?}");
        }
        if k > 0 {
            assert!(s.index == strides[k - 1].index + 1);
            assert!(
                s.events.start >= strides[k - 1].events.end || s.flags.has(StrideFlags::FROM_REST),
                "{s:?}"
            );
        }
    }
    strides
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn arbitrary_samples_never_panic(samples in prop::collection::vec(sample(), 0..3000), rate in 50u32..=1000) {
        check::<1024>(&samples, rate, &[]);
    }

    #[test]
    fn runs_and_gaps_never_panic(samples in runs(), rate in 50u32..=1000, gaps in prop::collection::vec((0usize..5000, 0u32..100_000), 0..5)) {
        check::<1024>(&samples, rate, &gaps);
    }

    #[test]
    fn a_small_movement_buffer_flags_instead_of_growing(samples in runs(), rate in 50u32..=1000) {
        check::<32>(&samples, rate, &[]);
    }

    /// A gap cut anywhere into a real walk: every stride the gap does not touch is the same
    /// as without it, and the stride it touches is reported once and flagged: bridged (still
    /// measured) when the hole is short, a gap stride without a length when it is long.
    #[test]
    fn a_gap_in_a_walk_costs_only_the_stride_it_falls_in(at in 0usize..6000, missing in 1u32..400) {
        let mut counts = walk();
        let whole = check::<1024>(&counts, 200, &[]);
        let at = at.min(counts.len() - 1);
        let lost = missing as usize;
        counts.drain(at..(at + lost).min(counts.len()));
        let cut = check::<1024>(&counts, 200, &[(at, missing)]);
        // A stride wholly before the gap is untouched, once the stance after it has lasted
        // long enough (1 s, 200 samples, plus the drain's reach) to say whether it was the
        // last before rest: a gap in that stance leaves the question open.
        let gap_end = at as u32 + missing;
        for w in &whole {
            let before = w.events.end + 210 < at as u32;
            if before {
                let c = cut.iter().find(|c| c.events.start == w.events.start).unwrap_or_else(|| panic!("{w:?} lost"));
                prop_assert_eq!(c.length_mm, w.length_mm);
                prop_assert_eq!(c.flags, w.flags);
            }
        }
        // Every stride that spans the hole says so: bridged when the hole is short enough
        // (never a gap then), bridged or a gap (in a stance, or a movement) when it was
        // filled, a gap when detection restarted after it.
        let rate = SampleRate::from_hz(200).unwrap();
        let (bridge, fill) = (rate.samples_in_ms(BRIDGE_MAX_MS), rate.samples_in_ms(FILL_MAX_MS));
        for c in &cut {
            if c.events.start < at as u32 && c.events.end > at as u32 {
                let bridged = c.flags.has(StrideFlags::BRIDGED);
                let gap = c.flags.has(StrideFlags::GAP);
                if missing <= bridge {
                    prop_assert!(bridged && !gap, "{:?} spans the hole at {}..{}", c, at, gap_end);
                } else if missing <= fill {
                    prop_assert!(bridged || gap, "{:?} spans the hole at {}..{}", c, at, gap_end);
                } else {
                    prop_assert!(gap, "{:?} spans the hole at {}..{}", c, at, gap_end);
                }
            }
        }
        let gap_strides = cut.iter().filter(|c| c.flags.has(StrideFlags::GAP)).count();
        prop_assert!(gap_strides <= 1, "{:?}", cut);
    }
}

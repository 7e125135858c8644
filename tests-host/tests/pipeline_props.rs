//! Property tests of the core on arbitrary input: never a panic (overflow checks are on in
//! tests), and every stride well formed.

use gaitclip::pipeline::{Config, Pipeline};
use gaitclip::rate::SampleRate;
use gaitclip::sample::{AccelRange, GyroRange, RawSample};
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

fn check(samples: &[RawSample], rate_hz: u32, gaps: &[usize]) {
    let mut p = Pipeline::new(Config::new(
        SampleRate::from_hz(rate_hz).unwrap(),
        AccelRange::G16,
        GyroRange::Dps2000,
    ));
    let mut strides = Vec::new();
    for (i, s) in samples.iter().enumerate() {
        if gaps.contains(&i) {
            strides.extend(p.gap(7));
        }
        strides.extend(p.process(s));
    }
    strides.extend(p.finish().into_iter().flatten());
    for (k, s) in strides.iter().enumerate() {
        assert!(s.start <= s.heel_off && s.heel_off <= s.toe_off, "{s:?}");
        assert!(s.toe_off <= s.heel_strike && s.heel_strike < s.end, "{s:?}");
        assert!(s.end <= p.next_index(), "{s:?}");
        if k > 0 {
            assert!(s.index == strides[k - 1].index + 1);
            assert!(
                s.start >= strides[k - 1].end
                    || s.flags.has(gaitclip::stride::StrideFlags::FROM_REST),
                "{s:?}"
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn arbitrary_samples_never_panic(samples in prop::collection::vec(sample(), 0..3000), rate in 100u32..=1000) {
        check(&samples, rate, &[]);
    }

    #[test]
    fn runs_and_gaps_never_panic(samples in runs(), rate in 100u32..=1000, gaps in prop::collection::vec(0usize..5000, 0..5)) {
        check(&samples, rate, &gaps);
    }
}

//! The dual-range merge against an f64 reference, the FIFO words, and the ranges against
//! ST's published sensitivities.

use gaitclip_imu::RawSample;
use gaitclip_lsm6dsv320x::fifo::{FifoWord, Tag, WORD_BYTES};
use gaitclip_lsm6dsv320x::merge::{Assembler, DualRange};
use gaitclip_lsm6dsv320x::{AccelRange, GyroRange, HighGRange};
use proptest::prelude::*;

const HIGH: [HighGRange; 5] = [
    HighGRange::G32,
    HighGRange::G64,
    HighGRange::G128,
    HighGRange::G256,
    HighGRange::G320,
];

/// ST's sensitivities as its driver converts them (`from_fs*_to_mg`, `from_fs*_to_mdps`,
/// lsm6dsv320x-rs 2.x), written here from that source, not from this crate.
#[test]
fn sensitivities_are_sts_to_their_rounding() {
    let low = [
        (AccelRange::G2, 0.061),
        (AccelRange::G4, 0.122),
        (AccelRange::G8, 0.244),
        (AccelRange::G16, 0.488),
    ];
    for (r, mg) in low {
        let ours = 1000.0 / r.lsb_per_g() as f64;
        assert!((ours - mg).abs() <= 0.0005, "{r:?}: {ours} mg vs ST's {mg}");
        assert_eq!(r.full_scale_g() as f64 * r.lsb_per_g() as f64, 32_768.0);
    }
    // ST truncates 1000/1024 = 0.9765625 to 0.976 and doubles that for ±64, ±128 and
    // ±256 g (7.808 where 1000/128 = 7.8125), so its figures sit up to 0.06 % below the
    // power-of-two counts; they agree to 0.1 %.
    let high = [0.976, 1.952, 3.904, 7.808, 10.417];
    for (r, mg) in HIGH.into_iter().zip(high) {
        let ours = 1000.0 / r.lsb_per_g() as f64;
        assert!(
            ((ours - mg) / mg).abs() < 1e-3,
            "{r:?}: {ours} mg vs ST's {mg}"
        );
        // The full scale fits the counts (±320 g at 96 per g is 30 720).
        assert!(r.full_scale_g() * r.lsb_per_g() <= 32_768, "{r:?}");
    }
    let gyro = [
        (GyroRange::Dps250, 8.75),
        (GyroRange::Dps500, 17.5),
        (GyroRange::Dps1000, 35.0),
        (GyroRange::Dps2000, 70.0),
        (GyroRange::Dps4000, 140.0),
    ];
    for (r, mdps) in gyro {
        let ours = 1000.0 / r.scale().lsb_per_dps();
        assert!(
            (ours - mdps).abs() <= 1e-9,
            "{r:?}: {ours} mdps vs ST's {mdps}"
        );
        assert!(r.full_scale_dps() as f64 * r.scale().lsb_per_dps() <= 32_768.0);
    }
    // Field values as ST's register map gives them (CTRL8.FS_XL, CTRL1_XL_HG.FS_XL_HG,
    // CTRL6.FS_G).
    assert_eq!(AccelRange::G16.field(), 0b11);
    assert_eq!(HIGH.map(|r| r.field()), [0, 1, 2, 3, 4]);
    assert_eq!(GyroRange::Dps4000.field(), 0x5);
    assert_eq!(GyroRange::Dps250.field(), 0x1);
}

/// The merge in f64: the low-g value in g unless the axis sits at or beyond its rail, then
/// the high-g samples' mean in g; out in the merged counts, unrounded.
fn merge_f64(d: &DualRange, low_lsb: f64, high_lsb: f64, low: i16, high: &[i16]) -> f64 {
    let g = if (low as i32).abs() >= d.rail_counts() && !high.is_empty() {
        high.iter().map(|&h| h as f64).sum::<f64>() / high.len() as f64 / high_lsb
    } else {
        low as f64 / low_lsb
    };
    g * d.scale().lsb_per_g() as f64
}

proptest! {
    /// Every axis within half a merged count of the f64 merge, and from the same channel.
    #[test]
    fn merge_is_within_half_a_count_of_f64(
        hi in 0usize..5,
        low in any::<i16>(),
        high in proptest::collection::vec(any::<i16>(), 0..20),
    ) {
        let r = HIGH[hi];
        let d = DualRange::new(AccelRange::G16, r);
        let sum: i32 = high.iter().map(|&h| h as i32).sum();
        let (got, took_high) = d.merge_axis(low, sum, high.len() as u32);
        let exact = merge_f64(&d, 2048.0, r.lsb_per_g() as f64, low, &high);
        prop_assert!((got as f64 - exact).abs() <= 0.5 + 1e-9, "{got} vs {exact}");
        prop_assert_eq!(took_high, (low as i32).abs() >= d.rail_counts() && !high.is_empty());
    }
}

#[test]
fn the_rail_is_15_and_a_half_g_of_16() {
    let d = DualRange::new(AccelRange::G16, HighGRange::G128);
    assert_eq!(d.rail_counts(), 31_744);
    assert_eq!(d.scale().lsb_per_g(), 256);
    // Just under the rail: the low-g value, rescaled (31 743 / 8 = 3 967.9 → 3 968).
    assert_eq!(d.merge_axis(31_743, 9_000, 2), (3_968, false));
    // At it: the high-g mean (9 001 / 2 = 4 500.5 → 4 501, half away from zero).
    assert_eq!(d.merge_axis(31_744, 9_001, 2), (4_501, true));
    assert_eq!(d.merge_axis(-32_768, -9_001, 2), (-4_501, true));
    // No high-g sample in the period: the clipped low-g value stays.
    assert_eq!(d.merge_axis(32_767, 0, 0), (4_096, false));
    assert_eq!(d.with_rail_counts(40_000).rail_counts(), 32_767);
}

#[test]
fn fifo_words_round_trip_and_decode_the_tag_byte() {
    // TAG_SENSOR 0x1D (high-g) in bits 3–7, TAG_CNT 2 in bits 1–2: 0b11101_10_0.
    let b: [u8; WORD_BYTES] = [0b1110_1100, 0x34, 0x12, 0xFF, 0xFF, 0x00, 0x80];
    let w = FifoWord::from_bytes(&b);
    assert_eq!(w.tag, Tag::HighG);
    assert_eq!(w.slot, 2);
    assert_eq!(w.data, [0x1234, -1, i16::MIN]);
    assert_eq!(w.to_bytes(), b);
    assert_eq!(
        FifoWord::from_bytes(&[0x01 << 3, 0, 0, 0, 0, 0, 0]).tag,
        Tag::Gyro
    );
    assert_eq!(
        FifoWord::from_bytes(&[0x02 << 3, 0, 0, 0, 0, 0, 0]).tag,
        Tag::Accel
    );
    assert_eq!(
        FifoWord::from_bytes(&[0x13 << 3, 0, 0, 0, 0, 0, 0]).tag,
        Tag::Other(0x13)
    );
}

fn word(tag: Tag, slot: u8, data: [i16; 3]) -> FifoWord {
    FifoWord {
        tag,
        slot: slot & 3,
        data,
    }
}

/// Low-g and gyro every other slot, high-g in every slot (480 Hz against 240 Hz), the words
/// of a slot in either order: each sample merges the high-g samples of its own period.
#[test]
fn the_assembler_merges_each_period_high_g_mean() {
    let d = DualRange::new(AccelRange::G16, HighGRange::G128);
    let mut a = Assembler::new(d);
    let mut out: Vec<RawSample> = Vec::new();
    let mut push = |a: &mut Assembler, w| out.extend(a.push(w));
    // Slot 0: high-g first, then accel (x at the rail) and gyro.
    push(&mut a, word(Tag::HighG, 0, [5_000, 10, 20]));
    push(&mut a, word(Tag::Accel, 0, [32_767, 80, 2_048]));
    push(&mut a, word(Tag::Gyro, 0, [1, 2, 3]));
    // Slot 1: high-g only.
    push(&mut a, word(Tag::HighG, 1, [6_000, 12, 22]));
    // Slot 2: accel and gyro first, then its high-g.
    push(&mut a, word(Tag::Gyro, 2, [4, 5, 6]));
    push(&mut a, word(Tag::Accel, 2, [-32_768, 0, 0]));
    push(&mut a, word(Tag::HighG, 2, [-7_001, 0, 0]));
    // Slot 3: high-g only, then the end.
    push(&mut a, word(Tag::HighG, 3, [-7_000, 0, 0]));
    out.extend(a.flush());
    assert_eq!(out.len(), 2);
    // First sample: x from slot 0's high-g; y, z rescaled from low-g (80/8, 2048/8).
    assert_eq!(out[0].accel, [5_000, 10, 256]);
    assert_eq!(out[0].gyro, [1, 2, 3]);
    // Second: x the mean of slots 1 and 2 ((6 000 − 7 001) / 2 = −500.5 → −501).
    assert_eq!(out[1].accel, [-501, 0, 0]);
    assert_eq!(out[1].gyro, [4, 5, 6]);
    assert_eq!(a.high_g_axes(), 2);
    assert_eq!(a.high_g_missing(), 0);
    // Slot 3's high-g sample had no low-g sample to join: nothing more came out.
    assert_eq!(a.unpaired(), 0);
}

#[test]
fn the_assembler_counts_what_it_cannot_pair() {
    let mut a = Assembler::new(DualRange::new(AccelRange::G16, HighGRange::G64));
    assert_eq!(a.push(word(Tag::Accel, 0, [32_767, 0, 0])), None);
    // A new slot with the gyro missing from the last: no sample, counted.
    assert_eq!(a.push(word(Tag::Accel, 1, [32_767, 0, 0])), None);
    assert_eq!(a.unpaired(), 1);
    assert_eq!(a.push(word(Tag::Gyro, 1, [0, 0, 0])), None);
    // At the rail with no high-g sample in the period: kept clipped, counted.
    let s = a.flush().unwrap();
    assert_eq!(s.accel[0], 8_192);
    assert_eq!(a.high_g_missing(), 1);
}

#[test]
fn rates_as_sts_codes_name_them() {
    use gaitclip_lsm6dsv320x::{HighGOdr, Odr};
    // DataRate: 0x2 = 7.5 Hz … 0x7 = 240 Hz … 0xC = 7 680 Hz; HgXlDataRate: 0x3 = 480 Hz …
    // 0x7 = 7 680 Hz.
    assert_eq!((Odr::Hz7_5.field(), Odr::Hz7_5.millihertz()), (0x2, 7_500));
    assert_eq!(
        (Odr::Hz240.field(), Odr::Hz240.millihertz()),
        (0x7, 240_000)
    );
    assert_eq!(
        (Odr::Hz7680.field(), Odr::Hz7680.millihertz()),
        (0xC, 7_680_000)
    );
    assert_eq!((HighGOdr::Hz480.field(), HighGOdr::Hz480.hz()), (0x3, 480));
    assert_eq!(
        (HighGOdr::Hz7680.field(), HighGOdr::Hz7680.hz()),
        (0x7, 7_680)
    );
    for odr in [Odr::Hz15, Odr::Hz240, Odr::Hz7680] {
        assert_eq!(Odr::from_hz(odr.millihertz() / 1000), Some(odr));
    }
    assert_eq!(Odr::from_hz(7), Some(Odr::Hz7_5));
    assert_eq!(Odr::from_hz(200), None);
    assert_eq!(HighGOdr::from_hz(960), Some(HighGOdr::Hz960));
    assert_eq!(HighGOdr::from_hz(240), None);
}

#[test]
fn field_values_name_their_ranges_back() {
    for r in [
        AccelRange::G2,
        AccelRange::G4,
        AccelRange::G8,
        AccelRange::G16,
    ] {
        assert_eq!(AccelRange::from_field(r.field()), Some(r));
    }
    for r in HIGH {
        assert_eq!(HighGRange::from_field(r.field()), Some(r));
    }
    for f in 1..=5 {
        assert_eq!(GyroRange::from_field(f).map(GyroRange::field), Some(f));
    }
    assert_eq!(AccelRange::from_field(4), None);
    assert_eq!(HighGRange::from_field(5), None);
    assert_eq!(GyroRange::from_field(0), None);
}

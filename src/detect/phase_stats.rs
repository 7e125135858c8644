//! Integer summaries of one movement's foot-frame acceleration, phase by phase.
//!
//! The stride stage keeps the movement (heel-off to foot-flat) in a buffer only until its
//! phases are split; what the length models need of it is a handful of sums per phase and
//! per signal, which this module takes. They are exact (integer) and small, so a stride
//! record carries them to the feature stage ([`crate::length::features`]) without the buffer.
//!
//! Signals, all in g/2048 (the foot frame's [`crate::sensor::units::FOOT_LSB_PER_G`]):
//! vertical (gravity removed), sagittal (forward), and the magnitude of the specific force
//! minus 1 g (orientation-free: what a phone's step-length models call `|a|`).

/// Number of signals summarised.
pub const CHANNELS: usize = 3;
/// Number of segments summarised: the three dynamic phases and the whole movement.
pub const SEGMENTS: usize = 4;

/// One signal of the movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Channel {
    /// Foot-frame vertical acceleration, gravity removed.
    Vertical = 0,
    /// Foot-frame forward (sagittal) acceleration.
    Sagittal = 1,
    /// Specific-force magnitude minus 1 g.
    Magnitude = 2,
}

impl Channel {
    /// Every channel, in index order.
    pub const ALL: [Channel; CHANNELS] = [Channel::Vertical, Channel::Sagittal, Channel::Magnitude];

    /// Short name (`vert`, `sag`, `mag`).
    pub const fn name(self) -> &'static str {
        match self {
            Channel::Vertical => "vert",
            Channel::Sagittal => "sag",
            Channel::Magnitude => "mag",
        }
    }
}

/// One stretch of the movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Segment {
    /// Heel-off to toe-off.
    PushOff = 0,
    /// Toe-off to heel-strike.
    Swing = 1,
    /// Heel-strike to foot-flat.
    HeelStrike = 2,
    /// Heel-off to foot-flat: the whole movement (the stance adds nothing but rest).
    Movement = 3,
}

impl Segment {
    /// Every segment, in index order.
    pub const ALL: [Segment; SEGMENTS] = [
        Segment::PushOff,
        Segment::Swing,
        Segment::HeelStrike,
        Segment::Movement,
    ];

    /// Short name (`push_off`, `swing`, `heel_strike`, `movement`).
    pub const fn name(self) -> &'static str {
        match self {
            Segment::PushOff => "push_off",
            Segment::Swing => "swing",
            Segment::HeelStrike => "heel_strike",
            Segment::Movement => "movement",
        }
    }
}

/// Sums of one signal over one segment, in g/2048.
///
/// Range: exact for segments of up to 2³² samples (sums in `i64`, squares in `u64` bounded
/// by 2³⁰ per sample).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ChannelStats {
    /// Largest value (0 for an empty segment).
    pub max: i16,
    /// Smallest value (0 for an empty segment).
    pub min: i16,
    /// Σ x.
    pub sum: i64,
    /// Σ |x|.
    pub sum_abs: u64,
    /// Σ x².
    pub sum_sq: u64,
}

/// Sums of every signal over one segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct SegmentStats {
    /// Number of samples.
    pub samples: u32,
    /// Per [`Channel`].
    pub channels: [ChannelStats; CHANNELS],
}

impl SegmentStats {
    /// Adds a sample's first [`CHANNELS`] columns.
    fn add<const N: usize>(&mut self, x: &[i16; N]) {
        let first = self.samples == 0;
        self.samples = self.samples.saturating_add(1);
        for (c, &v) in self.channels.iter_mut().zip(x.iter()) {
            if first {
                c.max = v;
                c.min = v;
            } else {
                c.max = c.max.max(v);
                c.min = c.min.min(v);
            }
            c.sum = c.sum.saturating_add(v as i64);
            c.sum_abs = c.sum_abs.saturating_add(v.unsigned_abs() as u64);
            c.sum_sq = c.sum_sq.saturating_add((v as i64 * v as i64) as u64);
        }
    }
}

/// The summaries of one movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct StrideStats {
    /// Per [`Segment`].
    pub segments: [SegmentStats; SEGMENTS],
}

impl StrideStats {
    /// No samples in any segment.
    pub const EMPTY: StrideStats = {
        let c = ChannelStats {
            max: 0,
            min: 0,
            sum: 0,
            sum_abs: 0,
            sum_sq: 0,
        };
        let seg = SegmentStats {
            samples: 0,
            channels: [c; CHANNELS],
        };
        StrideStats {
            segments: [seg; SEGMENTS],
        }
    };

    /// Summarises `movement` (`[vertical, sagittal, magnitude, …]` per sample; columns after
    /// the [`CHANNELS`] are not summed) split at the offsets `toe_off` and `heel_strike`
    /// (clamped to the movement, in order).
    // Not inlined (nor are the splitter and the stride closing): each keeps its
    // temporaries on the stack only while it runs, which a 16 KiB Cortex-M0 needs.
    #[inline(never)]
    pub fn measure<const N: usize>(movement: &[[i16; N]], toe_off: u32, heel_strike: u32) -> Self {
        let len = movement.len();
        let to = (toe_off as usize).min(len);
        let hs = (heel_strike as usize).clamp(to, len);
        let mut out = StrideStats::EMPTY;
        for (i, x) in movement.iter().enumerate() {
            let phase = if i < to {
                Segment::PushOff
            } else if i < hs {
                Segment::Swing
            } else {
                Segment::HeelStrike
            };
            out.segments[phase as usize].add(x);
            out.segments[Segment::Movement as usize].add(x);
        }
        out
    }

    /// The summary of `channel` over `segment`.
    pub const fn get(&self, segment: Segment, channel: Channel) -> &ChannelStats {
        &self.segments[segment as usize].channels[channel as usize]
    }
}

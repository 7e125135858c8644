//! One raw sample as the sensor seam hands it over ([`gaitclip_imu::RawSample`], whichever
//! part read it), and where a reading clips ([`Rails`]).

pub use gaitclip_imu::RawSample;

/// Where one axis clips, in counts: a reading at or beyond `low` or `high` sits at a rail
/// and the true value may lie beyond it.
///
/// A part's output registers saturate at the counts' extremes ([`AxisRails::FULL_SCALE`]), but
/// real parts clip below their nominal range (a ±16 g accelerometer axis at −15.6 g, a
/// ±2000 °/s gyro at ±1 988 °/s), so a replayed recording's rails are learnt from its data
/// or given, axis by axis, and the core is told them ([`Rails`]), never assumes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisRails {
    /// Lowest reading that is not at a rail, less one: readings `<= low` are clipped.
    pub low: i16,
    /// Readings `>= high` are clipped.
    pub high: i16,
}

impl AxisRails {
    /// The counts' own extremes: what a part's output registers saturate at.
    pub const FULL_SCALE: AxisRails = AxisRails {
        low: i16::MIN,
        high: i16::MAX,
    };

    /// Rails at `low` < 0 < `high`; `None` for rails that do not bracket zero (an axis at
    /// rest reads near zero or near 1 g, never at a rail).
    pub const fn new(low: i16, high: i16) -> Option<Self> {
        if low < 0 && high > 0 {
            Some(AxisRails { low, high })
        } else {
            None
        }
    }

    /// True when `v` sits at (or beyond) a rail.
    pub const fn clipped(self, v: i16) -> bool {
        v >= self.high || v <= self.low
    }

    /// The rail on `v`'s side of zero, counts: the one a clipped run of `v`'s sign sits at.
    pub const fn rail_of(self, v: i32) -> i32 {
        if v >= 0 {
            self.high as i32
        } else {
            self.low as i32
        }
    }

    /// The smaller of the two rails' magnitudes, counts.
    pub const fn min_magnitude(self) -> u32 {
        let lo = (self.low as i32).unsigned_abs();
        let hi = self.high as u32;
        if lo < hi {
            lo
        } else {
            hi
        }
    }
}

/// The rails of every axis of both sensors ([`AxisRails`]), in the counts the pipeline is fed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rails {
    /// Accelerometer x, y, z.
    pub accel: [AxisRails; 3],
    /// Gyroscope x, y, z.
    pub gyro: [AxisRails; 3],
}

impl Rails {
    /// Every axis at the counts' extremes: a part as the firmware reads it.
    pub const FULL_SCALE: Rails = Rails {
        accel: [AxisRails::FULL_SCALE; 3],
        gyro: [AxisRails::FULL_SCALE; 3],
    };

    /// True if an accelerometer axis of `s` sits at a rail.
    pub const fn accel_clipped(&self, s: &RawSample) -> bool {
        self.accel[0].clipped(s.accel[0])
            || self.accel[1].clipped(s.accel[1])
            || self.accel[2].clipped(s.accel[2])
    }

    /// True if a gyroscope axis of `s` sits at a rail.
    pub const fn gyro_clipped(&self, s: &RawSample) -> bool {
        self.gyro[0].clipped(s.gyro[0])
            || self.gyro[1].clipped(s.gyro[1])
            || self.gyro[2].clipped(s.gyro[2])
    }

    /// Which axes of `s` sit at a rail: bits 0–2 accelerometer x, y, z, bits 3–5 gyroscope
    /// x, y, z.
    pub const fn clipped_axes(&self, s: &RawSample) -> u8 {
        let mut bits = 0u8;
        let mut k = 0;
        while k < 3 {
            if self.accel[k].clipped(s.accel[k]) {
                bits |= 1 << k;
            }
            if self.gyro[k].clipped(s.gyro[k]) {
                bits |= 1 << (k + 3);
            }
            k += 1;
        }
        bits
    }
}

/// Where a sample fed to the tracker comes from: the sensor, or the pipeline's
/// interpolation across a hole of lost samples ([`crate::pipeline::Pipeline::gap`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Origin {
    /// Read from the sensor.
    #[default]
    Measured,
    /// Interpolated across a hole short enough to measure through
    /// ([`crate::pipeline::config::BRIDGE_MAX_MS`]): the stride is [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED).
    Bridged,
    /// Interpolated across a longer hole ([`crate::pipeline::config::FILL_MAX_MS`]), so that the
    /// stride's events outside the hole can still be found: in a movement the stride is a
    /// [`StrideFlags::GAP`](crate::record::stride::StrideFlags::GAP) stride, in a stance only [`StrideFlags::BRIDGED`](crate::record::stride::StrideFlags::BRIDGED) (a foot at rest
    /// is at rest either side of it).
    Filled,
}

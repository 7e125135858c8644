//! Rest detector, orientation-free: is the clip still?
//!
//! The foot frame ([`crate::detect::foot_frame`]) needs rest periods before it knows which way is
//! up, so this test cannot use the frame. Over a sliding window of `W` samples (≈ 50 ms) the
//! clip is at rest when both
//! - the total variance of the (mean-filtered) specific force, `Σ_axes var(a)`, is under
//!   [`ACCEL_STD_MAX_MMPS2`]², and
//! - the mean angular-rate energy `mean(|ω|²)` is under [`GYRO_RMS_MAX_MRADPS`]²,
//!
//! the accelerometer and gyroscope halves of the SHOE detector (Skog et al. 2010). Neither
//! statistic depends on how the clip is mounted. Thresholds are set in physical units and
//! converted to counts for the configured ranges; the window follows the sample rate.

use crate::sensor::rate::SampleRate;
use crate::sensor::units::{AccelScale, GyroScale};

/// Window length in milliseconds (5 samples at 100 Hz, as SHOE uses).
pub const WINDOW_MS: u32 = 50;
/// Capacity of the window ring, a power of two ≥ the longest window (50 ms at 1 kHz).
pub const WINDOW_CAPACITY: usize = 64;
/// Stance: standard deviation of the specific force (all axes together) under 0.6 m/s².
/// Walking swing stays above 3 m/s²; standing with a wobble stays under 0.3 m/s².
pub const ACCEL_STD_MAX_MMPS2: u32 = 600;
/// Stance: RMS angular rate under 0.7 rad/s (40 °/s). Mid-swing exceeds 5 rad/s; a flat
/// foot that rolls over stays under 0.5 rad/s on the recordings in `../shared/datasets`.
pub const GYRO_RMS_MAX_MRADPS: u32 = 700;

/// Thresholds of the detector, in counts of the configured ranges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RestThresholds {
    /// Window length in samples (3..=63).
    pub window: u32,
    /// Variance threshold, counts².
    pub accel_var_counts2: i64,
    /// Energy threshold, counts².
    pub gyro_energy_counts2: i64,
}

impl RestThresholds {
    /// Thresholds for a sample rate and sensor ranges.
    pub const fn new(rate: SampleRate, accel: AccelScale, gyro: GyroScale) -> Self {
        let window = rate.samples_in_ms(WINDOW_MS);
        let window = if window < 3 {
            3
        } else if window > WINDOW_CAPACITY as u32 - 1 {
            WINDOW_CAPACITY as u32 - 1
        } else {
            window
        };
        // m/s² → counts: · lsb_per_g / 9.80665.
        let a = ACCEL_STD_MAX_MMPS2 as i64 * accel.lsb_per_g() as i64 / 9807;
        // rad/s → counts: · (180/π) · lsb/dps; 180/(π·1000) = 18 000/314 159 per 10 °/s.
        let g =
            GYRO_RMS_MAX_MRADPS as i64 * gyro.lsb() as i64 * 18_000 / (314_159 * gyro.dps() as i64);
        RestThresholds {
            window,
            accel_var_counts2: a * a,
            gyro_energy_counts2: g * g,
        }
    }
}

/// Streaming, orientation-free rest detector.
#[derive(Clone, Debug)]
pub struct RestDetector {
    thresholds: RestThresholds,
    accel: [[i16; 3]; WINDOW_CAPACITY],
    /// |ω|² of each sample, counts² (≤ 3·2³⁰, fits a `u32`).
    gyro_sq: [u32; WINDOW_CAPACITY],
    sum_a: [i64; 3],
    sum_a_sq: i64,
    sum_g_sq: i64,
    head: usize,
    seen: u32,
}

impl RestDetector {
    /// A detector with no history.
    pub const fn new(thresholds: RestThresholds) -> Self {
        RestDetector {
            thresholds,
            accel: [[0; 3]; WINDOW_CAPACITY],
            gyro_sq: [0; WINDOW_CAPACITY],
            sum_a: [0; 3],
            sum_a_sq: 0,
            sum_g_sq: 0,
            head: 0,
            seen: 0,
        }
    }

    /// Forgets the history (after a gap in the samples).
    pub fn reset(&mut self) {
        *self = RestDetector::new(self.thresholds);
    }

    /// Samples of delay between the newest input and the centre of the window the answer
    /// describes.
    pub const fn delay(&self) -> u32 {
        self.thresholds.window / 2
    }

    /// Pushes one filtered sample; returns `Some(rest)` for the window ending here, `None`
    /// until the window is full.
    pub fn process(&mut self, accel: [i16; 3], gyro: [i16; 3]) -> Option<bool> {
        let w = self.thresholds.window as usize;
        let slot = self.head & (WINDOW_CAPACITY - 1);
        let leaving = (self.head + WINDOW_CAPACITY - w) & (WINDOW_CAPACITY - 1);
        let square = |v: &[i16; 3]| -> u32 {
            v.iter()
                .map(|&x| x.unsigned_abs() as u32 * x.unsigned_abs() as u32)
                .sum()
        };
        let a_sq = square(&accel) as i64;
        let g_sq = square(&gyro);
        self.accel[slot] = accel;
        self.gyro_sq[slot] = g_sq;
        for (s, &v) in self.sum_a.iter_mut().zip(accel.iter()) {
            *s += v as i64;
        }
        self.sum_a_sq += a_sq;
        self.sum_g_sq += g_sq as i64;
        if self.seen as usize >= w {
            for (s, &v) in self.sum_a.iter_mut().zip(self.accel[leaving].iter()) {
                *s -= v as i64;
            }
            self.sum_a_sq -= square(&self.accel[leaving]) as i64;
            self.sum_g_sq -= self.gyro_sq[leaving] as i64;
        } else {
            self.seen += 1;
        }
        self.head = (self.head + 1) & (WINDOW_CAPACITY - 1);
        if (self.seen as usize) < w {
            return None;
        }
        let w = w as i64;
        // W²·var_total = W·Σ|a|² − |Σa|²; both terms < 2^44 for W < 64 and i16 inputs.
        let sum_sq_of_sum: i64 = self.sum_a.iter().map(|&s| s * s).sum();
        let var_w2 = w * self.sum_a_sq - sum_sq_of_sum;
        let still_accel = var_w2 < self.thresholds.accel_var_counts2 * w * w;
        let still_gyro = self.sum_g_sq < self.thresholds.gyro_energy_counts2 * w;
        Some(still_accel && still_gyro)
    }
}

/// Sums of the raw samples of one still period (a rest, a stance): what gravity, the gyro
/// bias and the levelling are computed from. Beyond [`RestSums::HALVING_AT`] samples all
/// sums are halved, so that standing for hours stays bounded (sums < 2³² for `i16` input)
/// while the mean is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct RestSums {
    /// Σ accelerometer counts per axis.
    pub accel: [i64; 3],
    /// Σ gyroscope counts per axis.
    pub gyro: [i64; 3],
    /// Σ |gyro|² (counts², all axes), for the rate's spread about its mean.
    pub gyro_sq: u64,
    /// Samples summed (after halvings).
    pub count: u32,
}

impl RestSums {
    /// Sample count at which the sums are halved.
    pub const HALVING_AT: u32 = 1 << 16;

    /// No samples.
    pub const fn new() -> Self {
        RestSums {
            accel: [0; 3],
            gyro: [0; 3],
            gyro_sq: 0,
            count: 0,
        }
    }

    /// Adds one sample.
    pub fn add(&mut self, s: &crate::sensor::sample::RawSample) {
        if self.count >= Self::HALVING_AT {
            self.accel = self.accel.map(|v| v / 2);
            self.gyro = self.gyro.map(|v| v / 2);
            self.gyro_sq /= 2;
            self.count /= 2;
        }
        self.gyro_sq = self.gyro_sq.saturating_add(
            s.gyro
                .iter()
                .map(|&g| (g as i64 * g as i64) as u64)
                .sum::<u64>(),
        );
        for ((a, g), (&sa, &sg)) in self
            .accel
            .iter_mut()
            .zip(self.gyro.iter_mut())
            .zip(s.accel.iter().zip(s.gyro.iter()))
        {
            *a += sa as i64;
            *g += sg as i64;
        }
        self.count += 1;
    }

    /// The angular rate's variance about its mean, counts² (all axes together).
    pub fn gyro_variance(&self) -> u64 {
        if self.count == 0 {
            return 0;
        }
        let n = self.count as i128;
        let sq = self.gyro_sq as i128 * n;
        let mean2: i128 = self.gyro.iter().map(|&g| g as i128 * g as i128).sum();
        ((sq - mean2).max(0) / (n * n)) as u64
    }
}

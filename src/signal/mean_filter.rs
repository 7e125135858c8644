//! Moving-average (mean) filter over a power-of-two ring buffer with a running sum.

/// Mean of the last `L` samples of a three-axis signal; the capacity `N` and the window
/// `L ≤ N` are powers of two (`L` chosen at run time, so that it can follow the sample rate).
///
/// O(1) per sample: the running sum gains the new sample and loses the one that leaves the
/// window, and the ring is indexed with `& (L − 1)`. Inputs are `i16` counts, the sums
/// `i32` (exact for `N` ≤ 65 536), the output the floor of the exact mean (error < 1 count).
/// Until `N` samples have arrived the mean is over the samples seen so far.
#[derive(Clone, Debug)]
pub struct MeanFilter<const N: usize> {
    ring: [[i16; 3]; N],
    sum: [i32; 3],
    head: usize,
    filled: usize,
    log2_len: u32,
}

impl<const N: usize> Default for MeanFilter<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> MeanFilter<N> {
    const POWER_OF_TWO: () = assert!(N.is_power_of_two() && N <= 65_536);

    /// An empty filter over the whole capacity, `L = N`.
    pub const fn new() -> Self {
        Self::with_len_log2(N.trailing_zeros())
    }

    /// An empty filter over `L = 2^log2_len` samples, clamped to `N`.
    pub const fn with_len_log2(log2_len: u32) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::POWER_OF_TWO;
        let cap = N.trailing_zeros();
        MeanFilter {
            ring: [[0; 3]; N],
            sum: [0; 3],
            head: 0,
            filled: 0,
            log2_len: if log2_len < cap { log2_len } else { cap },
        }
    }

    /// The window `L`, samples.
    pub const fn window(&self) -> usize {
        1 << self.log2_len
    }

    /// Samples of delay of the window's centre behind its newest sample, rounded down:
    /// `(L − 1) / 2`.
    pub const fn delay(&self) -> u32 {
        ((1u32 << self.log2_len) - 1) / 2
    }

    /// Pushes `x` and returns the mean of the window.
    pub fn process(&mut self, x: [i16; 3]) -> [i16; 3] {
        let len = self.window();
        let slot = self.head & (len - 1);
        let old = self.ring[slot];
        self.ring[slot] = x;
        self.head = (self.head + 1) & (len - 1);
        if self.filled < len {
            self.filled += 1;
        }
        let mut out = [0i16; 3];
        for ((s, (&new, &gone)), o) in self
            .sum
            .iter_mut()
            .zip(x.iter().zip(old.iter()))
            .zip(out.iter_mut())
        {
            // Slots not yet written hold 0, so subtracting them is harmless.
            *s += new as i32 - gone as i32;
            *o = if self.filled == len {
                (*s >> self.log2_len) as i16
            } else {
                s.div_euclid(self.filled as i32) as i16
            };
        }
        out
    }
}

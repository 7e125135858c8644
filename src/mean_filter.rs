//! Moving-average (mean) filter over a power-of-two ring buffer with a running sum.

/// Mean of the last `N` samples of a three-axis signal, `N` a power of two.
///
/// O(1) per sample: the running sum gains the new sample and loses the one that leaves the
/// window, and the ring is indexed with `& (N − 1)`. Inputs are `i16` counts, the sums
/// `i32` (exact for `N` ≤ 65 536), the output the floor of the exact mean (error < 1 count).
/// Until `N` samples have arrived the mean is over the samples seen so far.
#[derive(Clone, Debug)]
pub struct MeanFilter<const N: usize> {
    ring: [[i16; 3]; N],
    sum: [i32; 3],
    head: usize,
    filled: usize,
}

impl<const N: usize> Default for MeanFilter<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> MeanFilter<N> {
    const POWER_OF_TWO: () = assert!(N.is_power_of_two() && N <= 65_536);

    /// An empty filter.
    pub const fn new() -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::POWER_OF_TWO;
        MeanFilter {
            ring: [[0; 3]; N],
            sum: [0; 3],
            head: 0,
            filled: 0,
        }
    }

    /// Pushes `x` and returns the mean of the window.
    pub fn process(&mut self, x: [i16; 3]) -> [i16; 3] {
        let slot = self.head & (N - 1);
        let old = self.ring[slot];
        self.ring[slot] = x;
        self.head = (self.head + 1) & (N - 1);
        if self.filled < N {
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
            *o = if self.filled == N {
                (*s >> N.trailing_zeros()) as i16
            } else {
                s.div_euclid(self.filled as i32) as i16
            };
        }
        out
    }
}

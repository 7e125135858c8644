//! The per-stride log line and the end-of-run summary, shared by every board.
//!
//! Format (one defmt line per stride; the host's bit-exact test parses it):
//! `stride <index> t=<start ms> dur=<ms> len=<mm> climb=<mm> phases=<stance>/<push-off>/<swing>/<heel-strike> ms flags=<bits> idx=<start>,<heel_off>,<toe_off>,<heel_strike>,<end>`

use gaitclip::rate::SampleRate;
use gaitclip::stride::Stride;

/// Running totals and the formatting of strides.
pub struct StrideLog {
    rate: SampleRate,
    strides: u32,
    distance_mm: u64,
}

impl StrideLog {
    /// A log for samples at `rate`.
    pub const fn new(rate: SampleRate) -> Self {
        StrideLog {
            rate,
            strides: 0,
            distance_mm: 0,
        }
    }

    /// Logs one stride.
    pub fn stride(&mut self, s: &Stride) {
        let ms = |a: u32, b: u32| self.rate.ms_of_samples(b.wrapping_sub(a));
        self.strides += 1;
        self.distance_mm += s.length_mm as u64;
        defmt::println!(
            "stride {=u32} t={=u32} dur={=u32} len={=u32} climb={=i32} phases={=u32}/{=u32}/{=u32}/{=u32} ms flags={=u8} idx={=u32},{=u32},{=u32},{=u32},{=u32}",
            s.index,
            self.rate.ms_of_samples(s.start),
            ms(s.start, s.end),
            s.length_mm,
            s.climb_mm,
            ms(s.start, s.heel_off),
            ms(s.heel_off, s.toe_off),
            ms(s.toe_off, s.heel_strike),
            ms(s.heel_strike, s.end),
            s.flags.0,
            s.start,
            s.heel_off,
            s.toe_off,
            s.heel_strike,
            s.end
        );
    }

    /// Logs the summary at the end of a run.
    pub fn summary(&self, samples: u32, overruns: u32, bus_errors: u32) {
        defmt::println!(
            "summary strides={=u32} distance_mm={=u64} samples={=u32} overruns={=u32} bus_errors={=u32}",
            self.strides,
            self.distance_mm,
            samples,
            overruns,
            bus_errors
        );
    }
}

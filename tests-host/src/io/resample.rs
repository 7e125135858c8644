//! Decimation of a recording to a lower rate, as a slower sensor would have recorded it: a
//! linear-phase anti-aliasing low-pass, then every `k`-th sample.
//!
//! The low-pass is a windowed sinc (Blackman window, `16·k + 1` taps) cut off at 0.4 of the
//! output rate: at 200 Hz out it passes the foot's motion (below 30 Hz but for impacts) and
//! stops everything above the output's Nyquist by more than 70 dB, as an MPU6050's digital
//! low-pass does before its sample-rate divider. The filter is symmetric and centred, so the
//! decimated samples keep the times of the samples they are taken at (no delay); at the ends
//! the recording is extended by its first and last sample.
//!
//! What filtering cannot keep is a rail: a clipped run at 800 Hz is averaged with the samples
//! around it and the 200 Hz sample there lies below the rail, unclipped to the core, as it
//! would in a sensor that filters before it decimates. `gaitclip rates` shows what that costs.

use crate::io::trace::{ImuSample, Trace};

/// The filter's taps for decimation by `k` (sum 1).
pub fn taps(k: usize) -> Vec<f64> {
    let n = 16 * k + 1;
    let mid = (n / 2) as f64;
    // Cut-off 0.4 of the output rate = 0.4/k of the input rate (cycles per sample).
    let fc = 0.4 / k as f64;
    let mut h: Vec<f64> = (0..n)
        .map(|i| {
            let x = i as f64 - mid;
            let sinc = if x == 0.0 {
                2.0 * fc
            } else {
                (2.0 * std::f64::consts::PI * fc * x).sin() / (std::f64::consts::PI * x)
            };
            let t = 2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64;
            let w = 0.42 - 0.5 * t.cos() + 0.08 * (2.0 * t).cos();
            sinc * w
        })
        .collect();
    let sum: f64 = h.iter().sum();
    for v in &mut h {
        *v /= sum;
    }
    h
}

/// `trace` at `1/k` of its rate (`k ≥ 1`; 1 returns it as it is), the nominal ranges kept.
pub fn decimate(trace: &Trace, k: usize) -> Trace {
    if k <= 1 {
        return trace.clone();
    }
    let h = taps(k);
    let half = h.len() / 2;
    let x = &trace.samples;
    let n = x.len();
    let at = |i: isize| x[i.clamp(0, n as isize - 1) as usize];
    let samples: Vec<ImuSample> = (0..n)
        .step_by(k)
        .map(|j| {
            let mut s = ImuSample {
                t_s: x[j].t_s,
                ..ImuSample::default()
            };
            for (m, &w) in h.iter().enumerate() {
                let v = at(j as isize + m as isize - half as isize);
                for c in 0..3 {
                    s.acc_mps2[c] += w * v.acc_mps2[c];
                    s.gyr_radps[c] += w * v.gyr_radps[c];
                }
            }
            s
        })
        .collect();
    Trace {
        samples,
        rate_hz: trace.rate_hz / k as f64,
        repeated: 0,
        given: trace.given,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(hz: f64, rate: f64, n: usize) -> Trace {
        Trace {
            samples: (0..n)
                .map(|i| {
                    let t = i as f64 / rate;
                    ImuSample {
                        t_s: t,
                        acc_mps2: [(2.0 * std::f64::consts::PI * hz * t).sin(), 0.0, 9.8],
                        gyr_radps: [0.0; 3],
                    }
                })
                .collect(),
            rate_hz: rate,
            ..Trace::default()
        }
    }

    fn amplitude(t: &Trace) -> f64 {
        let m = t.samples.len();
        t.samples[m / 4..3 * m / 4]
            .iter()
            .map(|s| s.acc_mps2[0].abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn passes_the_gait_band_and_stops_what_would_alias() {
        // 800 → 200 Hz: 10 Hz passes within 0.1 %, 150 Hz (would alias to 50 Hz) is gone.
        let pass = decimate(&sine(10.0, 800.0, 8000), 4);
        assert!(
            (amplitude(&pass) - 1.0).abs() < 1e-3,
            "{}",
            amplitude(&pass)
        );
        let stop = decimate(&sine(150.0, 800.0, 8000), 4);
        assert!(amplitude(&stop) < 3e-4, "{}", amplitude(&stop));
        // Gravity (DC) is kept exactly, and the times are the input's.
        assert!((pass.samples[100].acc_mps2[2] - 9.8).abs() < 1e-9);
        assert_eq!(pass.samples[3].t_s, 12.0 / 800.0);
        assert_eq!(pass.rate_hz, 200.0);
    }
}

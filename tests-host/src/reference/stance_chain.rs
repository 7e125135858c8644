//! An `f64` reference of the gait core: the same stages as the firmware's integer pipeline
//! (mean filter, rest test, foot frame, Huang stance detector, stride segmentation, Huang
//! phase splitter), written again in floating point and physical units, so that tests can
//! check the fixed-point core against it.
//!
//! Shared with the core are only the *definitions*: constants (thresholds, windows in ms),
//! the window lengths in samples they round to, and the order of the stages. Every
//! computation (means, variances, rotations, deflation, quartiles, k-means, fusion) is done
//! here in `f64` on the physical values of the same input counts.

use gaitclip::detect::foot_frame::{
    AXIS_MAX_MOVEMENT_MS, AXIS_MIN_MOVEMENT_MS, FIRST_FRAME_AFTER_MS, REMOUNT_DEG,
};
use gaitclip::detect::phases::{
    PhaseMethod, KMEANS_MAX_ITERATIONS, MAX_EXTREMES, MERGE_MS, MIN_EXTREME_MG,
};
use gaitclip::detect::seam::{MAX_MOVEMENT_SAMPLES, MAX_STANCE_IN_STRIDE_MS, MIN_MOVEMENT_MS};
use gaitclip::detect::{rest, stance};
use gaitclip::pipeline::config::Config;
use gaitclip::pipeline::MEAN_FILTER_MS;
use gaitclip::sensor::rate::SampleRate;
use gaitclip::sensor::sample::RawSample;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use crate::eval::matching::Detected;
use crate::io::trace::G_MPS2;
use gaitclip::record::stride::StrideEvents;

/// Runs the reference over raw counts; strides in the order the core reports them.
pub fn strides(samples: &[RawSample], config: Config) -> Vec<Detected> {
    let (ka, kg) = (
        config.accel.lsb_per_g() as f64 / G_MPS2,
        config.gyro.lsb_per_dps() * 180.0 / std::f64::consts::PI,
    );
    let acc: Vec<Vector3<f64>> = samples
        .iter()
        .map(|s| Vector3::from(s.accel.map(|c| c as f64 / ka)))
        .collect();
    let gyr: Vec<Vector3<f64>> = samples
        .iter()
        .map(|s| Vector3::from(s.gyro.map(|c| c as f64 / kg)))
        .collect();
    let saturated: Vec<bool> = samples.iter().map(|s| s.is_saturated()).collect();
    Reference::new(config.rate, config.phases).run(&acc, &gyr, &saturated)
}

struct Reference {
    filter_len: usize,
    rest_window: usize,
    half: [usize; 3],
    rate: SampleRate,
    method: PhaseMethod,
}

fn ms(rate: SampleRate, v: u32) -> usize {
    rate.samples_in_ms(v) as usize
}

impl Reference {
    fn new(rate: SampleRate, method: PhaseMethod) -> Self {
        let filter_len = {
            let n = ms(rate, MEAN_FILTER_MS) as f64;
            // Power of two nearest n, at most 16.
            (2f64.powf(n.log2().round())).min(16.0) as usize
        };
        let t = stance::StanceThresholds::new(rate, gaitclip_mpu6050::GyroRange::Dps2000.scale());
        let r = rest::RestThresholds::new(
            rate,
            gaitclip_mpu6050::AccelRange::default().scale(),
            gaitclip_mpu6050::GyroRange::default().scale(),
        );
        Reference {
            filter_len,
            rest_window: r.window as usize,
            half: t.half.map(|h| h as usize),
            rate,
            method,
        }
    }

    fn run(&self, acc: &[Vector3<f64>], gyr: &[Vector3<f64>], sat: &[bool]) -> Vec<Detected> {
        let n = acc.len();
        let fd = (self.filter_len - 1) / 2;
        // Mean filter, exact.
        let filtered: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                let from = (i + 1).saturating_sub(self.filter_len);
                acc[from..=i].iter().sum::<Vector3<f64>>() / (i + 1 - from) as f64
            })
            .collect();
        let w = self.rest_window;
        let rest_delay = w / 2 + fd;
        let a_max = rest::ACCEL_STD_MAX_MMPS2 as f64 / 1000.0;
        let g_rest = rest::GYRO_RMS_MAX_MRADPS as f64 / 1000.0;
        let mut frame = FrameEstimator::new(self.rate);
        let mut frames: Vec<Option<Frame>> = vec![None; n];
        for i in 0..n {
            if i + 1 >= w && i >= rest_delay {
                let win = &filtered[i + 1 - w..=i];
                let mean = win.iter().sum::<Vector3<f64>>() / w as f64;
                let var: f64 =
                    win.iter().map(|a| (a - mean).norm_squared()).sum::<f64>() / w as f64;
                let energy: f64 = gyr[i + 1 - w..=i]
                    .iter()
                    .map(|g| g.norm_squared())
                    .sum::<f64>()
                    / w as f64;
                let is_rest = var < a_max * a_max && energy < g_rest * g_rest;
                let at = i - rest_delay;
                frame.process(acc[at], gyr[at], is_rest);
            }
            frames[i] = frame.frame();
        }
        // Foot-frame signals from the first input with a frame on.
        let first = frames.iter().position(Option::is_some).unwrap_or(n);
        let foot: Vec<[f64; 3]> = (0..n)
            .map(|i| match &frames[i] {
                Some(f) => f.apply(filtered[i]),
                None => [0.0; 3],
            })
            .collect();
        let deflate = |x: f64| x * x.abs();
        let std_max = stance::DEFLATED_STD_MAX as f64 / 1000.0;
        let iqr_max = stance::DEFLATED_IQR_MAX as f64 / 1000.0;
        let gyro_max = stance::GYRO_RMS_MAX_MRADPS as f64 / 1000.0;
        let big = self.half[2];
        // stance[c] about foot input c (centre); raw sample c − fd.
        let mut decisions: Vec<(usize, bool)> = Vec::new();
        for c in first + big..n.saturating_sub(big) {
            let mut still = true;
            for axis in [2usize, 0] {
                let mut var = 0.0;
                for &h in &self.half {
                    let v: Vec<f64> = (c - h..=c + h).map(|k| deflate(foot[k][axis])).collect();
                    let m = v.iter().sum::<f64>() / v.len() as f64;
                    var += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64;
                }
                still &= var / 3.0 < std_max * std_max;
                let h = self.half[1];
                let mut v: Vec<f64> = (c - h..=c + h).map(|k| deflate(foot[k][axis])).collect();
                v.sort_by(f64::total_cmp);
                let q = v.len() - 1;
                still &= v[3 * q / 4] - v[q / 4] < iqr_max;
            }
            let h = self.half[1];
            let energy = gyr[c - h..=c + h]
                .iter()
                .map(|g| g.norm_squared())
                .sum::<f64>()
                / (2 * h + 1) as f64;
            still &= energy < gyro_max * gyro_max;
            if c >= fd {
                decisions.push((c, still));
            }
        }
        let mut tracker = Tracker::new(self.rate, self.method);
        let mut out = Vec::new();
        for &(c, still) in &decisions {
            let at = c - fd;
            out.extend(tracker.process(at, &foot[c], sat[at], still));
        }
        // End of the recording: the core drains the last `big` decisions with the last
        // answer, then reports what it still holds.
        if let Some(&(c_last, still)) = decisions.last() {
            let drained = (c_last + 1 + big).min(n);
            for (c, f) in foot.iter().enumerate().take(drained).skip(c_last + 1) {
                let at = c - fd;
                out.extend(tracker.process(at, f, sat[at], still));
            }
        }
        out.extend(tracker.finish());
        out
    }
}

#[derive(Clone, Copy, Debug)]
struct Frame {
    forward: Vector3<f64>,
    left: Vector3<f64>,
    up: Vector3<f64>,
    gravity: f64,
}

impl Frame {
    /// `[forward, left, up − g]` in m/s².
    fn apply(&self, a: Vector3<f64>) -> [f64; 3] {
        [
            self.forward.dot(&a),
            self.left.dot(&a),
            self.up.dot(&a) - self.gravity,
        ]
    }
}

struct FrameEstimator {
    axis_min: usize,
    axis_max: usize,
    first_after: usize,
    frame: Option<Frame>,
    up: Vector3<f64>,
    gravity: f64,
    left_sum: Vector3<f64>,
    was_rest: bool,
    rest: Vec<(Vector3<f64>, Vector3<f64>)>,
    bias: Vector3<f64>,
    movement: Vec<Vector3<f64>>,
}

impl FrameEstimator {
    fn new(rate: SampleRate) -> Self {
        FrameEstimator {
            axis_min: ms(rate, AXIS_MIN_MOVEMENT_MS),
            axis_max: ms(rate, AXIS_MAX_MOVEMENT_MS),
            first_after: ms(rate, FIRST_FRAME_AFTER_MS),
            frame: None,
            up: Vector3::zeros(),
            gravity: 0.0,
            left_sum: Vector3::zeros(),
            was_rest: false,
            rest: Vec::new(),
            bias: Vector3::zeros(),
            movement: Vec::new(),
        }
    }

    fn frame(&self) -> Option<Frame> {
        self.frame
    }

    fn process(&mut self, a: Vector3<f64>, w: Vector3<f64>, rest: bool) {
        match (self.was_rest, rest) {
            (false, true) => {
                self.end_movement();
                self.rest = vec![(a, w)];
            }
            (true, true) => {
                self.rest.push((a, w));
                if self.frame.is_none() && self.rest.len() == self.first_after {
                    self.end_rest();
                }
            }
            (true, false) => {
                self.end_rest();
                self.movement.clear();
                self.movement.push(w - self.bias);
            }
            (false, false) => {
                if self.movement.len() < self.axis_max {
                    self.movement.push(w - self.bias);
                }
            }
        }
        self.was_rest = rest;
    }

    fn end_rest(&mut self) {
        // The core halves its sums past 2¹⁶ samples; rests that long do not occur here.
        let n = self.rest.len() as f64;
        let mean = self.rest.iter().map(|r| r.0).sum::<Vector3<f64>>() / n;
        self.bias = self.rest.iter().map(|r| r.1).sum::<Vector3<f64>>() / n;
        let g = mean.norm();
        let u = mean / g;
        let cos_remount = (REMOUNT_DEG as f64).to_radians().cos();
        if self.frame.is_none() || u.dot(&self.up) < cos_remount {
            self.up = u;
            self.gravity = g;
            self.left_sum = Vector3::zeros();
        } else {
            self.up = (self.up * 0.875 + u * 0.125).normalize();
            self.gravity = self.gravity * 0.875 + g * 0.125;
        }
        self.rebuild();
    }

    fn end_movement(&mut self) {
        let n = self.movement.len();
        if self.frame.is_none() || n < self.axis_min || n >= self.axis_max {
            return;
        }
        let cov: Matrix3<f64> = self.movement.iter().map(|w| w * w.transpose()).sum();
        let eig = SymmetricEigen::new(cov);
        let k = eig.eigenvalues.imax();
        let axis: Vector3<f64> = eig.eigenvectors.column(k).into();
        let horizontal = axis - self.up * axis.dot(&self.up);
        if horizontal.norm() < 0.7 {
            return;
        }
        let centre = (n as f64 - 1.0) / 2.0;
        let moment: Vector3<f64> = self
            .movement
            .iter()
            .enumerate()
            .map(|(k, w)| w * (k as f64 - centre))
            .sum();
        let sign = if horizontal.dot(&moment) < 0.0 {
            1.0
        } else {
            -1.0
        };
        self.left_sum = self.left_sum * 0.875 + horizontal.normalize() * sign;
        self.rebuild();
    }

    fn rebuild(&mut self) {
        let up = self.up;
        let mut left = self.left_sum - up * self.left_sum.dot(&up);
        if left.norm() < 1e-3 {
            let k = up.iamin();
            let mut e = Vector3::zeros();
            e[k] = 1.0;
            left = e - up * e.dot(&up);
        }
        let left = left.normalize();
        self.frame = Some(Frame {
            forward: left.cross(&up),
            left,
            up,
            gravity: self.gravity,
        });
    }
}

#[derive(PartialEq)]
enum State {
    Unprimed,
    Stance,
    Moving,
}

struct Tracker {
    state: State,
    min_movement: usize,
    max_stance: usize,
    merge: usize,
    method: PhaseMethod,
    stance_start: usize,
    heel_off: usize,
    movement: Vec<[f64; 2]>,
    pending: Option<Detected>,
}

impl Tracker {
    fn new(rate: SampleRate, method: PhaseMethod) -> Self {
        Tracker {
            state: State::Unprimed,
            min_movement: ms(rate, MIN_MOVEMENT_MS),
            max_stance: ms(rate, MAX_STANCE_IN_STRIDE_MS),
            merge: ms(rate, MERGE_MS),
            method,
            stance_start: 0,
            heel_off: 0,
            movement: Vec::new(),
            pending: None,
        }
    }

    fn process(
        &mut self,
        at: usize,
        foot: &[f64; 3],
        _sat: bool,
        stance: bool,
    ) -> Option<Detected> {
        match (&self.state, stance) {
            (State::Unprimed, false) => None,
            (State::Unprimed, true) => {
                self.state = State::Stance;
                self.stance_start = at;
                None
            }
            (State::Stance, true) => {
                if at - self.stance_start > self.max_stance {
                    return self.pending.take();
                }
                None
            }
            (State::Stance, false) => {
                self.state = State::Moving;
                self.heel_off = at;
                self.movement = vec![[foot[2], foot[0]]];
                self.pending.take()
            }
            (State::Moving, false) => {
                if self.movement.len() < MAX_MOVEMENT_SAMPLES {
                    self.movement.push([foot[2], foot[0]]);
                }
                None
            }
            (State::Moving, true) => {
                self.state = State::Stance;
                if at - self.heel_off < self.min_movement {
                    return None;
                }
                let (to, hs) = split(&self.movement, self.method, self.merge);
                let start = if self.heel_off - self.stance_start > self.max_stance {
                    self.heel_off - self.max_stance
                } else {
                    self.stance_start
                };
                let d = Detected {
                    events: StrideEvents {
                        start: start as u32,
                        heel_off: self.heel_off as u32,
                        toe_off: (self.heel_off + to) as u32,
                        heel_strike: (self.heel_off + hs) as u32,
                        foot_flat: at as u32,
                        end: at as u32,
                    },
                    too_long: false,
                };
                self.stance_start = at;
                self.pending.replace(d)
            }
        }
    }

    fn finish(&mut self) -> Option<Detected> {
        self.pending.take()
    }
}

#[derive(Clone, Copy, Debug)]
struct Extreme {
    at: usize,
    value: f64,
    vertical: bool,
    peak: bool,
}

/// Huang's splitter in `f64`: returns (toe-off, heel-strike) offsets into the movement.
pub fn split(m: &[[f64; 2]], method: PhaseMethod, merge: usize) -> (usize, usize) {
    let len = m.len();
    let fallback = (len / 4, (3 * len / 4).min(len.saturating_sub(1)));
    if len < 3 {
        return fallback;
    }
    let min = MIN_EXTREME_MG as f64 / 1000.0 * G_MPS2;
    let mut ex = Vec::new();
    for (a, vertical) in [(0, true), (1, false)] {
        let mut i = 1;
        while i + 1 < len {
            let mut j = i;
            while j + 1 < len && m[j + 1][a] == m[i][a] {
                j += 1;
            }
            if j + 1 >= len {
                break;
            }
            let (p, x, q) = (m[i - 1][a], m[i][a], m[j + 1][a]);
            let peak = x > p && x > q && x > min;
            let valley = x < p && x < q && x < -min;
            if (peak || valley) && ex.len() < MAX_EXTREMES {
                ex.push(Extreme {
                    at: (i + j) / 2,
                    value: x,
                    vertical,
                    peak,
                });
            }
            i = j + 1;
        }
    }
    if ex.is_empty() {
        return fallback;
    }
    // Algorithm 1.
    let mut c = [0.0, (len - 1) as f64];
    for _ in 0..KMEANS_MAX_ITERATIONS {
        let mut s = [(0.0, 0usize); 2];
        for e in &ex {
            let x = e.at as f64;
            let k = usize::from((x - c[0]).abs() >= (x - c[1]).abs());
            s[k].0 += x;
            s[k].1 += 1;
        }
        let mut next = c;
        for k in 0..2 {
            if s[k].1 > 0 {
                next[k] = s[k].0 / s[k].1 as f64;
            }
        }
        if next == c {
            break;
        }
        c = next;
    }
    let left = |e: &Extreme| (e.at as f64 - c[0]).abs() < (e.at as f64 - c[1]).abs();
    let major = |vertical: bool, l: bool| -> Option<(Extreme, Extreme)> {
        let set: Vec<&Extreme> = ex
            .iter()
            .filter(|e| e.vertical == vertical && left(e) == l)
            .collect();
        let pairs: Vec<(Extreme, Extreme)> = set
            .iter()
            .filter(|e| e.peak)
            .filter_map(|p| {
                set.iter()
                    .filter(|v| !v.peak && v.at < p.at)
                    .min_by_key(|v| p.at - v.at)
                    .map(|v| (**p, **v))
            })
            .collect();
        let mag = |p: &(Extreme, Extreme)| p.0.value - p.1.value;
        let mut best = *pairs
            .iter()
            .fold(None, |b: Option<&(Extreme, Extreme)>, p| match b {
                Some(b) if mag(p) <= mag(b) => Some(b),
                _ => Some(p),
            })?;
        let first = best;
        for p in &pairs {
            if p.0.at != first.0.at
                && p.0.at.abs_diff(first.1.at) <= merge
                && 2.0 * mag(p) > mag(&first)
            {
                if p.0.value > best.0.value {
                    best.0 = p.0;
                }
                if p.1.value < best.1.value {
                    best.1 = p.1;
                }
            }
        }
        Some(best)
    };
    let (sag_l, vert_l, sag_r, vert_r) = (
        major(false, true),
        major(true, true),
        major(false, false),
        major(true, false),
    );
    let mut to: Vec<f64> = Vec::new();
    let mut hs: Vec<f64> = Vec::new();
    to.extend(sag_l.map(|p| p.0.at as f64));
    to.extend(vert_l.map(|p| p.1.at as f64));
    hs.extend(sag_r.map(|p| p.0.at as f64));
    hs.extend(vert_r.map(|p| p.0.at as f64));
    if method == PhaseMethod::Augmented {
        let crossing = |pair: Option<(Extreme, Extreme)>, a: usize, down: bool| -> Option<f64> {
            let (p, v) = pair?;
            let centre = (p.at + v.at) as f64 / 2.0;
            let d = |i: usize| m[i + 1][a] - m[i - 1][a];
            (2..len - 1)
                .filter(|&i| {
                    let (b, n) = (d(i - 1), d(i));
                    if down {
                        b > 0.0 && n <= 0.0
                    } else {
                        b < 0.0 && n >= 0.0
                    }
                })
                .map(|i| i as f64)
                .fold(None, |best: Option<f64>, x| match best {
                    Some(b) if (b - centre).abs() <= (x - centre).abs() => Some(b),
                    _ => Some(x),
                })
        };
        to.extend(crossing(sag_l, 1, true));
        to.extend(crossing(vert_l, 0, false));
        hs.extend(crossing(sag_r, 1, true));
        hs.extend(crossing(vert_r, 0, true));
    }
    let fuse = |r: &[f64]| -> Option<f64> {
        let kept: Vec<f64> = r
            .iter()
            .enumerate()
            .filter(|&(i, &x)| {
                if r.len() < 3 {
                    return true;
                }
                let others: Vec<f64> = r
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, &v)| v)
                    .collect();
                let mean = others.iter().sum::<f64>() / others.len() as f64;
                let var =
                    others.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / others.len() as f64;
                (x - mean).abs() <= 3.0 * var.sqrt()
            })
            .map(|(_, &x)| x)
            .collect();
        (!kept.is_empty()).then(|| kept.iter().sum::<f64>() / kept.len() as f64)
    };
    match (fuse(&to), fuse(&hs)) {
        (Some(t), Some(h)) if t.round() < h.round() && (h.round() as usize) < len => {
            (t.round() as usize, h.round() as usize)
        }
        _ => (
            (c[0].round() as usize).min(len - 1),
            (c[1].round() as usize).min(len - 1),
        ),
    }
}

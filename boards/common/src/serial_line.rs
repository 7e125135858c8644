//! The serial line protocol: one CSV line per stride, readable with any terminal.
//!
//! A board without a debug probe prints this on a UART (115 200 baud, 8N1). Lines end in
//! `\r\n`. Lines starting with `#` are status for a human (start-up, calibration, faults);
//! every other line is CSV under the header line that follows the banner:
//!
//! ```text
//! # gaitclip 0.1.0 board=nrf52840-dk rate_mhz=200000 detector=stance model=huang_svr_fusion
//! index,t_ms,length_mm,duration_ms,stance_ms,push_off_ms,swing_ms,heel_strike_ms,climb_mm,flags,valid,stance_time_ms,swing_time_ms,stance_permille,gait_velocity_mm_s,cadence_spm,max_sensor_lift_mm,turning_angle_cdeg,gait
//! # hold still: waiting for the clip to rest (2 s)
//! # still: gyro_bias_mdps=-1220,305,61 gravity_mg=1003
//! 0,5120,1362,1105,420,150,380,155,3,4,1,725,380,656,1233,109,131,-215,unknown
//! # hole samples=12 filled: a stride whose movement it falls in is a gap stride (flag 64), without a length
//! # status samples=24000 strides=96 distance_mm=131012 bus_errors=0 restarts=0 fifo_overflows=0 silences=0 overruns=0 lost_samples=0 sleeps=0 slept_periods=0 estimated=0 clipped=0,0,3,0,0,0
//! # sleep still_ms=10000 wake_mhz=5000 sensor_ua=20: waiting for motion
//! # wake unsampled_ms=2310 detection restarts: a step the wake-up cut into is a gap stride (flag 64)
//! ```
//!
//! `index` counts strides from 0; `t_ms` is the start of the stride since power-up;
//! `duration_ms` is the whole stride and the four phase columns add up to it; `flags` is
//! the bit set of [`gaitclip::record::stride::StrideFlags`] (1 saturated, 2 too long, 4 from rest,
//! 8 to rest, 16 turn, 32 phases guessed, 64 gap, 128 implausible, 256 bridged, 512 gyro
//! clipped and restored); `valid` is 0 when a flag
//! makes the length untrustworthy (a gap stride has length 0). The columns after `valid` are
//! the stride's gait parameters ([`gaitclip::gait`], gaitmap's names): `duration_ms` is the
//! `stride_time`; `stance_time_ms` is the ground contact within the cycle (both ends of it,
//! unlike `stance_ms`, the part before heel-off); the heading change in centidegrees,
//! counter-clockwise positive; `gait` is `walking`, `running` or `unknown` (not one cycle).
//! `tests-host/tests/board_glue.rs` parses these lines back.

use core::fmt::{self, Write};

use gaitclip::detect::step_check::Rejected;
use gaitclip::length::models::Model;
use gaitclip::pipeline::detectors::Detector;
use gaitclip::pipeline::BetweenTotals;
use gaitclip::record::stride::Stride;
use gaitclip::sensor::rate::SampleRate;

use crate::imu_sampler::Counters;

/// Longest line this module writes, with its `\r\n` (the status line with every counter
/// at its maximum): the size of a board's line buffer.
pub const MAX_LINE: usize = 512;

/// The CSV header line.
pub const HEADER: &str = "index,t_ms,length_mm,duration_ms,stance_ms,push_off_ms,swing_ms,heel_strike_ms,climb_mm,flags,valid,stance_time_ms,swing_time_ms,stance_permille,gait_velocity_mm_s,cadence_spm,max_sensor_lift_mm,turning_angle_cdeg,gait,swing_deg,still_before_ms,moving_before_ms";

/// The banner and the CSV header.
pub fn banner(
    out: &mut impl Write,
    board: &str,
    rate: SampleRate,
    detector: Detector,
    model: Model,
) -> fmt::Result {
    write!(
        out,
        "# gaitclip {} board={} rate_mhz={} detector={} model={}\r\n{}\r\n",
        env!("CARGO_PKG_VERSION"),
        board,
        rate.millihertz(),
        detector.name(),
        model.name(),
        HEADER
    )
}

/// One stride.
pub fn stride(out: &mut impl Write, rate: SampleRate, s: &Stride) -> fmt::Result {
    let t = s.times_ms(rate);
    write!(
        out,
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\r\n",
        s.index,
        t.start,
        s.length_mm,
        t.duration,
        t.stance,
        t.push_off,
        t.swing,
        t.heel_strike,
        s.climb_mm,
        s.flags.0,
        s.flags.valid() as u8,
        s.gait.stance_time_ms,
        s.gait.swing_time_ms,
        s.gait.stance_permille,
        s.gait.gait_velocity_mm_s,
        s.gait.cadence_spm,
        s.max_sensor_lift_mm,
        s.turning_angle_cdeg,
        s.gait.gait.name(),
        s.swing_deg,
        s.between.still_ms,
        s.between.moving_ms
    )
}

/// A status line for a human.
pub fn comment(out: &mut impl Write, args: fmt::Arguments<'_>) -> fmt::Result {
    write!(out, "# {args}\r\n")
}

/// The periodic (and final) status line.
/// `totals`: strides, distance (mm), estimated strides; `steps`: the movements the step
/// check refused by reason and the time outside the strides.
pub fn status(
    out: &mut impl Write,
    samples: u32,
    totals: (u32, u64, u32),
    clipped: &[u32; 6],
    steps: (&Rejected, &BetweenTotals),
    c: &Counters,
) -> fmt::Result {
    let (strides, distance_mm, estimated) = totals;
    let (rejected, between) = steps;
    write!(
        out,
        "# status samples={} strides={} distance_mm={} bus_errors={} restarts={} fifo_overflows={} silences={} overruns={} lost_samples={} sleeps={} slept_periods={} estimated={} clipped={},{},{},{},{},{} rejected={},{},{},{} still_s={} moving_s={}\r\n",
        samples,
        strides,
        distance_mm,
        c.bus_errors,
        c.restarts,
        c.fifo_overflows,
        c.silences,
        c.overruns,
        c.lost_samples,
        c.sleeps,
        c.slept_periods,
        estimated,
        clipped[0],
        clipped[1],
        clipped[2],
        clipped[3],
        clipped[4],
        clipped[5],
        rejected.by_reason[0],
        rejected.by_reason[1],
        rejected.by_reason[2],
        rejected.by_reason[3],
        between.still_ms / 1000,
        between.moving_ms / 1000
    )
}

//! A stride's gait parameters, as the last stage of the pipeline ([`crate::gait`]) fills
//! them in: what a runner's watch and a clinician's stride list read.

/// What the stride was: walking or running by the duty factor, stairs by the climb.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Gait {
    /// Stance over [`RUNNING_STANCE_MAX_PERMILLE`](crate::gait::RUNNING_STANCE_MAX_PERMILLE) of the cycle: a double support.
    Walking,
    /// Stance under [`RUNNING_STANCE_MAX_PERMILLE`](crate::gait::RUNNING_STANCE_MAX_PERMILLE): a flight phase.
    Running,
    /// The stride is not one gait cycle (from or into a rest, across a gap).
    #[default]
    Unknown,
    /// The stride climbed a stair's height at a stair's slope ([`crate::gait::stairs`]).
    StairsUp,
    /// The stride went down a stair's height at a stair's slope.
    StairsDown,
}

impl Gait {
    /// The name the logs and `--json` use.
    pub const fn name(self) -> &'static str {
        match self {
            Gait::Walking => "walking",
            Gait::Running => "running",
            Gait::Unknown => "unknown",
            Gait::StairsUp => "stairs_up",
            Gait::StairsDown => "stairs_down",
        }
    }
}

/// The temporal and derived parameters of one stride.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct GaitParameters {
    /// One gait cycle, `end − start`, ms (saturates at 65.5 s).
    pub stride_time_ms: u16,
    /// Ground contact within the cycle, `stride_time − swing_time`, ms.
    pub stance_time_ms: u16,
    /// Toe-off to heel-strike, ms.
    pub swing_time_ms: u16,
    /// Stance time per stride time, ‰ (0 for a zero stride time).
    pub stance_permille: u16,
    /// Swing time per stride time, ‰ (`1000 − stance_permille`; 0 for a zero stride time).
    pub swing_permille: u16,
    /// Length per stride time, mm/s (0 without a length or a time; saturates at 65.5 m/s).
    pub gait_velocity_mm_s: u16,
    /// Steps per minute: two steps per cycle of the instrumented foot (0 for a zero time).
    pub cadence_spm: u16,
    /// Walking or running.
    pub gait: Gait,
}

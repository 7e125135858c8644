//! The still runs the emulated sensor adds to the demo walk with the `replay-sleep` feature
//! (`replay_mpu6050::Still`), so that the replay firmware sleeps and wakes as a clip left
//! standing does; the host model (`tests-host/tests/firmware_qemu.rs`) reads the same list.

/// `(sample, periods)`: the demo walk's sample 4100 (the stand in the middle of the walk)
/// held for 12 s more, and its sample 6200 (the final stand) for 13 s more. The first
/// outlasts the firmware's 10 s still period and the walk resumes after it: the clip sleeps
/// and wakes on the first step. The second sleeps until the recording ends.
pub const STILL: &[(u32, u32)] = &[(4100, 2400), (6200, 2600)];

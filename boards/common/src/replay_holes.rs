//! The holes the emulated sensor cuts into the demo walk with the `replay-holes` feature
//! (`replay_mpu6050`), one of every kind the pipeline knows; the host test
//! (`tests-host/tests/firmware_qemu.rs`) reads the same list to replay the same holes.

/// Runs of samples lost, `(first sample, samples)`, in the demo walk's swings unless said:
/// 5 ms, 15 ms in a stance, 10 ms (bridged), 30 ms and 60 ms (filled: a gap stride with its
/// events) and 200 ms (detection restarts after it).
pub const LOST: &[(u32, u32)] = &[
    (1240, 1),
    (1565, 3),
    (1680, 2),
    (2110, 6),
    (2630, 12),
    (3420, 40),
];

"""Times gaitclip's Python layer against its core, the Rust CLI and gaitmap's pipeline, on
gaitmap_walk/left (7 928 samples at 204.8 Hz), in one run, and writes the table into
docs/python.md between its bench markers.

Usage: python bench_replay.py GAITCLIP_BINARY [REPEATS]

Needs ../shared/datasets and gaitmap (the venv tests-host/test-all.sh makes has both). Each
figure is the median of REPEATS runs (default 30; gaitmap 5, after a first run that includes
numba's compilation); reading the CSV into a DataFrame is not timed, the CLI's run is (as a
user runs it: start, read, replay, print).
"""

import datetime
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import time

import pandas as pd

import gaitclip
from gaitclip import _gaitclip

ROOT = pathlib.Path(__file__).resolve().parents[2]
TRACE = ROOT.parent / "shared" / "datasets" / "gaitmap_walk" / "left.csv"
RATE_HZ = 204.8
DOC = ROOT / "docs" / "python.md"
OPEN, CLOSE = "<!-- bench: python/bench/bench_replay.py -->", "<!-- end bench -->"


def median_ms(f, n):
    times = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def main() -> None:
    binary = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 30
    frame = pd.read_csv(TRACE)
    acc = [frame[c].to_numpy() for c in ["acc_x", "acc_y", "acc_z"]]
    gyr = [frame[c].to_numpy() for c in ["gyr_x", "gyr_y", "gyr_z"]]
    t_s = frame["t_s"].to_numpy()
    native = lambda: _gaitclip.replay_arrays(t_s, acc, gyr, "rad/s", RATE_HZ, "cycle", None, False)
    full = lambda: gaitclip.replay(frame, RATE_HZ)
    # The core and the whole call alternate, so that the machine's drift falls on both alike;
    # the layer's cost is the median of their differences.
    core_ms, full_ms = [], []
    for _ in range(n):
        core_ms.append(median_ms(native, 1))
        full_ms.append(median_ms(full, 1))
    layer_ms = statistics.median(f - c for f, c in zip(full_ms, core_ms))
    rows = [
        ("core (the native call: arrays in, the strides' columns out)", statistics.median(core_ms)),
        ("gaitclip.replay(DataFrame)", statistics.median(full_ms)),
        ("gaitclip.replay(path)", median_ms(lambda: gaitclip.replay(TRACE), n)),
        (
            "gaitclip replay --json (the Rust CLI, a process)",
            median_ms(
                lambda: subprocess.run(
                    [binary, "replay", "--json", str(TRACE)], check=True, capture_output=True
                ),
                n,
            ),
        ),
    ]
    sys.path.insert(0, str(ROOT / "tests-host" / "gaitmap"))
    from bench_gaitmap import pipeline  # gaitmap's MAD pipeline, as `gaitclip cost` times it

    data = frame.drop(columns=["t_s"]).copy()
    data[["gyr_x", "gyr_y", "gyr_z"]] = data[["gyr_x", "gyr_y", "gyr_z"]] * (180 / 3.141592653589793)
    pipeline(data, RATE_HZ)  # numba compiles
    rows.append(("gaitmap 2.6 MAD pipeline (DTW, Rampp, trajectory, parameters)", median_ms(lambda: pipeline(data, RATE_HZ), 5)))
    core = rows[0][1]
    lines = [
        f"Measured {datetime.date.today().isoformat()} on {platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, gaitclip {gaitclip.__version__}; `gaitmap_walk/left` "
        f"({len(frame)} samples, {len(frame) / RATE_HZ:.1f} s); median of {n} runs (gaitmap: 5):",
        "",
        "| what | ms | vs the core |",
        "|---|---:|---:|",
    ]
    for name, ms in rows:
        lines.append(f"| {name} | {ms:.2f} | {ms / core:.2f}× |")
    # The layer's cost is per call (≈ 30 columns of a DataFrame), not per sample: on a longer
    # recording it is a smaller share.
    long_path = TRACE.parent.parent / "esangeni_run" / "course_run_800hz.csv"
    long = pd.read_csv(long_path)
    la = [long[c].to_numpy() for c in ["acc_x", "acc_y", "acc_z"]]
    lg = [long[c].to_numpy() for c in ["gyr_x", "gyr_y", "gyr_z"]]
    lt = long["t_s"].to_numpy()
    lc, lf = [], []
    for _ in range(max(n // 10, 5)):
        lc.append(median_ms(lambda: _gaitclip.replay_arrays(lt, la, lg, "rad/s", 800.0, "cycle", None, False), 1))
        lf.append(median_ms(lambda: gaitclip.replay(long, 800.0), 1))
    long_layer = statistics.median(f - c for f, c in zip(lf, lc))
    lines += [
        "",
        f"The Python layer (the checks, the DataFrame) costs {layer_ms:.2f} ms, "
        f"{layer_ms / core * 100:+.1f} % over the core (the median of the differences of "
        "alternated runs); on `esangeni_run` "
        f"({len(long)} samples at 800 Hz, core {statistics.median(lc):.1f} ms) "
        f"{long_layer:.2f} ms, {long_layer / statistics.median(lc) * 100:+.1f} %: a cost per call.",
    ]
    table = "\n".join(lines)
    print(table)
    text = DOC.read_text()
    a, b = text.index(OPEN) + len(OPEN), text.index(CLOSE)
    DOC.write_text(text[:a] + "\n" + table + "\n" + text[b:])


if __name__ == "__main__":
    main()

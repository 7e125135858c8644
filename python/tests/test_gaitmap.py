"""gaitclip beside gaitmap: gaitmap's own example data, loaded with gaitmap's loader, replays
and matches its motion-capture stride lengths as the Rust eval does; and a gaitmap pipeline
whose stride algorithm is swapped for gaitclip's runs.

gaitmap's loader fetches its example data from GitHub into a cache; the test command fills that
cache from gaitmap's own sdist on PyPI (`GAITMAP_DATA_DIR`), so nothing is downloaded here.
"""

import numpy as np
import pandas as pd
import pytest

import gaitclip

gaitmap = pytest.importorskip("gaitmap")
from gaitmap import example_data  # noqa: E402

RATE_HZ = 204.8


@pytest.fixture(scope="module")
def imu() -> pd.DataFrame:
    return example_data.get_healthy_example_imu_data()


@pytest.fixture(scope="module")
def mocap_lengths() -> dict:
    """Per sensor, gaitmap's mocap stride list with each stride's length: the horizontal
    displacement of the heel marker (FCC) between its start and end (min_vel) samples."""
    events = example_data.get_healthy_example_stride_events()
    mocap = example_data.get_healthy_example_mocap_data()
    out = {}
    for sensor, marker in [("left_sensor", "L_FCC"), ("right_sensor", "R_FCC")]:
        t = mocap.index.to_numpy(dtype=float)
        x = mocap[(marker, "x")].to_numpy(dtype=float)
        y = mocap[(marker, "y")].to_numpy(dtype=float)
        at = lambda s: np.array([np.interp(s / RATE_HZ, t, x), np.interp(s / RATE_HZ, t, y)])
        e = events[sensor].copy()
        e["length"] = [
            float(np.linalg.norm(at(b) - at(a))) for a, b in zip(e["start"], e["end"])
        ]
        if e["length"].median() > 100:  # the markers in mm
            e["length"] /= 1000.0
        out[sensor] = e
    return out


def match(ours: pd.DataFrame, refs: pd.DataFrame) -> list:
    """(our ZUPT length, reference length) of each reference matched by overlap, as the Rust
    eval matches: a detected movement (heel-off to foot-flat) and a reference stride overlap
    by at least half the shorter; the first and last reference strides (the walk's start and
    end, flagged in the dataset) are left out."""
    pairs = []
    inner = refs.iloc[1:-1]
    for _, r in inner.iterrows():
        best, shared = None, 0
        for _, s in ours.iterrows():
            o = min(s["foot_flat"], r["end"]) - max(s["heel_off"], r["start"])
            if o > shared:
                best, shared = s, o
        if best is None:
            continue
        shorter = min(best["foot_flat"] - best["heel_off"], r["end"] - r["start"])
        if 2 * shared >= shorter and best["valid"] and "turn" not in best["flags"]:
            pairs.append((best["zupt_length"], r["length"]))
    return pairs


def test_gaitmaps_example_data_replays_and_matches_its_mocap(imu, mocap_lengths, datasets):
    # The heel-marker lengths are the shared dataset's reference (built from the same data).
    shared = pd.read_csv(datasets / "gaitmap_walk" / "strides.csv")
    for sensor, trial in [("left_sensor", "left"), ("right_sensor", "right")]:
        ref = shared[shared.trial == trial]["length_m"].to_numpy()
        assert np.allclose(mocap_lengths[sensor]["length"].to_numpy(), ref, atol=0.01), sensor
    pairs = []
    for sensor in ["left_sensor", "right_sensor"]:
        # gaitmap's units: acc m/s², gyr deg/s, no t_s column; the sensor's own axes.
        ours = gaitclip.replay(imu[sensor], RATE_HZ)
        assert ours.attrs["summary"]["strides"] == len(ours) >= 28
        pairs += match(ours, mocap_lengths[sensor])
    e = np.array([a - b for a, b in pairs])
    rmse, bias = float(np.sqrt(np.mean(e**2))), float(np.mean(e))
    print(f"gaitmap example data: {len(e)} strides, RMSE {rmse * 100:.1f} cm, bias {bias * 100:+.1f} cm")
    # The Rust eval: 49 clean strides, 3.7 / −0.2 cm (docs/accuracy.md).
    assert len(e) >= 40
    assert rmse <= 0.045 and abs(bias) <= 0.01, (rmse, bias)


def test_a_gaitmap_pipeline_runs_with_gaitclips_strides(imu, mocap_lengths):
    """gaitmap's MAD pipeline with its DTW segmentation and Rampp event detection swapped for
    gaitclip: gaitmap's own trajectory and spatial parameters on gaitclip's stride list."""
    from gaitmap.parameters import SpatialParameterCalculation, TemporalParameterCalculation
    from gaitmap.trajectory_reconstruction import StrideLevelTrajectory

    strides = gaitclip.GaitclipStrides(detector="cycle").estimate(imu, sampling_rate_hz=RATE_HZ)
    assert set(strides.stride_list_) == {"left_sensor", "right_sensor"}
    data = {s: imu[s] for s in ["left_sensor", "right_sensor"]}
    # gaitmap's trajectory reads its own units (deg/s), on the sensor's axes.
    trajectory = StrideLevelTrajectory().estimate(
        data=data, stride_event_list=strides.stride_list_, sampling_rate_hz=RATE_HZ
    )
    temporal = TemporalParameterCalculation().calculate(
        stride_event_list=strides.stride_list_, sampling_rate_hz=RATE_HZ
    )
    spatial = SpatialParameterCalculation().calculate(
        stride_event_list=strides.stride_list_,
        positions=trajectory.position_,
        orientations=trajectory.orientation_,
        sampling_rate_hz=RATE_HZ,
    )
    for sensor in ["left_sensor", "right_sensor"]:
        gm = spatial.parameters_[sensor]["stride_length"]
        ours = strides.parameters_[sensor]["stride_length"]
        assert len(gm) == len(ours) >= 25, sensor
        assert len(temporal.parameters_[sensor]) == len(ours)
        # gaitmap's own ZUPT on gaitclip's strides agrees with gaitclip's lengths on the
        # straight strides (turns differ by definition: the instep's path against gaitmap's).
        common = ours.index.intersection(gm.index)
        straight = strides.strides_[sensor].loc[common, "flags"].map(lambda f: "turn" not in f)
        d = (gm.loc[common] - ours.loc[common])[straight]
        assert float(np.median(np.abs(d))) <= 0.05, d.describe()


def test_the_readmes_example_runs(capsys):
    """The README's Python example, as written there."""
    import pathlib
    import re

    readme = (pathlib.Path(__file__).resolve().parents[2] / "README.md").read_text()
    code = re.search(r"## Python.*?```python\n(.*?)```", readme, re.S).group(1)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "stride_length_gaitmap" in out and len(out.splitlines()) >= 20, out

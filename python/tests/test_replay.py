"""`gaitclip.replay` is `gaitclip replay --json`, field for field, on every shared recording,
from the file and from a DataFrame of it; bad input raises the right Python exception."""

import json
import math
import pathlib
import subprocess

import numpy as np
import pandas as pd
import pytest

import gaitclip

RENAMED = {
    "index": None,  # the DataFrame's index, s_id
    "length_m": "stride_length",
    "stride_time_s": "stride_time",
    "stance_time_s": "stance_time",
    "swing_time_s": "swing_time",
    "gait_velocity_m_s": "gait_velocity",
    "max_sensor_lift_m": "max_sensor_lift",
    "turning_angle_deg": "turning_angle",
    "zupt_m": "zupt_length",
    "climb_m": "climb",
    "cadence_spm": "cadence",
}


def recordings(root: pathlib.Path):
    for d in sorted(p for p in root.iterdir() if p.is_dir()):
        for f in sorted(d.glob("*.csv")):
            if f.name in ("strides.csv", "trials.csv", "events.csv") or f.name.endswith(
                ".reference.csv"
            ):
                continue
            yield f


def cli(binary: str, path: pathlib.Path):
    out = subprocess.run(
        [binary, "replay", "--json", str(path)], check=True, capture_output=True, text=True
    ).stdout
    lines = [json.loads(l) for l in out.splitlines() if l.strip()]
    # Stride lines, then the refused movements (`{"rejected": …}`), then the summary.
    return [l for l in lines if "index" in l], lines[-1]["summary"]


def same(a, b) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        return (a == b) or (math.isnan(a) and math.isnan(b))
    return a == b


def check(frame: pd.DataFrame, strides, where: str) -> None:
    assert len(frame) == len(strides), where
    for (s_id, row), s in zip(frame.iterrows(), strides):
        assert s_id == s["index"], where
        for field, value in s.items():
            column = RENAMED.get(field, field)
            if column is None:
                continue
            got = row[column]
            if isinstance(value, list):
                got = list(got)
            assert same(got, value), f"{where} stride {s_id}: {field} {value!r} vs {column} {got!r}"


def test_every_shared_recording_replays_as_the_cli_does(datasets, gaitclip_cli):
    files = list(recordings(datasets))
    assert len(files) >= 200, len(files)
    for f in files:
        strides, summary = cli(gaitclip_cli, f)
        frame = gaitclip.replay(f)
        check(frame, strides, str(f))
        assert frame.attrs["summary"] == summary, f
        # A DataFrame of the same samples (the datasets' layout: t_s, rad/s), at the rate the
        # meta.json gives, replays the same.
        rate = json.loads((f.parent / "meta.json").read_text())["sample_rate_hz"]
        frame = gaitclip.replay(pd.read_csv(f), rate)
        check(frame, strides, f"{f} (DataFrame)")


def test_events_are_rows_of_the_input_in_gaitmap_order(datasets):
    frame = gaitclip.replay(datasets / "gaitmap_walk" / "left.csv")
    inner = frame.dropna(subset=["pre_ic"])
    assert len(inner) >= 25
    for c in ["start", "end", "ic", "tc", "min_vel"]:
        assert frame[c].dtype.kind == "i", c
    assert (inner["min_vel"] == inner["start"]).all()
    assert (inner["pre_ic"] < inner["start"]).all()
    assert (inner["start"] <= inner["tc"]).all() and (inner["tc"] <= inner["ic"]).all()
    assert (inner["ic"] <= inner["end"]).all()
    # Rows of a grid without holes are the times times the rate.
    rate = 204.8
    assert np.allclose(frame["start"], np.round(frame["start_s"] * rate))


def test_detectors_and_models(datasets):
    f = datasets / "gaitmap_walk" / "right.csv"
    every = gaitclip.replay(f, detector="stance", all_models=True)
    for m in gaitclip.MODELS:
        assert f"length_{m}" in every.columns, m
    lu = gaitclip.replay(f, detector="lu", model="lu_fuzzy")
    assert (lu["model"] == "lu_fuzzy").all() and len(lu) > 20
    assert gaitclip.DEFAULT_MODEL in gaitclip.MODELS


def frame_of(datasets: pathlib.Path) -> pd.DataFrame:
    return pd.read_csv(datasets / "gaitmap_walk" / "left.csv")


def test_bad_input_raises_the_right_exception(datasets, tmp_path):
    good = frame_of(datasets)
    with pytest.raises(ValueError, match="missing column 'gyr_y'"):
        gaitclip.replay(good.drop(columns=["gyr_y"]))
    nan = good.copy()
    nan.loc[17, "acc_z"] = float("nan")
    with pytest.raises(ValueError, match="column 'acc_z', row 17"):
        gaitclip.replay(nan)
    text = good.copy()
    text["gyr_x"] = text["gyr_x"].astype(object)
    text.loc[3, "gyr_x"] = "fast"
    with pytest.raises(ValueError, match="column 'gyr_x' is not numeric"):
        gaitclip.replay(text)
    back = good.copy()
    back.loc[100, "t_s"] = back.loc[10, "t_s"]
    with pytest.raises(ValueError, match="row 100: t_s"):
        gaitclip.replay(back)
    # The datasets' layout read as deg/s: no rotation a foot makes (it is rad/s).
    with pytest.raises(ValueError, match="gyr_unit='rad/s'"):
        gaitclip.replay(good, gyr_unit="deg/s")
    # gaitmap's layout (deg/s) read as rad/s: beyond any IMU.
    deg = good.drop(columns=["t_s"])
    deg[["gyr_x", "gyr_y", "gyr_z"]] = np.rad2deg(deg[["gyr_x", "gyr_y", "gyr_z"]])
    with pytest.raises(ValueError, match="gyr_unit='deg/s'"):
        gaitclip.replay(deg, 204.8, gyr_unit="rad/s")
    with pytest.raises(ValueError, match="needs sampling_rate_hz"):
        gaitclip.replay(deg)
    with pytest.raises(ValueError, match="detector 'fast' is not one of"):
        gaitclip.replay(good, detector="fast")
    with pytest.raises(ValueError, match="model 'guess' is not one of"):
        gaitclip.replay(good, model="guess")
    with pytest.raises(ValueError, match="lu_fuzzy"):
        gaitclip.replay(good, detector="lu", model="zupt")
    with pytest.raises(FileNotFoundError):
        gaitclip.replay(tmp_path / "nowhere.csv")
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n0,0,0,9.8,0,0,0\n0.005,0,zero,9.8,0,0,0\n")
    with pytest.raises(ValueError, match=r"bad\.csv:3:3: column `acc_y`"):
        gaitclip.replay(bad)
    with pytest.raises(TypeError):
        gaitclip.replay(42)
    # gaitmap's layout (deg/s, no t_s) at its rate replays as the datasets' layout does (to
    # the rounding of deg/s back to rad/s, and the stamps' to the grid).
    a = gaitclip.replay(deg, 204.8)
    b = gaitclip.replay(good)
    assert len(a) == len(b)
    assert np.allclose(a["stride_length"], b["stride_length"], atol=0.002)


def test_units_are_checked_on_every_path_and_declared_by_keyword(datasets, tmp_path):
    """The rule is the command line's (Rust): an accelerometer in g is refused from a path and
    from a DataFrame alike, naming the keyword; declared, it replays as the original."""
    good = frame_of(datasets)
    ref = gaitclip.replay(good)
    in_g = good.copy()
    in_g[["acc_x", "acc_y", "acc_z"]] = in_g[["acc_x", "acc_y", "acc_z"]] / 9.80665
    with pytest.raises(ValueError, match="acc_unit='g'"):
        gaitclip.replay(in_g)
    assert np.allclose(gaitclip.replay(in_g, acc_unit="g")["stride_length"], ref["stride_length"], atol=0.002)
    path = tmp_path / "walk.csv"
    in_g.to_csv(path, index=False)
    with pytest.raises(ValueError, match="acc_unit='g'"):
        gaitclip.replay(path)
    a = gaitclip.replay(path, acc_unit="g")
    assert len(a) == len(ref)
    # meta.json beside the file says it too.
    (tmp_path / "meta.json").write_text('{"units": {"acc": "g"}}')
    assert len(gaitclip.replay(path)) == len(ref)
    with pytest.raises(ValueError, match="unknown acc unit"):
        gaitclip.replay(good, acc_unit="furlongs")


def test_a_rate_the_stamps_contradict_is_refused_and_a_low_rate_warns(datasets):
    good = frame_of(datasets)
    with pytest.raises(ValueError, match="rate_overrides_stamps=True"):
        gaitclip.replay(good, 100.0)
    # A rate within a host clock's drift of the stamps' is the caller's to give.
    gaitclip.replay(good, 204.0)
    # Every third row: 68 Hz, below the checked range: it replays, with the CLI's warning.
    with pytest.warns(gaitclip.GaitclipWarning, match="below 100 Hz"):
        gaitclip.replay(good.iloc[::3].reset_index(drop=True))


def test_the_frame_built_from_blocks_is_the_plain_constructors(datasets):
    """`_frame.frame_of` hands pandas one block per dtype (the Python layer's main cost is the
    plain constructor): the frame must be the one `pd.DataFrame(dict)` builds, dtypes, order,
    lists in `flags` and all, for every detector, with every model, and with no stride."""
    from gaitclip import _gaitclip
    from gaitclip._frame import _BUILD

    assert _BUILD is not None, "the pinned pandas has a constructor from blocks"
    walk = str(datasets / "gaitmap_walk" / "left.csv")
    still = np.zeros((400, 3))
    still[:, 2] = 9.81
    cases = {
        "cycle": (_gaitclip.replay_path(walk, None, "cycle", None, False, None, None, None, None, False), False),
        "every model": (_gaitclip.replay_path(walk, None, "stance", None, True, None, None, None, None, False), True),
        "lu": (_gaitclip.replay_path(walk, None, "lu", "lu_fuzzy", False, None, None, None, None, False), False),
        "no stride": (
            _gaitclip.replay_arrays(
                np.arange(400) / 100.0, list(still.T.copy()), [np.zeros(400)] * 3,
                "rad/s", 100.0, "cycle", None, False, None, None, None, False,
            ),
            False,
        ),
    }
    for name, (native, all_models) in cases.items():
        fast = gaitclip._to_frame(native, all_models)
        plain = gaitclip._to_frame(native, all_models, blocks=False)
        pd.testing.assert_frame_equal(fast, plain, check_exact=True, obj=name)
        assert fast.attrs == plain.attrs, name
        if len(fast):
            assert fast._mgr.nblocks <= 4, f"{name}: {fast._mgr.nblocks} blocks"
            assert isinstance(fast["flags"].iloc[0], list), name
    assert len(gaitclip._to_frame(cases["no stride"][0], False)) == 0
    # Frames of the same columns share no Index: naming one's columns names no other's.
    a, b = (gaitclip._to_frame(cases["cycle"][0], False) for _ in range(2))
    a.columns.name = "field"
    assert b.columns.name is None

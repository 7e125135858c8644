"""`gaitclip.cohort` on a Dask `LocalCluster` of two workers: its Parquet stride table is
`gaitclip replay --json`, stride for stride, for every recording; a bad recording is reported
in its summary row and does not stop the others."""

import pandas as pd
import pytest

import gaitclip
from test_replay import check, cli

distributed = pytest.importorskip("dask.distributed")


def test_a_cohort_on_two_workers_is_the_cli_stride_for_stride(datasets, gaitclip_cli, tmp_path):
    good = sorted((datasets / "gaitmap_walk").glob("*.csv"))
    good = [p for p in good if p.name not in ("strides.csv", "trials.csv", "events.csv")]
    pyshoe = sorted((datasets / "pyshoe_vicon").glob("2017-11-22-11-2*.csv"))
    good += [p for p in pyshoe if not p.name.endswith(".reference.csv")][:3]
    assert len(good) >= 4, good
    bad = tmp_path / "broken.csv"
    bad.write_text("t_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n0.0,1,2,3,4,5\n")
    paths = [str(p) for p in good] + [str(bad)]
    out = tmp_path / "out"

    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        summary = gaitclip.cohort(paths, out, client=client, progress=False)

    assert list(summary.recording) == paths
    strides = pd.read_parquet(out / "strides.parquet")
    assert pd.read_parquet(out / "summary.parquet").equals(summary)
    for path in good:
        expected, expected_summary = cli(gaitclip_cli, path)
        row = summary[summary.recording == str(path)].iloc[0]
        assert row.error is None, row.error
        assert row.sensor == path.stem
        assert row.strides == len(expected)
        assert row["distance_m"] == expected_summary["distance_m"]
        frame = strides[strides.recording == str(path)].set_index("s_id")
        assert (frame.sensor == path.stem).all()
        check(frame.drop(columns=["recording", "sensor"]), expected, str(path))
    broken = summary[summary.recording == str(bad)].iloc[0]
    assert broken.strides == 0
    assert "ValueError" in broken.error and "broken.csv" in broken.error, broken.error
    assert not (strides.recording == str(bad)).any()


def test_a_glob_and_the_default_cluster(datasets, tmp_path):
    pattern = str(datasets / "gaitmap_walk" / "*t.csv")  # left.csv, right.csv
    summary = gaitclip.cohort(pattern, tmp_path, progress=False)
    assert sorted(summary.sensor) == ["left", "right"]
    assert summary.error.isna().all()
    assert (summary.strides > 20).all()
    strides = pd.read_parquet(tmp_path / "strides.parquet")
    assert len(strides) == summary.strides.sum()

"""Times gaitmap's stride-length pipeline on one trace, as `gaitclip cost` compares it.

Usage: python bench_gaitmap.py TRACE.csv RATE_HZ [REPEATS]

TRACE.csv has the dataset layout (t_s, acc_* in m/s², gyr_* in rad/s) in gaitmap's sensor
frame of a left foot (x to the toe, y left, z up), as ../shared/datasets/gaitmap_walk is.
The pipeline is gaitmap's own example ("MAD pipeline"): conversion to the body frame,
BarthDtw stride segmentation, RamppEventDetection, StrideLevelTrajectory and the spatial and
temporal parameters (stride length per stride). Reading the CSV is not timed. The first run
(which includes numba's compilation) is reported apart; the figure compared is the median
of the runs after it. Prints one JSON object.
"""

import json
import statistics
import sys
import time

import numpy as np
import pandas as pd
from gaitmap.event_detection import RamppEventDetection
from gaitmap.parameters import SpatialParameterCalculation, TemporalParameterCalculation
from gaitmap.stride_segmentation import BarthDtw
from gaitmap.trajectory_reconstruction import StrideLevelTrajectory
from gaitmap.utils.coordinate_conversion import convert_left_foot_to_fbf


def pipeline(data: pd.DataFrame, rate_hz: float) -> pd.DataFrame:
    bf = convert_left_foot_to_fbf(data)
    dtw = BarthDtw().segment(data=bf, sampling_rate_hz=rate_hz)
    ed = RamppEventDetection().detect(
        data=bf, stride_list=dtw.stride_list_, sampling_rate_hz=rate_hz
    )
    strides = ed.min_vel_event_list_
    traj = StrideLevelTrajectory().estimate(
        data=data, stride_event_list=strides, sampling_rate_hz=rate_hz
    )
    TemporalParameterCalculation().calculate(
        stride_event_list=strides, sampling_rate_hz=rate_hz
    )
    spatial = SpatialParameterCalculation().calculate(
        stride_event_list=strides,
        positions=traj.position_,
        orientations=traj.orientation_,
        sampling_rate_hz=rate_hz,
    )
    return spatial.parameters_


def main() -> None:
    path, rate_hz = sys.argv[1], float(sys.argv[2])
    repeats = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    raw = pd.read_csv(path)
    data = pd.DataFrame(
        {
            "acc_x": raw["acc_x"],
            "acc_y": raw["acc_y"],
            "acc_z": raw["acc_z"],
            "gyr_x": np.rad2deg(raw["gyr_x"]),
            "gyr_y": np.rad2deg(raw["gyr_y"]),
            "gyr_z": np.rad2deg(raw["gyr_z"]),
        }
    )
    t0 = time.perf_counter()
    params = pipeline(data, rate_hz)
    first_s = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        params = pipeline(data, rate_hz)
        runs.append(time.perf_counter() - t0)
    median_s = statistics.median(runs)
    lengths = params["stride_length"].to_numpy()
    print(
        json.dumps(
            {
                "samples": len(data),
                "strides": int(len(lengths)),
                "distance_m": float(np.nansum(lengths)),
                "first_run_s": first_s,
                "median_run_s": median_s,
                "runs": repeats,
                "samples_per_s": len(data) / median_s,
            }
        )
    )


if __name__ == "__main__":
    main()

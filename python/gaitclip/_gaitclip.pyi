"""The native half of gaitclip (Rust, PyO3): the host replay of the firmware's core."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
LOW_RATE_HZ: float

def replay_arrays(
    t_s: Optional[npt.NDArray[np.float64]],
    acc: Sequence[npt.NDArray[np.float64]],
    gyr: Sequence[npt.NDArray[np.float64]],
    gyr_unit: str,
    rate_hz: Optional[float],
    detector: str,
    model: Optional[str],
    all_models: bool,
    acc_range_g: Optional[float] = None,
    gyro_range_dps: Optional[float] = None,
    acc_unit: Optional[str] = None,
    rate_overrides_stamps: bool = False,
) -> Tuple[Dict[str, Any], str]:
    """Replays one sensor (acc x, y, z in ``acc_unit``, ``m/s^2`` by default, ``g`` or
    ``mg``; gyr x, y, z in ``gyr_unit``, ``rad/s`` or ``deg/s``; both checked): the strides'
    columns, named as ``gaitclip replay --json`` names its fields (numpy arrays; ``row_*``:
    the events' rows of the input), and the summary's JSON."""

def replay_path(
    path: Union[str, PathLike[str]],
    rate_hz: Optional[float],
    detector: str,
    model: Optional[str],
    all_models: bool,
    acc_range_g: Optional[float] = None,
    gyro_range_dps: Optional[float] = None,
    acc_unit: Optional[str] = None,
    gyr_unit: Optional[str] = None,
    rate_overrides_stamps: bool = False,
) -> Tuple[Dict[str, Any], str]:
    """Replays a CSV or MCAP recording (units: the arguments, else its meta.json's, else
    m/s² and rad/s; checked): the same columns and summary."""

def names() -> Tuple[List[str], List[str], str]:
    """The detector names, the model names and the default model."""

"""The native half of gaitclip (Rust, PyO3): the host replay of the firmware's core."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

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
) -> Tuple[Dict[str, Any], str]:
    """Replays one sensor (acc x, y, z in m/s²; gyr x, y, z in ``gyr_unit``, ``rad/s`` or
    ``deg/s``): the strides' columns, named as ``gaitclip replay --json`` names its fields
    (numpy arrays; ``row_*``: the events' rows of the input), and the summary's JSON."""

def replay_path(
    path: Union[str, PathLike[str]],
    rate_hz: Optional[float],
    detector: str,
    model: Optional[str],
    all_models: bool,
    acc_range_g: Optional[float] = None,
    gyro_range_dps: Optional[float] = None,
) -> Tuple[Dict[str, Any], str]:
    """Replays a ``.csv`` or ``.mcap`` recording: the same columns and summary."""

def names() -> Tuple[List[str], List[str], str]:
    """The detector names, the model names and the default model."""

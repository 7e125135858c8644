"""gaitclip for Python: the shoe-clip firmware's own stride detector and length."""

from os import PathLike
from typing import Any, Dict, Iterable, List, Mapping, Optional, Union

import pandas as pd

__version__: str
DETECTORS: List[str]
MODELS: List[str]
DEFAULT_MODEL: str

def replay(
    data: Union[pd.DataFrame, str, PathLike[str]],
    sampling_rate_hz: Optional[float] = None,
    *,
    detector: str = "cycle",
    model: Optional[str] = None,
    all_models: bool = False,
    gyr_unit: Optional[str] = None,
    acc_unit: Optional[str] = None,
    acc_range_g: Optional[float] = None,
    gyro_range_dps: Optional[float] = None,
    rate_overrides_stamps: bool = False,
) -> pd.DataFrame: ...

class GaitclipStrides:
    detector: str
    model: Optional[str]
    all_models: bool
    gyr_unit: Optional[str]
    acc_unit: Optional[str]
    data: Union[pd.DataFrame, Mapping[str, pd.DataFrame]]
    sampling_rate_hz: float
    strides_: Union[pd.DataFrame, Dict[str, pd.DataFrame]]
    stride_list_: Union[pd.DataFrame, Dict[str, pd.DataFrame]]
    parameters_: Union[pd.DataFrame, Dict[str, pd.DataFrame]]
    summary_: Union[Dict[str, Any], Dict[str, Dict[str, Any]]]
    def __init__(
        self,
        detector: str = "cycle",
        model: Optional[str] = None,
        all_models: bool = False,
        gyr_unit: Optional[str] = None,
        acc_unit: Optional[str] = None,
    ) -> None: ...
    def get_params(self) -> Dict[str, Any]: ...
    def estimate(
        self,
        data: Union[pd.DataFrame, Mapping[str, pd.DataFrame]],
        *,
        sampling_rate_hz: float,
    ) -> "GaitclipStrides": ...

def cohort(
    paths_or_glob: Union[str, PathLike[str], Iterable[Union[str, PathLike[str]]]],
    out: Union[str, PathLike[str]],
    client: Optional[Any] = None,
    *,
    progress: Optional[bool] = None,
    **replay_kwargs: Any,
) -> pd.DataFrame: ...

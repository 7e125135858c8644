"""gaitclip for Python: the shoe-clip firmware's own stride detector and length, on recordings.

``gaitclip.replay`` runs the firmware's fixed-point core (the same Rust code the Cortex-M
boards run, through the host replay of ``gaitclip replay``: the recovered sensor clock, holes
bridged or filled, the three step detectors, every length model, the gait parameters) on one
sensor's recording and returns its strides as a pandas DataFrame in gaitmap's stride-list
conventions. ``GaitclipStrides`` wraps it as a gaitmap-style algorithm object for pipelines.

Units of the input, told apart by the columns, never guessed from the values:

- a DataFrame with a ``t_s`` column is the datasets' CSV layout: ``t_s`` in s, ``acc_*`` in
  m/s², ``gyr_*`` in rad/s;
- a DataFrame without one is gaitmap's: ``acc_*`` in m/s², ``gyr_*`` in deg/s, one row per
  sample at ``sampling_rate_hz``;
- ``gyr_unit="deg/s"`` or ``"rad/s"`` and ``acc_unit="g"``, ``"mg"`` or ``"m/s^2"`` say it
  outright, for a DataFrame or a path (a path's ``meta.json`` may say it too: ``"units":
  {"acc": "g", "gyr": "deg/s"}``). Values that cannot be in their unit (an accelerometer
  whose stillest quarter does not read about 1 g; a gyro over 75 rad/s, beyond any IMU's range, or under
  30 °/s while the accelerometer shows steps) raise ``ValueError`` naming the unit they look
  like; the check is the command line's own (Rust, ``gaitclip_host::io::units``).

A recording below ``LOW_RATE_HZ`` (the core's checked range) replays with a
``GaitclipWarning``, as the command line warns.

Axes are the sensor's, any mounting: the core finds the foot frame itself.
"""

from __future__ import annotations

import json
import os
import warnings
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np
import pandas as pd

from . import _gaitclip
from ._frame import frame_of

__all__ = [
    "replay",
    "cohort",
    "GaitclipStrides",
    "GaitclipWarning",
    "DETECTORS",
    "MODELS",
    "DEFAULT_MODEL",
    "LOW_RATE_HZ",
    "__version__",
]

__version__: str = _gaitclip.__version__
LOW_RATE_HZ: float = _gaitclip.LOW_RATE_HZ


class GaitclipWarning(UserWarning):
    """A recording gaitclip replays but whose strides it cannot vouch for (a low rate)."""

DETECTORS, MODELS, DEFAULT_MODEL = _gaitclip.names()

ACC = ["acc_x", "acc_y", "acc_z"]
GYR = ["gyr_x", "gyr_y", "gyr_z"]

# gaitmap's names for what they mean here: the JSON field of `gaitclip replay --json` → the
# DataFrame's column. Fields not named here keep their JSON name.
RENAMED = {
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
# The events as rows of the input (gaitmap's stride list is in samples).
ROWS = {
    "start": "start",
    "end": "end",
    "heel_off": "heel_off",
    "toe_off": "tc",
    "heel_strike": "ic",
    "foot_flat": "foot_flat",
    "pre_ic": "pre_ic",
}
STRIDE_LIST = ["start", "end", "pre_ic", "ic", "min_vel", "tc"]
PARAMETERS = [
    "stride_length",
    "stride_time",
    "stance_time",
    "swing_time",
    "gait_velocity",
    "max_sensor_lift",
    "turning_angle",
]

PathLike = Union[str, "os.PathLike[str]"]


def _columns(frame: pd.DataFrame) -> Dict[str, np.ndarray]:
    """The sensor's columns as float arrays: present and numeric (the core checks that every
    value is finite, and `_not_finite` names the one that is not)."""
    missing = [c for c in ACC + GYR if c not in frame.columns]
    if missing:
        raise ValueError(
            f"missing column {missing[0]!r} (need {', '.join(ACC + GYR)}; have "
            f"{', '.join(map(str, frame.columns))})"
        )
    out = {}
    for c in (["t_s"] if "t_s" in frame.columns else []) + ACC + GYR:
        try:
            out[c] = frame[c].to_numpy(dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(f"column {c!r} is not numeric: {e}") from None
    return out


def _not_finite(frame: pd.DataFrame, columns: Dict[str, np.ndarray]) -> ValueError:
    """The error for the first value that is not a finite number, its column and row named."""
    for c, v in columns.items():
        finite = np.isfinite(v)
        if not finite.all():
            bad = int(np.argmin(finite))
            return ValueError(
                f"column {c!r}, row {frame.index[bad]!r}: {v[bad]!r} is not a finite number"
            )
    return ValueError("a value is not a finite number")


def _to_frame(
    native: Tuple[Dict[str, Any], str], all_models: bool, *, blocks: bool = True
) -> pd.DataFrame:
    columns, summary = native
    rows = {ROWS[k[4:]]: v for k, v in columns.items() if k.startswith("row_")}
    rows["min_vel"] = rows["start"]
    named = {RENAMED.get(k, k): v for k, v in columns.items() if not k.startswith("row_")}
    s_id = named.pop("index")
    data = {c: rows[c] for c in STRIDE_LIST}
    data.update({c: named.pop(c) for c in PARAMETERS})
    data.update({c: rows[c] for c in ("heel_off", "foot_flat")})
    data.update(named)
    frame = frame_of(data, pd.Index(s_id, name="s_id"), blocks=blocks)
    frame.attrs["summary"] = json.loads(summary)
    return frame


def replay(
    data: Union[pd.DataFrame, PathLike],
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
) -> pd.DataFrame:
    """Replays one sensor's recording through gaitclip's core and returns its strides.

    ``data`` is a DataFrame of one sensor (the module's docs say how its units are read) or
    the path of a CSV (the datasets' layout) or MCAP file (told by its first bytes, whatever
    its name). ``sampling_rate_hz`` is the nominal rate (needed without a ``t_s`` column;
    otherwise the stamps give it, and the core runs on the clock it recovers from them; a
    rate more than 10 % off the stamps' is refused unless ``rate_overrides_stamps=True``). ``detector`` is ``cycle`` (the firmware's),
    ``stance`` (Huang's) or ``lu`` (Lu's peak-valley, measured by ``lu_fuzzy`` only);
    ``model`` names the length model behind ``stride_length`` (default: the firmware's);
    ``all_models`` adds a ``length_<model>`` column for every model.

    Returns a DataFrame indexed by ``s_id``: gaitmap's ``start``, ``end``, ``pre_ic``, ``ic``,
    ``min_vel``, ``tc`` (rows of the input), ``stride_length`` (m), ``stride_time``,
    ``stance_time``, ``swing_time`` (s), ``gait_velocity`` (m/s), ``max_sensor_lift`` (m),
    ``turning_angle`` (deg) (``pre_ic`` is NaN where the stride before does not end at
    ``start``, so it is a float column, as in gaitmap's stride lists), then gaitclip's own columns (``heel_off``, ``foot_flat``, the
    events' times ``*_s``, ``zupt_length``, ``climb``, ``cadence``, ``stance_pct``,
    ``swing_pct``, ``gait`` (``walking``, ``running``, ``stairs_up``, ``stairs_down`` or
    ``unknown``), ``swing_deg``, ``still_before_s`` and ``moving_before_s`` (what the foot did
    since the stride before that counted: at rest, or moving without a step), ``valid``,
    ``flags``, ``model``, ``detector``). The replay's summary (holes, clock, counts,
    distance, the movements the step check refused by reason, minutes still and moving
    between strides) is ``frame.attrs["summary"]``.

    Raises ``ValueError`` for a missing or non-numeric column, a value that is not finite (its
    column and row named), stamps that go back, a unit that cannot be, a rate the stamps
    contradict, an unknown detector or model, or a malformed file (its line and column
    named); ``FileNotFoundError`` for a path
    that is not there.
    """
    if isinstance(data, (str, os.PathLike)):
        path = os.fspath(data)
        if not os.path.exists(path):
            raise FileNotFoundError(path)
        native = _gaitclip.replay_path(
            path,
            sampling_rate_hz,
            detector,
            model,
            all_models,
            acc_range_g,
            gyro_range_dps,
            acc_unit,
            gyr_unit,
            rate_overrides_stamps,
        )
    elif isinstance(data, pd.DataFrame):
        columns = _columns(data)
        has_t = "t_s" in columns
        unit = gyr_unit or ("rad/s" if has_t else "deg/s")
        if not has_t and sampling_rate_hz is None:
            raise ValueError("a DataFrame without a t_s column needs sampling_rate_hz")
        try:
            native = _gaitclip.replay_arrays(
                columns.get("t_s"),
                [columns[c] for c in ACC],
                [columns[c] for c in GYR],
                unit,
                sampling_rate_hz,
                detector,
                model,
                all_models,
                acc_range_g,
                gyro_range_dps,
                acc_unit,
                rate_overrides_stamps,
            )
        except ValueError as e:
            if "not a finite number" in str(e):
                raise _not_finite(data, columns) from None
            raise
    else:
        raise TypeError(f"data must be a DataFrame or a path, not {type(data).__name__}")
    frame = _to_frame(native, all_models)
    rate = frame.attrs["summary"].get("core_rate_hz", 0.0)
    if 0.0 < rate < LOW_RATE_HZ:
        warnings.warn(
            f"the recording is at {rate:.1f} Hz, below {LOW_RATE_HZ:g} Hz: gait events are "
            "coarse and lengths are not checked at this rate",
            GaitclipWarning,
            stacklevel=2,
        )
    return frame


class GaitclipStrides:
    """gaitclip as a gaitmap-style algorithm: stride list and parameters from raw IMU data.

    ``GaitclipStrides(detector="cycle").estimate(data, sampling_rate_hz=204.8)`` sets
    ``stride_list_`` (gaitmap's min_vel stride list: ``start``, ``end``, ``pre_ic``, ``ic``,
    ``min_vel``, ``tc`` in samples, indexed by ``s_id``; the strides whose every event is
    known: not the first of a walk, which has no ``pre_ic``), ``parameters_`` (the gait
    parameters of those strides in gaitmap's names and units), ``strides_`` (everything
    ``replay`` returns, every stride) and ``summary_``. For a multi-sensor dataset, a dict of
    DataFrames keyed by sensor (``left_sensor``, ``right_sensor``; or a DataFrame whose columns
    are a (sensor, axis) MultiIndex, as gaitmap's example data is), each attribute is a dict
    keyed the same way, as gaitmap's algorithms do.
    """

    def __init__(
        self,
        detector: str = "cycle",
        model: Optional[str] = None,
        all_models: bool = False,
        gyr_unit: Optional[str] = None,
        acc_unit: Optional[str] = None,
    ) -> None:
        self.detector = detector
        self.model = model
        self.all_models = all_models
        self.gyr_unit = gyr_unit
        self.acc_unit = acc_unit

    def get_params(self) -> Dict[str, Any]:
        """The constructor's parameters, as gaitmap's and scikit-learn's objects give them."""
        return {
            "detector": self.detector,
            "model": self.model,
            "all_models": self.all_models,
            "gyr_unit": self.gyr_unit,
            "acc_unit": self.acc_unit,
        }

    def _one(self, data: pd.DataFrame, sampling_rate_hz: float):
        strides = replay(
            data,
            sampling_rate_hz,
            detector=self.detector,
            model=self.model,
            all_models=self.all_models,
            gyr_unit=self.gyr_unit,
            acc_unit=self.acc_unit,
        )
        complete = strides.dropna(subset=["pre_ic"])
        stride_list = complete[STRIDE_LIST].astype("int64")
        return strides, stride_list, complete[PARAMETERS], strides.attrs["summary"]

    def estimate(
        self,
        data: Union[pd.DataFrame, Mapping[str, pd.DataFrame]],
        *,
        sampling_rate_hz: float,
    ) -> "GaitclipStrides":
        """Replays ``data`` (one sensor, or several) and sets the results; returns ``self``."""
        self.data = data
        self.sampling_rate_hz = sampling_rate_hz
        sensors: Optional[Dict[str, pd.DataFrame]] = None
        if isinstance(data, Mapping):
            sensors = dict(data)
        elif isinstance(data, pd.DataFrame) and isinstance(data.columns, pd.MultiIndex):
            sensors = {s: data[s] for s in data.columns.get_level_values(0).unique()}
        if sensors is None:
            self.strides_, self.stride_list_, self.parameters_, self.summary_ = self._one(
                data, sampling_rate_hz
            )
            return self
        results = {s: self._one(d, sampling_rate_hz) for s, d in sensors.items()}
        self.strides_ = {s: r[0] for s, r in results.items()}
        self.stride_list_ = {s: r[1] for s, r in results.items()}
        self.parameters_ = {s: r[2] for s, r in results.items()}
        self.summary_ = {s: r[3] for s, r in results.items()}
        return self


# A cohort of recordings on Dask (its own module; Dask is imported only when it runs).
from .cohort import cohort  # noqa: E402

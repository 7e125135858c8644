"""A cohort of recordings through gaitclip's core on Dask: one Parquet stride table, one summary.

``cohort(paths, out=…)`` replays every recording with :func:`gaitclip.replay` as a task of a
Dask cluster (``dask.distributed``): the ``client`` given, or a ``LocalCluster`` of one
single-threaded worker process per core when none is. Each task writes its recording's
strides as one part of the Parquet folder ``out/strides.parquet`` itself, so the strides of
a thousand recordings never travel through the client or sit in its memory; what comes back
is one summary row per recording, written to ``out/summary.parquet``.

A recording that cannot be replayed (malformed, a unit that cannot be, missing) is reported in
its summary row (``error``) and writes no part; the others go on. Columns:

- ``strides.parquet`` (a folder of parts, ``pandas.read_parquet`` reads it whole):
  ``recording`` (the path as given), ``sensor`` (the file's name without its extension),
  ``s_id``, then every column of :func:`gaitclip.replay`'s frame.
- ``summary.parquet``: ``recording``, ``sensor``, ``strides``, ``error`` (None when it
  replayed) and the replay's summary (``frame.attrs["summary"]``), nested fields flattened
  with dots (``rejected.no_rest``), lists (``rails``, one record per axis) as JSON text.

Needs the ``cohort`` extra: ``pip install "gaitclip[cohort]"`` (dask[distributed], pyarrow,
tqdm).
"""

from __future__ import annotations

import glob
import json
import os
import sys
from typing import Any, Dict, Iterable, List, Optional, Union

import pandas as pd

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["cohort"]


def _paths(paths_or_glob: Union[PathLike, Iterable[PathLike]]) -> List[str]:
    """The recordings named: a glob pattern (``**`` for any depth), one path, or many."""
    if isinstance(paths_or_glob, (str, os.PathLike)):
        text = os.fspath(paths_or_glob)
        if any(c in text for c in "*?["):
            found = sorted(glob.glob(text, recursive=True))
            if not found:
                raise FileNotFoundError(f"no recording matches {text}")
            return found
        return [text]
    return [os.fspath(p) for p in paths_or_glob]


def _sensor(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]


def _replay_one(index: int, path: str, parts: str, kwargs: Dict[str, Any]) -> Dict[str, Any]:
    """One recording on a worker: its strides into a part of its own, its summary back."""
    from . import replay  # on the worker

    row: Dict[str, Any] = {"recording": path, "sensor": _sensor(path)}
    try:
        frame = replay(path, **kwargs)
    except Exception as e:  # reported in the row: one bad recording does not stop the cohort
        row.update(strides=0, error=f"{type(e).__name__}: {e}")
        return row
    summary = frame.attrs.pop("summary", {})
    frame = frame.reset_index()
    frame.insert(0, "sensor", row["sensor"])
    frame.insert(0, "recording", path)
    # Parts are named by the recording's place in the list: the folder reads back in order.
    frame.to_parquet(os.path.join(parts, f"part-{index:06d}.parquet"), index=False)
    row.update(strides=len(frame), error=None, summary=summary)
    return row


def cohort(
    paths_or_glob: Union[PathLike, Iterable[PathLike]],
    out: PathLike,
    client: Optional[Any] = None,
    *,
    progress: Optional[bool] = None,
    **replay_kwargs: Any,
) -> pd.DataFrame:
    """Replays every recording on Dask; writes ``out/strides.parquet`` and
    ``out/summary.parquet`` (see the module) and returns the summary table.

    ``paths_or_glob`` is a glob pattern (``"data/**/*.csv"``), one path or an iterable of
    paths (CSV or MCAP, as :func:`gaitclip.replay` takes them). ``client`` is a
    ``dask.distributed.Client`` of any scheduler; without one a ``LocalCluster`` of one
    worker process per core runs the cohort and is closed after. ``progress`` shows a bar
    (tqdm, on stderr; default: when stderr is a terminal). Other keywords go to every
    :func:`gaitclip.replay` (``detector=``, ``model=``, ``gyr_unit=``, …).

    ``out`` is created if absent; a ``strides.parquet`` folder already in it is replaced.
    """
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as e:  # pragma: no cover - the extra is installed in the tests
        raise ImportError(
            'gaitclip.cohort needs Dask: pip install "gaitclip[cohort]"'
        ) from e
    paths = _paths(paths_or_glob)
    out = os.fspath(out)
    parts = os.path.join(out, "strides.parquet")
    os.makedirs(parts, exist_ok=True)
    for old in os.listdir(parts):
        if old.startswith("part-") and old.endswith(".parquet"):
            os.remove(os.path.join(parts, old))
    parts = os.path.abspath(parts)

    own = client is None
    cluster = None
    if own:
        cluster = LocalCluster(
            n_workers=os.cpu_count() or 1, threads_per_worker=1, processes=True
        )
        client = Client(cluster)
    try:
        futures = [
            client.submit(_replay_one, i, p, parts, replay_kwargs, pure=False)
            for i, p in enumerate(paths)
        ]
        show = sys.stderr.isatty() if progress is None else progress
        bar = None
        if show:
            from tqdm import tqdm

            bar = tqdm(total=len(futures), desc="recordings", unit="rec", file=sys.stderr)
        rows: List[Optional[Dict[str, Any]]] = [None] * len(futures)
        place = {f.key: i for i, f in enumerate(futures)}
        for future in as_completed(futures):
            rows[place[future.key]] = future.result()
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
    finally:
        if own:
            client.close()
            cluster.close()

    flat = []
    for row in rows:
        assert row is not None
        summary = row.pop("summary", None)
        if summary:
            fields = pd.json_normalize(summary, sep=".").iloc[0].to_dict()
            # Lists (the rails, one record per axis) as JSON text: one flat, portable table.
            row.update(
                {k: json.dumps(v) if isinstance(v, (list, dict)) else v for k, v in fields.items()}
            )
        flat.append(row)
    table = pd.DataFrame(flat)
    table.to_parquet(os.path.join(out, "summary.parquet"), index=False)
    return table

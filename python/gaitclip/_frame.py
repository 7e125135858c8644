"""A DataFrame from the core's columns, one block per dtype.

``pd.DataFrame(dict_of_columns)`` checks, infers and wraps every column on its own and then
consolidates them: about 7 µs a column, 0.28 ms for a replay's 37, which is most of what the
Python layer adds to the core (docs/python.md). The columns here are already what the frame
holds (float64, int64 and bool arrays from the core, lists of strings), so they are stacked
into one 2-D array per dtype and handed to pandas as its blocks, as pyarrow's ``to_pandas``
does: ``pandas.api.internals.create_dataframe_from_blocks`` where pandas has it (3.0 on),
``pandas.core.internals.api.make_block`` and a ``BlockManager`` before (the API pyarrow uses
on pandas 2). Where neither is there, or pandas would store strings as its own string dtype
(``future.infer_string``, pandas 3's default), the plain constructor builds the frame, so the
frame is the same either way (a test compares the two on real replays).
"""

from __future__ import annotations

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
import pandas as pd

Blocks = List[Tuple[np.ndarray, np.ndarray]]


def _object_array(values: Sequence[Any]) -> np.ndarray:
    """A 1-D object array holding each value as it is (a list stays one list)."""
    out = np.empty(len(values), dtype=object)
    for i, v in enumerate(values):
        out[i] = v
    return out


def _builder() -> Optional[Callable[[Blocks, pd.Index, pd.Index], pd.DataFrame]]:
    """pandas' constructor from blocks, or None where this pandas has none we can use."""
    try:
        from pandas.api.internals import create_dataframe_from_blocks  # pandas >= 3.0

        return lambda blocks, index, columns: create_dataframe_from_blocks(blocks, index, columns)
    except ImportError:
        pass
    try:
        from pandas.core.internals.api import make_block
        from pandas.core.internals.managers import BlockManager
    except ImportError:
        return None
    if not hasattr(pd.DataFrame, "_from_mgr"):  # pandas < 2.1
        return None

    def build(blocks: Blocks, index: pd.Index, columns: pd.Index) -> pd.DataFrame:
        mgr = BlockManager([make_block(v, placement=p) for v, p in blocks], [columns, index])
        return pd.DataFrame._from_mgr(mgr, axes=mgr.axes)

    return build


_BUILD = _builder()


def _infers_strings() -> bool:
    try:
        return bool(pd.get_option("future.infer_string"))
    except (KeyError, pd.errors.OptionError):
        return False


def frame_of(data: Dict[str, Any], index: pd.Index, *, blocks: bool = True) -> pd.DataFrame:
    """The DataFrame of ``data``'s columns, in its order, on ``index``: each column a 1-D
    numpy array or a list (of strings, or of lists) as long as the index. ``blocks=False``
    builds it with the plain constructor (what the fast path is checked against)."""
    # No rows: the plain constructor's dtypes for empty lists are its own (float64 on pandas 2).
    if not blocks or len(index) == 0 or _BUILD is None or _infers_strings():
        return pd.DataFrame(data, index=index, copy=False)
    groups: Dict[np.dtype, List[int]] = {}
    arrays: List[np.ndarray] = []
    for j, v in enumerate(data.values()):
        a = v if isinstance(v, np.ndarray) else _object_array(v)
        arrays.append(a)
        groups.setdefault(a.dtype, []).append(j)
    stacked = []
    for dtype, js in groups.items():
        block = np.empty((len(js), len(index)), dtype=dtype)
        for row, j in enumerate(js):
            block[row] = arrays[j]
        stacked.append((block, np.asarray(js, dtype=np.intp)))
    return _BUILD(stacked, index, _columns_index(tuple(data)))


_COLUMNS: Dict[Tuple[str, ...], pd.Index] = {}


def _columns_index(names: Tuple[str, ...]) -> pd.Index:
    """The columns' Index, its strings inferred once per set of names (a replay has one of a
    few), a copy per frame: an Index's values are immutable, its name is not."""
    index = _COLUMNS.get(names)
    if index is None:
        index = _COLUMNS[names] = pd.Index(list(names))
    return index.copy()

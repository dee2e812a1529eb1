"""Which points share a table cell or a plot line.

A table is keyed by (scene, tile, SIMD width); a sweep may vary more than that (ray-buffer size,
bank count, fidelity, ...). A configuration column that takes more than one value inside one
key cell is a *context* column: tables are repeated once per context (one block per combination
of its values), plots use the most common context and say which in their caption. Columns that
merely follow the key (a preset name per width, a seed per scene) are not contexts.
"""

from __future__ import annotations

from typing import Dict, List, Sequence, Tuple

import pandas as pd

from .store import FIDELITIES

SCENE, TILE, WIDTH = "workload.scene", "workload.tile", "hw.simd.width"
TABLE_KEY = [SCENE, TILE, WIDTH]


def candidate_columns(points: pd.DataFrame) -> List[str]:
    cols = [c for c in points.columns
            if c.startswith("workload.") or c.startswith("hw.") or c == "fidelity"]
    if "sfx_version" in points.columns:
        cols.append("sfx_version")
    return cols


def context_columns(points: pd.DataFrame, key: Sequence[str]) -> List[str]:
    key = list(key)
    result = []
    for c in candidate_columns(points):
        if c in key:
            continue
        per_cell = points.groupby(key, dropna=False)[c].nunique(dropna=False)
        if (per_cell > 1).any():
            result.append(c)
    return result


def _value_text(v) -> str:
    if isinstance(v, float) and v.is_integer():
        return str(int(v))
    return str(v)


def describe(context: Dict[str, object]) -> str:
    return ", ".join(f"{k} = {_value_text(v)}" for k, v in context.items())


def contexts(points: pd.DataFrame, key: Sequence[str]) -> List[Tuple[Dict[str, object],
                                                                       pd.DataFrame]]:
    """(context, points) per combination of the context columns, in sorted order; one entry
    with an empty context when nothing but the key varies."""
    cols = context_columns(points, key)
    if not cols:
        return [({}, points)]
    result = []
    by = cols[0] if len(cols) == 1 else cols  # a one-item list makes pandas warn
    for values, group in points.groupby(by, dropna=False, sort=True):
        if not isinstance(values, tuple):
            values = (values,)
        result.append((dict(zip(cols, values)), group))
    return result


def dominant_context(points: pd.DataFrame, key: Sequence[str]) -> Tuple[Dict[str, object],
                                                                        pd.DataFrame]:
    """The context holding the most points (ties: the first in sorted order)."""
    best = None
    for context, group in contexts(points, key):
        if best is None or len(group) > len(best[1]):
            best = (context, group)
    return best


def one_per_cell(points: pd.DataFrame, key: Sequence[str]) -> pd.DataFrame:
    """Within one context two rows of a cell differ only in columns outside the configuration
    (a re-run under another key); keep the most recently finished one rather than average."""
    if "finished_at" in points.columns:
        points = points.sort_values("finished_at", kind="mergesort", na_position="first")
    return points.drop_duplicates(subset=list(key), keep="last")


def fidelity_rank(fidelity: str) -> int:
    return FIDELITIES.index(fidelity) if fidelity in FIDELITIES else -1

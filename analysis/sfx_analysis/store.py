"""Reads an sfx results store (SQLite, schema version 1) into a tidy DataFrame.

One row per point; the configuration columns are already flat in the store (`workload.*`,
`hw.<dotted path>`, `fidelity`); metric columns keep their raw stat names (`fps`,
`simd_utilization.primary.traversal`, ...). Units are added only for display, from the store's
own `units` table (written from the C++ declarations of each column; a store without one shows
none).
"""

from __future__ import annotations

import os
import sqlite3
import urllib.parse
from dataclasses import dataclass, field
from typing import Dict, List

import pandas as pd

SCHEMA_VERSION = 1

# Columns that say where a row came from rather than what it configures or measures.
IDENTITY_COLUMNS = ["key", "sfx_version", "sweep", "point_index", "started_at", "finished_at",
                    "config_yaml"]
# What every schema-1 store has; the tables and plots are keyed by these.
REQUIRED_COLUMNS = ["workload.scene", "workload.tile", "hw.simd.width", "fidelity"]
STAGES = ["traversal", "intersection", "shading"]
# Most accurate last: a row's rank in this list orders fidelities in plots.
FIDELITIES = ["analytic", "sampled", "full"]


class StoreError(Exception):
    """A results store that cannot be reported on. The CLI prints the message and exits 2."""


@dataclass
class Store:
    path: str
    schema_version: int
    created_by: str
    points: pd.DataFrame
    config_columns: List[str]
    metric_columns: List[str]
    warnings: List[str] = field(default_factory=list)
    units: Dict[str, str] = field(default_factory=dict)  # column -> unit ("" for ratios)

    def has(self, column: str) -> bool:
        return column in self.points.columns and self.points[column].notna().any()


def is_config_column(name: str) -> bool:
    return name.startswith("workload.") or name.startswith("hw.") or name == "fidelity"


def _connect_read_only(path: str) -> sqlite3.Connection:
    if not os.path.exists(path):
        raise StoreError(f"{path}: no such file")
    if os.path.isdir(path):
        raise StoreError(f"{path}: is a directory, not a results store")
    if not os.path.isfile(path):
        raise StoreError(f"{path}: not a regular file, not a results store")
    # In a read-only directory SQLite cannot create the write-ahead log's index beside the
    # store; with no log left to replay the file alone is the whole store ("immutable").
    wal = path + "-wal"
    read_only_dir = not os.access(os.path.dirname(os.path.abspath(path)), os.W_OK | os.X_OK)
    pending_wal = os.path.exists(wal) and os.path.getsize(wal) > 0
    mode = "mode=ro&immutable=1" if read_only_dir and not pending_wal else "mode=ro"
    uri = "file:" + urllib.parse.quote(os.path.abspath(path)) + "?" + mode
    try:
        con = sqlite3.connect(uri, uri=True)
        con.execute("SELECT name FROM sqlite_master").fetchall()
    except sqlite3.DatabaseError as e:
        if read_only_dir and pending_wal:
            raise StoreError(f"{path}: its write-ahead log holds unfinished writes and its "
                             f"directory is read-only ({e}): run sfx sweep on it once where it "
                             f"is writable, or copy it") from None
        raise StoreError(f"{path}: not an SQLite results store ({e})") from None
    return con


def _read_meta(con: sqlite3.Connection, path: str) -> dict:
    tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    if "meta" not in tables:
        raise StoreError(f"{path}: no 'meta' table: not an sfx results store, or one written "
                         f"before schema version {SCHEMA_VERSION}")
    if "points" not in tables:
        raise StoreError(f"{path}: no 'points' table: not an sfx results store")
    try:
        return dict(con.execute("SELECT key, value FROM meta").fetchall())
    except sqlite3.DatabaseError as e:
        raise StoreError(f"{path}: unreadable 'meta' table ({e})") from None


def _check_schema(meta: dict, path: str) -> int:
    text = meta.get("schema_version")
    if text is None:
        raise StoreError(f"{path}: meta has no schema_version: written by an sfx older than "
                         f"schema version {SCHEMA_VERSION}; re-run the sweep with this sfx")
    try:
        version = int(str(text).strip())
    except ValueError:
        raise StoreError(f"{path}: meta.schema_version is '{text}', not a number") from None
    if version < SCHEMA_VERSION:
        raise StoreError(f"{path}: schema version {version} is older than the version this "
                         f"analysis reads ({SCHEMA_VERSION}); re-run the sweep with this sfx "
                         f"(`sfx sweep SWEEP --store NEW.db`)")
    if version > SCHEMA_VERSION:
        raise StoreError(f"{path}: schema version {version} is newer than the version this "
                         f"analysis reads ({SCHEMA_VERSION}); use the analysis/ of the sfx "
                         f"that wrote it ({meta.get('created_by', 'unknown')})")
    return version


def _read_units(con: sqlite3.Connection, path: str) -> Dict[str, str]:
    """The store's units table (column name -> unit); empty for a store written before it."""
    tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    if "units" not in tables:
        return {}
    try:
        return {name: unit or "" for name, unit in con.execute("SELECT name, unit FROM units")}
    except sqlite3.DatabaseError as e:
        raise StoreError(f"{path}: unreadable 'units' table ({e})") from None


def _numeric_if_possible(column: pd.Series) -> pd.Series:
    """hw.* columns are REAL for numbers and TEXT for strings and bools: convert only when every
    stored value is a number, so 'soa' or 'true' stay text."""
    converted = pd.to_numeric(column, errors="coerce")
    if converted.notna().sum() == column.notna().sum():
        return converted
    return column


def load_store(path: str) -> Store:
    """Loads the points of a results store. Raises StoreError with a message meant for the user
    (no traceback) when the store is not one this analysis can read or holds no points."""
    con = _connect_read_only(path)
    try:
        meta = _read_meta(con, path)
        version = _check_schema(meta, path)
        try:
            points = pd.read_sql_query("SELECT * FROM points", con)
        except (sqlite3.DatabaseError, pd.errors.DatabaseError) as e:
            raise StoreError(f"{path}: unreadable 'points' table ({e})") from None
        units = _read_units(con, path)
    finally:
        con.close()

    if len(points) == 0:
        raise StoreError(f"{path}: the store holds no points yet; run `sfx sweep SWEEP "
                         f"--store {path}` first")
    missing = [c for c in REQUIRED_COLUMNS if c not in points.columns]
    if missing:
        raise StoreError(f"{path}: the points table lacks {', '.join(missing)} (schema "
                         f"version {SCHEMA_VERSION} requires them)")

    config_columns = [c for c in points.columns if is_config_column(c)]
    metric_columns = [c for c in points.columns
                      if c not in IDENTITY_COLUMNS and c not in config_columns]
    if not metric_columns:
        raise StoreError(f"{path}: the points table has no metric columns (fps, ...)")

    for c in metric_columns:
        points[c] = pd.to_numeric(points[c], errors="coerce")
    for c in config_columns:
        if c not in ("workload.scene", "fidelity", "hw.name"):
            points[c] = _numeric_if_possible(points[c])
    points["workload.scene"] = points["workload.scene"].astype(str)
    points["fidelity"] = points["fidelity"].astype(str)
    points = points.sort_values(["workload.scene", "workload.tile", "hw.simd.width"],
                                kind="mergesort").reset_index(drop=True)

    store = Store(path=path, schema_version=version, created_by=meta.get("created_by", ""),
                  points=points, config_columns=config_columns, metric_columns=metric_columns,
                  units=units)
    if len(points) == 1:
        store.warnings.append("the store holds one point: tables have one cell each and "
                              "every plot that compares points is skipped")
    for stage in STAGES:
        stage_columns = [c for c in metric_columns if c.endswith("." + stage)]
        if not any(store.has(c) for c in stage_columns):
            store.warnings.append(f"the store has no values for the {stage} stage "
                                  f"(simd_utilization.*.{stage}, stream_length.{stage}, ...): "
                                  f"its cells are shown as missing")
    if not store.has("fps"):
        store.warnings.append("the store has no fps values: Table 6 and the fps plots are "
                              "empty or skipped")
    return store


def display_name(name: str, units: Dict[str, str]) -> str:
    """`fps` -> `fps [frames/s]`; names without a unit (ratios) are returned unchanged."""
    u = units.get(name, "")
    return f"{name} [{u}]" if u else name


def for_display(store: Store, points: pd.DataFrame) -> pd.DataFrame:
    """The tidy frame with units in the column names, for CSV and HTML output."""
    return points.rename(columns={c: display_name(c, store.units) for c in points.columns})

"""Small results stores built in the test with sqlite3, following the results-store schema
(version 1, described in sweeps/README.md). No binary store is checked in."""

import os
import sqlite3
import sys

import pytest

ANALYSIS_DIR = os.path.join(os.path.dirname(__file__), "..", "..", "analysis")
sys.path.insert(0, os.path.abspath(ANALYSIS_DIR))

IDENTITY = {"key": "TEXT PRIMARY KEY", "sfx_version": "TEXT", "sweep": "TEXT",
            "point_index": "INTEGER", "started_at": "TEXT", "finished_at": "TEXT",
            "config_yaml": "TEXT"}
WORKLOAD = {"workload.scene": "TEXT", "workload.width": "INTEGER", "workload.height": "INTEGER",
            "workload.spp": "INTEGER", "workload.depth": "INTEGER", "workload.tile": "INTEGER",
            "workload.seed": "INTEGER", "fidelity": "TEXT"}


def write_store(path, points, schema_version="1", meta=True, units=None):
    """Writes a store: meta(schema_version, created_by) and points with the identity and
    workload columns of schema 1, then one column per key the points use (hw.* REAL or TEXT,
    metrics REAL); with `units` (column -> unit), the units table sfx writes beside them."""
    con = sqlite3.connect(path)
    if units is not None:
        con.execute("CREATE TABLE units(name TEXT PRIMARY KEY, unit TEXT, description TEXT)")
        con.executemany("INSERT INTO units VALUES(?, ?, '')", list(units.items()))
    if meta:
        con.execute("CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT)")
        if schema_version is not None:
            con.execute("INSERT INTO meta VALUES('schema_version', ?)", (schema_version,))
        con.execute("INSERT INTO meta VALUES('created_by', 'sfx 0.1.0')")
    columns = dict(IDENTITY)
    columns.update(WORKLOAD)
    for p in points:
        for k, v in p.items():
            if k not in columns:
                columns[k] = "TEXT" if isinstance(v, str) else "REAL"
    con.execute("CREATE TABLE points(" + ", ".join(f'"{k}" {t}' for k, t in columns.items()) + ")")
    for i, p in enumerate(points):
        row = {"key": f"{i:064x}", "sfx_version": "0.1.0", "sweep": "test", "point_index": i,
               "started_at": "2026-01-01T00:00:00Z", "finished_at": f"2026-01-01T00:00:{i:02d}Z",
               "config_yaml": "hw: {}\n", "workload.width": 64, "workload.height": 64,
               "workload.spp": 1, "workload.depth": 3, "workload.seed": 0,
               "fidelity": "analytic"}
        row.update(p)
        keys = list(row)
        con.execute("INSERT INTO points(" + ", ".join(f'"{k}"' for k in keys) + ") VALUES(" +
                    ", ".join("?" for _ in keys) + ")", [row[k] for k in keys])
    con.commit()
    con.close()
    return path


STAGES = ["traversal", "intersection", "shading"]
CAUSES = ["bank_conflict", "alignment", "address_fetch", "partition", "scene_memory",
          "interconnect", "pipeline_fill"]


def point(scene, tile, width, kib=512.0, fps=None, **extra):
    """A full point whose metrics follow simple formulas, so tests can compute cells by hand:
    utilization u(stage) = 0.5 + 0.01 * tile / width * (stage index + 1) capped below 1."""
    s = {"conference": 0, "rtrt": 1}.get(scene, 2)
    p = {"workload.scene": scene, "workload.tile": tile, "hw.simd.width": float(width),
         "hw.ray_buffer.kib": float(kib), "hw.ray_buffer.buffers": 2.0, "hw.name": "gr08",
         "hw.ray_buffer.layout": "soa",
         "fps": fps if fps is not None else 10.0 * (s + 1) + width / 4.0 + tile / 32.0,
         "frame_cycles": 5e7, "host_seconds": 0.01, "error.relative": -1.0}
    for k, stage in enumerate(STAGES):
        for kind in ["primary", "secondary"]:
            ideal = min(0.99, 0.6 + 0.01 * (tile / width) * (k + 1))
            p[f"ideal_simd_utilization.{kind}.{stage}"] = ideal
            p[f"simd_utilization.{kind}.{stage}"] = ideal * 0.9
        p[f"simd_utilization.{stage}"] = 0.5 + 0.1 * k + width / 1000.0
        p[f"ideal_simd_utilization.{stage}"] = 0.6 + 0.1 * k + width / 1000.0
        p[f"stream_length.{stage}"] = tile * (k + 1) / 4.0
    for j, cause in enumerate(CAUSES):
        p[f"stall_cycles.{cause}"] = 1e5 * (j + 1)
    p["stall_cycles.total"] = sum(1e5 * (j + 1) for j in range(len(CAUSES)))
    for name, v in [("load", 24.1), ("store", 14.9), ("compute", 35.4), ("scatter_gather", 19.6),
                    ("partition", 5.0)]:
        p[f"op_mix.{name}_percent"] = v + (width - 4) / 100.0
    # Area grows with the lanes and the buffers; energy per frame falls with width.
    p["area.total_mm2"] = 20.0 + 0.5 * width + kib / 64.0
    p["energy.total_per_frame_mj"] = 30.0 - width / 2.0 + tile / 16.0
    p["tech.node_nm"] = 90.0
    p.update(extra)
    return p


def grid_points(kibs=(512.0,)):
    return [point(scene, tile, width, kib)
            for scene in ["rtrt", "conference"] for tile in [8, 32] for width in [4, 16]
            for kib in kibs]


def accuracy_store(tmp_path):
    """Every plot of the report has data: two ray-buffer sizes, and one configuration at three
    fidelities."""
    points = grid_points(kibs=(128.0, 512.0))
    for fidelity, fps, err, host in [("sampled", 26.0, 0.05, 0.5), ("full", 25.0, 0.0, 5.0)]:
        points.append(point("rtrt", 32, 16, 512.0, fps=fps, fidelity=fidelity,
                            **{"error.relative": err, "host_seconds": host}))
    return write_store(str(tmp_path / "acc.db"), points)


@pytest.fixture
def grid_store(tmp_path):
    return write_store(str(tmp_path / "grid.db"), grid_points())


@pytest.fixture
def buffer_store(tmp_path):
    return write_store(str(tmp_path / "buffers.db"), grid_points(kibs=(128.0, 512.0)))

"""The report's plots (PNG, matplotlib's Agg backend). A plot with no data is skipped with a
reason, never drawn empty. Error bars show fps × error.relative where the model reported an
interval (error.relative > 0)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after choosing the backend)
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from .slicing import (SCENE, TABLE_KEY, TILE, WIDTH, describe, dominant_context,  # noqa: E402
                      fidelity_rank)
from .store import FIDELITIES, STAGES, Store  # noqa: E402

KIB = "hw.ray_buffer.kib"
BUFFERS = "hw.ray_buffer.buffers"
DPI = 110


@dataclass
class Plot:
    name: str                    # file stem, 'fps_vs_width'
    title: str
    caption: str = ""
    file: Optional[str] = None   # the PNG's file name (beside index.html); None when skipped
    skipped: str = ""            # why the plot was not drawn


def _n(v) -> str:
    f = float(v)
    return str(int(f)) if f.is_integer() else f"{f:g}"


def _subplots(n: int, ncols: int = 3, size=(4.4, 3.3)):
    ncols = max(1, min(ncols, n))
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows),
                             squeeze=False, layout="constrained")
    flat = list(axes.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def _save(fig, directory: str, name: str) -> str:
    file = f"{name}.png"
    fig.savefig(os.path.join(directory, file), dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    return file


def _fps_error(frame: pd.DataFrame) -> pd.Series:
    """Half-width of the fps interval: fps × error.relative where the model reported a
    non-zero interval, NaN elsewhere (full fidelity is exact: no bar)."""
    if "error.relative" not in frame.columns:
        return pd.Series(np.nan, index=frame.index)
    rel = frame["error.relative"].where(frame["error.relative"] > 0)
    return frame["fps"] * rel


def _line_with_errors(ax, x, y, err, **style) -> bool:
    """Draws a line; adds error bars at the points that have an interval. True if any did."""
    (line,) = ax.plot(x, y, marker="o", **style)
    ok = np.isfinite(np.asarray(err, dtype=float))
    if ok.any():
        ax.errorbar(np.asarray(x)[ok], np.asarray(y)[ok], yerr=np.asarray(err, dtype=float)[ok],
                    fmt="none", ecolor=line.get_color(), capsize=3, linewidth=1)
        return True
    return False


def _context_caption(context: Dict[str, object]) -> str:
    return f" Points with {describe(context)} (the sweep's most common setting)." if context \
        else ""


def _titled(plot: Plot, data: pd.DataFrame) -> str:
    """The plot's title with the technology nodes of its points (hw.tech.node; tech.node_nm in
    stores from before the node was a knob): "... (7nm)"."""
    if "hw.tech.node" in data.columns:
        nodes = sorted(data["hw.tech.node"].dropna().astype(str).unique())
    elif "tech.node_nm" in data.columns:
        nodes = [f"{_n(v)}nm" for v in sorted(data["tech.node_nm"].dropna().unique())]
    else:
        nodes = []
    if nodes:
        plot.title += f" ({', '.join(nodes)})"
    return plot.title


def _with(points: pd.DataFrame, columns: Sequence[str]) -> pd.DataFrame:
    if any(c not in points.columns for c in columns):
        return points.iloc[0:0]
    return points.dropna(subset=list(columns))


def plot_fps_vs_width(store: Store, directory: str) -> Plot:
    plot = Plot("fps_vs_width", "Predicted frame rate against SIMD width")
    data = _with(store.points, ["fps"])
    if data.empty:
        plot.skipped = "the store has no fps values"
        return plot
    context, data = dominant_context(data, TABLE_KEY)
    if data.groupby([SCENE, TILE])[WIDTH].nunique().max() < 2:
        widths = ", ".join(_n(w) for w in sorted(data[WIDTH].unique()))
        plot.skipped = f"needs two SIMD widths for one scene and tile; the store has N = {widths}"
        return plot
    scenes = sorted(data[SCENE].unique())
    fig, axes = _subplots(len(scenes))
    any_error = False
    for ax, scene in zip(axes, scenes):
        at_scene = data[data[SCENE] == scene]
        for tile in sorted(at_scene[TILE].unique()):
            d = at_scene[at_scene[TILE] == tile].sort_values(WIDTH)
            any_error |= _line_with_errors(ax, d[WIDTH], d["fps"], _fps_error(d),
                                           label=f"tile {_n(tile)}×{_n(tile)}")
        ax.set_title(scene)
        ax.set_xlabel("SIMD width N [lanes]")
        ax.set_ylabel("predicted fps [frames/s]")
        ax.set_xticks(sorted(at_scene[WIDTH].unique()))
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = ("One panel per scene, one line per initial stream (tile) size." +
                    (" Error bars: the model's fps interval." if any_error else "") +
                    _context_caption(context))
    return plot


def plot_utilization_vs_width(store: Store, directory: str) -> Plot:
    plot = Plot("utilization_vs_width", "SIMD utilization per stage against SIMD width")
    stages = [s for s in STAGES if store.has(f"simd_utilization.{s}")]
    if not stages:
        plot.skipped = "the store has no simd_utilization.<stage> values"
        return plot
    data = store.points[store.points[[f"simd_utilization.{s}" for s in stages]].notna().any(axis=1)]
    context, data = dominant_context(data, TABLE_KEY)
    if data.groupby([SCENE, TILE])[WIDTH].nunique().max() < 2:
        plot.skipped = "needs two SIMD widths for one scene and tile"
        return plot
    panels = [(s, t) for s in sorted(data[SCENE].unique())
              for t in sorted(data[data[SCENE] == s][TILE].unique())]
    tiles = sorted(data[TILE].unique())
    # A row per scene while the tiles fit on one; three columns beyond that.
    fig, axes = _subplots(len(panels), ncols=len(tiles) if 1 < len(tiles) <= 4 else 3)
    colors = {s: f"C{i}" for i, s in enumerate(STAGES)}
    for ax, (scene, tile) in zip(axes, panels):
        d = data[(data[SCENE] == scene) & (data[TILE] == tile)].sort_values(WIDTH)
        for s in stages:
            ax.plot(d[WIDTH], 100 * d[f"simd_utilization.{s}"], marker="o", color=colors[s],
                    label=f"{s}")
            ideal = f"ideal_simd_utilization.{s}"
            if ideal in d.columns and d[ideal].notna().any():
                ax.plot(d[WIDTH], 100 * d[ideal], linestyle=":", color=colors[s],
                        label=f"{s} (ideal)")
        ax.set_title(f"{scene}, tile {_n(tile)}×{_n(tile)}")
        ax.set_xlabel("SIMD width N [lanes]")
        ax.set_ylabel("SIMD utilization [%]")
        ax.set_xticks(sorted(d[WIDTH].unique()))
        ax.set_ylim(0, 105)
        ax.grid(True, alpha=0.3)
        if ax is axes[0]:  # the same stages in every panel: one legend
            ax.legend(fontsize="x-small")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = ("All rays. Solid: effective utilization (stalls issue nothing); dotted: the "
                    "ideal from the trace." + _context_caption(context))
    return plot


def plot_stalls(store: Store, directory: str) -> Plot:
    plot = Plot("stalls", "Stall cycles by cause")
    causes = [c for c in store.points.columns
              if c.startswith("stall_cycles.") and c != "stall_cycles.total" and store.has(c)]
    if not causes:
        plot.skipped = "the store has no stall_cycles.<cause> values"
        return plot
    data = store.points[store.points[causes].notna().any(axis=1)]
    context, data = dominant_context(data, TABLE_KEY)
    scenes = sorted(data[SCENE].unique())
    fig, axes = _subplots(len(scenes), ncols=2, size=(6.0, 3.6))
    colors = {c: f"C{i}" for i, c in enumerate(causes)}
    scale = 1e6 if data[causes].sum(axis=1).max() >= 1e6 else 1.0
    unit = "Mcycles" if scale == 1e6 else "cycles"
    for ax, scene in zip(axes, scenes):
        d = data[data[SCENE] == scene].sort_values([TILE, WIDTH], kind="mergesort")
        x = np.arange(len(d))
        bottom = np.zeros(len(d))
        for c in causes:
            v = d[c].fillna(0).to_numpy() / scale
            ax.bar(x, v, bottom=bottom, color=colors[c], label=c.split(".", 1)[1])
            bottom += v
        ax.set_xticks(x)
        ax.set_xticklabels([f"N={_n(w)}\n{_n(t)}×{_n(t)}" for t, w in zip(d[TILE], d[WIDTH])],
                           fontsize="small" if len(d) <= 8 else "x-small",
                           rotation=0 if len(d) <= 8 else 90)
        ax.set_title(scene)
        ax.set_xlabel("SIMD width, tile")
        ax.set_ylabel(f"stall cycles per frame [{unit}]")
        ax.grid(True, axis="y", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=min(4, len(causes)),
               bbox_to_anchor=(0.5, -0.02), fontsize="small")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = ("Cycles per frame in which the SIMD unit issued nothing, stacked by cause." +
                    _context_caption(context))
    return plot


def _best_tile_per_buffer(data: pd.DataFrame) -> pd.DataFrame:
    """Per scene, SIMD width and ray-buffer size, the row with the highest fps over the tiles
    the store has (a buffer holds any tile up to the largest that fits: `tile: auto`)."""
    best = data.sort_values("fps", ascending=False, kind="mergesort")
    return best.drop_duplicates(subset=[SCENE, WIDTH, KIB], keep="first")


def plot_fps_vs_buffer(store: Store, directory: str) -> Plot:
    plot = Plot("fps_vs_buffer", "Predicted frame rate against ray-buffer size")
    data = _with(store.points, ["fps", KIB])
    if data.empty:
        plot.skipped = f"the store has no fps or {KIB} values"
        return plot
    context, data = dominant_context(data, TABLE_KEY + [KIB])
    # A fixed tile at several buffer sizes gives one line per (tile, width); a tile that
    # follows the buffer (`tile: auto`, the paper's question) one line per width through the
    # best tile at each size.
    fixed_tile = data.groupby(TABLE_KEY)[KIB].nunique().max() >= 2
    if not fixed_tile:
        if data.groupby([SCENE, WIDTH])[KIB].nunique().max() < 2:
            sizes = ", ".join(_n(k) for k in sorted(data[KIB].unique()))
            plot.skipped = f"needs two ray-buffer sizes for one scene and SIMD width; the " \
                           f"store has {sizes} KiB"
            return plot
        data = _best_tile_per_buffer(data)
    scenes = sorted(data[SCENE].unique())
    fig, axes = _subplots(len(scenes))
    any_error = False
    for ax, scene in zip(axes, scenes):
        at_scene = data[data[SCENE] == scene]
        lines = at_scene.groupby([TILE, WIDTH]) if fixed_tile else at_scene.groupby(WIDTH)
        for key, d in lines:
            d = d.sort_values(KIB)
            if fixed_tile:
                tile, width = key
                label = f"N={_n(width)}, {_n(tile)}×{_n(tile)}"
            else:
                label = f"N={_n(key)}"
            if len(d) < 2:
                continue
            any_error |= _line_with_errors(ax, d[KIB], d["fps"], _fps_error(d), label=label)
            if not fixed_tile:
                for _, r in d.iterrows():
                    ax.annotate(f"{_n(r[TILE])}²", (r[KIB], r["fps"]),
                                textcoords="offset points", xytext=(4, -10),
                                fontsize="x-small")
        ax.set_xscale("log", base=2)
        ticks = sorted(at_scene[KIB].unique())
        ax.set_xticks(ticks)
        ax.set_xticklabels([_n(t) for t in ticks])
        ax.minorticks_off()
        ax.set_title(scene)
        ax.set_xlabel("ray-buffer size [KiB per buffer]")
        ax.set_ylabel("predicted fps [frames/s]")
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="lower right")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = (("One line per SIMD width and tile: what a bigger buffer buys at a fixed "
                     "stream size." if fixed_tile else
                     "One line per SIMD width through the best tile the store has at each "
                     "buffer size (labels: the tile); a bigger buffer holds a longer initial "
                     "stream, which keeps the SIMD lanes fuller.") +
                    (" Error bars: the model's fps interval." if any_error else "") +
                    _context_caption(context))
    return plot


def pareto_front(area: Sequence[float], fps: Sequence[float]) -> List[int]:
    """Indices of the points no other point beats: none has less or equal area with more or
    equal fps (strictly better in one). Ordered by area."""
    order = sorted(range(len(area)), key=lambda i: (area[i], -fps[i]))
    front, best = [], -math.inf
    for i in order:
        if fps[i] > best:
            front.append(i)
            best = fps[i]
    return front


def plot_pareto(store: Store, directory: str) -> Plot:
    plot = Plot("pareto_fps_vs_buffer", "Pareto front: frame rate against ray-buffer capacity")
    data = _with(store.points, ["fps", KIB])
    if data.empty:
        plot.skipped = f"the store has no fps or {KIB} values"
        return plot
    data = data.copy()
    if BUFFERS in data.columns and data[BUFFERS].notna().all():
        data["area"] = data[KIB] * data[BUFFERS]
        xlabel = "ray-buffer capacity [KiB] (kib × buffers)"
    else:
        data["area"] = data[KIB]
        xlabel = "ray-buffer size [KiB]"
    # Every hardware point and tile of a scene competes; the workload and fidelity are held.
    hw_key = [SCENE, TILE] + [c for c in data.columns if c.startswith("hw.")]
    context, data = dominant_context(data, hw_key)
    if data.groupby(SCENE)["area"].nunique().max() < 2:
        plot.skipped = "needs points at two ray-buffer sizes for one scene"
        return plot
    scenes = sorted(data[SCENE].unique())
    fig, axes = _subplots(len(scenes))
    for ax, scene in zip(axes, scenes):
        d = data[data[SCENE] == scene].reset_index(drop=True)
        ax.scatter(d["area"], d["fps"], color="0.6", s=18, label="sweep points")
        front = pareto_front(list(d["area"]), list(d["fps"]))
        f = d.iloc[front]
        ax.step(f["area"], f["fps"], where="post", color="C3", linewidth=1.2)
        ax.scatter(f["area"], f["fps"], color="C3", s=30, zorder=3, label="Pareto front")
        for _, r in f.iterrows():
            ax.annotate(f"N={_n(r[WIDTH])}, {_n(r[TILE])}²", (r["area"], r["fps"]),
                        textcoords="offset points", xytext=(4, 4), fontsize="x-small")
        ax.set_xscale("log", base=2)
        ticks = sorted(d["area"].unique())
        ax.set_xticks(ticks)
        ax.set_xticklabels([_n(t) for t in ticks])
        ax.set_title(scene)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("predicted fps [frames/s]")
        ax.margins(x=0.15)
        ax.set_ylim(0, 1.12 * d["fps"].max())  # room for the labels
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="lower right")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = ("Ray-buffer capacity as an area proxy. Red: the designs no other design "
                    "beats with less or equal capacity; labels give SIMD width and tile." +
                    _context_caption(context))
    return plot


AREA = "area.total_mm2"
ENERGY = "energy.total_per_frame_mj"


def _varying_label(rows: pd.DataFrame, columns: Sequence[str]) -> Callable[[pd.Series], str]:
    """Names a point by the configuration columns that vary among `rows` (N for the SIMD width,
    else the parameter's last name): what tells the designs on a front apart."""
    varying = [c for c in dict.fromkeys(columns)
               if c in rows.columns and rows[c].nunique(dropna=False) > 1]

    last = [c.rsplit(".", 1)[-1] for c in varying]

    def short(c: str) -> str:
        if c == WIDTH:
            return "N"
        if c == TILE:
            return "tile"
        name = c.rsplit(".", 1)[-1]  # the parameter, or unit.parameter when that is ambiguous
        return name if last.count(name) == 1 and name != "count" else ".".join(c.split(".")[-2:])

    def label(r: pd.Series) -> str:
        parts = []
        for c in varying:
            name = short(c)
            v = r[c]
            parts.append(f"{name}={_n(v) if isinstance(v, (int, float, np.number)) else v}")
        return " ".join(parts) or "the one design"
    return label


def _cost_front(store: Store, directory: str, plot: Plot, cost: str, cost_label: str,
                fps_on_x: bool) -> Plot:
    """Pareto front of fps against a cost column (less cost and more fps are better), one
    panel per scene, the designs on the front named on the plot and in the caption."""
    data = _with(store.points, ["fps", cost])
    if data.empty:
        plot.skipped = f"the store has no {cost} values (results of an sfx without area and " \
                       "energy)"
        return plot
    hw = [c for c in data.columns if c.startswith("hw.") and c != "hw.name"]
    context, data = dominant_context(data, [SCENE, TILE] + hw)
    if data.groupby(SCENE)[cost].nunique().max() < 2:
        plot.skipped = f"needs points of two different {cost} for one scene"
        return plot
    scenes = sorted(data[SCENE].unique())
    fig, axes = _subplots(len(scenes), ncols=2, size=(5.6, 4.0))
    named = []
    for ax, scene in zip(axes, scenes):
        d = data[data[SCENE] == scene].reset_index(drop=True)
        label = _varying_label(d, [WIDTH, TILE] + hw)
        front = pareto_front(list(d[cost]), list(d["fps"]))
        f = d.iloc[front]
        x, y = ("fps", cost) if fps_on_x else (cost, "fps")
        ax.scatter(d[x], d[y], color="0.6", s=18, label="sweep points")
        ax.plot(f[x], f[y], color="C3", linewidth=1.2)
        ax.scatter(f[x], f[y], color="C3", s=30, zorder=3, label="Pareto front")
        # At most eight labels on the plot (spread along the front); the caption names all.
        step = max(1, math.ceil(len(f) / 8))
        for k, (_, r) in enumerate(f.iterrows()):
            if k % step == 0 or k == len(f) - 1:
                ax.annotate(label(r), (r[x], r[y]), textcoords="offset points", xytext=(4, 4),
                            fontsize="x-small")
        named.append(f"{scene}: " + "; ".join(label(r) for _, r in f.iterrows()))
        ax.set_title(scene)
        ax.set_xlabel("predicted fps [frames/s]" if fps_on_x else cost_label)
        ax.set_ylabel(cost_label if fps_on_x else "predicted fps [frames/s]")
        ax.margins(0.15)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="x-small", loc="best")
    fig.suptitle(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    tech = ""
    if "tech.node_nm" in data.columns and data["tech.node_nm"].nunique() == 1:
        tech = f" Priced at {_n(data['tech.node_nm'].iloc[0])} nm."
    plot.caption = ("Red: the designs no other design beats with less or equal " +
                    cost_label.split(" [")[0] + " and more or equal fps. On the front: " +
                    " | ".join(named) + "." + tech + _context_caption(context))
    return plot


def plot_pareto_area(store: Store, directory: str) -> Plot:
    return _cost_front(store, directory,
                       Plot("pareto_fps_vs_area", "Pareto front: frame rate against chip area"),
                       AREA, "on-chip area [mm²]", fps_on_x=False)


def plot_pareto_energy(store: Store, directory: str) -> Plot:
    return _cost_front(store, directory,
                       Plot("pareto_energy_vs_fps", "Pareto front: energy per frame against "
                                                    "frame rate"),
                       ENERGY, "energy per frame [mJ]", fps_on_x=True)


def accuracy_rows(points: pd.DataFrame) -> pd.DataFrame:
    """Points whose configuration was run at two or more fidelities (a sweep with `fidelity`
    as an axis), with
    `error.measured`: |fps - fps at full fidelity| / fps at full fidelity, when a full row
    exists."""
    if "host_seconds" not in points.columns or "fps" not in points.columns:
        return points.iloc[0:0]
    config = [c for c in points.columns
              if (c.startswith("hw.") or c.startswith("workload.")) and c != "fidelity"]
    data = points.dropna(subset=["host_seconds"]).copy()
    data["config_id"] = data.groupby(config, dropna=False).ngroup()
    counts = data.groupby("config_id")["fidelity"].nunique()
    data = data[data["config_id"].isin(counts[counts > 1].index)].copy()
    data["error.measured"] = np.nan
    for _, group in data.groupby("config_id"):
        full = group[group["fidelity"] == "full"]["fps"].dropna()
        if len(full) and full.iloc[0] > 0:
            ref = full.iloc[0]
            data.loc[group.index, "error.measured"] = (group["fps"] - ref).abs() / ref
    return data


def plot_error_vs_host_time(store: Store, directory: str) -> Plot:
    plot = Plot("error_vs_host_time", "Fidelity: error against host time")
    data = accuracy_rows(store.points)
    if data.empty:
        plot.skipped = ("no accuracy rows: no configuration in the store was run at more than "
                        "one fidelity (sweep with `fidelity` as an axis; `sfx accuracy --plot` draws "
                        "the same for one point)")
        return plot
    estimate = data["error.relative"].where(data["error.relative"] >= 0) \
        if "error.relative" in data.columns else pd.Series(np.nan, index=data.index)
    if data["error.measured"].isna().all() and estimate.isna().all():
        plot.skipped = "the accuracy rows have neither a full-fidelity reference nor an error " \
                       "estimate"
        return plot
    fig, ax = plt.subplots(figsize=(6.0, 4.2), layout="constrained")
    markers = {"analytic": "s", "sampled": "o", "full": "D"}
    for i, fidelity in enumerate(sorted(data["fidelity"].unique(), key=fidelity_rank)):
        d = data[data["fidelity"] == fidelity]
        color = f"C{FIDELITIES.index(fidelity) if fidelity in FIDELITIES else 3 + i}"
        m = d["error.measured"].notna()
        if m.any():
            ax.scatter(d["host_seconds"][m], 100 * d["error.measured"][m], color=color,
                       marker=markers.get(fidelity, "^"), label=f"{fidelity}: measured vs full")
        e = estimate[d.index].notna()
        if e.any():
            ax.scatter(d["host_seconds"][e], 100 * estimate[d.index][e], facecolors="none",
                       edgecolors=color, marker=markers.get(fidelity, "^"), s=60,
                       label=f"{fidelity}: model's estimate")
    ax.set_xscale("log")
    ax.set_xlabel("host time per prediction [s]")
    ax.set_ylabel("relative fps error [%]")
    top = ax.get_ylim()[1]
    ax.set_ylim(-0.03 * top, top)  # exact (0 %) points stay visible
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(_titled(plot, data))
    plot.file = _save(fig, directory, plot.name)
    plot.caption = (f"{data['config_id'].nunique()} configuration(s) run at several fidelities. "
                    "Filled: |fps − fps at full fidelity| / fps at full fidelity; hollow: the "
                    "half-width of the interval the model reports (error.relative).")
    return plot


PLOTTERS: List[Callable[[Store, str], Plot]] = [
    plot_fps_vs_width,
    plot_utilization_vs_width,
    plot_stalls,
    plot_fps_vs_buffer,
    plot_pareto,
    plot_pareto_area,
    plot_pareto_energy,
    plot_error_vs_host_time,
]


def make_plots(store: Store, directory: str) -> List[Plot]:
    return [plotter(store, directory) for plotter in PLOTTERS]

"""The seed papers' alternatives on our machine model: docs/seed-kernels.md from a store of
sweeps/seed-kernels.sweep.yaml, seed-kernels-lod.sweep.yaml, seed-kernels-raygrid.sweep.yaml and
seed-options.sweep.yaml (scripts/seed-kernels).

Each table pairs points that differ only in one workload option (`workload.primary_entry`,
`workload.reorder`, `workload.batching`), everything else equal, and sets the change beside the
paper's headline.
The prose says what the model shows; where an effect does not appear it says why."""

from __future__ import annotations

from typing import List, Optional

import pandas as pd

from .store import Store, StoreError

# Option columns and their "off" values: a store from before an option holds NULL there.
OPTION_DEFAULTS = {"workload.primary_entry": "root", "workload.reorder": "none",
                   "workload.reorder_lod_ppm": 20000, "workload.batching": "none",
                   "workload.batching_queue": 384, "workload.batching_cell_prims": 4096}
KEYS = ["workload.scene", "workload.tile", "hw.simd.width", "workload.depth", "fidelity"]
# Every option off but the one a section studies.
OFF = {"workload.primary_entry": "root", "workload.reorder": "none",
       "workload.reorder_lod_ppm": 20000, "workload.batching": "none"}


def _off_but(*names: str) -> dict:
    return {k: v for k, v in OFF.items() if k not in names}


def _points(store: Store) -> pd.DataFrame:
    df = store.points.copy()
    for col, default in OPTION_DEFAULTS.items():
        if col not in df.columns:
            df[col] = default
        df[col] = df[col].fillna(default)
    for col in KEYS:
        if col not in df.columns:
            raise StoreError(f"{store.path}: no column {col}")
    return df


def _cache_name(df: pd.DataFrame, level: int) -> Optional[str]:
    names = sorted(c[len("scene_cache."):-len(".misses")] for c in df.columns
                   if c.startswith("scene_cache.") and c.endswith(".misses"))
    return names[level] if level < len(names) else None


def _pct(a: float, b: float) -> str:
    """Change from a to b in percent."""
    if a is None or b is None or pd.isna(a) or pd.isna(b) or a == 0:
        return "n/a"
    return f"{100.0 * (b - a) / a:+.1f} %"


def _num(v, digits=2) -> str:
    return "n/a" if v is None or pd.isna(v) else f"{v:.{digits}f}"


def _pairs(df: pd.DataFrame, option: str, off: str, on: str, fixed: dict) -> pd.DataFrame:
    """Rows with the option off and on, joined on everything the sweep varies."""
    sel = df
    for col, value in fixed.items():
        sel = sel[sel[col] == value]
    a = sel[sel[option] == off].set_index(KEYS)
    b = sel[sel[option] == on].set_index(KEYS)
    both = a.join(b, lsuffix=".off", rsuffix=".on", how="inner")
    return both.reset_index().sort_values(KEYS)


def _table(header: List[str], rows: List[List[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def aepsa_section(df: pd.DataFrame) -> str:
    p = _pairs(df, "workload.primary_entry", "root", "aepsa", _off_but("workload.primary_entry"))
    rows = []
    for _, r in p.iterrows():
        rows.append([str(r["workload.scene"]), str(int(r["workload.tile"])),
                     str(int(r["hw.simd.width"])),
                     _num(r["trace.box_tests_per_ray.primary.off"], 1),
                     _num(r["trace.box_tests_per_ray.primary.on"], 1),
                     _pct(r["trace.box_tests_per_ray.primary.off"],
                          r["trace.box_tests_per_ray.primary.on"]),
                     _num(r["trace.entry_depth.on"]),
                     _num(r["op_mix.option_percent.on"]),
                     _num(r["fps.off"], 1), _num(r["fps.on"], 1),
                     _pct(r["fps.off"], r["fps.on"])])
    table = _table(["scene", "tile", "width", "box tests / primary ray (root)", "(aepsa)",
                    "change", "mean entry depth", "search overhead % of instructions",
                    "fps root", "fps aepsa", "fps change"], rows) if rows else "(no points)"
    best = max((float(x.strip(" %+")) for x in [r[-1] for r in rows] if x != "n/a"),
               default=None)
    saved = [float(r[5].strip(" %")) for r in rows if r[5] != "n/a"]
    kind = ("The paper's gain appears only in kind where the frustum lets streams enter below "
            "the root." if best is not None and best > 0 else
            "The paper's gain does not appear: no point here runs faster with AEPSA.")
    return f"""## AEPSA: frustum entry points for primary streams (seeds/004)

**Paper:** deeper entry points than MLRTA (2.5 % deeper on average) and up to 36 % more fps than
packet tracing, 18 % more than MLRTA, on kD-trees.

{table}

{kind} Box tests per primary ray change by {min(saved, default=0):+.1f} % to
{max(saved, default=0):+.1f} %, and the best fps change is {best if best is not None else 0:+.1f} %.
Why the effect is small on our model: (1) the entry points stay near the root (the mean
depth column): a BVH leaf holding a large triangle (a floor, a wall) has a box as large as
the triangle, so a tile's frustum overlaps leaves on both sides of the upper splits, and the
deepest node holding all of them is high. The paper's kD-tree cuts such triangles into many
small leaves, which is what lets its entry points go deep. (2) Stream filtering already pays one box test per node for the whole stream: the levels
AEPSA skips are the cheapest ones (the full stream is tested against a node once, in long SIMD
groups), while the frustum tests are one-lane ops that leave the SIMD unit nearly idle. Larger
tiles (64) make the frustum wider and the entry shallower.
"""


def reorder_section(df: pd.DataFrame) -> str:
    p = _pairs(df, "workload.reorder", "none", "hit_point", _off_but("workload.reorder"))
    l2 = _cache_name(df, 1)
    rows = []
    for _, r in p.iterrows():
        miss = f"scene_cache.{l2}.misses" if l2 else None
        rows.append([str(r["workload.scene"]), str(int(r["workload.tile"])),
                     str(int(r["hw.simd.width"])),
                     _num(r[miss + ".off"], 0) if miss else "n/a",
                     _num(r[miss + ".on"], 0) if miss else "n/a",
                     _pct(r[miss + ".off"], r[miss + ".on"]) if miss else "n/a",
                     _num(r["trace.box_tests_per_ray.secondary.off"], 1),
                     _num(r["trace.box_tests_per_ray.secondary.on"], 1),
                     _num(r["op_mix.option_percent.on"], 1),
                     _num(r["fps.off"], 1), _num(r["fps.on"], 1), _pct(r["fps.off"], r["fps.on"])])
    table = _table(["scene", "tile", "width", f"{l2} misses (none)", "(hit_point)", "change",
                    "box tests / secondary ray (none)", "(hit_point)",
                    "reorder overhead % of instructions", "fps none", "fps hit_point",
                    "fps change"], rows) if rows else "(no points)"
    lod = df[(df["workload.reorder"] == "hit_point") & (df["workload.tile"] == 16) &
             (df["hw.simd.width"] == 16) & (df["workload.scene"] == "conference") &
             (df["workload.primary_entry"] == "root") &
             (df["workload.batching"] == "none")].sort_values("workload.reorder_lod_ppm")
    base = df[(df["workload.reorder"] == "none") & (df["workload.tile"] == 16) &
              (df["hw.simd.width"] == 16) & (df["workload.scene"] == "conference") &
              (df["workload.primary_entry"] == "root") & (df["workload.batching"] == "none")]
    base_fps = float(base["fps"].iloc[0]) if len(base) else None
    lod_rows = [[f"{r['workload.reorder_lod_ppm'] / 1e4:g} %",
                 _num(r["op_mix.option_percent"], 1), _num(r["fps"], 1), _pct(base_fps, r["fps"])]
                for _, r in lod.iterrows()]
    lod_table = _table(["simplified geometry", "overhead % of instructions", "fps",
                        "fps change against none"], lod_rows) if lod_rows else "(no points)"
    return f"""## Hit-point reordering (seeds/001)

**Paper:** on a 346 K-triangle in-core model, 23 % faster with L2 misses more than halved; the
overhead (approximate hit points and the sort) is 6 % of render time with simplified geometry
of 2 % of the triangles, the best balance of Table 2 (0.0125 % to 8 %).

Reordering every generation (2 % simplified geometry), against none:

{table}

The simplified-geometry fraction as an axis (conference, tile 16, width 16):

{lod_table}

**The effect does not appear on our model, by construction, and the overhead remains.** A
stream filter tests the *whole* stream against each node and primitive (G&R Fig. 3): which
nodes are visited, in which order, and how many lanes each test has depend only on the set of
rays in the stream, not on their order (the front child is chosen by a majority vote of the
stream). So sorting a stream leaves the scene-data accesses, and with them the scene caches'
misses from traversal and intersection, exactly as they were (a unit test checks that the box-
and primitive-test counts and lanes are identical). The L2 misses that do change are those of
the reordering's own traversal of the simplified hierarchy (its node fetches, and the lines
they evict). Moon et al.'s gain comes from a single-ray (or small-packet) tracer in which
consecutive rays walk the tree one after another; stream filtering already amortizes each node
fetch over every ray of the stream, which is the coherence the reordering buys.

The overhead is far above the paper's 6 %: our simplified geometry is a cut of the scene's own
BVH, so finding an approximate hit costs most of a real traversal (the upper levels, where a
ray spends most of its box tests, are all still there); the paper traces a separately built,
much shallower hierarchy over its simplified mesh. A smaller fraction cuts the overhead (the
axis above) but not to zero, and no fraction can win back time here, since the order buys
nothing on this machine.
"""


def _col(r, name: str, digits=1) -> str:
    return _num(r[name], digits) if name in r.index else "n/a"


def raygrid_section(df: pd.DataFrame) -> str:
    fixed = _off_but("workload.batching")
    fixed["workload.batching_queue"] = 384
    fixed["workload.batching_cell_prims"] = 4096
    p = _pairs(df, "workload.batching", "none", "raygrid", fixed)
    full_depth = p[p["workload.depth"] == p["workload.depth"].max()] if len(p) else p
    l1, l2 = _cache_name(df, 0), _cache_name(df, 1)
    rows = []
    for _, r in full_depth.iterrows():
        hit = lambda name, side: (_num(100 * r[f"scene_cache.{name}.hit_rate.{side}"], 1)
                                  if name and f"scene_cache.{name}.hit_rate.{side}" in r.index
                                  else "n/a")
        rows.append([str(r["workload.scene"]), str(int(r["workload.tile"])),
                     str(int(r["hw.simd.width"])),
                     _col(r, "trace.box_tests_per_ray.secondary.off"),
                     _col(r, "trace.box_tests_per_ray.secondary.on"),
                     _num(100 * r["ideal_simd_utilization.secondary.traversal.off"], 1),
                     _num(100 * r["ideal_simd_utilization.secondary.traversal.on"], 1),
                     f"{hit(l1, 'off')} / {hit(l2, 'off')}", f"{hit(l1, 'on')} / {hit(l2, 'on')}",
                     _col(r, "trace.batching.mean_queue_length.on"),
                     _num(100 * r["trace.batching.full_queue_share.on"], 0)
                     if "trace.batching.full_queue_share.on" in r.index else "n/a",
                     _col(r, "trace.batching.lanes_per_ray.on"),
                     _col(r, "op_mix.option_percent.on"),
                     _num(r["fps.off"], 1), _num(r["fps.on"], 1), _pct(r["fps.off"], r["fps.on"])])
    table = _table(["scene", "tile", "width", "box tests / secondary ray (none)", "(raygrid)",
                    "ideal secondary traversal utilization % (none)", "(raygrid)",
                    f"{l1} / {l2} hit % (none)", "(raygrid)", "mean queue (rays)", "full queues %",
                    "walk + enqueue lanes / secondary ray", "walk overhead % of instructions", "fps none", "fps raygrid", "fps change"],
                   rows) if rows else "(no points)"
    # Per bounce: rays per node and leaf from the deepest render; each bounce's time is the
    # frame-time step from depth k-1 to k, and its gain the ratio of those steps (Table 3's
    # rays per second per bounce, in kind).
    bounce_rows = []
    gains = []
    widest = int(p["hw.simd.width"].max()) if len(p) else 0
    for scene in sorted(p["workload.scene"].unique()) if len(p) else []:
        sp = p[(p["workload.scene"] == scene) & (p["hw.simd.width"] == widest)]
        by_depth = {int(r["workload.depth"]): r for _, r in sp.iterrows()}
        if not by_depth:
            continue
        deepest = by_depth[max(by_depth)]
        for k in (1, 2, 3):
            if k > max(by_depth):
                break
            step = {}
            for side in ("off", "on"):
                if k in by_depth and k - 1 in by_depth:
                    step[side] = (1e3 / by_depth[k][f"fps.{side}"] -
                                  1e3 / by_depth[k - 1][f"fps.{side}"])
            gain = (step["off"] / step["on"] - 1.0) * 100.0 if len(step) == 2 and step["on"] > 0 \
                else None
            if gain is not None:
                gains.append(gain)
            b = f"trace.bounce{k}."
            bounce_rows.append([scene, str(k),
                                _col(deepest, b + "rays_per_node.off"),
                                _col(deepest, b + "rays_per_node.on"),
                                _col(deepest, b + "rays_per_leaf.off"),
                                _col(deepest, b + "rays_per_leaf.on"),
                                _num(step.get("off"), 2), _num(step.get("on"), 2),
                                "n/a" if gain is None else f"{gain:+.1f} %"])
    bounce_table = _table(["scene", "bounce", "rays / node (none)", "(raygrid)",
                           "rays / leaf (none)", "(raygrid)", "bounce ms (none)", "(raygrid)",
                           "gain"], bounce_rows) if bounce_rows else "(no points)"
    fps = [float(r[-1].strip(" %+")) for r in rows if r[-1] != "n/a"]
    queues = [(r["trace.batching.mean_queue_length.on"],
               r["trace.batching.full_queue_share.on"]) for _, r in full_depth.iterrows()
              if "trace.batching.mean_queue_length.on" in r.index]
    queue_text = (f"{min(q for q, _ in queues):.0f} to {max(q for q, _ in queues):.0f} rays "
                  f"against the paper's 384, and at most {100 * max(f for _, f in queues):.0f} % "
                  "of the queues fill" if queues else "few rays")
    stall = []
    for _, r in full_depth.iterrows():
        if "stall_cycles.scene_memory.off" in r.index and "frame_cycles.off" in r.index:
            stall.append(100.0 * r["stall_cycles.scene_memory.off"] / r["frame_cycles.off"])

    def miss_change(level):
        out = []
        if level and f"scene_cache.{level}.misses.off" in full_depth.columns:
            for _, r in full_depth.iterrows():
                a, b = r[f"scene_cache.{level}.misses.off"], r[f"scene_cache.{level}.misses.on"]
                if a and not pd.isna(a) and not pd.isna(b):
                    out.append(100.0 * (b - a) / a)
        return out
    l2_change, l1_change = miss_change(l2), miss_change(l1)
    if not l2_change or not l1_change:
        cache_text = "No scene-cache misses were stored."
    else:
        lo, hi = min(l2_change), max(l2_change)
        trend = ("fall, the locality the paper is after" if hi < 0 else
                 "rise" if lo > 0 else "move both ways")
        stall_text = (f" Without batching, scene-memory stalls are {min(stall):.1f} % to "
                      f"{max(stall):.1f} % of the frame's cycles, so even removing every miss "
                      "could not buy the paper's gain here." if stall else "")
        cache_text = (f"{l2.upper()} misses change by {lo:+.1f} % to {hi:+.1f} % with batching "
                      f"(they {trend}); {l1.upper()} misses change by {min(l1_change):+.1f} % to "
                      f"{max(l1_change):+.1f} %, and the {l1.upper()} hit rate rises because the "
                      "walk adds many accesses to the few nodes above the cut, which stay cached. "
                      "Stream filtering already fetches each node once per stream for every ray "
                      "of the tile's generation, so little is left for per-cell queues to "
                      f"amortize.{stall_text}")
    verdict = ("The paper's gain does not appear: batching slows every point here"
               if fps and max(fps) < 0 else "The paper's gain appears at some points")
    return f"""## RayGrid batching (seeds/000 Sec. 3)

**Paper:** secondary rays queued in the leaves of a shallow octree (at most 4096 primitives per
leaf, queues of 384 rays), each full queue traced against its leaf's own MBVH: +6 % to +41 %
over single-ray traversal for bounces 1-4 (Table 3), with more rays per visited node of the
mini-MBVHs than MBVH/RS has in the whole tree (Table 4 against Table 2, Modern Room: interior
22.3 / 14.3 / 12.5 rays for bounces 1-3 against 13.3 / 7.0 / 5.7; leaves 12.3 / 7.4 / 6.4
against 6.3 / 3.2 / 2.6).

Here (`workload.batching: raygrid`, kernels/stream/ray_grid.h) the cells are a top cut of the
BVH (the highest nodes with at most 4096 primitives) rather than an octree, so each cell's
hierarchy is the BVH's own subtree and scene data keep their addresses; rays walk the cut front
to back (the `raygrid_walk` and `raygrid_enqueue` ops, costed from our code). Batching covers
the secondary generations of one tile pass, flushed at the end of each generation.

At the scene's full depth (3), batching against none:

{table}

Per bounce (width {widest}): rays per visited node (box-test stream length) and per visited
leaf (primitive-test stream length) from the depth-3 render; a bounce's time is the predicted
frame-time step from depth k-1 to depth k, and its gain the ratio of those steps (positive:
batching traces that bounce faster):

{bounce_table}

{verdict} (fps change {min(fps, default=0):+.1f} % to {max(fps, default=0):+.1f} %; per-bounce
gain {min(gains, default=0):+.1f} % to {max(gains, default=0):+.1f} %). What does appear is
the paper's mechanism in part: a ray walks the cells front to back and stops at the first cell
that holds its hit, so box tests per secondary ray fall (the first table). Why the gain does
not follow on our model:

1. **The batch is too small.** The paper fills queues from a million rays in flight; a tile
   pass has at most tile^2 rays per generation, spread over the cut's cells, so the mean queue
   holds {queue_text} (the queue columns). Stream filtering
   already traces the whole generation as one stream from the root; splitting it into per-cell
   queues makes the streams *shorter*, so rays per node and per leaf fall (the per-bounce
   table: the opposite of Table 4) and SIMD utilization with them. The paper's baseline is
   single rays and 256-ray packets, which batching lengthens; ours is already the batch.
2. **The walk costs more than it saves.** Cut boxes overlap rather than tile space, so each
   step of the walk is a branch-and-bound pass over the nodes above the cut, not an octree's
   neighbour link; its lanes per secondary ray exceed the box tests it saves (the first
   table's columns), and its instructions are the overhead column. The paper
   too spends 47 % of its time in octree traversal (Sec. 4.1), against 26 % in the MBVHs.
3. **The scene caches.** {cache_text}
"""


def options_section(df: pd.DataFrame) -> str:
    sel = df[(df["workload.scene"] == "conference") & (df["workload.tile"] == 32) &
             (df["workload.depth"] == df["workload.depth"].max()) &
             (df["workload.reorder_lod_ppm"] == 20000) &
             (df["workload.batching_queue"] == 384) & (df["workload.batching_cell_prims"] == 4096)]
    rows = []
    cols = sorted(int(w) for w in sel["hw.simd.width"].unique())
    for entry in ("root", "aepsa"):
        for reorder in ("none", "hit_point"):
            for batching in ("none", "raygrid"):
                o = sel[(sel["workload.primary_entry"] == entry) &
                        (sel["workload.reorder"] == reorder) &
                        (sel["workload.batching"] == batching)]
                if not len(o):
                    continue
                by_width = {int(r["hw.simd.width"]): r for _, r in o.iterrows()}
                rows.append([entry, reorder, batching] +
                            [_num(by_width[w]["fps"], 1) if w in by_width else "n/a"
                             for w in cols] +
                            [_num(by_width[cols[-1]]["op_mix.option_percent"], 1)
                             if cols[-1] in by_width else "n/a"])
    if not rows:
        return ""
    table = _table(["primary_entry", "reorder", "batching"] + [f"fps width {w}" for w in cols] +
                   [f"options' overhead % (width {cols[-1]})"], rows)
    fps = [[float(x) for x in r[3:3 + len(cols)] if x != "n/a"] for r in rows]
    ranked = all(f == sorted(f) for f in fps)
    ranking = ("In every combination a wider SIMD unit is faster: no option changes the ranking "
               "of the widths." if ranked else
               "The options change the ranking of the SIMD widths in some combinations.")
    return f"""## The three options crossed with SIMD width

`sweeps/seed-options.sweep.yaml` (conference, tile 32): every combination renders the same
image (tested); the predicted frame rate of each:

{table}

{ranking}
"""


def build_page(store: Store, command: str = "") -> str:
    df = _points(store)
    source = f"Regenerate with `{command}`." if command else ""
    scenes = ", ".join(sorted(df["workload.scene"].astype(str).unique()))
    res = ", ".join(sorted({f"{int(w)}x{int(h)}" for w, h in
                            zip(df["workload.width"], df["workload.height"])}))
    fid = ", ".join(sorted(df["fidelity"].astype(str).unique()))
    widths = " and ".join(str(int(w)) for w in sorted(df["hw.simd.width"].unique()))
    return f"""# The seed kernels on the stream-filtering machine

Generated from `{store.path}` ({len(df)} points: {scenes} at {res} x 1 spp, fidelity {fid},
the paper's machine `gr08` at SIMD widths {widths}). {source}
The options never change the image (bit-identical, tested); each adds its own kinds of stream
op, costed in `hw_model/op_costs.cpp` (counts from our code; the papers give host times).
"Overhead" is the share of the machine's SIMD instructions issued by the option's own ops.

{aepsa_section(df)}
{reorder_section(df)}
{raygrid_section(df)}
{options_section(df)}"""


def write_page(store: Store, path: str, command: str = "") -> None:
    text = build_page(store, command)
    tmp = path + ".partial"
    with open(tmp, "w") as f:
        f.write(text)
    import os
    os.replace(tmp, path)


# The report's columns for the options, in order: (store column, heading, digits).
REPORT_COLUMNS = [("fps", "fps", 1),
                  ("ideal_simd_utilization.secondary.traversal", "ideal sec. trav. util", 2),
                  ("trace.box_tests_per_ray.primary", "box tests / primary ray", 1),
                  ("trace.box_tests_per_ray.secondary", "box tests / sec. ray", 1),
                  ("scene_cache.l1.hit_rate", "L1 hit rate", 3),
                  ("scene_cache.l2.hit_rate", "L2 hit rate", 3),
                  ("op_mix.option_percent", "options' overhead %", 1)]
REPORT_MAX_ROWS = 80


def html_section(store: Store) -> str:
    """The report's section: with and without each seed-paper option, side by side. Empty when
    every point of the store has every option off."""
    import html
    df = store.points
    options = [c for c in OFF if c in df.columns]
    if not options or all((df[c].fillna(OPTION_DEFAULTS[c]) == OFF[c]).all() for c in options):
        return ""
    df = _points(store)
    group = [c for c in ["workload.scene", "workload.tile", "hw.simd.width", "fidelity"]
             if c in df.columns] + [c for c in OPTION_DEFAULTS if c in df.columns]
    cols = [(c, h, d) for c, h, d in REPORT_COLUMNS if c in df.columns]
    agg = df.groupby(group, dropna=False)[[c for c, _, _ in cols]].mean().reset_index()
    shown = agg.head(REPORT_MAX_ROWS)
    e = html.escape
    head = "".join(f"<th>{e(c.split('.', 1)[-1])}</th>" for c in group) + \
        "".join(f"<th>{e(h)}</th>" for _, h, _ in cols)
    rows = []
    for _, r in shown.iterrows():
        cells = [str(int(r[c])) if isinstance(r[c], float) and float(r[c]).is_integer()
                 else str(r[c]) for c in group] + [_num(r[c], d) for c, _, d in cols]
        rows.append("<tr>" + "".join(f"<td>{e(x)}</td>" for x in cells) + "</tr>")
    more = (f"<p>{len(agg) - len(shown)} more rows in points.csv.</p>"
            if len(agg) > len(shown) else "")
    return "\n".join([
        "<h2>Seed-paper options</h2>",
        "<p>AEPSA entry points (<code>primary_entry</code>), hit-point reordering "
        "(<code>reorder</code>) and RayGrid batching (<code>batching</code>), each with its "
        "parameters, as the store's points have them; means over the other inputs. The options "
        "never change the image; <code>scripts/seed-kernels</code> compares each with its "
        "paper (<code>docs/seed-kernels.md</code>).</p>",
        f'<table class="paper"><tr>{head}</tr>' + "".join(rows) + "</table>", more])

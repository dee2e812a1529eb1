"""The silicon check: the machine model's predicted cycles for the host CPU (one host
configuration per SIMD back end) against the native stream tracer's measured cycles (the rows
`sfx calibrate --check --json` prints). Per back end: a table per workload, the mean absolute and
worst relative error of frame cycles, the same per stage, the tile-size ranking per scene and
resolution; across back ends, the SIMD-width ranking; a predicted-against-measured scatter plot
with the y = x line, and the Markdown page `docs/silicon-check-*.md`.

Only converged workloads are scored: `sfx calibrate --check` renders each workload until its
fastest renders agree (the rule, base/convergence.h, is in every row as `convergence_rule`) or
its budget runs out; a workload that ran out is shown, marked, and left out of every error and
ranking. A ranking is judged only where the measurement can tell: two converged variants count
as measurably different when their measured ranges do not overlap, and a ranking is right when
the prediction orders every such pair as the measurement does. A converged workload's range is
what the rule vouches for: its fastest render to its k-th fastest (`measured.spread` above the
fastest); rows without a spread (written before the rule) take their renders' min to max.

Self-consistency: a scene's frame of 4x the pixels (128x128 against 64x64) must cost 3 to 5
times as much (0.75 to 1.25 times the pixel ratio, for any pair of resolutions); a pair outside
flags the host's measurement, not the model."""

import html
import itertools
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

STAGES = ("traversal", "intersection", "shading")
# Issue targets, on held-out workloads: frame MAE and worst, each stage's MAE.
TARGETS = {"frame_mae": 0.10, "frame_worst": 0.20, "stage_mae": 0.20, "converged": 0.90}
# A frame of r times the pixels costs between these multiples of r.
CONSISTENT = (0.75, 1.25)
WIDTHS = {"scalar": 1, "avx2": 8, "avx512": 16}
# A speed probe (the same microbenchmark points re-run around the renders) this far from the
# host's fitted costs says the machine ran faster or slower than when it was calibrated.
SPEED_PROBE_LIMIT = 0.10
# The L3 this core keeps, chased again just after the last render, this far (in size) from the
# one chased just before the predictions says the renders met another memory than predicted
# (chosen: temple's 64x64 prediction moved about 12 % between L3s of 7 and 12 MiB, 2026-11-28).
L3_MOVE_LIMIT = 0.25


def load_rows(path):
    """The JSON list of `sfx calibrate --check --json` as a DataFrame with error columns."""
    with open(path) as f:
        rows = json.load(f)
    if not isinstance(rows, list) or not rows:
        raise ValueError(f"{path}: expected a non-empty JSON list of workload rows")
    df = pd.DataFrame(rows)
    df["res"] = df["width"].astype(str) + "x" + df["height"].astype(str)
    if "simd_width" not in df:
        df["simd_width"] = df["isa"].map(WIDTHS)
    df["error.frame"] = df["predicted.frame_cycles"] / df["measured.frame_cycles"] - 1.0
    for s in STAGES:
        df[f"error.{s}"] = df[f"predicted.{s}_cycles"] / df[f"measured.{s}_cycles"] - 1.0
    # Spread of the measurement itself: (max - min) / median of the unclocked renders.
    df["noise"] = df["measured.frame_samples"].apply(
        lambda v: (max(v) - min(v)) / sorted(v)[len(v) // 2] if v else float("nan"))
    # A workload whose every render was set aside (the core shared over each) has none.
    df["measured.lo"] = df["measured.frame_samples"].apply(lambda v: min(v) if v else float("nan"))
    df["measured.hi"] = df["measured.frame_samples"].apply(lambda v: max(v) if v else float("nan"))
    if "measured.spread" in df:
        # The range the convergence rule vouches for: the fastest to the k-th fastest render
        # (an unconverged workload's spread may be null: infinite, never judged anyway).
        spread = pd.to_numeric(df["measured.spread"], errors="coerce").fillna(float("inf"))
        df["measured.lo"] = df["measured.frame_cycles"]
        df["measured.hi"] = df["measured.frame_cycles"] * (1.0 + spread)
    # Rows written before the convergence rule carry no verdict: they are taken as they were.
    if "measured.converged" not in df:
        df["measured.converged"] = True
    df["measured.converged"] = df["measured.converged"].fillna(False).astype(bool)
    if "measured.renders" not in df:
        df["measured.renders"] = df["measured.frame_samples"].apply(len)
    return df


def scored(df):
    """The rows that count: converged workloads only."""
    return df[df["measured.converged"]]


def self_consistency(df):
    """Per back end, scene and tile, each pair of resolutions measured (converged rows): the
    measured cost ratio against the pixel ratio, and whether it lies within CONSISTENT."""
    rows = []
    g_df = scored(df).assign(pixels=lambda d: d["width"] * d["height"])
    for (isa, scene, tile), g in g_df.groupby(["isa", "scene", "tile"], sort=False):
        g = g.sort_values("pixels")
        for (_, a), (_, b) in zip(g.iloc[:-1].iterrows(), g.iloc[1:].iterrows()):
            if a["pixels"] == b["pixels"]:
                continue
            pixel_ratio = b["pixels"] / a["pixels"]
            ratio = b["measured.frame_cycles"] / a["measured.frame_cycles"]
            lo, hi = CONSISTENT[0] * pixel_ratio, CONSISTENT[1] * pixel_ratio
            rows.append({"isa": isa, "scene": scene, "tile": tile, "small": a["res"],
                         "large": b["res"], "ratio": ratio,
                         "predicted_ratio":
                             b["predicted.frame_cycles"] / a["predicted.frame_cycles"],
                         "lo": lo, "hi": hi, "consistent": bool(lo <= ratio <= hi)})
    return pd.DataFrame(rows, columns=["isa", "scene", "tile", "small", "large", "ratio",
                                       "predicted_ratio", "lo", "hi", "consistent"])


def reproducibility(df, repeats):
    """Workloads of the check measured again in processes of their own (`repeats`: their rows,
    as load_rows reads them; the script repeats one cell's tiles): each one's fastest render in
    each process, the run's own first, against the range each process's convergence rule
    vouched for, and each pair's difference (one tile's frame over another's) from process to
    process. A placement fixed for a whole process (code and stack under ASLR, the scene's
    arrays, the physical pages) moves a workload's fastest render from one process to the next,
    and no range measured inside one process sees it: the fastest renders of scalar furnace
    64x64 tile 16 in four processes of one Intel Xeon VM, 3812-3921 K cycles, their own ranges
    0.2-1.9 %; and its tile 64 over tile 16, +1.1 % in one process and -0.1 % in the next, the
    same frames (2026-12-07). None where no repeat matches a converged workload of `df`."""
    keys = ["isa", "scene", "res", "tile"]
    main_rows = scored(df).set_index(keys)
    repeats = [scored(r).set_index(keys) for r in repeats]
    # The workloads: those of the repeats that the run measured too (converged in both), in
    # the first repeat's order.
    order = [w for r in repeats for w in r.index if w in main_rows.index]
    order = list(dict.fromkeys(order))
    if not order:
        return None
    runs = [main_rows] + repeats
    workloads = []
    for w in order:
        found = [r.loc[w] for r in runs if w in r.index]
        fastest = [f["measured.frame_cycles"] for f in found]
        ranges = [f["measured.hi"] / f["measured.lo"] - 1 for f in found]
        # The processes measured one thing: every two ranges overlap, as the rankings' rule
        # would have them (the faster process's range reaches the slower one's fastest).
        by_speed = sorted(zip(fastest, ranges))
        workloads.append({
            "workload": w, "fastest": fastest, "ranges": ranges,
            "apart": max(fastest) / min(fastest) - 1,
            "within_ranges": all(f * (1 + r) >= g for i, (f, r) in enumerate(by_speed)
                                 for g, _ in by_speed[i + 1:])})
    # Each pair of one cell's workloads: its difference in every process that measured both.
    pairs = []
    for a, b in itertools.combinations(order, 2):
        if a[:3] != b[:3]:
            continue
        diffs = [r.loc[b, "measured.frame_cycles"] / r.loc[a, "measured.frame_cycles"] - 1
                 for r in runs if a in r.index and b in r.index]
        if len(diffs) > 1:
            pairs.append({"pair": (a, b), "differences": diffs,
                          "spread": max(diffs) - min(diffs),
                          "flipped": min(diffs) < 0 < max(diffs)})
    return {"workloads": workloads, "processes": len(runs),
            "apart": max(w["apart"] for w in workloads),
            "within_ranges": all(w["within_ranges"] for w in workloads),
            "pairs": pairs,
            "pair_spread": max((p["spread"] for p in pairs), default=None)}


def wrong_pair_gaps(df):
    """wrong_gaps over every ranking of the rows: each back end's tiles, and the widths."""
    gaps = [g for isa in isas(df) for g in wrong_gaps(ranking(df[df["isa"] == isa]))]
    return gaps + wrong_gaps(width_ranking(df))


def reproducibility_text(rep, df=None):
    """The page summary's lines (and their verdict); with the run's rows `df`, how many of the
    pairs the rankings ordered wrong were measured closer than a pair moved between processes."""
    if rep is None:
        return "- reproducibility: no workload measured again in processes of its own"
    verdict = ("within the ranges" if rep["within_ranges"] else
               "FLAGGED: a run's ranges understate its workloads' spread from run to run, and a "
               "pair of workloads closer than this may order either way in another run")
    lines = [f"- reproducibility: {len(rep['workloads'])} workloads measured in "
             f"{rep['processes']} processes (the run's and {rep['processes'] - 1} of their own), "
             f"up to {100 * rep['apart']:.1f} % apart: {verdict}"]
    for w in rep["workloads"]:
        isa, scene, res, tile = w["workload"]
        lines.append(f"  - {isa} {scene} {res} tile {tile}: fastest "
                     f"{min(w['fastest']) / 1e6:.2f}-{max(w['fastest']) / 1e6:.2f} Mcyc, "
                     f"{100 * w['apart']:.1f} % apart, against each process's own range of "
                     f"{100 * min(w['ranges']):.1f}-{100 * max(w['ranges']):.1f} %")
    for p in rep["pairs"]:
        (_, _, _, a), (_, _, _, b) = p["pair"]
        diffs = ", ".join(pct(d) for d in p["differences"])
        lines.append(f"  - tile {b} over tile {a}: {diffs} by process"
                     f"{' (the order flipped)' if p['flipped'] else ''}")
    if rep["pair_spread"] is not None and df is not None:
        gaps = wrong_pair_gaps(df)
        closer = sum(g <= rep["pair_spread"] for g in gaps)
        lines.append(f"  - a pair's difference moved by up to {100 * rep['pair_spread']:.1f} "
                     f"points between processes; of the {len(gaps)} pairs the rankings ordered "
                     f"wrong, {closer} were measured closer than that")
    return "\n".join(lines)


def scaling_text(df):
    """Per back end and scene, the larger resolution's frame over the smaller one's, measured
    and predicted (the mean over the tiles converged at both). A check of the model that no
    draw of the machine's speed moves: a model whose misses grow with the frame's length (lines
    that age out between two frames) predicts a ratio the silicon does not show."""
    c = self_consistency(df)
    if c.empty:
        return "No scene was measured (converged) at two resolutions."
    lines = ["| back end | scene | resolutions | tiles | measured ratio | predicted ratio | "
             "error |", "|---|---|---|---|---|---|---|"]
    for (isa, scene, small, large), g in c.groupby(["isa", "scene", "small", "large"],
                                                   sort=False):
        m, p = g["ratio"].mean(), g["predicted_ratio"].mean()
        lines.append(f"| {isa} | {scene} | {large} / {small} | {len(g)} | {m:.2f} | {p:.2f} | "
                     f"{pct(p / m - 1)} |")
    return "\n".join(lines)


def consistency_text(df):
    """One line per back end: how many resolution pairs are consistent, and the ones that are
    not (the host's measurement is flagged by them)."""
    c = self_consistency(df)
    if c.empty:
        return "- self-consistency: no scene measured (converged) at two resolutions"
    lines = []
    for isa in isas(df):
        g = c[c["isa"] == isa]
        if g.empty:
            continue
        bad = g[~g["consistent"]]
        lo, hi = g["lo"].iloc[0], g["hi"].iloc[0]
        verdict = "consistent" if bad.empty else "FLAGGED: this host's measurement is suspect"
        lines.append(f"- self-consistency ({isa}): {len(g) - len(bad)} of {len(g)} "
                     f"(scene, tile) frames cost {lo:g}-{hi:g}x at {g['large'].iloc[0]} what "
                     f"they cost at {g['small'].iloc[0]}: {verdict}")
        for _, r in bad.iterrows():
            lines.append(f"  - {r['scene']} tile {r['tile']}: {r['ratio']:.2f}x")
    return "\n".join(lines)


def cold_text(df):
    """Per workload measured from cold caches too: what the frame pays for starting with none
    of its scene cached (cold - warm), measured and predicted. The measured pair counts only
    where both converged."""
    if "measured.cold_frame_cycles" not in df:
        return "These rows carry no renders from cold caches."
    g = df[df["measured.cold_frame_cycles"].notna()]
    if g.empty:
        return "These rows carry no renders from cold caches."
    lines = ["| back end | scene | res | tile | measured warm / cold Mcyc | measured cost | "
             "predicted warm / cold Mcyc | predicted cost | predicted / measured cost |",
             "|---|---|---|---|---|---|---|---|---|"]
    for _, r in g.iterrows():
        mw, mc = r["measured.frame_cycles"], r["measured.cold_frame_cycles"]
        pw, pc = r["predicted.frame_cycles"], r["predicted.cold_frame_cycles"]
        both = bool(r["measured.converged"]) and bool(r["measured.cold_converged"])
        measured = (f"{(mc - mw) / 1e6:+.2f} M ({pct(mc / mw - 1)})" if both
                    else "not converged")
        ratio = f"{(pc - pw) / (mc - mw):.2f}" if both and mc > mw else "n/a"
        lines.append(f"| {r['isa']} | {r['scene']} | {r['res']} | {r['tile']} | "
                     f"{mw / 1e6:.2f} / {mc / 1e6:.2f} | {measured} | "
                     f"{pw / 1e6:.2f} / {pc / 1e6:.2f} | {(pc - pw) / 1e6:+.2f} M "
                     f"({pct(pc / pw - 1)}) | {ratio} |")
    return "\n".join(lines)


def isas(df):
    """The back ends of the rows, narrowest first."""
    return sorted(df["isa"].unique(), key=lambda i: WIDTHS.get(i, 0))


def judged_ranking(g, key):
    """Variants of one cell (rows of `g`, told apart by column `key`): both orders fastest
    first, the measurably different pairs and how many of them the prediction orders right."""
    pred = list(g.sort_values("predicted.frame_cycles")[key])
    meas = list(g.sort_values("measured.frame_cycles")[key])
    pairs = right = 0
    wrong = []  # per pair ordered wrong: how far apart measured and predicted
    for (_, a), (_, b) in itertools.combinations(g.iterrows(), 2):
        if a["measured.hi"] < b["measured.lo"] or b["measured.hi"] < a["measured.lo"]:
            pairs += 1
            faster_measured = a["measured.frame_cycles"] < b["measured.frame_cycles"]
            faster_predicted = a["predicted.frame_cycles"] < b["predicted.frame_cycles"]
            right += faster_measured == faster_predicted
            if faster_measured != faster_predicted:
                slow, fast = (b, a) if faster_measured else (a, b)
                wrong.append({
                    "slower": slow[key], "faster": fast[key],
                    "measured": slow["measured.frame_cycles"] / fast["measured.frame_cycles"] - 1,
                    "predicted":
                        slow["predicted.frame_cycles"] / fast["predicted.frame_cycles"] - 1})
    return {"predicted": pred, "measured": meas, "pairs": pairs, "pairs_right": right,
            "measurable": pairs > 0, "right": right == pairs, "wrong": wrong}


def ranking(df):
    """Per back end, scene and resolution: tiles fastest first, predicted and measured (the
    converged workloads)."""
    rows = []
    for (isa, scene, res), g in scored(df).groupby(["isa", "scene", "res"], sort=False):
        rows.append({"isa": isa, "scene": scene, "res": res, **judged_ranking(g, "tile")})
    return pd.DataFrame(rows, columns=["isa", "scene", "res", "predicted", "measured", "pairs",
                                       "pairs_right", "measurable", "right", "wrong"])


def width_ranking(df):
    """Per scene, resolution and tile (with more than one back end): SIMD widths fastest
    first, predicted and measured."""
    rows = []
    for (scene, res, tile), g in scored(df).groupby(["scene", "res", "tile"], sort=False):
        if g["isa"].nunique() < 2:
            continue
        rows.append({"scene": scene, "res": res, "tile": tile,
                     **judged_ranking(g, "simd_width")})
    return pd.DataFrame(rows)


def summary(df):
    """For one back end's rows: how many converged; over the converged ones, MAE and worst
    |error| of frame cycles, per stage, the tile ranking; and whether the targets hold."""
    all_rows = df
    df = scored(df)
    out = {"workloads": len(all_rows), "converged": len(df),
           "converged_share": len(df) / len(all_rows) if len(all_rows) else 0.0,
           "frame_mae": df["error.frame"].abs().mean(),
           "frame_worst": df["error.frame"].abs().max()}
    for s in STAGES:
        out[f"{s}_mae"] = df[f"error.{s}"].abs().mean()
        out[f"{s}_worst"] = df[f"error.{s}"].abs().max()
    rank = ranking(df)
    measurable = rank[rank["measurable"].astype(bool)]
    if "predicted.memory_now" in df and df["predicted.memory_now"].any():
        described = df["predicted.frame_cycles_described"] / df["measured.frame_cycles"] - 1.0
        out["frame_mae_described"] = described.abs().mean()
        out["frame_worst_described"] = described.abs().max()
        if "predicted.frame_cycles_round" in df and (df["predicted.frame_cycles_round"] > 0).all():
            round_ = df["predicted.frame_cycles_round"] / df["measured.frame_cycles"] - 1.0
            out["frame_mae_round"] = round_.abs().mean()
            out["frame_worst_round"] = round_.abs().max()
    if "measured.frame_cycles_parts" in all_rows:
        # The second reading of the same renders, each part's fastest where the core was alone
        # over it, summed: against the fastest render where both converged, and the prediction
        # against it wherever it converged (rows written before its verdict: wherever it was read).
        parts = all_rows[all_rows["measured.frame_cycles_parts"] > 0]
        if "measured.frame_parts_converged" in parts:
            parts = parts[parts["measured.frame_parts_converged"].fillna(False).astype(bool)]
        both = df[df.index.isin(parts.index)]
        agree = both["measured.frame_cycles_parts"] / both["measured.frame_cycles"] - 1.0
        against = parts["predicted.frame_cycles"] / parts["measured.frame_cycles_parts"] - 1.0
        out["parts_agree_median"] = agree.abs().median() if len(agree) else float("nan")
        out["parts_agree_worst"] = agree.abs().max() if len(agree) else float("nan")
        out["parts_agree_signed"] = agree.median() if len(agree) else float("nan")
        out["parts_workloads"] = len(parts)
        out["parts_only"] = len(parts) - len(both)
        out["parts_frame_mae"] = against.abs().mean() if len(against) else float("nan")
        out["parts_frame_worst"] = against.abs().max() if len(against) else float("nan")
    out["ranking_right"] = int(measurable["right"].sum())
    out["ranking_cells"] = len(measurable)
    out["ranking_within_noise"] = len(rank) - len(measurable)
    out["ranking_wrong_gaps"] = wrong_gaps_text(measurable)
    out["targets"] = {
        "at least 90 % of workloads converge":
            bool(out["converged_share"] >= TARGETS["converged"]),
        "frame MAE <= 10 %": bool(out["frame_mae"] <= TARGETS["frame_mae"]),
        "frame worst <= 20 %": bool(out["frame_worst"] <= TARGETS["frame_worst"]),
        "each stage's MAE <= 20 %": all(bool(out[f"{s}_mae"] <= TARGETS["stage_mae"])
                                        for s in STAGES),
        "tile ranking right in every measurable cell":
            out["ranking_right"] == out["ranking_cells"],
    }
    return out


def width_summary(df):
    """Across back ends: per scene, is the width ranking right in every measurable cell."""
    rank = width_ranking(df)
    if rank.empty:
        return None
    scenes = []
    for scene, g in rank.groupby("scene", sort=False):
        m = g[g["measurable"].astype(bool)]
        scenes.append({"scene": scene, "cells": len(m), "right": int(m["right"].sum()),
                       "pairs": int(m["pairs"].sum()), "pairs_right": int(m["pairs_right"].sum())})
    scenes = pd.DataFrame(scenes)
    return {"scenes": scenes,
            "scenes_right": int((scenes["right"] == scenes["cells"]).sum()),
            "scene_count": len(scenes),
            "wrong_gaps": wrong_gaps_text(rank[rank["measurable"].astype(bool)]),
            "target": bool((scenes["right"] == scenes["cells"]).all())}


def pct(x):
    """'+4.2 %', or '-' where there is nothing to compare (a workload with no render kept)."""
    return f"{100 * x:+.1f} %" if pd.notna(x) and abs(x) != float("inf") else "-"


def mcyc(cycles):
    """Mcycles with two decimals, or '-' for none (a workload with no render kept)."""
    return f"{cycles / 1e6:.2f}" if pd.notna(cycles) and cycles > 0 else "-"


def share_text(x):
    """'12 %', or '-' for none (the noise of a workload with no render kept)."""
    return f"{100 * x:.0f} %" if pd.notna(x) else "-"


def converged_text(r):
    """'yes (9)' or 'NO (31)': the verdict and the renders it took."""
    return f"{'yes' if r['measured.converged'] else 'NO'} ({r['measured.renders']})"


def workload_cells(r):
    """One workload's row of the per-workload table, the page's and the report's alike."""
    return [r["isa"], r["scene"], r["res"], r["tile"], mcyc(r["predicted.frame_cycles"]),
            mcyc(r["measured.frame_cycles"]), pct(r["error.frame"]), pct(r["error.traversal"]),
            pct(r["error.intersection"]), pct(r["error.shading"]), share_text(r["noise"]),
            converged_text(r)]


def table_text(df):
    lines = ["| back end | scene | res | tile | predicted Mcyc | measured Mcyc | error | trav err | "
             "isect err | shade err | noise | converged (renders) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in df.iterrows():
        lines.append("| " + " | ".join(str(c) for c in workload_cells(r)) + " |")
    return "\n".join(lines)


def stage_table_text(df):
    lines = ["| back end | scene | stage | predicted Mcyc (sum) | measured Mcyc (sum) | "
             "error of sum | mean abs error | of which scene-data stalls (predicted) |",
             "|---|---|---|---|---|---|---|---|"]
    for (isa, scene), g in scored(df).groupby(["isa", "scene"], sort=False):
        for s in STAGES:
            p = g[f"predicted.{s}_cycles"].sum()
            m = g[f"measured.{s}_cycles"].sum()
            mem = g[f"predicted.{s}_memory_cycles"].sum()
            lines.append(f"| {isa} | {scene} | {s} | {p / 1e6:.2f} | {m / 1e6:.2f} | "
                         f"{pct(p / m - 1)} | "
                         f"{100 * g[f'error.{s}'].abs().mean():.1f} % | {mem / max(p, 1):.0%} |")
    return "\n".join(lines)


def wrong_pair_text(w):
    """'64 over 32: measured +1.5 %, predicted -0.2 %': a pair ordered wrong, the measured
    slower one first, each frame over the other's."""
    return (f"{w['slower']} over {w['faster']}: measured {pct(w['measured'])}, "
            f"predicted {pct(w['predicted'])}")


def wrong_gaps(rank):
    """How far apart each pair ordered wrong was measured, over the rows of a ranking (each
    frame over the other's, the measured slower first)."""
    return [w["measured"] for ws in rank.get("wrong", []) for w in ws]


def wrong_gaps_text(rank):
    """How far apart the pairs ordered wrong were measured, over the rows of a ranking: a miss
    of a pair 1 % apart asks of the model what a miss of one 10 % apart does not."""
    gaps = wrong_gaps(rank)
    if not gaps:
        return ""
    if len(gaps) == 1:
        return f"; the pair ordered wrong was measured {100 * gaps[0]:.1f} % apart"
    return (f"; the {len(gaps)} pairs ordered wrong were measured "
            f"{100 * min(gaps):.1f}-{100 * max(gaps):.1f} % apart")


def _verdict(r):
    if not r["measurable"]:
        return "within noise"
    wrong = "".join(f"; {wrong_pair_text(w)}" for w in r.get("wrong") or [])
    return f"{'yes' if r['right'] else 'no'} ({r['pairs_right']} of {r['pairs']} pairs{wrong})"


def _ranking_table(rank, keys, order):
    """A ranking's rows: the `keys` columns, both orders (`order` names them), the verdict."""
    titles = {"isa": "back end"}
    lines = ["| " + " | ".join(titles.get(k, k) for k in keys) +
             f" | predicted ({order}) | measured | right |", "|" + "---|" * (len(keys) + 3)]
    for _, r in rank.iterrows():
        cells = [str(r[k]) for k in keys] + [", ".join(map(str, r["predicted"])),
                                             ", ".join(map(str, r["measured"])), _verdict(r)]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def ranking_text(df):
    return _ranking_table(ranking(df), ["isa", "scene", "res"], "fastest first")


def width_ranking_text(df):
    rank = width_ranking(df)
    if rank.empty:
        return "One back end only: no width ranking."
    return _ranking_table(rank, ["scene", "res", "tile"], "fastest first, lanes")


def misses_text(df):
    """Per back end and stage over every workload: the summed error, and how much of the
    prediction is scene-data stalls - where to look first."""
    lines = ["| back end | stage | predicted Mcyc | measured Mcyc | error of sum | "
             "predicted scene-data stalls | error without them |", "|---|---|---|---|---|---|---|"]
    for isa, g in scored(df).groupby("isa", sort=False):
        for s in STAGES:
            p = g[f"predicted.{s}_cycles"].sum()
            m = g[f"measured.{s}_cycles"].sum()
            mem = g[f"predicted.{s}_memory_cycles"].sum()
            lines.append(f"| {isa} | {s} | {p / 1e6:.1f} | {m / 1e6:.1f} | {pct(p / m - 1)} | "
                         f"{mem / max(p, 1):.0%} | {pct((p - mem) / m - 1)} |")
    return "\n".join(lines)


def cache_levels(df):
    """The model's scene-cache levels the rows carry misses of, in name order (the host files
    name them l1, l2, l3)."""
    prefix, suffix = "predicted.scene_cache.", ".misses"
    return sorted(c[len(prefix):-len(suffix)] for c in df.columns
                  if c.startswith(prefix) and c.endswith(suffix))


def residual_text(df):
    """Per back end, scene and resolution (converged tiles summed): the measured frame less the
    predicted one, against the model's scene-data misses per level. A residual that keeps one
    size per miss of the first level across scenes and resolutions points at what the model
    charges for scene data beyond the L1D; one that keeps a size per pixel, at the op costs."""
    levels = cache_levels(df)
    if not levels or "predicted.scene_memory.dram_reads" not in df:
        return "These rows carry no scene-data misses of the model."
    first = levels[0]
    lines = ["| back end | scene | res | tiles | measured - predicted Mcyc | per pixel | "
             + " | ".join(f"model's {lv} misses" for lv in levels)
             + f" | model's DRAM reads | per {first} miss |",
             "|---|---|---|---|---|---|" + "---|" * (len(levels) + 2)]
    for (isa, scene, res), g in scored(df).groupby(["isa", "scene", "res"], sort=False):
        residual = (g["measured.frame_cycles"] - g["predicted.frame_cycles"]).sum()
        pixels = (g["width"] * g["height"]).sum()
        misses = [g[f"predicted.scene_cache.{lv}.misses"].sum() for lv in levels]
        per_miss = f"{residual / misses[0]:+.0f}" if misses[0] > 0 else "n/a"
        lines.append(f"| {isa} | {scene} | {res} | {len(g)} | {residual / 1e6:+.2f} | "
                     f"{residual / pixels:+.0f} | "
                     + " | ".join(f"{m:,.0f}" for m in misses)
                     + f" | {g['predicted.scene_memory.dram_reads'].sum():,.0f} | {per_miss} |")
    return "\n".join(lines)


def predictor_text(df):
    """Per back end and scene (and the synthetic scene the per-op costs come from): what the
    branch predictor saves a tile's traversal it has just run (displaced over lines cached),
    and what the caches do (lines cached over primed), for camera rays and their bounces,
    beside what the model's predictor adds on the same batches (its mispredictions from primed
    to displaced at the host's fitted cost; rows written before it carry none) and the scene's
    frame error at its smallest resolution (mean over the converged tiles)."""
    if "measured.predictor.camera.primed_cycles" not in df:
        return "These rows carry no branch-predictor microbenchmarks."
    modelled = "predicted.predictor.camera.extra_cycles" in df
    lines = ["| back end | scene | rays | box tests per batch | batches converged | "
             "caches (cached / primed) | predictor (displaced / cached) | "
             + ("model's predictor (mispredictions primed, displaced) | " if modelled else "")
             + "frame error |",
             "|---|---|---|---|---|---|---|" + ("---|" if modelled else "") + "---|"]

    def row(isa, scene, prefix, r, error):
        for rays in ("camera", "bounce"):
            k = f"{prefix}{rays}."
            primed, cached = r[k + "primed_cycles"], r[k + "cached_cycles"]
            displaced, batches = r[k + "displaced_cycles"], r[k + "batches"]
            model = ""
            if modelled:
                m = f"predicted.predictor.{rays}."
                model = ("- | " if prefix.endswith("synthetic.") or pd.isna(r.get(m + "extra_cycles"))
                         else f"{pct(r[m + 'extra_cycles'] / cached)} "
                              f"({r[m + 'primed_mispredictions']:,.0f}, "
                              f"{r[m + 'displaced_mispredictions']:,.0f}) | ")
            lines.append(f"| {isa} | {scene} | {rays} | {r[k + 'box_tests'] / batches:,.0f} | "
                         f"{r[k + 'converged_batches']:.0f} of {batches:.0f} | "
                         f"{pct(cached / primed - 1)} | {pct(displaced / cached - 1)} | "
                         f"{model}{error} |")

    for isa in isas(df):
        g = df[df["isa"] == isa]
        row(isa, "synthetic (the per-op costs' scene)", "measured.predictor.synthetic.",
            g.iloc[0], "-")
        for scene, h in g.groupby("scene", sort=False):
            smallest = scored(h)
            smallest = smallest[smallest["width"] * smallest["height"]
                                == (smallest["width"] * smallest["height"]).min()]
            error = (f"{pct(smallest['error.frame'].mean())} ({smallest['res'].iloc[0]})"
                     if not smallest.empty else "not converged")
            row(isa, scene, "measured.predictor.", h.iloc[0], error)
    return "\n".join(lines)


def dram_text(df):
    """Per back end and scene: the predictor microbenchmark's batches right after themselves and
    a read of other data (every scene line in DRAM) over right after themselves,
    measured, beside the model's same batches from empty caches over right after themselves
    (rows written before either carry none)."""
    if ("measured.predictor.camera.evicted_cycles" not in df
            or "predicted.predictor.camera.cold_cycles" not in df):
        return "These rows carry no batches timed from DRAM."
    lines = ["| back end | scene | rays | measured (evicted / primed) | the synthetic scene's | "
             "measured beyond it | model (cold / warm) | measured extra beyond it, Mcyc | "
             "model extra, Mcyc |", "|---|---|---|---|---|---|---|---|---|"]
    for isa in isas(df):
        for scene, h in df[df["isa"] == isa].groupby("scene", sort=False):
            r = h.iloc[0]
            for rays in ("camera", "bounce"):
                m, p = f"measured.predictor.{rays}.", f"predicted.predictor.{rays}."
                s = f"measured.predictor.synthetic.{rays}."
                primed, evicted = r[m + "primed_cycles"], r[m + "evicted_cycles"]
                base = r.get(s + "evicted_cycles", r[s + "primed_cycles"]) - r[s + "primed_cycles"]
                warm, cold = r[p + "warm_cycles"], r[p + "cold_cycles"]
                lines.append(f"| {isa} | {scene} | {rays} | {pct(evicted / primed - 1)} | "
                             f"{base / 1e6:.2f} Mcyc | {pct((evicted - base) / primed - 1)} | "
                             f"{pct(cold / warm - 1)} | {(evicted - base - primed) / 1e6:.2f} | "
                             f"{(cold - warm) / 1e6:.2f} |")
    return "\n".join(lines)


LOOPS = (("one_ray", "one-ray loop"), ("few_ray", "few-ray loop"), ("stream", "stream loop"))


def predictor_loops_text(df):
    """Per back end, scene, rays and loop: the predictor microbenchmark's batches split by the
    loop that ran them (the stage clock, as a frame's traversal is split): displaced over
    cached (what the branch predictor saves, measured) beside the model's mispredictions added
    from primed to displaced in that loop at the host's price, and evicted over primed (the
    scene read from DRAM, measured; the code, TLB and page tables the read evicts are in it)
    beside the model's cold over warm in that loop (rows written before the split carry none)."""
    if "measured.predictor.camera.displaced_loop_cycles.stream" not in df:
        return "These rows carry no branch-predictor batches split by loop."
    lines = ["| back end | scene | rays | loop | share of cached | predictor, measured "
             "(displaced - cached), Mcyc | model's mispredictions added, Mcyc | DRAM, measured "
             "(evicted - primed), Mcyc | model (cold - warm), Mcyc |",
             "|---|---|---|---|---|---|---|---|---|"]
    for isa in isas(df):
        for scene, h in df[df["isa"] == isa].groupby("scene", sort=False):
            r = h.iloc[0]
            for rays in ("camera", "bounce"):
                m, p = f"measured.predictor.{rays}.", f"predicted.predictor.{rays}."
                cached_all = sum(r[f"{m}cached_loop_cycles.{k}"] for k, _ in LOOPS)
                for key, name in LOOPS:
                    cached = r[f"{m}cached_loop_cycles.{key}"]
                    if cached < 0.01 * max(cached_all, 1):  # a loop the batches barely run
                        continue
                    price = r.get(f"{p}loop_mispredict_cycles.{key}",
                                  r.get(p + "mispredict_cycles", float("nan")))
                    if pd.isna(price):  # rows without it: the price the extra cycles imply
                        added_all = (r[p + "displaced_mispredictions"]
                                     - r[p + "primed_mispredictions"])
                        price = r[p + "extra_cycles"] / added_all if added_all else 0.0
                    added = price * (r[f"{p}displaced_loop_mispredictions.{key}"]
                                     - r[f"{p}primed_loop_mispredictions.{key}"])
                    dram = r[f"{m}evicted_loop_cycles.{key}"] - r[f"{m}primed_loop_cycles.{key}"]
                    model_dram = r[f"{p}cold_loop_cycles.{key}"] - r[f"{p}warm_loop_cycles.{key}"]
                    lines.append(
                        f"| {isa} | {scene} | {rays} | {name} | {cached / cached_all:.0%} | "
                        f"{(r[f'{m}displaced_loop_cycles.{key}'] - cached) / 1e6:.2f} | "
                        f"{added / 1e6:.2f} | {dram / 1e6:.2f} | {model_dram / 1e6:.2f} |")
    return "\n".join(lines)


def stage_loop_rows(df, stage):
    """Per back end and scene, `stage` (traversal or intersection) by the tracer's loop: each
    loop's (isa, scene, key, name, predicted, measured, share of the measured stage) over the
    scored rows, a loop under 1 % of the stage on both sides left out (noise)."""
    for (isa, scene), g in scored(df).groupby(["isa", "scene"], sort=False):
        total = g[f"measured.{stage}_cycles"].sum()
        for key, name in LOOPS:
            p = g[f"predicted.{stage}_{key}_loop_cycles"].sum()
            m = g[f"measured.{stage}_{key}_loop_cycles"].sum()
            if max(p, m) < 0.01 * total:
                continue
            yield g, isa, scene, key, name, p, m, m / max(total, 1)


def loop_row(isa, scene, name, p, m, share):
    return (f"| {isa} | {scene} | {name} | {p / 1e6:.2f} | {m / 1e6:.2f} | "
            f"{pct(p / m - 1) if m > 0 else 'n/a'} | {share:.0%} |")


def loops_text(df):
    """Per back end and scene, the traversal by the tracer's loop that runs its box tests (the
    stage clock's short-loop ticks; rows written before it carry none)."""
    if "measured.traversal_stream_loop_cycles" not in df:
        return "These rows carry no traversal split by loop."
    # The prediction's parts (rows written before them carry none): its mispredictions and its
    # wait for scene data; the rest is its ops' own costs.
    parts = "predicted.traversal_stream_loop_branch_cycles" in df
    lines = ["| back end | scene | loop | predicted Mcyc (sum) | measured Mcyc (sum) | "
             "error of sum | share of measured traversal |"
             + (" of the prediction: mispredictions | scene data |" if parts else ""),
             "|---|---|---|---|---|---|---|" + ("---|---|" if parts else "")]
    for g, isa, scene, key, name, p, m, share in stage_loop_rows(df, "traversal"):
        line = loop_row(isa, scene, name, p, m, share)
        if parts:
            for part in ("branch", "memory"):
                c = g[f"predicted.traversal_{key}_loop_{part}_cycles"].sum()
                line += f" {c / max(p, 1):.0%} |"
        lines.append(line)
    return "\n".join(lines)


def leaf_loops_text(df):
    """Per back end and scene, the intersection stage by the loop whose leaf code runs its tests
    (the stage clock's ticks in the leaves each short loop reaches; rows written before it carry
    none)."""
    if "measured.intersection_stream_loop_cycles" not in df:
        return "These rows carry no intersection split by loop."
    lines = ["| back end | scene | loop | predicted Mcyc (sum) | measured Mcyc (sum) | "
             "error of sum | share of measured intersection |", "|---|---|---|---|---|---|---|"]
    lines += [loop_row(isa, scene, name, p, m, share)
              for _, isa, scene, _, name, p, m, share in stage_loop_rows(df, "intersection")]
    return "\n".join(lines)


def batch_loops_text(df):
    """Per back end, scene and loop, the branch predictor's batches (camera rays and bounces
    summed) as microbenchmarks of the scene's own traversals: each loop's box tests and leaf
    tests right after themselves (primed) against the model's same ops right after themselves
    (warm; its predictor off), their lines aged by the other batches' (cached over primed)
    against the model's same ops after themselves and the other batches (over warm), and
    their scene read from DRAM (evicted - primed, less the synthetic scene's batches' same
    part) against the model's (cold - warm); a part under 1 % of the batches' primed cycles on
    both sides left out (rows written before the leaves' split carry none)."""
    if ("measured.predictor.camera.primed_leaf_loop_cycles.stream" not in df
            or "predicted.predictor.camera.warm_leaf_loop_cycles.stream" not in df):
        return "These rows carry no batches split into box tests and leaves by loop."
    lines = ["| back end | scene | tests | loop | model warm, Mcyc | measured primed, Mcyc | "
             "error | lines aged: model (after the others / warm) | measured (cached / "
             "primed) | model (cold - warm), Mcyc | measured (evicted - primed) beyond the "
             "synthetic scene's, Mcyc | model / measured |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    # Rows written before the model's state after the other batches carry none.
    aged = "predicted.predictor.camera.displaced_leaf_loop_cycles.stream" in df
    for isa in isas(df):
        for scene, h in df[df["isa"] == isa].groupby("scene", sort=False):
            r = h.iloc[0]

            def total(side, state, part, key, which=""):
                return sum(r[f"{side}.predictor.{which}{rays}.{state}_{part}_cycles.{key}"]
                           for rays in ("camera", "bounce"))

            primed_all = sum(r[f"measured.predictor.{rays}.primed_cycles"]
                             for rays in ("camera", "bounce"))
            for part, tests in (("loop", "box"), ("leaf_loop", "leaf")):
                for key, name in LOOPS:
                    warm = total("predicted", "warm", part, key)
                    primed = total("measured", "primed", part, key)
                    if max(warm, primed) < 0.01 * primed_all:
                        continue
                    cold = total("predicted", "cold", part, key) - warm
                    # Less the synthetic scene's part (the code, TLB and page tables the read
                    # evicts too: dram_text).
                    evicted = (total("measured", "evicted", part, key) - primed
                               - total("measured", "evicted", part, key, "synthetic.")
                               + total("measured", "primed", part, key, "synthetic."))
                    cached = total("measured", "cached", part, key)
                    after = (pct(total("predicted", "displaced", part, key) / warm - 1)
                             if aged and warm > 0 else "-")
                    lines.append(
                        f"| {isa} | {scene} | {tests} | {name} | {warm / 1e6:.2f} | "
                        f"{primed / 1e6:.2f} | {pct(warm / primed - 1) if primed > 0 else 'n/a'} | "
                        f"{after} | {pct(cached / primed - 1) if primed > 0 else 'n/a'} | "
                        f"{cold / 1e6:.2f} | {evicted / 1e6:.2f} | "
                        f"{f'{cold / evicted:.2f}' if evicted > 0 else 'n/a'} |")
    return "\n".join(lines)


def shading_ops_text(df):
    """Per back end and scene, the shading stage by op kind (the stage clock's ticks of each
    kind's filter), and the ray set-up the tracer runs apart, which the model prices in the ops
    that made the rays (rows written before the split carry none)."""
    if "measured.ray_setup_cycles" not in df:
        return "These rows carry no shading stage split by op kind."
    kinds = [c[len("measured.op_cycles."):] for c in df.columns
             if c.startswith("measured.op_cycles.")]
    lines = ["| back end | scene | op | predicted Mcyc (sum) | measured Mcyc (sum) | "
             "error of sum | share of measured shading |", "|---|---|---|---|---|---|---|"]
    for (isa, scene), g in scored(df).groupby(["isa", "scene"], sort=False):
        shading = max(g["measured.shading_cycles"].sum(), 1.0)
        for kind in kinds:
            p = g[f"predicted.op_cycles.{kind}"].fillna(0).sum()
            m = g[f"measured.op_cycles.{kind}"].fillna(0).sum()
            if max(p, m) < 0.01 * shading:  # an op the scene barely runs: noise
                continue
            lines.append(f"| {isa} | {scene} | {kind} | {p / 1e6:.2f} | {m / 1e6:.2f} | "
                         f"{pct(p / m - 1) if m > 0 else 'n/a'} | {m / shading:.0%} |")
        setup = g["measured.ray_setup_cycles"].sum()
        lines.append(f"| {isa} | {scene} | ray set-up (in the ops that made the rays) | - | "
                     f"{setup / 1e6:.2f} | - | {setup / shading:.0%} |")
        if "ray_making_ops" in g:
            # What the model prices together: the ops that make rays, with their set-up.
            making = [k for k in str(g["ray_making_ops"].iloc[0]).split(",")
                      if f"measured.op_cycles.{k}" in g]
            p = sum(g[f"predicted.op_cycles.{k}"].fillna(0).sum() for k in making)
            m = setup + sum(g[f"measured.op_cycles.{k}"].fillna(0).sum() for k in making)
            lines.append(f"| {isa} | {scene} | **the ops that make rays, with their set-up** | "
                         f"{p / 1e6:.2f} | {m / 1e6:.2f} | "
                         f"{pct(p / m - 1) if m > 0 else 'n/a'} | {m / shading:.0%} |")
    return "\n".join(lines)


def summary_text(s, isa=None):
    at = f" ({isa})" if isa else ""
    lines = [f"- workloads{at}: {s['workloads']}, of which {s['converged']} converged "
             f"({100 * s['converged_share']:.0f} %; only these are scored)",
             f"- frame cycles: MAE {100 * s['frame_mae']:.1f} %, worst {100 * s['frame_worst']:.1f} %"]
    instead = ("the run's (the median of the chases its renders met)" if "frame_mae_round" in s
               else "the one chased in the round of each fastest render")
    if "frame_mae_described" in s:
        lines.append(f"  - with the host file's L3 instead of {instead} (same renders): "
                     f"MAE {100 * s['frame_mae_described']:.1f} %, worst "
                     f"{100 * s['frame_worst_described']:.1f} %")
    if "frame_mae_round" in s:
        lines.append(f"  - with the L3 chased in the round of each workload's fastest render "
                     f"instead (same renders): MAE {100 * s['frame_mae_round']:.1f} %, worst "
                     f"{100 * s['frame_worst_round']:.1f} %")
    if s.get("parts_workloads"):
        lines.append(f"  - the frame as the sum of its parts' fastest (a pass's generations, each "
                     f"over the renders, kept or set aside, in which the monitor's probes around "
                     f"it found the core alone; not scored): converged (the rule on the parts' "
                     f"fastest and k-th fastest sums) on {s['parts_workloads']} workloads, "
                     f"{s['parts_only']} of them workloads whose renders did not; "
                     f"{100 * s['parts_agree_signed']:+.1f} % against the fastest render "
                     f"(median; worst {100 * s['parts_agree_worst']:.1f} % apart) where both "
                     f"converged; the prediction against it where it converged: MAE "
                     f"{100 * s['parts_frame_mae']:.1f} %, worst "
                     f"{100 * s['parts_frame_worst']:.1f} %")
    for st in STAGES:
        lines.append(f"- {st}: MAE {100 * s[f'{st}_mae']:.1f} %, worst {100 * s[f'{st}_worst']:.1f} %")
    lines.append(f"- tile ranking right in {s['ranking_right']} of {s['ranking_cells']} "
                 f"(scene, resolution) cells with a measurable difference "
                 f"({s['ranking_within_noise']} within noise){s.get('ranking_wrong_gaps', '')}")
    for name, ok in s["targets"].items():
        lines.append(f"- target {name}: {'met' if ok else 'MISSED'}")
    return "\n".join(lines)


def width_summary_text(w):
    if w is None:
        return "- one back end only: no width ranking"
    lines = [f"- width ranking right in {w['scenes_right']} of {w['scene_count']} scenes"
             f"{w.get('wrong_gaps', '')}"]
    for _, r in w["scenes"].iterrows():
        lines.append(f"  - {r['scene']}: {r['right']} of {r['cells']} measurable (res, tile) "
                     f"cells right ({r['pairs_right']} of {r['pairs']} pairs)")
    lines.append(f"- target width ranking right in every scene: "
                 f"{'met' if w['target'] else 'MISSED'}")
    return "\n".join(lines)


def measurement_text(df):
    """How the rows were measured: the convergence rule, the cycle source of each back end,
    the host's microarchitecture, the huge pages the process held."""
    lines = []
    if "convergence_rule" in df:
        for rule in df["convergence_rule"].dropna().unique():
            lines.append(f"- convergence rule: {rule}")
    if "measured.cycle_source" in df:
        for isa in isas(df):
            for src in df[df["isa"] == isa]["measured.cycle_source"].dropna().unique():
                lines.append(f"- cycles ({isa}): {src}")
    else:
        lines.append("- cycles: not recorded (rows written before the cycle source)")
    if "measured.clock_mhz_before" in df and not df["measured.cycles_counted"].any():
        for isa in isas(df):
            g = df[df["isa"] == isa]
            g = g[g["measured.frame_cycles"] > 0]  # a workload with no render kept has no clock
            clocks = pd.concat([g["measured.clock_mhz_before"], g["measured.clock_mhz_after"]])
            drift = (g["measured.clock_mhz_after"] / g["measured.clock_mhz_before"] - 1).abs()
            lines.append(f"- core clock around the fastest renders ({isa}): "
                         f"{clocks.min():.0f}-{clocks.max():.0f} MHz, before and after one render "
                         f"apart by {100 * drift.median():.1f} % (median), "
                         f"{100 * drift.max():.1f} % at most")
    if "measured.clock_moved_renders" in df and not df["measured.cycles_counted"].any():
        moved = df["measured.clock_moved_renders"]
        renders = moved + df["measured.renders"]
        lines.append(f"- renders set aside because the clock moved over them by more than the "
                     f"convergence tolerance (their cycles could lie anywhere between the two "
                     f"clocks'): {int(moved.sum())} of {int(renders.sum())}, in "
                     f"{int((moved > 0).sum())} of {len(df)} workloads")
    if "measured.contended_renders" in df:
        shared = df["measured.contended_renders"]
        renders = shared + df["measured.renders"] + df.get("measured.clock_moved_renders", 0)
        monitored = "measured.render_shared_share" in df
        how = ("over more than a tenth of the probes every millisecond during them, or just "
               "after them" if monitored else "after them")
        lines.append(f"- renders set aside because another hardware thread shared the core {how} "
                     f"(base/core_contention.h: its rate of independent adds below the "
                     f"best seen; the core waited for before each render): {int(shared.sum())} "
                     f"of {int(renders.sum())}, in {int((shared > 0).sum())} of {len(df)} "
                     f"workloads")
        if monitored:
            share = pd.Series([s for row in df["measured.render_shared_share"].dropna()
                               for s in row], dtype=float)
            if len(share):
                lines.append(f"- the core found shared during the renders (the monitor's "
                             f"probes): in none of their probes in {100 * (share == 0).mean():.0f} "
                             f"% of the renders, in more than half in "
                             f"{100 * (share > 0.5).mean():.0f} %; the probes took "
                             f"{100 * df['measured.monitor_share'].mean():.2f} % of a kept render "
                             f"(taken off its cycles)")
    if "measured.rewarmed_renders" in df:
        rewarmed = int(df["measured.rewarmed_renders"].sum())
        lines.append(f"- the gate's waits for the core before a measured render (each asleep 10 ms "
                     f"or more, over which others' fills take what the render before left in a "
                     f"shared L3): {rewarmed}, each followed by a render of the workload "
                     f"(another frame) again to warm the caches (CoreContention::wait_warm)")
    if "host.microarchitecture" in df:
        for m in df["host.microarchitecture"].dropna().unique():
            lines.append(f"- microarchitecture: {m}")
    if "measured.huge_page_kib_min" in df:
        lo, hi = df["measured.huge_page_kib_min"].min(), df["measured.huge_page_kib_max"].max()
        lines.append(f"- transparent huge pages held by the process after each render: "
                     f"{lo / 1024:.0f}-{hi / 1024:.0f} MiB "
                     f"(AnonHugePages, /proc/self/smaps_rollup)")
    if "measured.neighbours_busy" in df:
        busy = df["measured.neighbours_busy"]
        busy = busy[busy >= 0]
        if len(busy):
            lines.append(f"- the other CPUs were busy {100 * busy.mean():.0f} % of the time during "
                         f"the renders (per workload {100 * busy.min():.0f}-{100 * busy.max():.0f} "
                         f"%; /proc/stat): a whole run can be slowed alike, which no convergence "
                         f"rule sees")
    if "measured.speed_probe_before" in df:
        for isa, g in df.groupby("isa", sort=False):
            before = g["measured.speed_probe_before"].iloc[0]
            after = g["measured.speed_probe_after"].iloc[0]
            what = (f"- speed probe ({isa}): box, triangle, emission and Lambertian filter "
                    f"microbenchmarks re-run just before the first render and after the last, "
                    f"against their cycles at calibration")
            if pd.isna(before) or pd.isna(after):
                lines.append(f"{what}: not measured at calibration (an older host file)")
                continue
            flag = (f"SLOWED OR SPED ALIKE (beyond +-{100 * SPEED_PROBE_LIMIT:.0f} %): the run's "
                    f"measurements are not the calibrated machine's"
                    if max(abs(before), abs(after)) > SPEED_PROBE_LIMIT else "as calibrated")
            lines.append(f"{what}: {100 * before:+.1f} % / {100 * after:+.1f} %: {flag}")
    if "measured.l3_kib_before" in df:
        lines.append(l3_text(df))
    return "\n".join(lines)


def l3_moved(df):
    """Whether the L3 chased after the renders is beyond L3_MOVE_LIMIT of the one before."""
    r = df.iloc[0]
    before, after = r["measured.l3_kib_before"], r["measured.l3_kib_after"]
    return bool(before > 0 and after > 0 and abs(after / before - 1) > L3_MOVE_LIMIT)


def l3_text(df):
    """The L3 this core kept: the host file's, and chased before the predictions and after the
    renders; which one the model predicted with, and whether it held."""
    r = df.iloc[0]

    def level(kib, fills):
        return f"{kib / 1024:.1f} MiB (others' fills {fills:.2f} lines/us)" if kib > 0 else \
            "not chased"
    now = bool(r.get("predicted.memory_now", False))
    run_kib = r.get("measured.l3_kib_run", 0)
    if now and run_kib and run_kib > 0:
        predicted_with = (f"every workload with the run's, "
                          f"{level(run_kib, r['measured.l3_fill_per_us_run'])}: the median of "
                          f"the rounds' chases over every kept render (--memory-now)")
    elif now:
        predicted_with = ("each workload with the one chased in the round of its fastest "
                          "render (--memory-now)")
    else:
        predicted_with = "with the host file's"
    rounds_max = r.get("measured.l3_kib_rounds_max", 0)
    held = (f"MOVED (beyond +-{100 * L3_MOVE_LIMIT:.0f} % in size): the renders did not all "
            f"meet one memory" if l3_moved(df) else "held")
    rounds = (f"; at the start of each round {r['measured.l3_kib_rounds_min'] / 1024:.1f} to "
              f"{rounds_max / 1024:.1f} MiB" if rounds_max > 0 else "")
    return (f"- the L3 this core keeps (`last_level_seen`): the host file's "
            f"{level(r.get('host.l3_kib', 0), r.get('host.l3_fill_per_us', 0.0))}; chased just "
            f"before the first render {level(r['measured.l3_kib_before'], r['measured.l3_fill_per_us_before'])}, "
            f"just after the last render {level(r['measured.l3_kib_after'], r['measured.l3_fill_per_us_after'])}: "
            f"{held}{rounds}; the model predicted " + predicted_with)


def all_summaries_text(df, repeats=()):
    """How it was measured, the summary of every back end, the width ranking's, and the
    self-consistency flags (with `repeats`, the rows of one workload measured again in
    processes of their own: reproducibility)."""
    parts = []
    head = measurement_text(df)
    if head:
        parts.append(head)
    for isa in isas(df):
        parts.append(summary_text(summary(df[df["isa"] == isa]), isa))
    parts.append(width_summary_text(width_summary(df)))
    parts.append(consistency_text(df))
    if repeats:
        parts.append(reproducibility_text(reproducibility(df, repeats), df))
    return "\n".join(parts)


def scatter_plot(df, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    ax = axes[0]
    markers = {"scalar": "x", "avx2": "o", "avx512": "s"}
    df = scored(df) if scored(df).shape[0] else df
    for (scene, isa), g in df.groupby(["scene", "isa"], sort=False):
        ax.scatter(g["measured.frame_cycles"] / 1e6, g["predicted.frame_cycles"] / 1e6,
                   label=f"{scene} {isa}", marker=markers.get(isa, "o"), s=28)
    lo = min(df["measured.frame_cycles"].min(), df["predicted.frame_cycles"].min()) / 1e6
    hi = max(df["measured.frame_cycles"].max(), df["predicted.frame_cycles"].max()) / 1e6
    for a in axes:
        a.set_xscale("log")
        a.set_yscale("log")
    ax.plot([lo, hi], [lo, hi], "k-", lw=1, label="y = x")
    ax.plot([lo, hi], [lo * 1.25, hi * 1.25], "k:", lw=0.8, label="±25 %")
    ax.plot([lo, hi], [lo / 1.25, hi / 1.25], "k:", lw=0.8)
    ax.set_xlabel("measured Mcycles per frame (core cycles, fastest render)")
    ax.set_ylabel("predicted Mcycles per frame")
    ax.set_title("frames")
    ax.legend(fontsize=6, ncol=2)
    ax = axes[1]
    markers = {"traversal": "o", "intersection": "s", "shading": "^"}
    for s in STAGES:
        ax.scatter(df[f"measured.{s}_cycles"] / 1e6, df[f"predicted.{s}_cycles"] / 1e6,
                   marker=markers[s], label=s, s=24)
    vals = pd.concat([df[f"measured.{s}_cycles"] for s in STAGES] +
                     [df[f"predicted.{s}_cycles"] for s in STAGES]) / 1e6
    vals = vals[vals > 0]
    ax.plot([vals.min(), vals.max()], [vals.min(), vals.max()], "k-", lw=1, label="y = x")
    ax.set_xlabel("measured Mcycles per stage")
    ax.set_ylabel("predicted Mcycles per stage")
    ax.set_title("stages")
    ax.legend(fontsize=8)
    fig.suptitle("the machine model of the host against the native stream tracer "
                 "(shared, noisy machine)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_page(df, page, plot_name, header, repeats=()):
    """docs/silicon-check-*.md: how it was run, the summaries, the tables; the plot beside it."""
    text = "\n\n".join([
        "# The timing model on silicon: the host CPU predicting the native stream tracer",
        header.strip(),
        "## Summary\n\n" + all_summaries_text(df, repeats),
        f"![predicted against measured]({plot_name})",
        "## Per workload\n\nError = predicted / measured - 1. Noise = (max - min) / median of the "
        "measured renders of that workload. Converged: whether its fastest renders agreed "
        "before the budget ran out (the rule above), and how many renders it took; a workload "
        "marked NO is shown but scored nowhere.\n\n" + table_text(df),
        "## Per scene and stage\n\n" + stage_table_text(df),
        "## Tile-size ranking\n\nJudged on the pairs of converged tiles whose measured ranges "
        "(the fastest to the k-th fastest render, what the convergence rule vouches for) do "
        "not overlap. A pair ordered wrong is named with each frame over the other's, the "
        "measured slower first: the frame MAE above is the scale to read them against.\n\n" +
        ranking_text(df),
        "## SIMD-width ranking\n\nThe same workload on each back end, each predicted by its "
        "own host configuration (per-op costs from that back end's microbenchmarks); judged as "
        "the tiles are.\n\n" + width_ranking_text(df),
        "## Resolution scaling\n\nA scene's frame at the larger resolution over its frame at "
        "the smaller, measured and predicted, on the tiles converged at both. Rays of the "
        "larger frame are more coherent, so the ratio is below the pixels' ratio; a model "
        "that loses lines by age between frames loses more of them in the longer frame and "
        "predicts a ratio above the measured one.\n\n" + scaling_text(df),
        "## Cold caches\n\nOne tile per scene, resolution and back end also rendered after "
        "reading other data (three times the largest cache the CPU reports, at least 256 MiB), "
        "so that none of the scene is left in this core's "
        "caches (the same convergence rule), and predicted from empty caches. The cost of cold "
        "caches is what the frame otherwise saves from the lines the render before left: on "
        "silicon, what those lines are worth after their ageing by the neighbours' fills; in "
        "the model, its misses to DRAM at its DRAM latency and exposure. (The eviction also "
        "empties the TLBs and the ray buffers' lines, which the model does not price.) "
        "Since 2026-12-05 the cold render is another frame of the workload (another seed, "
        "as each render before a timed one is: the core's branch predictor learns a frame it "
        "has just rendered), measured and predicted alike, so the cost also holds the two "
        "frames' difference in work.\n\n"
        + cold_text(df),
        "## Where the prediction goes wrong, by stage\n\nScene-data stalls are what the "
        "machine model exposes of each miss (the latency of the level that holds the line, less "
        "the L1D hit inside the measured op costs, after the prefetch of the next op's data); "
        "the last column is the prediction without them.\n\n" + misses_text(df),
        "## The residual against the model's misses\n\nPer resolution, the tiles' measured "
        "frames less their predicted ones (summed over the converged tiles), per pixel and "
        "per miss of the model's first scene-cache level, beside the model's misses per level "
        "and its DRAM reads. A residual that the model's pricing of scene data beyond the L1D "
        "leaves keeps one size per first-level miss across scenes and resolutions; one that "
        "the op costs leave keeps one size per pixel. DRAM reads the silicon does not pay (the "
        "cold-cache table) lower the residual where the model has them.\n\n"
        + residual_text(df),
        "## The branch predictor\n\nThe batches of a 64x64 frame's 16x16 tiles (camera "
        "rays, and a bounce of each in a random direction from its hit), each traversed by the "
        "native kernels and timed (the fastest repetition, the microbenchmarks' rule) in three "
        "states: right after itself (primed); after itself and a read of the scene lines the "
        "other tiles' batches touch (cached); after the other tiles' traversals (displaced: a "
        "frame's traversals never repeat). Displaced over cached is what the branch predictor "
        "saves a traversal it has just run; cached over primed, what the caches do. The per-op "
        "costs are fitted on the synthetic scene's displaced traversals, which a predictor "
        "learns well; a scene whose traversals it learns less well costs more than they say, "
        "whatever its caches hold. The model runs the host file's predictor "
        "(`branch_predictor.kind`, `hw_model/branch_predictor.h`: `unseen_ops` counts each "
        "op of a traversal not just run one misprediction, none primed; `tage` runs L-TAGE's "
        "TAGE over the traversal's branches, which it derives from the trace) and prices each "
        "misprediction at the host file's `mispredict_cycles` (a box test's in the loop that "
        "runs it, `one_ray_` / `few_ray_` / `stream_mispredict_cycles`), fitted on a scene of "
        "random triangles (the branch microbenchmark), never on these scenes: its column is "
        "its prediction for the same batches (what its mispredictions from primed to "
        "displaced cost, over the cached cycles), held out.\n\n"
        + predictor_text(df),
        "## Scene data from DRAM\n\nThe same batches right after themselves and a read of "
        "other data (three times the largest cache the CPU reports, at least 256 MiB: every "
        "scene line in DRAM, the predictor primed), over right "
        "after themselves: what reading the scene from DRAM costs a traversal, measured, less "
        "what evicting costs the synthetic scene's batches, whose scene is a few lines (the "
        "code, TLB and page tables the read evicts too, which a frame keeps), beside the "
        "model's timing of the same batches' traces from empty caches over right after "
        "themselves: how the model prices a scene read from DRAM (its measured latency, less "
        "what the tracer's prefetch of a node's children hides, and in the one-ray and "
        "few-ray loops the share of it the core leaves exposed, `node_read_exposed_share`, "
        "fitted on the branch microbenchmark's batches from DRAM, never on these scenes), "
        "held out.\n\n" + dram_text(df),
        "## The traversal by loop\n\nThe native tracer runs a stream of one ray in its "
        "one-ray loop and, on a back end of 8 lanes or more, one of two to four rays in its "
        "few-ray loop, each down to the subtree's leaves (`kernels/trace.h`); the rest in the "
        "stream loop. Measured: the stage clock's ticks in the short loops (their leaves left "
        "out), split as the stages are; the stream loop is the rest of the traversal. "
        "Predicted: the model's cycles of the box tests each loop runs (the stage's "
        "end-of-pass tail is in no loop), and the shares of them its branch predictor's "
        "mispredictions and its wait for scene data take (the rest is the ops' own costs)."
        "\n\n" + loops_text(df) + "\n\nThe same split on the branch predictor's batches "
        "(the tables above), each state's fastest cycles split by the shares of 5 clocked "
        "repetitions: what the predictor and a scene read from DRAM cost each loop, measured, "
        "beside the model's parts of the same loop.\n\n" + predictor_loops_text(df),
        "## The intersection stage by loop\n\nThe leaf tests by the loop whose leaf code runs "
        "them: the one-ray loop's (one lane), the few-ray loop's (a leaf that one to four of its "
        "rays reach, in the wide back end's code), and the stream loop's. Measured: the stage "
        "clock's ticks in the leaves each short loop reaches, split as the stages are; the "
        "stream loop's are the rest of the intersection. Predicted: the model's cycles of the "
        "intersection ops below a box test of each loop.\n\n" + leaf_loops_text(df)
        + "\n\nThe same split on the branch predictor's batches (the tables above; camera "
        "rays and bounces summed), each a microbenchmark of the scene's own traversals: each "
        "loop's box tests and leaf tests right after themselves (primed: caches and predictor "
        "warm), against the model's timing of the same ops right after themselves (warm, its "
        "predictor off); what the other batches' lines cost each, aged in the caches "
        "(cached over primed, measured; the model's same ops after themselves and then the "
        "other batches, over warm); and what reading the scene from DRAM adds to each "
        "(evicted - primed, measured, less the same of the synthetic scene's batches, as "
        "above) against the model's cold - warm. The per-op costs are fitted on the "
        "synthetic scenes' microbenchmarks, never on these batches: held out. Where a loop's "
        "leaves are priced right here and not in the frames above, the frame's state (its "
        "caches, its predictor, the work between its traversals) costs them what the batches "
        "do not.\n\n" + batch_loops_text(df),
        "## The shading stage by op\n\nMeasured: the stage clock's ticks of each shading "
        "op kind's filter (the camera's loop; the emission filter with the hits' surfaces, as "
        "the model prices it; the material filters as the sort by material the tracer runs "
        "for them), each its fewest over the clocked renders, split as the stages are, and "
        "the tracer's set-up of the rays a generation made for the next one's traversal "
        "(`load_rays`), which the model prices in the ops that made them. Predicted: the "
        "model's cycles of each kind's ops. The stage's rest (a pass's tail, the sums into "
        "the image) is in no row.\n\n" + shading_ops_text(df),
    ])
    with open(page, "w") as f:
        f.write(text + "\n")
    return text


def html_section(df, directory, plot_name="silicon-check.png"):
    """The report's section (`sfx report DB --silicon ROWS`): the summary, the scatter plot
    (drawn into the report directory) and the per-workload table."""
    e = html.escape
    scatter_plot(df, os.path.join(directory, plot_name))
    items = "".join(f"<li>{e(line.strip()[2:])}</li>"
                    for line in all_summaries_text(df).splitlines())
    head = ["back end", "scene", "res", "tile", "predicted Mcyc", "measured Mcyc", "error", "trav err",
            "isect err", "shade err", "noise", "converged (renders)"]
    rows = []
    for _, r in df.iterrows():
        rows.append("<tr>" + "".join(f"<td>{e(str(c))}</td>" for c in workload_cells(r)) +
                    "</tr>")
    return "\n".join([
        "<h2>The timing model on silicon</h2>",
        "<p>The host CPU described as a hardware configuration of the machine model "
        "(<code>sfx calibrate --describe-host</code>, per-op costs fitted only on "
        "microbenchmarks) predicting the native stream tracer's cycles per frame on held-out "
        "workloads (<code>sfx calibrate --check</code>; <code>scripts/silicon-check</code> "
        "writes the same as <code>docs/silicon-check-*.md</code>). Error = predicted / "
        "measured &minus; 1.</p>",
        f"<ul class=\"notes\">{items}</ul>",
        f'<figure><img src="{e(plot_name)}" alt="predicted against measured cycles">'
        "<figcaption>Predicted against measured Mcycles per frame and per stage, with the "
        "y = x line (and &plusmn;25 % dotted).</figcaption></figure>",
        '<table class="paper"><caption>Per workload</caption><tr>'
        + "".join(f"<th>{e(h)}</th>" for h in head) + "</tr>" + "".join(rows) + "</table>",
    ])

#!/usr/bin/python3
"""`sfx explore` against the exhaustive grid of the same space.

    /usr/bin/python3 bench/explore_vs_grid.py SFX EXPLORE.yaml WORKDIR [--seeds 1,2,3] [--jobs N]
    /usr/bin/python3 bench/explore_vs_grid.py --self-check

1. The grid: `SFX explore FILE --exhaustive --json --store WORKDIR/store.db` evaluates every
   configuration of the space at the screen fidelity.
2. Per seed: `SFX explore FILE --json --seed N --study WORKDIR/study-N.db` on the same store (its
   points are reused, so a search costs little host time; the study file is removed first, so
   every seed searches from scratch).
3. Hypervolume, all at the grid's screen values (each explored configuration's values are looked
   up in the grid's "screened" by "config", so both sets are measured with the same numbers):
   every objective turned into minimisation (maximised ones negated), normalised to [0, 1] by
   the min and max of the grid's feasible configurations, reference point 1.1 in each
   dimension; Optuna's WFG (`optuna._hypervolume.WFG`) computes it. The grid's value is the
   hypervolume of its feasible configurations (= of its feasible Pareto front); a seed's is that
   of the feasible configurations it screened.
4. Per seed: evaluations, their share of the grid's configurations, the hypervolume share; then
   the medians over the seeds and the target: at least 95 % of the grid's hypervolume with at
   most 30 % of its evaluations.

Exit status: 0 target met, 1 target missed, 2 a run failed or its output was not understood.
`--self-check` checks the hypervolume logic on synthetic fronts (no sfx needed).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from typing import Dict, List, Sequence, Tuple

import numpy as np

HV_TARGET = 0.95     # share of the grid's hypervolume
EVAL_TARGET = 0.30   # share of the grid's evaluations
REFERENCE = 1.1      # reference point, each normalised dimension


class BenchError(Exception):
    pass


# ---- hypervolume ---------------------------------------------------------------------------

def wfg_hypervolume(points: np.ndarray, reference: np.ndarray) -> float:
    """Optuna's WFG: the volume dominated by `points` (minimisation) up to `reference`."""
    from optuna._hypervolume import WFG
    if len(points) == 0:
        return 0.0
    return float(WFG().compute(np.asarray(points, dtype=float),
                               np.asarray(reference, dtype=float)))


def nondominated(points: np.ndarray) -> np.ndarray:
    """The points no other point dominates (minimisation); duplicates kept once."""
    points = np.unique(np.asarray(points, dtype=float), axis=0)
    keep = []
    for i, p in enumerate(points):
        dominated = np.any(np.all(points <= p, axis=1) & np.any(points < p, axis=1))
        if not dominated:
            keep.append(i)
    return points[keep]


def to_minimisation(values: Sequence[Sequence[float]], directions: Sequence[str]) -> np.ndarray:
    signs = np.array([-1.0 if d == "maximize" else 1.0 for d in directions])
    return np.asarray(values, dtype=float).reshape(-1, len(directions)) * signs


class Normaliser:
    """Maps minimisation values to [0, 1] by the min and max of a reference set (the grid's
    feasible configurations); a dimension with one value maps to 0."""

    def __init__(self, reference_set: np.ndarray):
        self.lo = reference_set.min(axis=0)
        span = reference_set.max(axis=0) - self.lo
        self.span = np.where(span > 0, span, 1.0)

    def __call__(self, points: np.ndarray) -> np.ndarray:
        if len(points) == 0:
            return points.reshape(0, len(self.lo))
        return (points - self.lo) / self.span


def hypervolume_share(grid_feasible: np.ndarray, subset: np.ndarray) -> Tuple[float, float]:
    """(hypervolume of the subset, of the grid), both normalised by the grid's feasible set,
    minimisation values; the subset's points must be among the grid's."""
    norm = Normaliser(grid_feasible)
    reference = np.full(grid_feasible.shape[1], REFERENCE)
    grid_hv = wfg_hypervolume(nondominated(norm(grid_feasible)), reference)
    sub_hv = wfg_hypervolume(nondominated(norm(subset)), reference) if len(subset) else 0.0
    return sub_hv, grid_hv


# ---- running sfx ---------------------------------------------------------------------------

def run_explore(sfx: str, explore_file: str, store: str, extra: List[str],
                timeout: float) -> dict:
    cmd = [sfx, "explore", explore_file, "--store", store, "--json"] + extra
    print("$ " + " ".join(cmd), flush=True)
    t0 = time.monotonic()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise BenchError(f"timed out after {timeout:.0f} s: {' '.join(cmd)}") from None
    except OSError as e:
        raise BenchError(f"cannot run {sfx}: {e}") from None
    wall = time.monotonic() - t0
    if done.returncode != 0:
        raise BenchError(f"exit status {done.returncode}: {' '.join(cmd)}\n{done.stderr.strip()}")
    out = done.stdout
    start = out.find("{")
    if start < 0:
        raise BenchError(f"no JSON document on stdout of {' '.join(cmd)}:\n{out[:2000]}")
    try:
        doc, _ = json.JSONDecoder().raw_decode(out[start:])
    except ValueError as e:
        raise BenchError(f"unreadable JSON from {' '.join(cmd)} ({e}):\n{out[:2000]}") from None
    for key in ["objectives", "screened"]:
        if key not in doc:
            raise BenchError(f"the JSON of {' '.join(cmd)} has no '{key}'")
    doc.setdefault("seconds", wall)
    return doc


def _directions(doc: dict) -> List[str]:
    dirs = [o.get("direction", "") for o in doc["objectives"]]
    if not dirs or any(d not in ("maximize", "minimize") for d in dirs):
        raise BenchError(f"objectives not understood: {doc['objectives']}")
    return dirs


def grid_table(grid: dict) -> Dict[int, dict]:
    """config -> its screened entry in the grid run."""
    table = {}
    n = len(grid["objectives"])
    for entry in grid["screened"]:
        values = entry.get("values")
        if values is None or len(values) != n:
            raise BenchError(f"grid config {entry.get('config')}: values {values} do not match "
                             f"the {n} objectives")
        table[int(entry["config"])] = entry
    return table


def _finite(values) -> bool:
    return all(v is not None and np.isfinite(float(v)) for v in values)


def seed_result(grid: dict, table: Dict[int, dict], doc: dict, seed: int,
                directions: List[str], grid_feasible: np.ndarray) -> dict:
    if [o.get("metric") for o in doc["objectives"]] != \
            [o.get("metric") for o in grid["objectives"]]:
        raise BenchError(f"seed {seed}: objectives {doc['objectives']} differ from the grid's")
    configs, mismatched = [], []
    for entry in doc["screened"]:
        cfg = int(entry["config"])
        if cfg not in table:
            raise BenchError(f"seed {seed}: config {cfg} is not in the grid (a different space?)")
        if entry.get("knobs") and table[cfg].get("knobs") and \
                entry["knobs"] != table[cfg]["knobs"]:
            mismatched.append(cfg)
        configs.append(cfg)
    if mismatched:
        raise BenchError(f"seed {seed}: configs {mismatched[:5]} have other knobs than the "
                         f"grid's configs of the same number: the numbering differs")
    configs = sorted(set(configs))
    feasible = [c for c in configs
                if table[c].get("feasible", True) and _finite(table[c]["values"])]
    points = to_minimisation([table[c]["values"] for c in feasible], directions) \
        if feasible else np.zeros((0, len(directions)))
    sub_hv, grid_hv = hypervolume_share(grid_feasible, points)
    evaluations = int(doc.get("evaluations", len(configs)))
    grid_evals = int(grid.get("configurations") or grid.get("evaluations") or len(table))
    return {"seed": seed, "evaluations": evaluations, "screened": len(configs),
            "feasible": len(feasible), "eval_share": evaluations / grid_evals,
            "hv": sub_hv, "hv_share": sub_hv / grid_hv if grid_hv > 0 else float("nan"),
            "seconds": float(doc.get("seconds", float("nan")))}


def bench(sfx: str, explore_file: str, workdir: str, seeds: List[int], jobs: int,
          timeout: float, samplers: List[str] = ("tpe",)) -> int:
    os.makedirs(workdir, exist_ok=True)
    store = os.path.join(workdir, "store.db")
    jobs_arg = ["--jobs", str(jobs)] if jobs else []
    grid = run_explore(sfx, explore_file, store, ["--exhaustive"] + jobs_arg, timeout)
    directions = _directions(grid)
    table = grid_table(grid)
    feasible = [c for c, e in table.items() if e.get("feasible", True) and _finite(e["values"])]
    if not feasible:
        raise BenchError("no configuration of the grid is feasible: nothing to compare")
    grid_feasible = to_minimisation([table[c]["values"] for c in feasible], directions)
    front = nondominated(grid_feasible)
    grid_evals = int(grid.get("configurations") or grid.get("evaluations") or len(table))
    print(f"grid: {len(table)} configurations ({grid_evals} in the space), {len(feasible)} "
          f"feasible, {len(front)} on the feasible Pareto front; "
          f"{float(grid.get('seconds', float('nan'))):.1f} s", flush=True)

    # The first sampler is judged against the target; the others (random: the baseline a
    # search must beat) are printed beside it.
    by_sampler = {}
    for sampler in samplers:
        results = []
        for seed in seeds:
            study = os.path.join(workdir, f"study-{sampler}-{seed}.db")
            if os.path.exists(study):
                os.remove(study)
            doc = run_explore(sfx, explore_file, store,
                              ["--seed", str(seed), "--sampler", sampler, "--study", study] + jobs_arg,
                              timeout)
            results.append(seed_result(grid, table, doc, seed, directions, grid_feasible))
            r = results[-1]
            print(f"{sampler} seed {seed}: {r['evaluations']} evaluations ({100 * r['eval_share']:.1f} % of "
                  f"the grid), {r['screened']} configurations screened, {r['feasible']} feasible; "
                  f"hypervolume {100 * r['hv_share']:.1f} % of the grid's; {r['seconds']:.1f} s",
                  flush=True)
        hv = statistics.median(r["hv_share"] for r in results)
        ev = statistics.median(r["eval_share"] for r in results)
        by_sampler[sampler] = {"seeds": results, "median_hv_share": hv, "median_eval_share": ev}
        print(f"{sampler}: median over {len(results)} seeds: hypervolume {100 * hv:.1f} % of the grid's "
              f"with {100 * ev:.1f} % of its evaluations")
    judged = by_sampler[samplers[0]]
    met = judged["median_hv_share"] >= HV_TARGET and judged["median_eval_share"] <= EVAL_TARGET
    print(f"target for {samplers[0]} (>= {100 * HV_TARGET:.0f} % of the hypervolume with <= "
          f"{100 * EVAL_TARGET:.0f} % of the evaluations): {'met' if met else 'missed'}")
    with open(os.path.join(workdir, "explore_vs_grid.json"), "w", encoding="utf-8") as f:
        json.dump({"grid": {"configurations": grid_evals, "feasible": len(feasible),
                            "front": len(front)},
                   "samplers": by_sampler, "target_met": met}, f, indent=1)
    return 0 if met else 1


# ---- self-check ----------------------------------------------------------------------------

def self_check() -> None:
    """The hypervolume logic on synthetic data, with answers computed by hand."""
    ref2 = np.array([REFERENCE, REFERENCE])
    # One point at the origin: 1.1 x 1.1.
    assert abs(wfg_hypervolume(np.array([[0.0, 0.0]]), ref2) - 1.21) < 1e-12
    # Two points of a 2-D front: union of two rectangles.
    two = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert abs(wfg_hypervolume(two, ref2) - (1.1 * 0.1 + 0.1 * 1.1 - 0.01)) < 1e-12
    assert abs(wfg_hypervolume(np.zeros((0, 2)), ref2)) == 0.0
    # Dominated points and duplicates do not count.
    assert nondominated(np.array([[0, 1], [1, 0], [1, 1], [0, 1]])).tolist() == \
        [[0.0, 1.0], [1.0, 0.0]]

    # A grid of (fps max, area min, energy min) configurations; directions and normalisation.
    rng = np.random.default_rng(7)
    fps = rng.uniform(1, 100, 60)
    area = fps * rng.uniform(0.5, 1.5, 60) + rng.uniform(0, 10, 60)
    energy = rng.uniform(1, 5, 60)
    values = np.column_stack([fps, area, energy])
    directions = ["maximize", "minimize", "minimize"]
    grid = to_minimisation(values, directions)
    assert (grid[:, 0] == -fps).all()
    front = nondominated(grid)
    sub_hv, grid_hv = hypervolume_share(grid, grid)
    assert grid_hv > 0 and abs(sub_hv - grid_hv) < 1e-12
    # The front alone has the whole hypervolume; the front less one point less.
    assert abs(hypervolume_share(grid, front)[0] - grid_hv) < 1e-12
    assert hypervolume_share(grid, front[1:])[0] < grid_hv
    # Off-front points add nothing; an empty set has none.
    assert abs(hypervolume_share(grid, np.vstack([front, grid[:5]]))[0] - grid_hv) < 1e-12
    assert hypervolume_share(grid, np.zeros((0, 3)))[0] == 0.0
    # Normalised to [0, 1] by the grid: the ideal point's box is at most 1.1^3.
    assert grid_hv <= REFERENCE ** 3 + 1e-12

    # seed_result: the lookup by config, the grid's feasibility, the shares.
    screened = [{"config": i, "knobs": {"hw.simd.width": str(i)}, "values": list(values[i]),
                 "feasible": bool(i % 4)} for i in range(60)]
    grid_doc = {"objectives": [{"metric": m, "direction": d} for m, d in
                               zip(["fps", "area_mm2", "energy_mj"], directions)],
                "configurations": 60, "evaluations": 60, "screened": screened}
    table = grid_table(grid_doc)
    feasible_grid = to_minimisation([values[i] for i in range(60) if i % 4], directions)
    everything = {"objectives": grid_doc["objectives"], "evaluations": 60,
                  # the explore's own values may differ (other runs); the grid's are used
                  "screened": [dict(e, values=[0, 0, 0]) for e in screened]}
    r = seed_result(grid_doc, table, everything, 1, directions, feasible_grid)
    assert abs(r["hv_share"] - 1.0) < 1e-12 and r["feasible"] == 45 and r["eval_share"] == 1.0
    few = {"objectives": grid_doc["objectives"], "evaluations": 6, "screened": screened[:6]}
    r = seed_result(grid_doc, table, few, 2, directions, feasible_grid)
    assert 0.0 <= r["hv_share"] < 1.0 and r["eval_share"] == 0.1 and r["feasible"] == 4
    try:
        seed_result(grid_doc, table, {"objectives": grid_doc["objectives"], "screened":
                                      [{"config": 3, "knobs": {"hw.simd.width": "99"},
                                        "values": [1, 1, 1]}]}, 3, directions, feasible_grid)
        raise AssertionError("a knob mismatch must fail")
    except BenchError:
        pass
    print("self-check: the hypervolume logic is right on synthetic data")


def main(argv: List[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sfx", nargs="?", help="the sfx binary (build/sfx)")
    ap.add_argument("explore_file", nargs="?", help="an explore file (bench/explore-grid.yaml)")
    ap.add_argument("workdir", nargs="?", help="where the store, studies and results go")
    ap.add_argument("--seeds", default="1,2,3", help="comma-separated search seeds")
    ap.add_argument("--samplers", default="tpe,random",
                    help="comma-separated samplers; the first is judged, the rest are baselines")
    ap.add_argument("--jobs", type=int, default=0, help="passed to sfx explore (0: its default)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per sfx run")
    ap.add_argument("--self-check", action="store_true",
                    help="check the hypervolume logic on synthetic data and exit")
    args = ap.parse_args(argv)
    if args.self_check:
        self_check()
        return 0
    if not (args.sfx and args.explore_file and args.workdir):
        ap.error("SFX, EXPLORE_FILE and WORKDIR are required (or --self-check)")
    try:
        seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    except ValueError:
        ap.error(f"--seeds {args.seeds}: not a comma-separated list of integers")
    if not seeds:
        ap.error("--seeds: at least one seed")
    try:
        samplers = [x.strip() for x in args.samplers.split(",") if x.strip()]
        if not samplers:
            ap.error("--samplers: at least one sampler")
        return bench(args.sfx, args.explore_file, args.workdir, seeds, args.jobs, args.timeout,
                     samplers)
    except BenchError as e:
        print(f"explore_vs_grid: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""The report's "What to build" section, from the results of `sfx explore` in the store.

`sfx explore` writes two tables beside `points`: `explores` (one row per explore file run:
name, file, fingerprint and its spec as JSON: objectives, constraints, workloads, knobs,
fidelities) and `explore_configs` (one row per configuration and stage: 'screen' for every
configuration the search evaluated, 'confirm' for the screened Pareto front re-run at the
confirm fidelity; its knobs as JSON, fps with its relative interval, area, energy, power,
fps/mm², feasible, front). A store without them (or with no explore) gives no section.

Per explore (all of them, newest first: the highest rowid of `explores`): the plot of fps
against area with energy as colour, the best configuration under each constraint of the file
and overall, and how the front's ranking by the first objective moved from the screen to the
confirm fidelity.
"""

from __future__ import annotations

import html
import json
import math
import os
import re
import sqlite3
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import pandas as pd

from .plots import DPI, Plot, plt
from .store import StoreError, _connect_read_only

METRICS = ["fps", "area_mm2", "energy_mj", "power_w", "fps_per_mm2"]
# Display name and unit of each metric an explore file may name.
LABELS = {"fps": ("fps", "frames/s"), "area_mm2": ("area", "mm²"),
          "energy_mj": ("energy per frame", "mJ"), "power_w": ("power", "W"),
          "fps_per_mm2": ("fps per mm²", "frames/s/mm²")}
SCREEN, CONFIRM = "screen", "confirm"


@dataclass
class Explore:
    name: str
    file: str
    fingerprint: str
    spec: dict
    screen: pd.DataFrame    # one row per configuration: config, knobs (dict), metrics, ...
    confirm: pd.DataFrame   # the same columns; empty when no confirmation ran
    warnings: List[str] = field(default_factory=list)

    @property
    def objectives(self) -> List[dict]:
        return [o for o in self.spec.get("objectives", []) if o.get("metric") in METRICS]

    @property
    def constraints(self) -> List[dict]:
        return [c for c in self.spec.get("constraints", []) if c.get("metric") in METRICS]

    @property
    def nodes_text(self) -> str:
        """The technology nodes the space was built at ("7nm"), "" for an explore stored
        before sfx recorded them."""
        return ", ".join(str(n) for n in self.spec.get("nodes", []))

    def first_objective(self) -> Tuple[str, bool]:
        """(metric, True when larger is better); fps maximised when the spec names none."""
        objs = self.objectives
        if not objs:
            return "fps", True
        return objs[0]["metric"], objs[0].get("direction", "maximize") != "minimize"


def _tables(con: sqlite3.Connection) -> set:
    return {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type='table'")}


def _knobs(text) -> Dict[str, str]:
    try:
        k = json.loads(text) if text else {}
    except (TypeError, ValueError):
        return {}
    return {str(p): str(v) for p, v in k.items()} if isinstance(k, dict) else {}


def load_explores(path: str) -> List[Explore]:
    """Every explore of the store, newest first; [] when the store has none (or no tables)."""
    con = _connect_read_only(path)
    try:
        tables = _tables(con)
        if "explores" not in tables:
            return []
        try:
            heads = con.execute("SELECT name, file, fingerprint, spec FROM explores "
                                "ORDER BY rowid DESC").fetchall()
            configs = (pd.read_sql_query("SELECT * FROM explore_configs", con)
                       if "explore_configs" in tables else None)
        except (sqlite3.DatabaseError, pd.errors.DatabaseError) as e:
            raise StoreError(f"{path}: unreadable explore tables ({e})") from None
    finally:
        con.close()
    out = []
    for name, file, fingerprint, spec_text in heads:
        warnings = []
        try:
            spec = json.loads(spec_text) if spec_text else {}
            if not isinstance(spec, dict):
                raise ValueError("not an object")
        except ValueError as e:
            spec = {}
            warnings.append(f"its spec is not readable JSON ({e}): objectives and constraints "
                            f"unknown")
        rows = configs[configs["explore"] == name].copy() if configs is not None \
            else pd.DataFrame(columns=["explore", "config", "stage", "knobs"] + METRICS)
        for m in METRICS + ["fps_error", "feasible", "front", "config"]:
            if m not in rows.columns:
                rows[m] = math.nan
            rows[m] = pd.to_numeric(rows[m], errors="coerce")
        rows["knobs"] = [_knobs(k) for k in rows.get("knobs", pd.Series([], dtype=object))]
        rows = rows.sort_values("config", kind="mergesort")
        screen = rows[rows["stage"] == SCREEN].reset_index(drop=True)
        confirm = rows[rows["stage"] == CONFIRM].reset_index(drop=True)
        out.append(Explore(str(name), str(file or ""), str(fingerprint or ""), spec, screen,
                           confirm, warnings))
    return out


# ---- the answers -------------------------------------------------------------------------

def meets(row: pd.Series, constraint: dict) -> bool:
    """Whether a row meets one constraint ({metric, min and/or max}); a missing value fails."""
    v = row.get(constraint["metric"], math.nan)
    if v is None or not math.isfinite(float(v)):
        return False
    if "min" in constraint and float(v) < float(constraint["min"]):
        return False
    if "max" in constraint and float(v) > float(constraint["max"]):
        return False
    return True


def _best(rows: pd.DataFrame, metric: str, larger: bool) -> Optional[pd.Series]:
    """The row with the best finite value of `metric` (ties: the lowest config)."""
    ok = rows[rows[metric].notna()]
    if ok.empty:
        return None
    ok = ok.sort_values([metric, "config"], ascending=[not larger, True], kind="mergesort")
    return ok.iloc[0]


@dataclass
class Choice:
    label: str                 # 'area_mm2 ≤ 40', 'every constraint'
    row: Optional[pd.Series]   # None: no configuration meets it
    stage: str                 # where the row's values come from: 'confirm' or 'screen'


def best_choices(ex: Explore) -> List[Choice]:
    """Per constraint of the file, the configuration meeting it with the best value of the
    first objective, from the confirmed rows when one of them meets it, else the screened ones;
    then the same over the rows sfx marked feasible (every constraint)."""
    metric, larger = ex.first_objective()
    choices = []

    def pick(label, keep):
        for stage, rows in [(CONFIRM, ex.confirm), (SCREEN, ex.screen)]:
            if rows.empty:
                continue
            mask = [keep(r) for _, r in rows.iterrows()]
            row = _best(rows[mask], metric, larger)
            if row is not None:
                return Choice(label, row, stage)
        return Choice(label, None, "")

    for c in ex.constraints:
        choices.append(pick(constraint_text(c), lambda r, c=c: meets(r, c)))
    choices.append(pick("every constraint (feasible)" if ex.constraints else "no constraints",
                        lambda r: r.get("feasible", 0) == 1 or
                        (not ex.constraints and pd.isna(r.get("feasible")))))
    return choices


def ranking_changes(ex: Explore) -> pd.DataFrame:
    """The confirmed front's configurations with their rank (1 = best) by the first objective
    among themselves at the screen and at the confirm fidelity, both values and the relative
    change; ordered by the confirm rank. Empty without a confirmation."""
    metric, larger = ex.first_objective()
    columns = ["config", "knobs", "screen_rank", "confirm_rank", "screen", "confirm",
               "change", "confirm_front"]
    if ex.confirm.empty or ex.screen.empty:
        return pd.DataFrame(columns=columns)
    screen = ex.screen.set_index("config")
    rows = []
    for _, r in ex.confirm.iterrows():
        cfg = int(r["config"])
        s = float(screen.loc[cfg, metric]) if cfg in screen.index else math.nan
        c = float(r[metric])
        rows.append({"config": cfg, "knobs": r["knobs"], "screen": s, "confirm": c,
                     "change": (c - s) / abs(s) if math.isfinite(s) and s != 0 else math.nan,
                     "confirm_front": r.get("front") == 1})
    df = pd.DataFrame(rows, columns=[c for c in columns if not c.endswith("_rank")])
    for stage in ["screen", "confirm"]:
        df[stage + "_rank"] = df[stage].rank(ascending=not larger, method="min")
    return df.sort_values(["confirm_rank", "screen_rank", "config"],
                          kind="mergesort")[columns].reset_index(drop=True)


# ---- the plot ----------------------------------------------------------------------------

def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_") or "explore"


def plot_explore(ex: Explore, directory: str, file_stem: str) -> Plot:
    """fps against area, energy per frame as colour: every screened configuration pale, the
    confirmed front (the screened front without a confirmation) large and joined by a step
    line; the constraints on fps and area as dashed lines."""
    at = f" at {ex.nodes_text}" if ex.nodes_text else ""
    plot = Plot(file_stem, f"{ex.name}{at}: frame rate against chip area, energy as colour")
    screen = ex.screen.dropna(subset=["fps", "area_mm2"])
    confirmed = not ex.confirm.empty
    front = ex.confirm if confirmed else ex.screen[ex.screen["front"] == 1]
    front = front.dropna(subset=["fps", "area_mm2"]).sort_values("area_mm2")
    if screen.empty and front.empty:
        plot.skipped = "no configuration has both fps and area values"
        return plot
    fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    feasible = screen["feasible"] == 1
    ax.scatter(screen.loc[feasible, "area_mm2"], screen.loc[feasible, "fps"], s=12,
               color="0.65", alpha=0.7, label="screened (feasible)", zorder=1)
    if (~feasible).any():
        ax.scatter(screen.loc[~feasible, "area_mm2"], screen.loc[~feasible, "fps"], s=12,
                   marker="x", color="0.8", label="screened (infeasible)", zorder=1)
    if not front.empty:
        ax.step(front["area_mm2"], front["fps"], where="post", color="0.25", linewidth=1.1,
                zorder=2)
        err = front["fps"] * front["fps_error"].where(front["fps_error"] > 0)
        if err.notna().any():
            ax.errorbar(front["area_mm2"], front["fps"], yerr=err, fmt="none", ecolor="0.3",
                        capsize=3, linewidth=0.8, zorder=2)
        energy = front["energy_mj"]
        label = "confirmed front" if confirmed else "screened front"
        if energy.notna().all():
            sc = ax.scatter(front["area_mm2"], front["fps"], c=energy, cmap="viridis", s=90,
                            edgecolors="black", linewidths=0.6, zorder=3, label=label)
            fig.colorbar(sc, ax=ax, label="energy per frame [mJ]")
        else:
            ax.scatter(front["area_mm2"], front["fps"], color="C3", s=90, edgecolors="black",
                       linewidths=0.6, zorder=3, label=label)
    for c in ex.constraints:
        for bound in ["min", "max"]:
            if bound not in c:
                continue
            if c["metric"] == "area_mm2":
                ax.axvline(float(c[bound]), color="C3", linestyle="--", linewidth=0.9)
            elif c["metric"] == "fps":
                ax.axhline(float(c[bound]), color="C3", linestyle="--", linewidth=0.9)
    ax.set_xlabel("chip area [mm²]")
    ax.set_ylabel("predicted fps [frames/s] (weighted over the workloads)")
    ax.set_title(f"What to build: {ex.name}{at}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", loc="best")
    plot.file = f"{file_stem}.png"
    fig.savefig(os.path.join(directory, plot.file), dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    spec = ex.spec
    plot.caption = (f"{len(ex.screen)} configurations screened at "
                    f"{spec.get('screen', 'the screen fidelity')} (grey; × infeasible), "
                    + (f"{len(ex.confirm)} on the screened front confirmed at "
                       f"{spec.get('confirm', 'the confirm fidelity')}"
                       if confirmed else "no confirmation: the screened front")
                    + " (large, colour: energy per frame; bars: the fps interval). Dashed red: "
                    "the constraints on fps and area.")
    return plot


# ---- HTML --------------------------------------------------------------------------------

def _num(v, digits: int = 4) -> str:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return "—"
    return f"{f:.{digits}g}" if math.isfinite(f) else "—"


def constraint_text(c: dict) -> str:
    m = c["metric"]
    if "min" in c and "max" in c:
        return f"{_num(c['min'])} ≤ {m} ≤ {_num(c['max'])}"
    if "max" in c:
        return f"{m} ≤ {_num(c['max'])}"
    if "min" in c:
        return f"{m} ≥ {_num(c['min'])}"
    return m


def _short_names(paths: List[str]) -> Dict[str, str]:
    """hw.simd.width -> simd.width: the knob's path without the leading hw."""
    return {p: p[3:] if p.startswith("hw.") else p for p in paths}


def knobs_text(knobs: Dict[str, str]) -> str:
    names = _short_names(list(knobs))
    return ", ".join(f"{names[p]}={v}" for p, v in knobs.items()) or "—"


def _fps_text(row: pd.Series) -> str:
    fps, rel = row.get("fps"), row.get("fps_error")
    text = _num(fps)
    if text != "—" and rel is not None and math.isfinite(float(rel)) and float(rel) > 0:
        text += f" ± {_num(float(fps) * float(rel), 2)}"
    return text


def _choices_html(ex: Explore) -> str:
    e = html.escape
    metric, larger = ex.first_objective()
    out = ['<table class="paper explore-best">',
           f"<caption><b>Best configuration under each constraint of the file</b>: the "
           f"configuration meeting it with the {'highest' if larger else 'lowest'} {e(metric)}, "
           f"from the confirmed configurations when one meets it, else from the screened "
           f"ones; the last row meets every constraint. fps ± the half-width of its interval."
           f"</caption>",
           "<tr><th>constraint</th><th>config</th><th>knobs</th><th>stage</th>"
           "<th>fps [frames/s]</th><th>area [mm²]</th><th>energy [mJ]</th></tr>"]
    for ch in best_choices(ex):
        if ch.row is None:
            out.append(f'<tr><th>{e(ch.label)}</th><td class="missing" colspan="6">no '
                       f"configuration meets it</td></tr>")
            continue
        r = ch.row
        out.append(f"<tr><th>{e(ch.label)}</th><td>{int(r['config'])}</td>"
                   f'<td style="text-align:left">{e(knobs_text(r["knobs"]))}</td>'
                   f"<td>{e(ch.stage)}</td><td>{e(_fps_text(r))}</td>"
                   f"<td>{e(_num(r['area_mm2']))}</td><td>{e(_num(r['energy_mj']))}</td></tr>")
    out.append("</table>")
    return "\n".join(out)


def _ranking_html(ex: Explore) -> str:
    e = html.escape
    metric, larger = ex.first_objective()
    df = ranking_changes(ex)
    if df.empty:
        return ("<p><b>How the ranking changed from screening to confirmation</b>: no "
                "configuration was confirmed (an exhaustive run, or one without a confirm "
                "fidelity).</p>")
    name, unit = LABELS.get(metric, (metric, ""))
    unit = f" [{unit}]" if unit else ""
    moved = int((df["screen_rank"] != df["confirm_rank"]).sum())
    top_same = bool(df.iloc[0]["screen_rank"] == 1)
    out = ['<table class="paper explore-ranking">',
           f"<caption><b>How the ranking changed from screening to confirmation</b>: the "
           f"{len(df)} configurations of the screened front, ranked by {e(metric)} "
           f"({'higher' if larger else 'lower'} is better; 1 = best) among themselves at "
           f"{e(str(ex.spec.get('screen', 'screen')))} and at "
           f"{e(str(ex.spec.get('confirm', 'confirm')))}. {moved} of {len(df)} changed rank; "
           f"the best at confirmation {'was' if top_same else 'was not'} the best at "
           f"screening.</caption>",
           f"<tr><th>confirm rank</th><th>screen rank</th><th>config</th><th>knobs</th>"
           f"<th>{e(name)} at screen{e(unit)}</th><th>{e(name)} at confirm{e(unit)}</th>"
           f"<th>change</th><th>on the confirmed front</th></tr>"]
    for _, r in df.iterrows():
        change = "—" if not math.isfinite(r["change"]) else f"{100 * r['change']:+.1f} %"
        out.append(f"<tr><td>{int(r['confirm_rank'])}</td>"
                   f"<td>{'—' if pd.isna(r['screen_rank']) else int(r['screen_rank'])}</td>"
                   f"<td>{int(r['config'])}</td>"
                   f'<td style="text-align:left">{e(knobs_text(r["knobs"]))}</td>'
                   f"<td>{e(_num(r['screen']))}</td><td>{e(_num(r['confirm']))}</td>"
                   f"<td>{e(change)}</td><td>{'yes' if r['confirm_front'] else 'no'}</td></tr>")
    out.append("</table>")
    return "\n".join(out)


def html_section(ex: Explore, plot: Plot) -> str:
    e = html.escape
    spec = ex.spec
    objs = ", ".join(f"{o['metric']} ({o.get('direction', 'maximize')})"
                     for o in ex.objectives) or "—"
    cons = ", ".join(constraint_text(c) for c in ex.constraints) or "none"
    loads = ", ".join(f"{w.get('scene')} ×{_num(w.get('weight', 1))}"
                      for w in spec.get("workloads", [])) or "—"
    out = [f'<section class="explore" id="explore-{e(_slug(ex.name))}">',
           f"<h2>What to build: {e(ex.name)}</h2>",
           '<table class="summary">',
           f"<tr><th>explore file</th><td>{e(ex.file or '—')}</td></tr>",
           f"<tr><th>technology node</th><td>{e(ex.nodes_text or '—')}</td></tr>",
           f"<tr><th>objectives</th><td>{e(objs)}</td></tr>",
           f"<tr><th>constraints</th><td>{e(cons)}</td></tr>",
           f"<tr><th>workloads</th><td>{e(loads)}</td></tr>",
           f"<tr><th>configurations</th><td>{e(str(spec.get('configurations', '—')))} in the "
           f"space, {len(ex.screen)} screened, {len(ex.confirm)} confirmed</td></tr>",
           "</table>"]
    for w in ex.warnings:
        out.append(f'<p class="warning">Note: {e(w)}</p>')
    if plot.file:
        out.append(f'<figure id="{e(plot.name)}"><img src="{e(plot.file)}" '
                   f'alt="{e(plot.title)}"><figcaption><b>{e(plot.title)}.</b> '
                   f"{e(plot.caption)}</figcaption></figure>")
    else:
        out.append(f"<p>Plot skipped: {e(plot.skipped)}.</p>")
    out.append(_choices_html(ex))
    out.append(_ranking_html(ex))
    out.append("</section>")
    return "\n".join(out)


def html_sections(db: str, directory: str) -> Tuple[List[str], List[Plot]]:
    """The "What to build" sections of every explore in the store (newest first) and their
    plots, the PNGs written into `directory`; ([], []) for a store without explores."""
    sections, plots = [], []
    used = set()
    for ex in load_explores(db):
        stem = "explore_" + _slug(ex.name)
        while stem in used:
            stem += "_"
        used.add(stem)
        plot = plot_explore(ex, directory, stem)
        plots.append(plot)
        sections.append(html_section(ex, plot))
    return sections, plots

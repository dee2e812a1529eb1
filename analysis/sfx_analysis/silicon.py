"""The silicon check: the host timing's predicted cycles against the native stream tracer's
measured cycles (the rows `sfx calibrate --check --json` prints). A table per workload, the
mean absolute and worst relative error of frame cycles, the same per stage, the tile-size
ranking per scene (predicted against measured), a predicted-against-measured scatter plot with
the y = x line, and the Markdown page `docs/silicon-check.md`."""

import html
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

STAGES = ("traversal", "intersection", "shading")
TARGETS = {"frame_mae": 0.15, "frame_worst": 0.25, "stage_worst": 0.25}


def load_rows(path):
    """The JSON list of `sfx calibrate --check --json` as a DataFrame with error columns."""
    with open(path) as f:
        rows = json.load(f)
    if not isinstance(rows, list) or not rows:
        raise ValueError(f"{path}: expected a non-empty JSON list of workload rows")
    df = pd.DataFrame(rows)
    df["res"] = df["width"].astype(str) + "x" + df["height"].astype(str)
    df["error.frame"] = df["predicted.frame_cycles"] / df["measured.frame_cycles"] - 1.0
    for s in STAGES:
        df[f"error.{s}"] = df[f"predicted.{s}_cycles"] / df[f"measured.{s}_cycles"] - 1.0
    # Spread of the measurement itself: (max - min) / median of the unclocked renders.
    df["noise"] = df["measured.frame_samples"].apply(
        lambda v: (max(v) - min(v)) / sorted(v)[len(v) // 2] if v else float("nan"))
    return df


def summary(df):
    """MAE and worst |error| of frame cycles, per stage, and whether the targets hold."""
    out = {"workloads": len(df),
           "frame_mae": df["error.frame"].abs().mean(),
           "frame_worst": df["error.frame"].abs().max()}
    for s in STAGES:
        out[f"{s}_mae"] = df[f"error.{s}"].abs().mean()
        out[f"{s}_worst"] = df[f"error.{s}"].abs().max()
    rank = ranking(df)
    out["ranking_right"] = int(rank["right"].sum())
    out["ranking_cells"] = len(rank)
    out["targets"] = {
        "frame MAE <= 15 %": bool(out["frame_mae"] <= TARGETS["frame_mae"]),
        "frame worst <= 25 %": bool(out["frame_worst"] <= TARGETS["frame_worst"]),
        "per stage worst <= 25 %": all(bool(out[f"{s}_worst"] <= TARGETS["stage_worst"])
                                       for s in STAGES),
        "tile ranking right in every scene": out["ranking_right"] == out["ranking_cells"],
    }
    return out


def ranking(df):
    """Per scene and resolution: tiles fastest first, predicted and measured."""
    rows = []
    for (scene, res), g in df.groupby(["scene", "res"], sort=False):
        pred = list(g.sort_values("predicted.frame_cycles")["tile"])
        meas = list(g.sort_values("measured.frame_cycles")["tile"])
        rows.append({"scene": scene, "res": res, "predicted": pred, "measured": meas,
                     "right": pred == meas})
    return pd.DataFrame(rows)


def pct(x):
    return f"{100 * x:+.1f} %"


def table_text(df):
    lines = ["| scene | res | tile | predicted Mcyc | measured Mcyc | error | trav err | "
             "isect err | shade err | noise |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in df.iterrows():
        lines.append(
            f"| {r['scene']} | {r['res']} | {r['tile']} | {r['predicted.frame_cycles'] / 1e6:.2f} | "
            f"{r['measured.frame_cycles'] / 1e6:.2f} | {pct(r['error.frame'])} | "
            f"{pct(r['error.traversal'])} | {pct(r['error.intersection'])} | "
            f"{pct(r['error.shading'])} | {100 * r['noise']:.0f} % |")
    return "\n".join(lines)


def stage_table_text(df):
    lines = ["| scene | stage | predicted Mcyc (sum) | measured Mcyc (sum) | error of sum | "
             "mean abs error | of which scene-data misses (predicted) |",
             "|---|---|---|---|---|---|---|"]
    for scene, g in df.groupby("scene", sort=False):
        for s in STAGES:
            p = g[f"predicted.{s}_cycles"].sum()
            m = g[f"measured.{s}_cycles"].sum()
            mem = g[f"predicted.{s}_memory_cycles"].sum()
            lines.append(f"| {scene} | {s} | {p / 1e6:.2f} | {m / 1e6:.2f} | {pct(p / m - 1)} | "
                         f"{100 * g[f'error.{s}'].abs().mean():.1f} % | {mem / max(p, 1):.0%} |")
    return "\n".join(lines)


def ranking_text(df):
    rank = ranking(df)
    lines = ["| scene | res | predicted (fastest first) | measured | right |", "|---|---|---|---|---|"]
    for _, r in rank.iterrows():
        lines.append(f"| {r['scene']} | {r['res']} | {', '.join(map(str, r['predicted']))} | "
                     f"{', '.join(map(str, r['measured']))} | {'yes' if r['right'] else 'no'} |")
    return "\n".join(lines)


def misses_text(df):
    """Per stage over every workload: the summed error, and how much of the prediction is
    scene-data misses (charged at the measured latency, no overlap) - where to look first."""
    lines = ["| stage | predicted Mcyc | measured Mcyc | error of sum | predicted scene-data misses |"
             " error without them |", "|---|---|---|---|---|---|"]
    for s in STAGES:
        p = df[f"predicted.{s}_cycles"].sum()
        m = df[f"measured.{s}_cycles"].sum()
        mem = df[f"predicted.{s}_memory_cycles"].sum()
        lines.append(f"| {s} | {p / 1e6:.1f} | {m / 1e6:.1f} | {pct(p / m - 1)} | "
                     f"{mem / max(p, 1):.0%} | {pct((p - mem) / m - 1)} |")
    return "\n".join(lines)


def summary_text(s):
    lines = [f"- workloads: {s['workloads']}",
             f"- frame cycles: MAE {100 * s['frame_mae']:.1f} %, worst {100 * s['frame_worst']:.1f} %"]
    for st in STAGES:
        lines.append(f"- {st}: MAE {100 * s[f'{st}_mae']:.1f} %, worst {100 * s[f'{st}_worst']:.1f} %")
    lines.append(f"- tile ranking right in {s['ranking_right']} of {s['ranking_cells']} "
                 "(scene, resolution) cells")
    for name, ok in s["targets"].items():
        lines.append(f"- target {name}: {'met' if ok else 'MISSED'}")
    return "\n".join(lines)


def scatter_plot(df, path):
    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    ax = axes[0]
    for scene, g in df.groupby("scene", sort=False):
        ax.scatter(g["measured.frame_cycles"] / 1e6, g["predicted.frame_cycles"] / 1e6,
                   label=scene, s=28)
    lo = min(df["measured.frame_cycles"].min(), df["predicted.frame_cycles"].min()) / 1e6
    hi = max(df["measured.frame_cycles"].max(), df["predicted.frame_cycles"].max()) / 1e6
    for a in axes:
        a.set_xscale("log")
        a.set_yscale("log")
    ax.plot([lo, hi], [lo, hi], "k-", lw=1, label="y = x")
    ax.plot([lo, hi], [lo * 1.25, hi * 1.25], "k:", lw=0.8, label="±25 %")
    ax.plot([lo, hi], [lo / 1.25, hi / 1.25], "k:", lw=0.8)
    ax.set_xlabel("measured Mcycles per frame (CPU time at the TSC rate, median)")
    ax.set_ylabel("predicted Mcycles per frame")
    ax.set_title("frames")
    ax.legend(fontsize=8)
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
    fig.suptitle("host timing against the native stream tracer (shared, noisy machine)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_page(df, page, plot_name, header):
    """docs/silicon-check.md: how it was run, the summary, the tables; the plot beside it."""
    s = summary(df)
    text = "\n\n".join([
        "# The timing model on silicon: the host CPU predicting the native stream tracer",
        header.strip(),
        "## Summary\n\n" + summary_text(s),
        f"![predicted against measured]({plot_name})",
        "## Per workload\n\nError = predicted / measured - 1. Noise = (max - min) / median of the "
        "measured renders of that workload.\n\n" + table_text(df),
        "## Per scene and stage\n\n" + stage_table_text(df),
        "## Tile-size ranking\n\n" + ranking_text(df),
        "## Where the prediction goes wrong, by stage\n\nScene-data misses are charged at the "
        "measured load latency of the level that holds the line, with no overlap; the last "
        "column is the prediction without them (the truth lies between when out-of-order "
        "execution and the tracer's prefetch of child nodes hide part of each miss).\n\n"
        + misses_text(df),
    ])
    with open(page, "w") as f:
        f.write(text + "\n")
    return s


def html_section(df, directory, plot_name="silicon-check.png"):
    """The report's section (`sfx report DB --silicon ROWS`): the summary, the scatter plot
    (drawn into the report directory) and the per-workload table."""
    e = html.escape
    scatter_plot(df, os.path.join(directory, plot_name))
    items = "".join(f"<li>{e(line[2:])}</li>" for line in summary_text(summary(df)).splitlines())
    head = ["scene", "res", "tile", "predicted Mcyc", "measured Mcyc", "error", "trav err",
            "isect err", "shade err", "noise"]
    rows = []
    for _, r in df.iterrows():
        cells = [r["scene"], r["res"], r["tile"], f"{r['predicted.frame_cycles'] / 1e6:.2f}",
                 f"{r['measured.frame_cycles'] / 1e6:.2f}", pct(r["error.frame"]),
                 pct(r["error.traversal"]), pct(r["error.intersection"]),
                 pct(r["error.shading"]), f"{100 * r['noise']:.0f} %"]
        rows.append("<tr>" + "".join(f"<td>{e(str(c))}</td>" for c in cells) + "</tr>")
    return "\n".join([
        "<h2>The timing model on silicon</h2>",
        "<p>The host CPU described as a hardware configuration (<code>sfx calibrate "
        "--describe-host</code>, per-op costs fitted only on microbenchmarks) predicting the "
        "native stream tracer's cycles per frame on held-out workloads (<code>sfx calibrate "
        "--check</code>; <code>scripts/silicon-check</code> writes the same as "
        "<code>docs/silicon-check.md</code>). Error = predicted / measured &minus; 1.</p>",
        f"<ul class=\"notes\">{items}</ul>",
        f'<figure><img src="{e(plot_name)}" alt="predicted against measured cycles">'
        "<figcaption>Predicted against measured Mcycles per frame and per stage, with the "
        "y = x line (and &plusmn;25 % dotted).</figcaption></figure>",
        '<table class="paper"><caption>Per workload</caption><tr>'
        + "".join(f"<th>{e(h)}</th>" for h in head) + "</tr>" + "".join(rows) + "</table>",
    ])

"""Draws `sfx accuracy` rows: relative error against host seconds, one point per fidelity.

Usage: /usr/bin/python3 accuracy_plot.py ROWS.json OUT.png (called by `sfx accuracy --plot`).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(rows_path, png_path):
    with open(rows_path) as f:
        rows = json.load(f)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for row in rows:
        error = abs(row["error.actual"]) * 100.0
        interval = row["error.relative"] * 100.0 if row["error.relative"] >= 0 else None
        ax.errorbar(row["host_seconds"], error, yerr=interval, fmt="o", capsize=3,
                    label=row["fidelity"])
        ax.annotate(row["fidelity"], (row["host_seconds"], error), textcoords="offset points",
                    xytext=(4, 4), fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("host time [s]")
    ax.set_ylabel("|frame cycles - full| / full [%]  (bars: interval half-width)")
    ax.set_title("speed against error")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])

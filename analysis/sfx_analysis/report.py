"""`report DB -o DIR`: index.html (images beside it, tables inline), tables.md, points.csv and
the plots' PNGs."""

from __future__ import annotations

import datetime
import html
import os
from dataclasses import dataclass, field
from typing import Callable, List

from . import explore as explore_module
from . import paper as paper_module
from . import plots as plots_module
from . import tables as tables_module
from .progress import Steps
from .slicing import SCENE, TILE, WIDTH
from .store import Store, StoreError, for_display, load_store

_CSS = """
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       color: #222; }
h1 { font-size: 1.6em; } h2 { margin-top: 2em; border-bottom: 1px solid #ccc; }
table.paper { border-collapse: collapse; margin: 1.5em 0 0.5em; }
table.paper { display: block; }  /* a block: the caption is not squeezed to the table */
table.paper caption { display: block; text-align: left; padding-bottom: 0.4em;
                      max-width: 800px; }
table.paper th, table.paper td { border: 1px solid #bbb; padding: 0.2em 0.7em;
                                 text-align: right; }
table.paper tr.section th { text-align: left; background: #f0f0f0; font-style: italic; }
td.missing { color: #999; text-align: center; }
ul.notes { font-size: 0.9em; color: #555; margin-top: 0; }
figure { margin: 1.5em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: 0.9em; color: #444; max-width: 900px; }
table.summary td, table.summary th { text-align: left; padding: 0.1em 1em 0.1em 0; }
.warning { color: #a40; }
"""


@dataclass
class Report:
    directory: str
    index: str
    tables_md: str
    points_csv: str
    tables: List[tables_module.Table]
    plots: List[plots_module.Plot]
    store: Store
    explore_plots: List[plots_module.Plot] = field(default_factory=list)  # "What to build"

    def files(self) -> List[str]:
        return [self.index, self.tables_md, self.points_csv] + \
            [os.path.join(self.directory, p.file) for p in self.plots + self.explore_plots
             if p.file]


def _values(store: Store, column: str) -> str:
    values = list(store.points[column].dropna().unique()) if column in store.points.columns \
        else []
    # Numbers in numeric order (32 before 104), text alphabetically.
    values.sort(key=lambda v: (0, float(v), "") if not isinstance(v, str) else (1, 0.0, v))
    texts = []
    for v in values:
        f = v if isinstance(v, str) else float(v)
        texts.append(f if isinstance(f, str) else (str(int(f)) if f.is_integer() else f"{f:g}"))
    return ", ".join(texts) if texts else "—"


def _summary_rows(store: Store) -> List[tuple]:
    p = store.points
    rows = [("store", os.path.abspath(store.path)),
            ("schema version", str(store.schema_version)),
            ("written by", store.created_by or "—"),
            ("points", str(len(p))),
            ("sweeps", _values(store, "sweep")),
            ("scenes", _values(store, SCENE)),
            ("tiles", _values(store, TILE)),
            ("SIMD widths", _values(store, WIDTH)),
            ("fidelities", _values(store, "fidelity"))]
    return rows


def _summary_section(store: Store, tables, plots) -> str:
    e = html.escape
    out = ['<table class="summary">']
    for k, v in _summary_rows(store):
        out.append(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>")
    out.append("</table>")
    for w in store.warnings:
        out.append(f'<p class="warning">Note: {e(w)}</p>')
    out.append('<p>Also here: <a href="tables.md">tables.md</a> (the tables in Markdown) and '
               '<a href="points.csv">points.csv</a> (every point, one row each, units in the '
               'column names).</p>')
    return "\n".join(out)


def _plots_section(store: Store, tables, plots) -> str:
    e = html.escape
    out = ["<h2>Plots</h2>"]
    drawn = [p for p in plots if p.file]
    skipped = [p for p in plots if not p.file]
    for p in drawn:
        out.append(f'<figure id="{e(p.name)}"><img src="{e(p.file)}" alt="{e(p.title)}">'
                   f"<figcaption><b>{e(p.title)}.</b> {e(p.caption)}</figcaption></figure>")
    if skipped:
        out.append("<h3>Skipped plots</h3><ul>")
        for p in skipped:
            out.append(f"<li><b>{e(p.title)}</b>: {e(p.skipped)}</li>")
        out.append("</ul>")
    return "\n".join(out)


def _tables_section(store: Store, tables, plots) -> str:
    out = ["<h2>Tables</h2>",
           "<p>In the layout of Gribble &amp; Ramani, <i>Coherent Ray Tracing via Stream "
           "Filtering</i> (RT 2008), Tables 2&ndash;6, from the points in this store. "
           f"{tables_module.MISSING} marks a cell the store has no value for.</p>"]
    for t in tables:
        out.append(tables_module.to_html(t))
    return "\n".join(out)


def _paper_section(store: Store, tables, plots) -> str:
    return paper_module.html_section(store)  # empty without the paper's scenes


def _seed_options_section(store: Store, tables, plots) -> str:
    from . import seed_kernels
    return seed_kernels.html_section(store)  # empty when no point has an option on


# The page, top to bottom: each section is a function (store, tables, plots) -> HTML. A new
# kind of answer adds its function here. Above them all: the "What to build" sections of the
# store's explores (explore.py; they draw their own plots, so write_report makes them).
SECTIONS: List[Callable[[Store, list, list], str]] = [
    _summary_section,
    _plots_section,
    _tables_section,
    _paper_section,
    _seed_options_section,
]


def _index_html(store: Store, tables, plots, title: str, extra: List[str],
                lead: List[str] = ()) -> str:
    e = html.escape
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>{e(title)}</title>", f"<style>{_CSS}</style>", "</head><body>",
           f"<h1>{e(title)}</h1>"]
    out.extend(lead)  # sections answering the question first (what to build)
    out.extend(section(store, tables, plots) for section in SECTIONS)
    out.extend(extra)  # sections from other inputs than the store (the silicon check)
    generated = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    out.append(f"<p><small>Generated by sfx_analysis on {e(generated)}.</small></p>")
    out.append("</body></html>")
    return "\n".join(out) + "\n"


def write_report(db: str, directory: str, silicon_rows: str = "") -> Report:
    """silicon_rows: `sfx calibrate --check --json` output, for the silicon-check section."""
    # Steps for a progress bar: the store, the tables, each plot, the files.
    steps = Steps(4 + len(plots_module.PLOTTERS) + bool(silicon_rows))
    steps.start("reading the store")
    store = load_store(db)
    silicon_df = None
    if silicon_rows:
        from . import silicon
        try:
            silicon_df = silicon.load_rows(silicon_rows)
        except (OSError, ValueError, KeyError) as e:
            raise StoreError(f"{silicon_rows}: cannot read the silicon-check rows ({e})") \
                from None
    try:
        os.makedirs(directory, exist_ok=True)
    except OSError as e:
        raise StoreError(f"{directory}: cannot create the report directory ({e.strerror})") \
            from None
    if not os.path.isdir(directory):
        raise StoreError(f"{directory}: not a directory")

    steps.start("what to build")
    lead, explore_plots = explore_module.html_sections(db, directory)

    steps.start("tables")
    tables = tables_module.build_tables(store)
    plots = []
    for plotter in plots_module.PLOTTERS:
        steps.start("plot " + plotter.__name__[len("plot_"):])
        plots.append(plotter(store, directory))
    extra = []
    if silicon_df is not None:
        from . import silicon
        steps.start("silicon check")
        extra.append(silicon.html_section(silicon_df, directory))
    steps.start("writing the files")
    title = f"sfx report: {os.path.basename(db)}"

    tables_md = os.path.join(directory, "tables.md")
    with open(tables_md, "w", encoding="utf-8") as f:
        f.write(tables_module.tables_markdown(
            tables, f"# {title}\n\n{len(store.points)} points from `{os.path.abspath(db)}`. "
                    f"{tables_module.MISSING} marks a cell the store has no value for."))
    points_csv = os.path.join(directory, "points.csv")
    for_display(store, store.points.drop(columns=["config_yaml"], errors="ignore")).to_csv(
        points_csv, index=False)
    index = os.path.join(directory, "index.html")
    with open(index, "w", encoding="utf-8") as f:
        f.write(_index_html(store, tables, plots, title, extra, lead))
    steps.finish()
    return Report(directory, index, tables_md, points_csv, tables, plots, store, explore_plots)

"""The paper's Tables 2-6 (Gribble & Ramani 2008) regenerated from whatever a store holds.

Cells the store has no value for are shown as MISSING, never filled in. A sweep that varies
more than scene, tile and SIMD width gets one block of each table per context (see slicing).
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Sequence, Union

import pandas as pd

from .slicing import SCENE, TABLE_KEY, TILE, WIDTH, contexts, describe, one_per_cell
from .store import STAGES, Store

MISSING = "—"
STAGE_ABBREVIATION = {"traversal": "T", "intersection": "I", "shading": "S"}


@dataclass
class Section:
    """A row spanning the table: 'SIMD width N = 16' in the paper's Tables 2, 3 and 6."""
    text: str


Row = Union[Section, List[str]]


@dataclass
class Table:
    ident: str                  # 'table2', 'table2-ideal', ...: anchors and tests
    title: str
    caption: str
    header: List[str]
    rows: List[Row]
    notes: List[str] = field(default_factory=list)
    context: Dict[str, object] = field(default_factory=dict)

    def body(self) -> List[List[str]]:
        return [r for r in self.rows if not isinstance(r, Section)]

    def cell(self, row_label: str, column: str, section: Optional[str] = None) -> str:
        """The cell in the row whose first cell is row_label (under section, when given)."""
        j = self.header.index(column)
        current = None
        for r in self.rows:
            if isinstance(r, Section):
                current = r.text
            elif r[0] == row_label and (section is None or current == section):
                return r[j]
        raise KeyError(f"{self.ident}: no row {row_label!r} in section {section!r}")


def _number(v) -> Optional[float]:
    if v is None:
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return None if f != f else f


def _int_text(v) -> str:
    f = float(v)
    return str(int(f)) if f.is_integer() else f"{f:g}"


def tile_text(tile) -> str:
    t = _int_text(tile)
    return f"{t}×{t}"


def width_section(width) -> str:
    return f"SIMD width N = {_int_text(width)}"


class _Cells:
    """Looks up one point per (scene, tile, width) and records which stats were absent."""

    def __init__(self, points: pd.DataFrame, all_columns: Sequence[str]):
        self.points = one_per_cell(points, TABLE_KEY)
        self.all_columns = set(all_columns)
        self.by_key = {(r[SCENE], r[TILE], r[WIDTH]): r for _, r in self.points.iterrows()}
        self.absent: List[str] = []
        self.empty: List[str] = []

    def check(self, columns: Sequence[str]) -> None:
        for c in columns:
            if c not in self.all_columns:
                if c not in self.absent:
                    self.absent.append(c)
            elif self.points[c].isna().all() and c not in self.empty:
                self.empty.append(c)

    def value(self, row: Optional[pd.Series], column: str) -> Optional[float]:
        if row is None or column not in row.index:
            return None
        return _number(row[column])

    def notes(self) -> List[str]:
        notes = []
        if self.absent:
            notes.append("not in the store (shown as " + MISSING + "): " + ", ".join(self.absent))
        if self.empty:
            notes.append("no values in the store (shown as " + MISSING + "): " +
                         ", ".join(self.empty))
        return notes

    def scenes(self) -> List[str]:
        return sorted(self.points[SCENE].unique())


def _grid(cells: _Cells, cell_text: Callable[[Optional[pd.Series]], str]) -> List[Row]:
    """The layout of Tables 2, 3 and 6: a section per SIMD width, a row per tile that exists at
    that width, a column per scene."""
    rows: List[Row] = []
    scenes = cells.scenes()
    for width in sorted(cells.points[WIDTH].unique()):
        rows.append(Section(width_section(width)))
        at_width = cells.points[cells.points[WIDTH] == width]
        for tile in sorted(at_width[TILE].unique()):
            row = [tile_text(tile)]
            for scene in scenes:
                row.append(cell_text(cells.by_key.get((scene, tile, width))))
            rows.append(row)
    return rows


def _utilization_text(cells: _Cells, row: Optional[pd.Series], columns: Sequence[str],
                      ideal_columns: Sequence[str]) -> str:
    if row is None:
        return MISSING
    parts = []
    for c, ideal in zip(columns, ideal_columns):
        v = cells.value(row, c)
        # An ideal utilization of exactly 0 means the stage issued no operation (C++ writes 0
        # for 0/0): there is no utilization to show.
        if v is None or cells.value(row, ideal) == 0.0:
            parts.append(MISSING)
        else:
            parts.append(f"{100.0 * v:.0f}")
    return " / ".join(parts)


def _utilization_table(cells: _Cells, ray_kind: str, stages: Sequence[str], ideal: bool,
                       number: str) -> Table:
    prefix = "ideal_simd_utilization" if ideal else "simd_utilization"
    columns = [f"{prefix}.{ray_kind}.{s}" for s in stages]
    ideal_columns = [f"ideal_simd_utilization.{ray_kind}.{s}" for s in stages]
    cells.check(columns)
    letters = "/".join(STAGE_ABBREVIATION[s] for s in stages)
    kind = "ideal " if ideal else ""
    title = f"Table {number}: {kind}SIMD utilization ({letters}) for {ray_kind} rays [%]"
    if ideal:
        caption = ("Lanes doing useful work over lanes issued, from the trace alone: no "
                   "stall or overhead is charged.")
    else:
        caption = ("Effective utilization: the ideal utilization times the share of each "
                   "stage's cycles that issue work (address fetch, alignment, partition and "
                   "memory stalls issue nothing).")
    rows = _grid(cells, lambda r: _utilization_text(cells, r, columns, ideal_columns))
    ident = f"table{number}" + ("-ideal" if ideal else "")
    return Table(ident, title, caption, ["size"] + cells.scenes(), rows)


def _stream_length_table(cells: _Cells, all_columns: Sequence[str]) -> Table:
    secondary = [f"stream_length.secondary.{s}" for s in STAGES]
    if any(c in all_columns for c in secondary):
        columns, which = secondary, "secondary rays (as in the paper)"
    else:
        columns, which = [f"stream_length.{s}" for s in STAGES], \
            "all rays, primary and secondary (the store has no secondary-only lengths)"
    cells.check(columns)
    points = cells.points
    # Stream lengths come from the trace, which does not depend on the SIMD width: one row per
    # (scene, tile) unless the store says otherwise.
    by_width = False
    for _, group in points.groupby([SCENE, TILE]):
        for c in columns:
            if c in group.columns and group[c].dropna().nunique() > 1:
                by_width = True
    header = ["scene", "size"] + (["N"] if by_width else []) + ["trav", "isec", "shade"]
    rows: List[Row] = []
    for scene in cells.scenes():
        first = True
        at_scene = points[points[SCENE] == scene]
        for tile in sorted(at_scene[TILE].unique()):
            at_tile = at_scene[at_scene[TILE] == tile]
            groups = ([(w, at_tile[at_tile[WIDTH] == w]) for w in sorted(at_tile[WIDTH].unique())]
                      if by_width else [(None, at_tile)])
            for width, group in groups:
                row = [scene if first else "", tile_text(tile)]
                if by_width:
                    row.append(_int_text(width))
                for c in columns:
                    values = group[c].dropna() if c in group.columns else pd.Series([], dtype=float)
                    row.append(f"{values.iloc[0]:.1f}" if len(values) else MISSING)
                rows.append(row)
                first = False
    title = "Table 4: average stream length [rays]"
    caption = f"Average input-stream length of each stage's operations, {which}."
    return Table("table4", title, caption, header, rows)


def _op_mix_table(cells: _Cells) -> Table:
    names = ["load", "store", "compute", "scatter_gather", "partition"]
    columns = [f"op_mix.{n}_percent" for n in names]
    cells.check(columns)
    rows: List[Row] = []
    points = cells.points
    for scene in cells.scenes():
        first = True
        at_scene = points[points[SCENE] == scene]
        for _, r in at_scene.sort_values([TILE, WIDTH], kind="mergesort").iterrows():
            row = [scene if first else "", tile_text(r[TILE]), _int_text(r[WIDTH])]
            for c in columns:
                v = cells.value(r, c)
                row.append(MISSING if v is None else f"{v:.1f}")
            rows.append(row)
            first = False
    header = ["scene", "size", "N", "load", "store", "comp", "scat/gath", "part"]
    title = "Table 5: distribution of major operations [% of total]"
    caption = ("SIMD instructions by class; integer address operations are counted in the "
               "loads and stores. The paper shows 64×64 streams at N = 16.")
    return Table("table5", title, caption, header, rows)


def _fps_table(cells: _Cells) -> Table:
    cells.check(["fps"])

    def text(r):
        v = cells.value(r, "fps")
        return MISSING if v is None else f"{v:.2f} fps"

    title = "Table 6: predicted rendering performance [frames/s]"
    caption = "Predicted frame rate per scene, initial stream (tile) size and SIMD width."
    return Table("table6", title, caption, ["size"] + cells.scenes(), _grid(cells, text))


def build_tables(store: Store) -> List[Table]:
    """Tables 2 (and its ideal), 3 (and its ideal), 4, 5 and 6, each once per context, in the
    paper's order."""
    all_columns = list(store.points.columns)
    per_context = []
    for context, group in contexts(store.points, TABLE_KEY):
        builders = [
            lambda c: _utilization_table(c, "primary", ["traversal", "intersection"], False, "2"),
            lambda c: _utilization_table(c, "primary", ["traversal", "intersection"], True, "2"),
            lambda c: _utilization_table(c, "secondary", STAGES, False, "3"),
            lambda c: _utilization_table(c, "secondary", STAGES, True, "3"),
            lambda c: _stream_length_table(c, all_columns),
            _op_mix_table,
            _fps_table,
        ]
        tables = []
        for build in builders:
            cells = _Cells(group, all_columns)
            t = build(cells)
            t.notes = cells.notes()
            t.context = context
            if context:
                t.title += f" — {describe(context)}"
                t.ident += "-" + str(len(per_context) + 1)
            tables.append(t)
        per_context.append(tables)
    # Table-major order: every block of Table 2 before Table 3.
    return [per_context[c][i] for i in range(len(per_context[0])) for c in range(len(per_context))]


def to_markdown(table: Table) -> str:
    n = len(table.header)
    lines = [f"### {table.title}", "", f"*{table.caption}*", ""]
    lines.append("| " + " | ".join(table.header) + " |")
    lines.append("|" + " --- |" * n)
    for r in table.rows:
        if isinstance(r, Section):
            lines.append(f"| **{r.text}** |" + "  |" * (n - 1))
        else:
            lines.append("| " + " | ".join(r) + " |")
    if table.notes:
        lines.append("")
        lines.extend(f"- {note}" for note in table.notes)
    return "\n".join(lines) + "\n"


def to_html(table: Table) -> str:
    e = html.escape
    out = [f'<table class="paper" id="{e(table.ident)}">',
           f"<caption><b>{e(table.title)}</b><br>{e(table.caption)}</caption>",
           "<thead><tr>" + "".join(f"<th>{e(h)}</th>" for h in table.header) + "</tr></thead>",
           "<tbody>"]
    for r in table.rows:
        if isinstance(r, Section):
            out.append(f'<tr class="section"><th colspan="{len(table.header)}">{e(r.text)}'
                       f"</th></tr>")
        else:
            tds = "".join(f'<td class="missing">{e(c)}</td>' if c == MISSING else f"<td>{e(c)}</td>"
                          for c in r)
            out.append(f"<tr>{tds}</tr>")
    out.append("</tbody></table>")
    if table.notes:
        out.append('<ul class="notes">' + "".join(f"<li>{e(n)}</li>" for n in table.notes) +
                   "</ul>")
    return "\n".join(out) + "\n"


def tables_markdown(tables: Sequence[Table], heading: str) -> str:
    return heading + "\n\n" + "\n".join(to_markdown(t) for t in tables)

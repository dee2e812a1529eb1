"""Command line: `python3 -m sfx_analysis report DB -o DIR`, `python3 -m sfx_analysis tables DB`,
`python3 -m sfx_analysis paper DB -o PAGE.md`, `python3 -m sfx_analysis seed-kernels DB -o
PAGE.md`. A store that cannot be reported on prints one line and exits 2 (no traceback)."""

from __future__ import annotations

import argparse
import os
import sys

from .slicing import fidelity_rank
from .store import StoreError, load_store
from .tables import build_tables, tables_markdown, to_markdown


def _report(args) -> int:
    from .report import write_report  # imports matplotlib: only when drawing

    report = write_report(args.db, args.output, args.silicon or "")
    for w in report.store.warnings:
        print(f"sfx report: note: {w}", file=sys.stderr)
    if not args.quiet:
        fps = [t for t in report.tables if t.ident.startswith("table6")]
        if fps:
            # The block at the most accurate fidelity (the sweep's reference) is printed.
            fps.sort(key=lambda t: -fidelity_rank(str(t.context.get("fidelity", "full"))))
            print(to_markdown(fps[0]))
            if len(fps) > 1:
                print(f"({len(fps) - 1} more block(s) of Table 6, one per configuration, in "
                      f"tables.md)\n")
    drawn = [p for p in report.plots if p.file]
    skipped = [p for p in report.plots if not p.file]
    print(f"report: {os.path.abspath(report.index)}")
    print(f"tables: {os.path.abspath(report.tables_md)}")
    print(f"points: {os.path.abspath(report.points_csv)}")
    print(f"plots:  {len(drawn)} in {os.path.abspath(report.directory)}/: "
          + (", ".join(p.file for p in drawn) if drawn else "none"))
    for p in skipped:
        print(f"skipped {p.name}: {p.skipped}")
    return 0


def _tables(args) -> int:
    store = load_store(args.db)
    for w in store.warnings:
        print(f"sfx_analysis: note: {w}", file=sys.stderr)
    print(tables_markdown(build_tables(store), f"# Tables from {args.db}"))
    return 0


def _paper(args) -> int:
    from . import paper

    store = load_store(args.db)
    trace = None
    if args.trace_stats:
        try:
            trace = paper.load_trace_stats(args.trace_stats)
        except (OSError, ValueError) as e:
            raise StoreError(f"{args.trace_stats}: cannot read trace statistics ({e})") from None
    check = paper.build(store, trace)
    try:
        paper.write_page(check, args.output, args.command)
    except OSError as e:
        raise StoreError(f"{args.output}: cannot write the page ({e.strerror})") from None
    if not args.quiet:
        print(paper.to_markdown_summary(check))
    for m in check.missing[:5]:
        print(f"sfx report: note: missing cell: {m}", file=sys.stderr)
    if len(check.missing) > 5:
        print(f"sfx report: note: ... and {len(check.missing) - 5} more missing cells (listed "
              f"in the page)", file=sys.stderr)
    print(f"paper check: {os.path.abspath(args.output)}")
    return 0


def _silicon(args) -> int:
    from . import silicon
    try:
        df = silicon.load_rows(args.rows)
    except (OSError, ValueError, KeyError) as e:
        raise StoreError(f"{args.rows}: cannot read the silicon-check rows ({e})") from None
    repeats = []
    for path in args.repeats:
        try:
            repeats.append(silicon.load_rows(path))
        except (OSError, ValueError, KeyError) as e:
            raise StoreError(f"{path}: cannot read the silicon-check rows ({e})") from None
    with open(args.header) as f:
        header = f.read()
    plot = os.path.join(os.path.dirname(os.path.abspath(args.output)), args.plot)
    silicon.scatter_plot(df, plot)
    silicon.write_page(df, args.output, args.plot, header, repeats)
    print(silicon.table_text(df))
    print()
    print(silicon.stage_table_text(df))
    print()
    print(silicon.ranking_text(df))
    print()
    print(silicon.width_ranking_text(df))
    print()
    print(silicon.all_summaries_text(df, repeats))
    print(f"silicon check: {os.path.abspath(args.output)}, {plot}")
    return 0


def _seed_kernels(args) -> int:
    from . import seed_kernels

    store = load_store(args.db)
    try:
        seed_kernels.write_page(store, args.output, args.command)
    except OSError as e:
        raise StoreError(f"{args.output}: cannot write the page ({e.strerror})") from None
    print(f"seed kernels: {os.path.abspath(args.output)}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="sfx_analysis",
                                     description="tables, plots and a report from a results store")
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("report", help="index.html, tables.md, points.csv and PNG plots")
    r.add_argument("db", help="results store (SQLite) written by `sfx sweep`")
    r.add_argument("-o", "--output", default="report", help="report directory (default: report)")
    r.add_argument("--quiet", action="store_true", help="print only where the files are")
    r.add_argument("--silicon", help="`sfx calibrate --check --json` output: adds the "
                                     "silicon-check section")
    r.set_defaults(run=_report)
    pp = sub.add_parser("paper", help="the paper check page (docs/paper-check.md) in Markdown")
    pp.add_argument("db")
    pp.add_argument("-o", "--output", required=True, help="page to write (Markdown)")
    pp.add_argument("--trace-stats", help="`sfx trace-stats conference --json` output, for the "
                                          "trace-side target")
    pp.add_argument("--command", default="", help="the command named on the page as its source")
    pp.add_argument("--quiet", action="store_true", help="print only where the page is")
    pp.set_defaults(run=_paper)
    si = sub.add_parser("silicon", help="the silicon check page (docs/silicon-check-*.md)")
    si.add_argument("rows", help="`sfx calibrate --check --json` output")
    si.add_argument("-o", "--output", required=True, help="page to write (Markdown)")
    si.add_argument("--plot", default="silicon-check.png", help="plot file name, beside the page")
    si.add_argument("--header", required=True, help="Markdown put under the page's title")
    si.add_argument("--repeats", nargs="*", default=[],
                    help="`sfx calibrate --check --json` outputs of one of the rows' workloads, "
                         "each measured in a process of its own: the reproducibility line")
    si.set_defaults(run=_silicon)
    sk = sub.add_parser("seed-kernels", help="the seed papers' options (docs/seed-kernels.md)")
    sk.add_argument("db")
    sk.add_argument("-o", "--output", required=True, help="page to write (Markdown)")
    sk.add_argument("--command", default="", help="the command named on the page as its source")
    sk.set_defaults(run=_seed_kernels)
    t = sub.add_parser("tables", help="the paper's Tables 2-6 in Markdown on stdout")
    t.add_argument("db")
    t.set_defaults(run=_tables)
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except StoreError as e:
        print(f"sfx report: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())

"""sfx_analysis: the paper's tables, plots and an HTML report from an sfx results store.

Run as `/usr/bin/python3 -m sfx_analysis report results.db -o report/` (what `sfx report`
does) or use load_store / build_tables / make_plots / write_report from Python.
"""

from .plots import make_plots
from .report import write_report
from .store import SCHEMA_VERSION, StoreError, load_store
from .tables import build_tables

__all__ = ["SCHEMA_VERSION", "StoreError", "build_tables", "load_store", "make_plots",
           "write_report"]

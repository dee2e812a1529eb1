"""The report's "What to build" section from the `explores` and `explore_configs` tables that
`sfx explore` adds to a store: first on the page, its plot drawn, the best configuration under
each constraint, the ranking from screen to confirm; nothing for a store without them."""

import json
import os
import re
import sqlite3

from conftest import grid_points, write_store
from sfx_analysis import explore
from sfx_analysis.report import write_report

SPEC = {"objectives": [{"metric": "fps", "direction": "maximize"},
                       {"metric": "area_mm2", "direction": "minimize"},
                       {"metric": "energy_mj", "direction": "minimize"}],
        "constraints": [{"metric": "area_mm2", "max": 40.0}, {"metric": "fps", "min": 3.0},
                        {"metric": "energy_mj", "max": 8.5}],
        "workloads": [{"scene": "atrium", "weight": 1.0}],
        "knobs": [{"path": "hw.simd.width", "values": ["4", "8", "16"]},
                  {"path": "hw.simd.units", "values": ["1", "2"]}],
        "screen": "analytic", "confirm": "sampled", "configurations": 6}

# config: (width, units, fps, area, energy, feasible, front) at the screen fidelity. The best
# per constraint is computed from the values; "every constraint" reads sfx's feasible column,
# which here follows the first two constraints only (none meets energy <= 8.5 and area <= 40):
# the test checks that the column is read, not recomputed.
SCREEN = {0: ("4", "1", 1.5, 20.0, 12.0, 0, 0),
          1: ("4", "2", 4.0, 30.0, 10.0, 1, 1),
          2: ("8", "1", 6.0, 38.0, 9.0, 1, 1),
          3: ("16", "2", 9.0, 55.0, 8.0, 0, 0),
          4: ("16", "1", 5.0, 45.0, 11.0, 0, 0),
          5: ("8", "2", 5.9, 36.0, 9.5, 1, 1)}
# The screened front re-run at the confirm fidelity: config 5 overtakes config 2.
CONFIRM = {1: (4.4, 0.05), 2: (5.7, 0.04), 5: (6.1, 0.03)}


def add_explore_tables(path, name="gr08-atrium", spec=SPEC, rows=True):
    con = sqlite3.connect(path)
    con.execute("CREATE TABLE explores(name TEXT PRIMARY KEY, file TEXT, fingerprint TEXT, "
                "spec TEXT)")
    con.execute("CREATE TABLE explore_configs(explore TEXT, config INTEGER, stage TEXT, "
                "trial INTEGER, knobs TEXT, fps REAL, fps_error REAL, area_mm2 REAL, "
                "energy_mj REAL, power_w REAL, fps_per_mm2 REAL, feasible INTEGER, "
                "front INTEGER, PRIMARY KEY(explore, config, stage))")
    if rows:
        con.execute("INSERT INTO explores VALUES(?, ?, ?, ?)",
                    (name, "explores/gr08.explore.yaml", "abc123", json.dumps(spec)))
        for cfg, (w, u, fps, area, energy, feasible, front) in SCREEN.items():
            knobs = json.dumps({"hw.simd.width": w, "hw.simd.units": u})
            con.execute("INSERT INTO explore_configs VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?)",
                        (name, cfg, "screen", cfg, knobs, fps, None, area, energy,
                         energy * fps / 1000, fps / area, feasible, front))
            if cfg in CONFIRM:
                cfps, err = CONFIRM[cfg]
                con.execute("INSERT INTO explore_configs VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?)",
                            (name, cfg, "confirm", cfg, knobs, cfps, err, area, energy,
                             energy * cfps / 1000, cfps / area, 1, 1))
    con.commit()
    con.close()
    return path


def explore_store(tmp_path, **kw):
    return add_explore_tables(write_store(str(tmp_path / "explore.db"), grid_points()), **kw)


def test_section_first_with_plot(tmp_path):
    report = write_report(explore_store(tmp_path), str(tmp_path / "r"))
    page = open(report.index, encoding="utf-8").read()
    assert page.index('<section class="explore"') < page.index("<th>store</th>")
    assert re.findall(r"<h2>([^<]*)</h2>", page)[0] == "What to build: gr08-atrium"
    assert [p.file for p in report.explore_plots] == ["explore_gr08-atrium.png"]
    png = os.path.join(report.directory, "explore_gr08-atrium.png")
    assert os.path.getsize(png) > 5000 and png in report.files()
    assert 'src="explore_gr08-atrium.png"' in page
    # The other plots are untouched.
    assert "explore" not in " ".join(p.name for p in report.plots)


def test_best_under_each_constraint(tmp_path):
    (ex,) = explore.load_explores(explore_store(tmp_path))
    choices = {c.label: c for c in explore.best_choices(ex)}
    assert list(choices) == ["area_mm2 ≤ 40", "fps ≥ 3", "energy_mj ≤ 8.5",
                             "every constraint (feasible)"]
    # Confirmed rows first: config 5 (6.1 fps confirmed) beats config 2 (5.7).
    assert (int(choices["area_mm2 ≤ 40"].row["config"]), choices["area_mm2 ≤ 40"].stage) == \
        (5, "confirm")
    assert int(choices["fps ≥ 3"].row["config"]) == 5
    # No confirmed configuration has energy <= 8.5: the screened config 3 (8.0 mJ).
    assert (int(choices["energy_mj ≤ 8.5"].row["config"]),
            choices["energy_mj ≤ 8.5"].stage) == (3, "screen")
    assert int(choices["every constraint (feasible)"].row["config"]) == 5
    page = explore.html_section(ex, explore.plot_explore(ex, str(tmp_path), "p"))
    assert "6.1 ± 0.18" in page and "simd.width=8, simd.units=2" in page


def test_ranking_from_screen_to_confirm(tmp_path):
    (ex,) = explore.load_explores(explore_store(tmp_path))
    df = explore.ranking_changes(ex)
    assert list(df["config"]) == [5, 2, 1]
    assert list(df["confirm_rank"]) == [1, 2, 3] and list(df["screen_rank"]) == [2, 1, 3]
    assert abs(df.iloc[0]["change"] - (6.1 - 5.9) / 5.9) < 1e-12
    page = explore.html_section(ex, explore.plot_explore(ex, str(tmp_path), "p"))
    assert "2 of 3 changed rank" in page and "was not the best at screening" in page
    assert "+3.4 %" in page


def test_exhaustive_run_without_confirmation(tmp_path):
    path = explore_store(tmp_path)
    con = sqlite3.connect(path)
    con.execute("DELETE FROM explore_configs WHERE stage = 'confirm'")
    con.commit()
    con.close()
    report = write_report(path, str(tmp_path / "r"))
    page = open(report.index, encoding="utf-8").read()
    assert "no configuration was confirmed" in page
    (ex,) = explore.load_explores(path)
    best = explore.best_choices(ex)[-1]
    assert (int(best.row["config"]), best.stage) == (2, "screen")
    assert report.explore_plots[0].file


def test_no_section_without_explores(grid_store, tmp_path):
    report = write_report(grid_store, str(tmp_path / "r"))
    page = open(report.index, encoding="utf-8").read()
    assert "What to build" not in page and report.explore_plots == []
    assert not [f for f in os.listdir(report.directory) if f.startswith("explore")]
    # The tables present but empty: still nothing.
    path = add_explore_tables(write_store(str(tmp_path / "empty.db"), grid_points()),
                              rows=False)
    report = write_report(path, str(tmp_path / "r2"))
    assert "What to build" not in open(report.index, encoding="utf-8").read()


def test_unreadable_spec_still_reports(tmp_path):
    path = explore_store(tmp_path)
    con = sqlite3.connect(path)
    con.execute("UPDATE explores SET spec = 'not json'")
    con.commit()
    con.close()
    report = write_report(path, str(tmp_path / "r"))
    page = open(report.index, encoding="utf-8").read()
    assert "What to build" in page and "not readable JSON" in page


def test_front_names_its_node(tmp_path):
    spec = dict(SPEC, nodes=["7nm"])
    report = write_report(explore_store(tmp_path, spec=spec), str(tmp_path / "r"))
    page = open(report.index, encoding="utf-8").read()
    assert "<tr><th>technology node</th><td>7nm</td></tr>" in page
    assert report.explore_plots[0].title.startswith("gr08-atrium at 7nm:")

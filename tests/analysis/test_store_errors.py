"""Stores the report cannot use give one clear line and exit code 2, never a traceback."""

import sqlite3

import pytest

from conftest import grid_points, point, write_store
from sfx_analysis.__main__ import main
from sfx_analysis.store import StoreError, load_store


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_older_schema(tmp_path, capsys):
    db = write_store(str(tmp_path / "old.db"), grid_points(), schema_version="0")
    with pytest.raises(StoreError, match="older"):
        load_store(db)
    code, _, err = run(capsys, "report", db, "-o", str(tmp_path / "r"))
    assert code == 2 and "schema version 0 is older" in err


def test_no_schema_version_and_newer_schema(tmp_path):
    with pytest.raises(StoreError, match="no schema_version"):
        load_store(write_store(str(tmp_path / "a.db"), grid_points(), schema_version=None))
    with pytest.raises(StoreError, match="newer"):
        load_store(write_store(str(tmp_path / "b.db"), grid_points(), schema_version="2"))


def test_empty_store_and_not_a_store(tmp_path, capsys):
    code, _, err = run(capsys, "report", write_store(str(tmp_path / "e.db"), []), "-o",
                       str(tmp_path / "r"))
    assert code == 2 and "holds no points" in err
    junk = tmp_path / "junk.db"
    junk.write_text("not sqlite")
    code, _, err = run(capsys, "report", str(junk), "-o", str(tmp_path / "r"))
    assert code == 2 and "not an SQLite" in err
    code, _, err = run(capsys, "report", str(tmp_path / "missing.db"))
    assert code == 2 and "no such file" in err
    con = sqlite3.connect(str(tmp_path / "other.db"))
    con.execute("CREATE TABLE t(x)")
    con.close()
    code, _, err = run(capsys, "report", str(tmp_path / "other.db"))
    assert code == 2 and "not an sfx results store" in err


def test_one_point_store_reports_with_plots_skipped(tmp_path, capsys):
    db = write_store(str(tmp_path / "one.db"), [point("rtrt", 32, 16)])
    code, out, err = run(capsys, "report", db, "-o", str(tmp_path / "r"))
    assert code == 0
    assert "holds one point" in err
    assert "skipped fps_vs_width: needs two SIMD widths" in out
    assert (tmp_path / "r" / "index.html").exists()


def test_missing_stage_is_a_note(tmp_path, capsys):
    points = grid_points()
    for p in points:
        for k in [k for k in p if k.endswith(".intersection")]:
            del p[k]
    db = write_store(str(tmp_path / "stage.db"), points)
    store = load_store(db)
    assert any("intersection stage" in w for w in store.warnings)
    code, out, err = run(capsys, "report", db, "-o", str(tmp_path / "r"))
    assert code == 0 and "no values for the intersection stage" in err


def test_missing_required_column(tmp_path):
    p = point("rtrt", 32, 16)
    del p["hw.simd.width"]
    with pytest.raises(StoreError, match="lacks hw.simd.width"):
        load_store(write_store(str(tmp_path / "nowidth.db"), [p]))

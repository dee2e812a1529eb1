"""Plots are drawn as valid, non-empty PNGs; index.html references only files that exist."""

import os
import re
import shutil
import struct
import subprocess

import pytest

from conftest import accuracy_store, grid_points, point, write_store
from sfx_analysis.plots import pareto_front
from sfx_analysis.report import write_report

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == PNG_SIGNATURE and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


def test_every_plot_drawn_and_valid(tmp_path):
    report = write_report(accuracy_store(tmp_path), str(tmp_path / "r"))
    assert [p.name for p in report.plots if p.skipped] == []
    for p in report.plots:
        path = os.path.join(report.directory, p.file)
        width, height = png_size(path)
        assert width > 200 and height > 150 and os.path.getsize(path) > 5000, p.name


def test_plots_without_data_are_skipped_and_listed(grid_store, tmp_path):
    report = write_report(grid_store, str(tmp_path / "r"))
    skipped = {p.name: p.skipped for p in report.plots if p.skipped}
    # One ray-buffer size and no accuracy rows.
    assert set(skipped) == {"fps_vs_buffer", "pareto_fps_vs_buffer", "error_vs_host_time"}
    assert not os.path.exists(tmp_path / "r" / "fps_vs_buffer.png")
    html = open(report.index, encoding="utf-8").read()
    assert "Skipped plots" in html and "no accuracy rows" in html


def test_index_references_only_existing_files(tmp_path):
    report = write_report(accuracy_store(tmp_path), str(tmp_path / "r"))
    html = open(report.index, encoding="utf-8").read()
    refs = re.findall(r'(?:src|href)="([^"]+)"', html)
    assert len([r for r in refs if r.endswith(".png")]) == 8
    for ref in refs:
        assert not re.match(r"^[a-z]+:", ref) and not ref.startswith("/"), ref
        assert os.path.isfile(os.path.join(report.directory, ref)), ref
    assert "<table" in html and "Table 6" in html
    # Seven tables per context; contexts: 128 KiB analytic, 512 KiB at each of three fidelities.
    assert open(report.tables_md, encoding="utf-8").read().count("### Table") == 28


def test_fps_vs_buffer_when_the_tile_follows_the_buffer(tmp_path):
    # tile: auto: each buffer size has its own tile, so no (scene, tile, width) has two sizes;
    # the plot draws one line per width through the best tile at each size.
    points = [point(scene, tile, width, kib)
              for scene in ["rtrt", "conference"] for width in [8, 16]
              for kib, tile in [(128.0, 36), (256.0, 52), (512.0, 73)]]
    report = write_report(write_store(str(tmp_path / "auto.db"), points), str(tmp_path / "r"))
    plot = {p.name: p for p in report.plots}["fps_vs_buffer"]
    assert plot.file and "best tile" in plot.caption, plot.skipped
    one_size = [point("rtrt", tile, 16, 512.0) for tile in [32, 64]]
    report = write_report(write_store(str(tmp_path / "one.db"), one_size), str(tmp_path / "r1"))
    plot = {p.name: p for p in report.plots}["fps_vs_buffer"]
    assert plot.file is None and "two ray-buffer sizes" in plot.skipped


def test_pareto_front():
    area = [256, 256, 512, 1024, 1024]
    fps = [10, 12, 11, 15, 15]
    assert pareto_front(area, fps) == [1, 3]


def sfx_binary():
    candidates = [os.environ.get("SFX_BIN", "")] + [
        os.path.join(os.path.dirname(__file__), "..", "..", d, "sfx")
        for d in ["build", "build-analysis"]]
    for c in candidates:
        if c and os.access(c, os.X_OK):
            return c
    return None


@pytest.mark.skipif(sfx_binary() is None, reason="no built sfx (set SFX_BIN)")
def test_sfx_report_command(grid_store, tmp_path):
    sfx = sfx_binary()
    out = tmp_path / "r"
    done = subprocess.run([sfx, "report", grid_store, "-o", str(out)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "report: " in done.stdout and (out / "index.html").exists()
    assert "25.00 fps" in done.stdout  # Table 6 printed
    old = write_store(str(tmp_path / "old.db"), grid_points(), schema_version="0")
    done = subprocess.run([sfx, "report", old, "-o", str(out)], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2 and "older" in done.stderr and "Traceback" not in done.stderr
    done = subprocess.run([sfx, "report", str(tmp_path / "none.db")], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 2


def test_area_and_energy_fronts_name_their_designs(buffer_store, tmp_path):
    report = write_report(buffer_store, str(tmp_path / "r"))
    plots = {p.name: p for p in report.plots}
    for name in ["pareto_fps_vs_area", "pareto_energy_vs_fps"]:
        assert not plots[name].skipped, plots[name].skipped
        assert os.path.isfile(os.path.join(report.directory, plots[name].file))
    # conftest: fps rises with width and tile, area with width and kib: at 128 KiB both widths
    # and the larger tile are on the fps/area front of each scene.
    caption = plots["pareto_fps_vs_area"].caption
    assert "N=4 tile=32 kib=128" in caption and "N=16 tile=32 kib=128" in caption
    assert "90 nm" in caption


def test_fronts_skip_stores_without_area(tmp_path):
    points = [{k: v for k, v in p.items() if not k.startswith(("area.", "energy."))}
              for p in grid_points()]
    report = write_report(write_store(str(tmp_path / "old.db"), points), str(tmp_path / "r"))
    skipped = {p.name: p.skipped for p in report.plots if p.skipped}
    assert "area.total_mm2" in skipped["pareto_fps_vs_area"]
    assert "energy.total_per_frame_mj" in skipped["pareto_energy_vs_fps"]


def test_plots_name_the_technology_node(tmp_path):
    # A store of one node names it in every drawn plot's title; older stores (no hw.tech.node)
    # fall back to tech.node_nm.
    points = [dict(p, **{"hw.tech.node": "7nm", "tech.node_nm": 7.0})
              for p in grid_points(kibs=(128.0, 512.0))]
    report = write_report(write_store(str(tmp_path / "n.db"), points), str(tmp_path / "r"))
    drawn = [p for p in report.plots if not p.skipped]
    assert drawn and all(p.title.endswith("(7nm)") for p in drawn), [p.title for p in drawn]
    old = write_report(write_store(str(tmp_path / "o.db"), grid_points()), str(tmp_path / "o"))
    assert all(p.title.endswith("(90nm)") for p in old.plots if not p.skipped)

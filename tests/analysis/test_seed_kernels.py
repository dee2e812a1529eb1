"""docs/seed-kernels.md's builder: points paired by one option, changes computed from the pair."""

from conftest import write_store

from sfx_analysis.seed_kernels import build_page
from sfx_analysis.store import load_store


def seed_point(entry, reorder, fps, box_primary, misses, ppm=20000, option=0.0, depth=0.0):
    return {"workload.scene": "conference", "workload.tile": 16, "hw.simd.width": 16.0,
            "fidelity": "full", "workload.primary_entry": entry, "workload.reorder": reorder,
            "workload.reorder_lod_ppm": ppm, "fps": fps,
            "trace.box_tests_per_ray.primary": box_primary,
            "trace.box_tests_per_ray.secondary": 50.0, "trace.entry_depth": depth,
            "op_mix.option_percent": option, "scene_cache.l1.misses": 1.0,
            "scene_cache.l2.misses": misses, "scene_cache.l3.misses": 1.0}


def test_page_pairs_points_by_option(tmp_path):
    points = [seed_point("root", "none", 40.0, 40.0, 1000.0),
              seed_point("aepsa", "none", 44.0, 30.0, 1000.0, option=1.5, depth=2.25),
              seed_point("root", "hit_point", 30.0, 40.0, 1200.0, option=28.0),
              seed_point("root", "hit_point", 35.0, 40.0, 1100.0, ppm=500, option=20.0)]
    store = load_store(write_store(str(tmp_path / "s.db"), points))
    page = build_page(store, "scripts/seed-kernels")
    assert "Regenerate with `scripts/seed-kernels`" in page
    # AEPSA: 40 -> 30 box tests per primary ray is -25 %, fps 40 -> 44 is +10 %.
    assert "| conference | 16 | 16 | 40.0 | 30.0 | -25.0 % | 2.25 | 1.50 | 40.0 | 44.0 | +10.0 % |" in page
    # Reordering at 2 %: L2 misses 1000 -> 1200 (+20 %), fps 40 -> 30 (-25 %).
    assert "| conference | 16 | 16 | 1000 | 1200 | +20.0 % |" in page
    assert "| 30.0 | -25.0 % |" in page
    # The fraction axis against the same baseline: 0.05 % and 2 %.
    assert "| 0.05 % | 20.0 | 35.0 | -12.5 % |" in page
    assert "| 2 % | 28.0 | 30.0 | -25.0 % |" in page
    assert "does not appear on our model" in page
    assert "## RayGrid batching (seeds/000 Sec. 3)" in page


def raygrid_point(batching, depth, fps, box_secondary, node1, option=0.0):
    p = seed_point("root", "none", fps, 40.0, 1000.0, option=option)
    p.update({"workload.tile": 32, "workload.depth": depth, "workload.batching": batching,
              "workload.batching_queue": 384, "workload.batching_cell_prims": 4096,
              "trace.box_tests_per_ray.secondary": box_secondary,
              "ideal_simd_utilization.secondary.traversal": 0.5,
              "scene_cache.l1.hit_rate": 0.5, "scene_cache.l2.hit_rate": 0.25,
              "trace.bounce1.rays_per_node": node1, "trace.bounce1.rays_per_leaf": 2.0,
              "trace.batching.mean_queue_length": 20.0 if batching == "raygrid" else 0.0,
              "trace.batching.full_queue_share": 0.1 if batching == "raygrid" else 0.0,
              "trace.batching.lanes_per_ray": 55.0 if batching == "raygrid" else 0.0})
    return p


def test_raygrid_section_pairs_by_batching_and_reads_bounce_steps(tmp_path):
    # Frame times (ms): none 10 -> 12.5 from depth 0 to 1 (bounce 1 costs 2.5 ms); raygrid
    # 10 -> 15 (5 ms): bounce 1 is half as fast, a gain of -50 %.
    points = [raygrid_point("none", 0, 100.0, 0.0, 0.0),
              raygrid_point("raygrid", 0, 100.0, 0.0, 0.0),
              raygrid_point("none", 1, 80.0, 50.0, 14.0),
              raygrid_point("raygrid", 1, 1000.0 / 15.0, 40.0, 8.0, option=30.0)]
    for p in points:  # the options table reads the batching columns of conference points
        p["workload.primary_entry"] = "root"
    store = load_store(write_store(str(tmp_path / "r.db"), points))
    page = build_page(store)
    # Depth 1 row: box tests 50 -> 40, fps 80 -> 66.7 (-16.7 %).
    assert "| conference | 32 | 16 | 50.0 | 40.0 | 50.0 | 50.0 | 50.0 / 25.0 | 50.0 / 25.0 | 20.0 | 10 | 55.0 | 30.0 | 80.0 | 66.7 | -16.7 % |" in page
    assert "| conference | 1 | 14.0 | 8.0 | 2.0 | 2.0 | 2.50 | 5.00 | -50.0 % |" in page
    assert "The paper's gain does not appear" in page


def test_report_section_shows_options_side_by_side(tmp_path):
    from sfx_analysis.seed_kernels import html_section
    points = [seed_point("root", "none", 40.0, 40.0, 1000.0),
              seed_point("aepsa", "none", 44.0, 30.0, 1000.0, option=1.5, depth=2.25)]
    store = load_store(write_store(str(tmp_path / "s.db"), points))
    section = html_section(store)
    assert "<h2>Seed-paper options</h2>" in section
    # One row per option combination: fps, then box tests per primary ray.
    assert "<td>aepsa</td><td>none</td>" in section
    assert "<td>44.0</td>" in section and "<td>30.0</td>" in section
    # A store with every option off has no such section.
    plain = load_store(write_store(str(tmp_path / "p.db"),
                                   [seed_point("root", "none", 40.0, 40.0, 1000.0)]))
    assert html_section(plain) == ""

"""docs/seed-kernels.md's builder: points paired by one option, changes computed from the pair."""

from conftest import write_store

from sfx_analysis.seed_kernels import build_page
from sfx_analysis.store import load_store


def seed_point(entry, reorder, fps, box_primary, misses, ppm=20000, option=0.0, depth=0.0):
    return {"workload.scene": "conference", "workload.tile": 16, "hw.simd.width": 16.0,
            "fidelity": "full", "workload.primary_entry": entry, "workload.reorder": reorder,
            "workload.reorder_lod_ppm": ppm, "fps": fps,
            "workload.box_tests_per_ray.primary": box_primary,
            "workload.box_tests_per_ray.secondary": 50.0, "workload.entry_depth": depth,
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
    assert "RayGrid batching (seeds/000 Sec. 3): not built" in page

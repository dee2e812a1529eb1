"""Tables 2-6 from a store built in the test: shape and values computed by hand."""

from conftest import grid_points, point, write_store
from sfx_analysis.store import display_name, load_store
from sfx_analysis.tables import MISSING, Section, build_tables, to_html, to_markdown


def by_ident(tables):
    return {t.ident: t for t in tables}


def test_table2_shape_and_values(grid_store):
    t = by_ident(build_tables(load_store(grid_store)))["table2"]
    assert t.header == ["size", "conference", "rtrt"]
    assert [r.text for r in t.rows if isinstance(r, Section)] == ["SIMD width N = 4",
                                                                  "SIMD width N = 16"]
    assert len(t.body()) == 4  # two tiles per width
    # conference, tile 32, N = 4: ideal T = 0.6 + 0.01*8*1 = 0.68, effective 0.9*0.68 = 0.612;
    # I: 0.6 + 0.01*8*2 = 0.76 -> 0.684.
    assert t.cell("32×32", "conference", "SIMD width N = 4") == "61 / 68"
    # N = 16, tile 8: ideal T = 0.6 + 0.005 = 0.605 -> 0.5445; I 0.61 -> 0.549.
    assert t.cell("8×8", "rtrt", "SIMD width N = 16") == "54 / 55"
    ideal = by_ident(build_tables(load_store(grid_store)))["table2-ideal"]
    assert ideal.cell("32×32", "conference", "SIMD width N = 4") == "68 / 76"


def test_table3_4_5_6_values(grid_store):
    tables = by_ident(build_tables(load_store(grid_store)))
    # S at tile 32, N = 4: ideal 0.6 + 0.08*3 = 0.84 -> 0.756.
    assert tables["table3"].cell("32×32", "rtrt", "SIMD width N = 4") == "61 / 68 / 76"
    t4 = tables["table4"]
    # Width-invariant stream lengths: one row per (scene, tile); tile*(k+1)/4.
    assert t4.header == ["scene", "size", "trav", "isec", "shade"]
    assert t4.body() == [["conference", "8×8", "2.0", "4.0", "6.0"],
                         ["", "32×32", "8.0", "16.0", "24.0"],
                         ["rtrt", "8×8", "2.0", "4.0", "6.0"],
                         ["", "32×32", "8.0", "16.0", "24.0"]]
    t5 = tables["table5"]
    assert len(t5.body()) == 8
    # load 24.1 + (16-4)/100 = 24.22 at N = 16.
    assert t5.body()[1] == ["", "8×8", "16", "24.2", "15.0", "35.5", "19.7", "5.1"]
    t6 = tables["table6"]
    # rtrt: 20 + 16/4 + 32/32 = 25.
    assert t6.cell("32×32", "rtrt", "SIMD width N = 16") == "25.00 fps"
    assert t6.cell("8×8", "conference", "SIMD width N = 4") == "11.25 fps"


def test_missing_cells_are_shown_not_invented(tmp_path):
    points = grid_points()
    points = [p for p in points if not (p["workload.scene"] == "rtrt" and p["workload.tile"] == 8
                                         and p["hw.simd.width"] == 16.0)]
    for p in points:
        del p["simd_utilization.secondary.shading"]
        del p["ideal_simd_utilization.secondary.shading"]
    store = load_store(write_store(str(tmp_path / "m.db"), points))
    tables = by_ident(build_tables(store))
    assert tables["table6"].cell("8×8", "rtrt", "SIMD width N = 16") == MISSING
    assert tables["table3"].cell("8×8", "conference", "SIMD width N = 16").endswith(f"/ {MISSING}")
    assert any("simd_utilization.secondary.shading" in n for n in tables["table3"].notes)
    assert "—" in to_markdown(tables["table3"]) and 'class="missing"' in to_html(tables["table3"])


def test_no_operations_is_missing_not_zero(tmp_path):
    p = point("rtrt", 8, 4, **{"ideal_simd_utilization.secondary.traversal": 0.0,
                               "simd_utilization.secondary.traversal": 0.0})
    tables = by_ident(build_tables(load_store(write_store(str(tmp_path / "z.db"), [p]))))
    assert tables["table3"].cell("8×8", "rtrt").startswith(MISSING + " /")


def test_varying_buffer_size_gives_one_block_per_context(buffer_store):
    tables = build_tables(load_store(buffer_store))
    fps = [t for t in tables if t.ident.startswith("table6")]
    assert len(fps) == 2
    assert "hw.ray_buffer.kib = 128" in fps[0].title and "hw.ray_buffer.kib = 512" in fps[1].title


def test_units_only_in_display_names_and_read_from_the_store(tmp_path):
    # Units the analysis could not have typed itself: they can only come from the store.
    units = {"fps": "frames per moon", "hw.ray_buffer.kib": "KiB", "simd_utilization.traversal": ""}
    store = load_store(write_store(str(tmp_path / "u.db"), grid_points(), units=units))
    assert "fps" in store.points.columns and "fps [frames per moon]" not in store.points.columns
    assert display_name("fps", store.units) == "fps [frames per moon]"
    assert display_name("hw.ray_buffer.kib", store.units) == "hw.ray_buffer.kib [KiB]"
    assert display_name("simd_utilization.traversal", store.units) == "simd_utilization.traversal"
    assert display_name("stall_cycles.partition", store.units) == "stall_cycles.partition"
    # A store written before the units table: names without units, no error.
    assert load_store(write_store(str(tmp_path / "old.db"), grid_points())).units == {}

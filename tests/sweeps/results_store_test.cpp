// The results store (schema version 1): columns and types, one row per key, new stat columns,
// CSV export; and a point group run from its JSON spec.

#include "sweeps/results_store.h"

#include <sqlite3.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "sweeps/group_runner.h"
#include "sweeps/store_compare.h"
#include "sweeps/sha256.h"
#include "sweeps/sweep.h"
#include "tests/temp_dir.h"
#include "base/input_error.h"

using namespace sfx;
namespace fs = std::filesystem;

namespace {

Sweep small_sweep(const std::string& fidelity = "analytic") {
    return parse_sweep(
        "version: 1\nhw: gr08.hw.yaml\n"
        "workload: {scene: cornell, res: 16x16, spp: 1, tile: 8}\n"
        "fidelity: " +
            fidelity +
            "\n"
            "axes:\n  hw.simd.width: [4, 8]\n",
        "small.sweep.yaml", SFX_SOURCE_DIR "/hw_model/presets");
}

std::vector<SweepPoint> group_points(const Sweep& sweep, size_t group) {
    std::vector<SweepPoint> out;
    for (size_t i : sweep.groups[group].points) out.push_back(sweep.point(i));
    return out;
}

PointRun fake_run(const std::string& key, double fps) {
    PointRun r;
    r.key = key;
    r.sfx_version = sfx_version();
    r.started_at = r.finished_at = iso8601_now();
    r.metrics = {{"fps", fps}, {"error.relative", -1}, {"scene_cache.l1.hit_rate", std::nan("")}};
    r.units = {{"fps", {"frames/s", "predicted frame rate"}}, {"error.relative", {"", "interval"}}};
    return r;
}

std::string query(sqlite3* db, const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    REQUIRE(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) == SQLITE_OK);
    std::string out;
    while (sqlite3_step(s) == SQLITE_ROW) {
        for (int c = 0; c < sqlite3_column_count(s); ++c) {
            const unsigned char* t = sqlite3_column_text(s, c);
            out += (c ? "|" : "") + std::string(t ? reinterpret_cast<const char*>(t) : "NULL");
        }
        out += "\n";
    }
    sqlite3_finalize(s);
    return out;
}

}  // namespace

TEST_CASE("The store keeps one row per key with typed, dotted columns", "[sweeps]") {
    TempDir dir;
    const std::string db = (dir.path / "r.db").string();
    const Sweep sweep = small_sweep();
    {
        ResultsStore store(db);
        CHECK(store.keys().empty());
        CHECK(store.write_point(sweep.all_points()[0], sweep.name, fake_run(sweep.all_points()[0].key, 10)));
        CHECK_FALSE(
            store.write_point(sweep.all_points()[0], sweep.name, fake_run(sweep.all_points()[0].key, 99)));
        CHECK(store.contains(sweep.all_points()[0].key));
        CHECK_FALSE(store.contains(sweep.all_points()[1].key));
        // A later sfx adds a stat: it becomes a new column, NULL in older rows.
        PointRun later = fake_run(sweep.all_points()[1].key, 20);
        later.metrics.emplace_back("new_stat.cycles", 5);
        CHECK(store.write_point(sweep.all_points()[1], sweep.name, later));
        sqlite3* h = store.handle();
        CHECK(query(h, "SELECT value FROM meta WHERE key = 'schema_version'") == "1\n");
        CHECK(query(h, "SELECT value FROM meta WHERE key = 'created_by'") ==
              std::string("sfx ") + sfx_version() + "\n");
        CHECK(query(h, "SELECT count(*) FROM points") == "2\n");
        CHECK(query(h, "SELECT fps FROM points ORDER BY point_index") ==
              "10.0\n20.0\n");  // not overwritten
        CHECK(query(h, "SELECT \"new_stat.cycles\" FROM points ORDER BY point_index") ==
              "NULL\n5.0\n");
        CHECK(query(h, "SELECT \"scene_cache.l1.hit_rate\" FROM points LIMIT 1") == "NULL\n");
        CHECK(query(h, "SELECT \"hw.simd.width\", \"hw.name\", \"hw.ray_buffer.pipelined\", "
                       "\"hw.scene_memory.caches[2].kib\", \"workload.scene\", \"workload.tile\", fidelity, sweep "
                       "FROM points ORDER BY point_index") ==
              "4.0|gr08|true|2048.0|cornell|8|analytic|small\n8.0|gr08|true|2048.0|cornell|8|analytic|small\n");
        const std::string types = query(h, "SELECT name, type FROM pragma_table_info('points') WHERE name IN "
                                           "('hw.simd.width', 'hw.name', 'fps', 'point_index', 'key')");
        CHECK(types == "key|TEXT\npoint_index|INTEGER\nhw.name|TEXT\nhw.simd.width|REAL\nfps|REAL\n");
        // Units come from the declarations: stats() for metrics, the visit()s for hw and workload.
        CHECK(
            query(h,
                  "SELECT name, unit, description FROM units WHERE name IN ('fps', "
                  "'error.relative', 'hw.simd.width', 'hw.ray_buffer.kib', 'workload.tile') "
                  "ORDER BY name") ==
            "error.relative||interval\nfps|frames/s|predicted frame rate\n"
            "hw.ray_buffer.kib|KiB|size of one ray buffer\nhw.simd.width|lanes|SIMD lanes per "
            "unit\n"
            "workload.tile|pixels|tile edge: the stream holds tile^2 rays (auto: the largest that "
            "fits the ray buffer)\n");
        // The stored YAML reproduces the point.
        const std::string yaml = query(h, "SELECT config_yaml FROM points WHERE point_index = 1");
        CHECK(point_key(yaml.substr(0, yaml.size() - 1)) == sweep.all_points()[1].key);

        store.export_csv((dir.path / "r.csv").string());
    }
    std::ifstream csv(dir.path / "r.csv");
    std::string header, row;
    std::getline(csv, header);
    std::getline(csv, row);
    CHECK(header.rfind("key,sfx_version,sweep,point_index,started_at,finished_at,workload.scene,",
                       0) == 0);
    CHECK(header.find("hw.simd.width") != std::string::npos);
    CHECK(header.find("config_yaml") == std::string::npos);
    CHECK(header.find(",fps,") != std::string::npos);
    CHECK(row.rfind(sweep.all_points()[0].key + ",", 0) == 0);

    // Reopening keeps everything; a store of another schema version is refused.
    ResultsStore again(db);
    CHECK(again.keys().size() == 2);
    sqlite3_exec(again.handle(), "UPDATE meta SET value = '9' WHERE key = 'schema_version'",
                 nullptr, nullptr, nullptr);
    CHECK_THROWS_AS(ResultsStore(db), InputError);
    std::ofstream((dir.path / "text.db").string())
        << "not a database, just some text that is long enough\n";
    CHECK_THROWS_AS(ResultsStore((dir.path / "text.db").string()), InputError);
}

TEST_CASE("A group's rows are written in one transaction, and stored keys are found in batches",
          "[sweeps]") {
    TempDir dir;
    ResultsStore store((dir.path / "b.db").string());
    const Sweep sweep = small_sweep();
    const std::vector<SweepPoint> points = sweep.all_points();
    REQUIRE(points.size() == 2);
    CHECK(store.write_points({{&points[0], fake_run(points[0].key, 1)}}, sweep.name) == 1);
    // A batch with a stored row and a new one: only the new one counts.
    CHECK(store.write_points({{&points[0], fake_run(points[0].key, 5)}, {&points[1], fake_run(points[1].key, 2)}},
                             sweep.name) == 1);
    CHECK(store.numbers(points[0].key).at("fps") == 1);  // the first write stays
    // A batch that fails part-way leaves nothing of itself.
    const Sweep other = small_sweep("full");
    const std::vector<SweepPoint> more = other.all_points();
    PointRun bad = fake_run(more[1].key, 3);
    for (int i = 0; i < 2000; ++i)  // beyond SQLite's 2000 columns a table: the ALTER fails
        bad.metrics.emplace_back("extra." + std::to_string(i), 1.0);
    CHECK_THROWS(store.write_points({{&more[0], fake_run(more[0].key, 4)}, {&more[1], bad}}, other.name));
    CHECK_FALSE(store.contains(more[0].key));
    // Keys by the thousand: one query per few hundred.
    std::vector<std::string> asked = {points[1].key, more[0].key};
    for (int i = 0; i < 1200; ++i) asked.push_back(sha256_hex(std::to_string(i)));
    CHECK(store.stored_keys(asked) == std::set<std::string>{points[1].key});
}

TEST_CASE("A point group runs from its JSON spec: one row per point, keys from the YAML",
          "[sweeps]") {
    const Sweep sweep = small_sweep();
    const nlohmann::json spec = group_spec_json(group_points(sweep, 0), 1);
    const std::vector<PointRun> rows = run_group(nlohmann::json::parse(spec.dump()));
    REQUIRE(rows.size() == 2);
    for (size_t i = 0; i < rows.size(); ++i) {
        CHECK(rows[i].key == sweep.point(sweep.groups[0].points[i]).key);
        CHECK(rows[i].sfx_version == sfx_version());
        // The JSON line a worker prints reads back the same.
        const PointRun back =
            point_run_from_json(nlohmann::ordered_json::parse(point_run_json(rows[i]).dump()));
        CHECK(back.key == rows[i].key);
        REQUIRE(back.metrics.size() == rows[i].metrics.size());
        CHECK(back.metrics.front().first == "fps");
        CHECK(back.metrics.front().second == rows[i].metrics.front().second);
        CHECK(back.units == rows[i].units);
        CHECK(back.units.at("fps") ==
              std::make_pair(std::string("frames/s"), std::string("predicted frame rate")));
    }
    CHECK(rows[0].metrics.front().second > 0);
    CHECK(rows[0].metrics.front().second != rows[1].metrics.front().second);  // widths 4 vs 8

    // Every fidelity of the ladder is accepted by the sweep language.
    CHECK(small_sweep("sampled").all_points()[0].fidelity == Fidelity::sampled);
    CHECK(small_sweep("full").all_points()[0].fidelity == Fidelity::full);
    // Points of different renders cannot share a group.
    const Sweep two = parse_sweep(
        "version: 1\nhw: gr08.hw.yaml\nworkload: {scene: cornell, res: 16x16, spp: 1}\n"
        "axes:\n  workload.seed: [1, 2]\n",
        "two.sweep.yaml", SFX_SOURCE_DIR "/hw_model/presets");
    REQUIRE(two.groups.size() == 2);
    CHECK_THROWS_AS(run_group(group_spec_json(two.all_points(), 1)), InputError);
}

TEST_CASE("Two store selections are matched on every other input and compared by means",
          "[sweeps]") {
    TempDir dir;
    ResultsStore store((dir.path / "c.db").string());
    const Sweep sweep = parse_sweep(
        "version: 1\nhw: gr08.hw.yaml\n"
        "workload: {scene: cornell, res: 16x16, spp: 1, tile: 8}\n"
        "axes:\n  workload.seed: [1, 2]\n  hw.simd.width: [8, 16]\n"
        "  hw.ray_buffer.banks: [16, 32]\n",
        "c.sweep.yaml", SFX_SOURCE_DIR "/hw_model/presets");
    REQUIRE(sweep.point_count == 8);
    // fps = width * seed; banks 32 rows are left out of the store except for width 8, seed 1.
    for (const SweepPoint& p : sweep.all_points()) {
        if (p.hw.ray_buffer.banks == 32 && !(p.hw.simd.width == 8 && p.workload.seed == 1))
            continue;
        store.write_point(p, sweep.name,
                          fake_run(p.key, double(p.hw.simd.width * p.workload.seed)));
    }
    const StoreComparison c = compare_store(store, parse_selection("hw.simd.width=8", "--a"),
                                            parse_selection("hw.simd.width=16", "--b"));
    CHECK(c.rows_a == 3);
    CHECK(c.rows_b == 2);
    CHECK(c.matched == 2);  // (seed 1, 16 banks) and (seed 2, 16 banks); banks 32 has no B
    CHECK(c.mean_a.at("fps") == Approx((8.0 + 16.0) / 2));
    CHECK(c.mean_b.at("fps") == Approx((16.0 + 32.0) / 2));
    CHECK(c.mean_a.count("point_index") == 0);  // bookkeeping is not a metric
    // Two conditions at once; text and number columns.
    const StoreComparison d =
        compare_store(store, parse_selection("hw.simd.width=8,workload.seed=1", "--a"),
                      parse_selection("hw.simd.width=16,workload.seed=1", "--b"));
    CHECK(d.matched == 1);
    CHECK(d.mean_b.at("fps") == Approx(16.0));
    CHECK_THROWS_AS(compare_store(store, parse_selection("hw.simd.lanes=8", "--a"),
                                  parse_selection("hw.simd.width=16", "--b")),
                    InputError);
    CHECK_THROWS_AS(compare_store(store, parse_selection("hw.simd.width=4", "--a"),
                                  parse_selection("hw.simd.width=16", "--b")),
                    InputError);
    CHECK_THROWS_AS(parse_selection("hw.simd.width", "--a"), InputError);
}

TEST_CASE("Another program's SQLite database is refused and left untouched", "[sweeps]") {
    TempDir dir;
    const std::string db = (dir.path / "other.db").string();
    sqlite3* h = nullptr;
    REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
    REQUIRE(sqlite3_exec(h, "CREATE TABLE t(x); INSERT INTO t VALUES (1)", nullptr, nullptr,
                         nullptr) == SQLITE_OK);
    sqlite3_close(h);
    auto bytes = [&] {
        std::ifstream in(db, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string before = bytes();
    CHECK_THROWS_WITH(ResultsStore(db),
                      Catch::Contains("not an sfx results store (its tables: t;"));
    CHECK_THROWS_WITH(ResultsStore(db, ResultsStore::Access::read_only),
                      Catch::Contains("not an sfx results store"));
    CHECK(bytes() == before);
    CHECK_FALSE(fs::exists(db + "-wal"));
    // Read-only never creates a store.
    CHECK_THROWS_WITH(
        ResultsStore((dir.path / "none.db").string(), ResultsStore::Access::read_only),
        Catch::Contains("no such results store"));
    CHECK_FALSE(fs::exists(dir.path / "none.db"));
}

TEST_CASE("A store with NULLs where text belongs, or without sfx's columns, says what is wrong",
          "[sweeps]") {
    TempDir dir;
    auto make = [&](const std::string& name, const char* sql) {
        const std::string db = (dir.path / name).string();
        sqlite3* h = nullptr;
        REQUIRE(sqlite3_open(db.c_str(), &h) == SQLITE_OK);
        REQUIRE(sqlite3_exec(h, sql, nullptr, nullptr, nullptr) == SQLITE_OK);
        sqlite3_close(h);
        return db;
    };
    const std::string null_version =
        make("null.db",
             "CREATE TABLE meta(key TEXT, value TEXT); CREATE TABLE points(key TEXT);"
             "INSERT INTO meta VALUES('schema_version', NULL)");
    CHECK_THROWS_WITH(ResultsStore(null_version, ResultsStore::Access::read_only),
                      Catch::Contains("meta.schema_version: results store has schema version ''"));
    // A bare points table: no input column to compare on, and the message must not offer the
    // missing column as an example.
    const std::string bare =
        make("bare.db",
             "CREATE TABLE meta(key TEXT, value TEXT); CREATE TABLE points(key TEXT);"
             "INSERT INTO meta VALUES('schema_version', '1')");
    const ResultsStore store(bare, ResultsStore::Access::read_only);
    CHECK_THROWS_WITH(
        compare_store(store, parse_selection("hw.simd.width=8", "--a"),
                      parse_selection("hw.simd.width=16", "--b")),
        Catch::Equals("command line: --a: the store has no column 'hw.simd.width': it "
                      "has no input columns at all"));
}

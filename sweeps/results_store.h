#pragma once
// The results store: one SQLite file, one row per point, written through SQLite's C API.
// The schema (version 1) is a contract with analysis/ and is described in sweeps/README.md:
// meta(key, value) and points(key, sfx_version, sweep, point_index, started_at, finished_at,
// config_yaml, "workload.*", fidelity, "hw.*" per parameter, one REAL column per stat) and
// units(name, unit, description): every workload, hw and stat column's unit, from the visit()
// or stats() that declares it, so analysis reads units rather than re-typing them.
//
// Each point is written in its own transaction (new stat columns included), so a process
// killed at any instant leaves only whole rows; the key makes re-writes no-ops.

#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "sweeps/explore.h"
#include "sweeps/sweep.h"

struct sqlite3;

namespace sfx {

// What a worker returns for one point (`sfx run-group` prints it as one JSON line).
struct PointRun {
    std::string key;
    std::string sfx_version;
    std::string started_at, finished_at;  // ISO-8601 UTC
    std::vector<std::pair<std::string, double>> metrics;  // Prediction::stats() names; NaN: NULL
    // Unit and description of each metric (Prediction::stats()), for the store's units table.
    std::map<std::string, std::pair<std::string, std::string>> units;
};

class ResultsStore {
public:
    static constexpr int k_schema_version = 1;

    enum class Access { read_write, read_only };
    // Opens or creates the store; throws InputError if the file is not a version-1 store
    // (another SQLite database is refused before anything is written to it). read_only
    // never writes and works in a read-only directory.
    explicit ResultsStore(const std::string& path, Access access = Access::read_write);
    ~ResultsStore();
    ResultsStore(const ResultsStore&) = delete;
    ResultsStore& operator=(const ResultsStore&) = delete;

    std::set<std::string> keys() const;
    bool contains(const std::string& key) const;
    // Writes one point in one transaction; false if its key was already stored.
    bool write_point(const SweepPoint& point, const std::string& sweep, const PointRun& run);
    // Writes a batch of points (a group's rows) in one transaction: all of them or none.
    // Returns how many were new.
    struct PointRow {
        const SweepPoint* point;
        PointRun run;
    };
    size_t write_points(const std::vector<PointRow>& rows, const std::string& sweep);
    // Which of `keys` are stored (one query per few hundred keys).
    std::set<std::string> stored_keys(const std::vector<std::string>& keys) const;

    // Metric and column values of one stored row by column name (NULLs left out).
    std::map<std::string, double> numbers(const std::string& key) const;
    // Every column name of the points table, in table order.
    std::vector<std::string> columns() const;

    // Every row: text of the TEXT columns, values of the numeric ones (NULLs left out).
    struct RowValues {
        std::map<std::string, std::string> text;
        std::map<std::string, double> numbers;
    };
    std::vector<RowValues> rows() const;

    // Writes the given keys' rows (all rows if `keys` is empty) as CSV: one column per stored
    // column except config_yaml, in table order; rows by sweep and point index.
    void export_csv(const std::string& csv_path, const std::vector<std::string>& keys = {}) const;

    // Explores (`sfx explore`): explores(name, file, fingerprint, spec) and
    // explore_configs(explore, config, stage, trial, knobs, fps, fps_error, area_mm2, energy_mj,
    // power_w, fps_per_mm2, feasible, front): each configuration an explore screened
    // (stage 'screen') and each one of the screened front it re-ran (stage 'confirm'). The
    // tables are made by the first explore. An explore whose fingerprint changed (its file's
    // space or objectives) starts anew: its old configurations are removed.
    void begin_explore(const std::string& name, const std::string& file, const std::string& fingerprint,
                       const std::string& spec_json);
    struct ExploreConfigRow {
        size_t config = 0;
        std::string stage;  // screen | confirm
        int64_t trial = -1;  // the Optuna trial that first asked for it (-1: none)
        std::string knobs_json;
        ExploreScore score;
        bool feasible = false, front = false;
    };
    // Inserts or replaces rows, in one transaction.
    void write_explore_configs(const std::string& explore, const std::vector<ExploreConfigRow>& rows);
    // (config, trial) of an explore's rows at `stage`, by config.
    std::vector<std::pair<size_t, int64_t>> explore_configs(const std::string& explore, const std::string& stage) const;

    sqlite3* handle() const { return m_db; }

private:
    // What a batch's rows share: prepared inserts by column list, units already written.
    struct Batch;
    bool insert_point(const SweepPoint& point, const std::string& sweep, const PointRun& run, Batch& batch);
    void exec(const std::string& sql) const;
    void ensure_column(const std::string& name, const char* type);

    std::string m_path;
    sqlite3* m_db = nullptr;
    std::set<std::string> m_columns;
};

// Quotes an identifier for SQL ("hw.simd.width" -> "\"hw.simd.width\"").
std::string sql_quote_identifier(const std::string& name);

// The current time as ISO-8601 UTC with milliseconds ("2026-11-22T01:02:03.456Z").
std::string iso8601_now();

}  // namespace sfx

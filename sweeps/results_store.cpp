#include "sweeps/results_store.h"

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <thread>

#include "base/input_error.h"
#include "base/strict_number.h"
#include "base/user_files.h"

namespace sfx {
namespace {

// One hardware column: its name, SQL type (numbers REAL, strings and bools TEXT), unit and
// description.
struct HwColumn {
    std::string name;
    bool numeric = false;
    std::string unit, description;
};

// Hardware columns, from the same visit() that drives YAML.
class HwColumns {
public:
  explicit HwColumns(std::vector<HwColumn>& out, std::string prefix = "")
      : m_out(out), m_prefix(std::move(prefix)) {}
  template <class T, class B>
  void param(const char* name, T& value, const char* unit, const char* description, B, B) {
      param(name, value, unit, description);
    }
    template <class T>
    void param(const char* name, T&, const char* unit, const char* description) {
        m_out.push_back({join(name), std::is_arithmetic<T>::value && !std::is_same<T, bool>::value,
                         unit, description});
    }
    void choice(const char* name, std::string&, std::initializer_list<const char*>,
                const char* description) {
        m_out.push_back({join(name), false, "", description});
    }
    template <class G>
    void group(const char* name, G& g) {
        HwColumns c(m_out, join(name));
        g.visit(c);
    }
    template <class G>
    void list(const char* name, std::vector<G>& items, const char*) {
        for (size_t i = 0; i < items.size(); ++i) {
            HwColumns c(m_out, join(name) + "[" + std::to_string(i) + "]");
            items[i].visit(c);
        }
    }

private:
    std::string join(const char* name) const { return m_prefix.empty() ? name : m_prefix + "." + name; }
    std::vector<HwColumn>& m_out;
    std::string m_prefix;
};

class Statement {
  public:
    Statement(sqlite3* db, const std::string& sql) : m_db(db) {
        if (sqlite3_prepare_v2(db, sql.c_str(), -1, &m_stmt, nullptr) != SQLITE_OK)
            throw std::runtime_error("results store: " + std::string(sqlite3_errmsg(db)) +
                                     " in: " + sql);
    }
    ~Statement() { sqlite3_finalize(m_stmt); }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    sqlite3_stmt* get() const { return m_stmt; }
    void bind(int i, const std::string& text) {
        sqlite3_bind_text(m_stmt, i, text.c_str(), int(text.size()), SQLITE_TRANSIENT);
    }
    void bind(int i, double v) {
        if (std::isnan(v))
            sqlite3_bind_null(m_stmt, i);
        else
            sqlite3_bind_double(m_stmt, i, v);
    }
    void bind_int(int i, int64_t v) { sqlite3_bind_int64(m_stmt, i, v); }
    // Column `c` of the current row as text; SQL NULL (which a damaged or foreign file may hold
    // anywhere) is the empty string.
    std::string text(int c) const {
        const unsigned char* t = sqlite3_column_text(m_stmt, c);
        return t ? reinterpret_cast<const char*>(t) : std::string();
    }
    // SQLITE_ROW: true, SQLITE_DONE: false; anything else throws.
    bool step() {
        const int rc = sqlite3_step(m_stmt);
        if (rc == SQLITE_ROW) return true;
        if (rc == SQLITE_DONE) return false;
        throw std::runtime_error("results store: " + std::string(sqlite3_errmsg(m_db)));
    }

  private:
    sqlite3* m_db;
    sqlite3_stmt* m_stmt = nullptr;
};

// The columns every row has; the workload's come from WorkloadConfig's visit().
std::string fixed_columns() {
    std::string sql =
        "key TEXT PRIMARY KEY, sfx_version TEXT, sweep TEXT, point_index INTEGER, started_at TEXT, "
        "finished_at TEXT, config_yaml TEXT";
    for (const WorkloadColumn& c : workload_columns(WorkloadConfig{}))
        sql += ", " + sql_quote_identifier(c.name) + (c.integer ? " INTEGER" : " TEXT");
    return sql + ", fidelity TEXT";
}

constexpr const char* k_create_units =
    "CREATE TABLE IF NOT EXISTS units(name TEXT PRIMARY KEY, unit TEXT, description TEXT)";

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

}  // namespace

std::string sql_quote_identifier(const std::string& name) {
    std::string out = "\"";
    for (char c : name) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string iso8601_now() {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() %
        1000;
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                  tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, int(ms));
    return buf;
}

namespace {

// Tests only (tests/sweeps/kill_resume.sh): SFX_TEST_HOLD_COMMIT_MS keeps the write
// transaction open that long before COMMIT, after saying so on stderr, so that a kill -9 can
// land inside it.
void hold_before_commit_for_tests(const std::string& key) {
    static const char* hold = std::getenv("SFX_TEST_HOLD_COMMIT_MS");
    if (!hold || !*hold) return;
    std::fprintf(stderr, "sfx-test: inside the write transaction of %s\n", key.c_str());
    std::fflush(stderr);
    std::this_thread::sleep_for(std::chrono::milliseconds(std::atol(hold)));
}

// A path as the path part of an SQLite URI: '?' and '#' and '%' escaped, made absolute.
std::string sqlite_uri_path(const std::string& path) {
    const std::string abs = std::filesystem::absolute(path).string();
    std::string out;
    for (char c : abs) {
        if (c == '?' || c == '#' || c == '%') {
            char buf[4];
            std::snprintf(buf, sizeof buf, "%%%02X", static_cast<unsigned char>(c));
            out += buf;
        } else {
            out += c;
        }
    }
    return out;
}

bool directory_writable(const std::string& path) {
    std::string dir = std::filesystem::path(path).parent_path().string();
    return ::access(dir.empty() ? "." : dir.c_str(), W_OK | X_OK) == 0;
}

bool file_nonempty(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && st.st_size > 0;
}

}  // namespace

ResultsStore::ResultsStore(const std::string& path, Access access) : m_path(path) {
    const bool read_only = access == Access::read_only;
    if (::access(path.c_str(), F_OK) == 0)
        check_regular_file(path, "results store");
    else if (read_only)
        throw InputError(path, 0, "--store", "no such results store");
    // A read-only directory: SQLite cannot create the write-ahead log's index (-shm) beside
    // the store. With no log left to replay (a finished sweep leaves none) the file alone is
    // the whole store, and `immutable` reads it without the index.
    const bool immutable = read_only && !directory_writable(path) && !file_nonempty(path + "-wal");
    const std::string uri = "file:" + sqlite_uri_path(path) +
                            (read_only ? (immutable ? "?mode=ro&immutable=1" : "?mode=ro") : "");
    const int flags =
        (read_only ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE) |
        SQLITE_OPEN_URI;
    if (sqlite3_open_v2(uri.c_str(), &m_db, flags, nullptr) != SQLITE_OK) {
        const std::string msg = m_db ? sqlite3_errmsg(m_db) : "out of memory";
        sqlite3_close(m_db);
        m_db = nullptr;
        throw InputError(path, 0, "--store", "cannot open the results store: " + msg);
    }
    // Readers (analysis, a progress check) may look while a sweep writes: wait, don't fail.
    sqlite3_busy_timeout(m_db, 30000);
    try {
        // Is this a SQLite file at all, and ours? (A text file fails on the first query.)
        // Nothing is written before the answer is yes: another program's database stays untouched.
        std::vector<std::string> tables;
        {
            Statement probe(m_db,
                            "SELECT name FROM sqlite_master WHERE type='table' ORDER BY name");
            while (probe.step()) tables.push_back(probe.text(0));
        }
        const bool has_meta = std::find(tables.begin(), tables.end(), "meta") != tables.end();
        const bool has_points = std::find(tables.begin(), tables.end(), "points") != tables.end();
        if (!tables.empty() && (!has_meta || !has_points)) {
            std::string list;
            for (const std::string& t : tables) list += (list.empty() ? "" : ", ") + t;
            throw InputError(path, 0, "--store",
                             "an SQLite database but not an sfx results store (its tables: " +
                                 list + "; a store has meta and points); left untouched");
        }
        if (has_meta) {
            Statement v(m_db, "SELECT value FROM meta WHERE key='schema_version'");
            const std::string version = v.step() ? v.text(0) : "";
            if (version != std::to_string(k_schema_version))
                throw InputError(path, 0, "meta.schema_version",
                                 "results store has schema version '" + version +
                                     "'; this sfx writes " + std::to_string(k_schema_version));
        }
        if (read_only) {
            if (tables.empty())
                throw InputError(path, 0, "--store", "an empty file, not a results store");
        } else {
            // WAL: a reader never blocks the writer; NORMAL sync still survives a killed
            // process (only a power loss may drop the last transactions, never part of one).
            exec("PRAGMA journal_mode=WAL");
            exec("PRAGMA synchronous=NORMAL");
            exec("BEGIN IMMEDIATE");
            exec("CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT)");
            exec("INSERT OR IGNORE INTO meta(key, value) VALUES('schema_version', '" +
                 std::to_string(k_schema_version) + "'), ('created_by', 'sfx " + sfx_version() +
                 "')");
            exec(std::string("CREATE TABLE IF NOT EXISTS points(") + fixed_columns() + ")");
            exec(k_create_units);  // stores written before the table get it here
            exec("COMMIT");
        }
    } catch (const InputError&) {
        sqlite3_close(m_db);
        throw;
    } catch (const std::exception& e) {
        sqlite3_close(m_db);
        std::string what = e.what();
        if (read_only && !directory_writable(path) && file_nonempty(path + "-wal"))
            what +=
                " (the store's write-ahead log holds unfinished writes, and its directory is "
                "read-only: run sfx sweep on it once where it is writable, or copy it)";
        throw InputError(path, 0, "--store", "not a usable results store: " + what);
    }
    for (const std::string& c : columns()) m_columns.insert(c);
}

ResultsStore::~ResultsStore() {
    sqlite3_close(m_db);
}

void ResultsStore::exec(const std::string& sql) const {
    char* err = nullptr;
    if (sqlite3_exec(m_db, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
        const std::string msg = err ? err : "unknown error";
        sqlite3_free(err);
        throw std::runtime_error("results store " + m_path + ": " + msg +
                                 " in: " + sql.substr(0, 200));
    }
}

std::vector<std::string> ResultsStore::columns() const {
    std::vector<std::string> out;
    Statement s(m_db, "PRAGMA table_info(points)");
    while (s.step()) out.push_back(s.text(1));
    return out;
}

std::set<std::string> ResultsStore::keys() const {
    std::set<std::string> out;
    Statement s(m_db, "SELECT key FROM points");
    while (s.step()) out.insert(s.text(0));
    return out;
}

bool ResultsStore::contains(const std::string& key) const {
    Statement s(m_db, "SELECT 1 FROM points WHERE key = ?");
    s.bind(1, key);
    return s.step();
}

void ResultsStore::ensure_column(const std::string& name, const char* type) {
    if (m_columns.count(name)) return;
    exec("ALTER TABLE points ADD COLUMN " + sql_quote_identifier(name) + " " + type);
    m_columns.insert(name);
}

bool ResultsStore::write_point(const SweepPoint& point, const std::string& sweep, const PointRun& run) {
    return write_points({{&point, run}}, sweep) == 1;
}

void ResultsStore::begin_explore(const std::string& name, const std::string& file,
                                 const std::string& fingerprint, const std::string& spec_json) {
    exec("BEGIN IMMEDIATE");
    try {
        exec("CREATE TABLE IF NOT EXISTS explores(name TEXT PRIMARY KEY, file TEXT, fingerprint TEXT, spec TEXT)");
        exec("CREATE TABLE IF NOT EXISTS explore_configs(explore TEXT, config INTEGER, stage TEXT, "
             "trial INTEGER, knobs TEXT, fps REAL, fps_error REAL, area_mm2 REAL, energy_mj REAL, "
             "power_w REAL, fps_per_mm2 REAL, feasible INTEGER, front INTEGER, "
             "PRIMARY KEY(explore, config, stage))");
        {
            Statement old(m_db, "SELECT fingerprint FROM explores WHERE name = ?");
            old.bind(1, name);
            if (old.step() && old.text(0) != fingerprint) {
                Statement del(m_db, "DELETE FROM explore_configs WHERE explore = ?");
                del.bind(1, name);
                del.step();
            }
        }
        Statement up(m_db, "INSERT OR REPLACE INTO explores(name, file, fingerprint, spec) VALUES(?, ?, ?, ?)");
        up.bind(1, name);
        up.bind(2, file);
        up.bind(3, fingerprint);
        up.bind(4, spec_json);
        up.step();
        exec("COMMIT");
    } catch (...) {
        exec("ROLLBACK");
        throw;
    }
}

void ResultsStore::write_explore_configs(const std::string& explore, const std::vector<ExploreConfigRow>& rows) {
    exec("BEGIN IMMEDIATE");
    try {
        Statement ins(m_db,
                      "INSERT OR REPLACE INTO explore_configs(explore, config, stage, trial, knobs, fps, "
                      "fps_error, area_mm2, energy_mj, power_w, fps_per_mm2, feasible, front) "
                      "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
        for (const ExploreConfigRow& r : rows) {
            sqlite3_reset(ins.get());
            ins.bind(1, explore);
            ins.bind_int(2, int64_t(r.config));
            ins.bind(3, r.stage);
            ins.bind_int(4, r.trial);
            ins.bind(5, r.knobs_json);
            const ExploreScore& x = r.score;
            ins.bind(6, x.fps);
            ins.bind(7, x.fps_error >= 0 ? x.fps_error : std::nan(""));  // unknown: NULL
            ins.bind(8, x.area_mm2);
            ins.bind(9, x.energy_mj);
            ins.bind(10, x.power_w);
            ins.bind(11, x.fps_per_mm2);
            ins.bind_int(12, r.feasible);
            ins.bind_int(13, r.front);
            ins.step();
        }
        exec("COMMIT");
    } catch (...) {
        exec("ROLLBACK");
        throw;
    }
}

std::vector<std::pair<size_t, int64_t>> ResultsStore::explore_configs(const std::string& explore,
                                                                      const std::string& stage) const {
    std::vector<std::pair<size_t, int64_t>> out;
    {
        Statement t(m_db, "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'explore_configs'");
        if (!t.step()) return out;
    }
    Statement s(m_db, "SELECT config, trial FROM explore_configs WHERE explore = ? AND stage = ? ORDER BY config");
    s.bind(1, explore);
    s.bind(2, stage);
    while (s.step())
        out.emplace_back(size_t(sqlite3_column_int64(s.get(), 0)), sqlite3_column_int64(s.get(), 1));
    return out;
}

std::set<std::string> ResultsStore::stored_keys(const std::vector<std::string>& keys) const {
    std::set<std::string> out;
    constexpr size_t k_batch = 500;  // below SQLite's bound-parameter limit
    for (size_t first = 0; first < keys.size(); first += k_batch) {
        const size_t n = std::min(k_batch, keys.size() - first);
        std::string sql = "SELECT key FROM points WHERE key IN (?";
        for (size_t i = 1; i < n; ++i) sql += ", ?";
        Statement s(m_db, sql + ")");
        for (size_t i = 0; i < n; ++i) s.bind(int(i + 1), keys[first + i]);
        while (s.step()) out.insert(s.text(0));
    }
    return out;
}

struct ResultsStore::Batch {
    std::set<std::string> units;                                // names whose unit row was written
    std::map<std::string, std::unique_ptr<Statement>> inserts;  // by SQL text
    std::unique_ptr<Statement> unit;
};

size_t ResultsStore::write_points(const std::vector<PointRow>& rows, const std::string& sweep) {
    if (rows.empty()) return 0;
    Batch batch;
    exec("BEGIN IMMEDIATE");
    try {
        // Another process may have added columns since we looked: re-read inside the lock.
        m_columns.clear();
        for (const std::string& c : columns()) m_columns.insert(c);
        size_t inserted = 0;
        for (const PointRow& row : rows) inserted += insert_point(*row.point, sweep, row.run, batch);
        hold_before_commit_for_tests(rows.front().point->key);
        exec("COMMIT");
        return inserted;
    } catch (...) {
        sqlite3_exec(m_db, "ROLLBACK", nullptr, nullptr, nullptr);
        m_columns.clear();
        for (const std::string& c : columns()) m_columns.insert(c);
        throw;
    }
}

// One row, inside the caller's transaction; true if its key was new.
bool ResultsStore::insert_point(const SweepPoint& point, const std::string& sweep, const PointRun& run,
                                Batch& batch) {
    std::vector<HwColumn> hw_columns;
    HwColumns visitor(hw_columns);
    const_cast<HwConfig&>(point.hw).visit(visitor);  // the visitor only reads names and types
    const std::vector<HwParamInfo> hw_values = flatten_hw_config(point.hw);
    const std::vector<WorkloadColumn> workload = workload_columns(point.workload);
    std::vector<std::string> names = {"key",        "sfx_version", "sweep",      "point_index",
                                      "started_at", "finished_at", "config_yaml"};
    for (const WorkloadColumn& c : workload) {
        ensure_column(c.name, c.integer ? "INTEGER" : "TEXT");  // a store from before the field
        names.push_back(c.name);
    }
    names.push_back("fidelity");
    if (!batch.unit)
        batch.unit = std::make_unique<Statement>(
            m_db, "INSERT OR IGNORE INTO units(name, unit, description) VALUES(?, ?, ?)");
    Statement& unit = *batch.unit;
    auto add_unit = [&](const std::string& name, const std::string& u, const std::string& d) {
        if (!batch.units.insert(name).second) return;
        unit.bind(1, name);
        unit.bind(2, u);
        unit.bind(3, d);
        unit.step();
        sqlite3_reset(unit.get());
    };
    for (const WorkloadColumn& c : workload) add_unit(c.name, c.unit, c.description);
    for (const HwColumn& c : hw_columns) {
        ensure_column("hw." + c.name, c.numeric ? "REAL" : "TEXT");
        names.push_back("hw." + c.name);
        add_unit("hw." + c.name, c.unit, c.description);
    }
    for (const auto& [name, value] : run.metrics) {
        (void)value;
        ensure_column(name, "REAL");
        names.push_back(name);
        const auto u = run.units.find(name);
        if (u != run.units.end()) add_unit(name, u->second.first, u->second.second);
    }
    std::string sql = "INSERT OR IGNORE INTO points(";
    std::string marks;
    for (size_t i = 0; i < names.size(); ++i) {
        sql += (i ? ", " : "") + sql_quote_identifier(names[i]);
        marks += i ? ", ?" : "?";
    }
    sql += ") VALUES(" + marks + ")";
    std::unique_ptr<Statement>& prepared = batch.inserts[sql];
    if (!prepared) prepared = std::make_unique<Statement>(m_db, sql);
    Statement& insert = *prepared;
    sqlite3_reset(insert.get());
    int i = 1;
    insert.bind(i++, point.key);
    insert.bind(i++, run.sfx_version);
    insert.bind(i++, sweep);
    insert.bind_int(i++, int64_t(point.index));
    insert.bind(i++, run.started_at);
    insert.bind(i++, run.finished_at);
    insert.bind(i++, point.config_yaml);
    for (const WorkloadColumn& c : workload) {
        if (c.integer)
            insert.bind_int(i++, c.number);
        else
            insert.bind(i++, c.text);
    }
    insert.bind(i++, std::string(to_string(point.fidelity)));
    for (size_t k = 0; k < hw_columns.size(); ++k) {
        if (hw_columns[k].numeric)
            insert.bind(i++, std::strtod(hw_values[k].value.c_str(), nullptr));
        else insert.bind(i++, hw_values[k].value);
    }
    for (const auto& [name, value] : run.metrics) {
        (void)name;
        insert.bind(i++, value);
    }
    insert.step();
    return sqlite3_changes(m_db) == 1;
}

std::map<std::string, double> ResultsStore::numbers(const std::string& key) const {
    std::map<std::string, double> out;
    Statement s(m_db, "SELECT * FROM points WHERE key = ?");
    s.bind(1, key);
    if (!s.step()) return out;
    for (int c = 0; c < sqlite3_column_count(s.get()); ++c) {
        const int type = sqlite3_column_type(s.get(), c);
        if (type == SQLITE_FLOAT || type == SQLITE_INTEGER)
            out[sqlite3_column_name(s.get(), c)] = sqlite3_column_double(s.get(), c);
    }
    return out;
}

std::vector<ResultsStore::RowValues> ResultsStore::rows() const {
    std::vector<RowValues> out;
    Statement s(m_db, "SELECT * FROM points ORDER BY sweep, point_index, key");
    while (s.step()) {
        RowValues r;
        for (int c = 0; c < sqlite3_column_count(s.get()); ++c) {
            const char* name = sqlite3_column_name(s.get(), c);
            switch (sqlite3_column_type(s.get(), c)) {
                case SQLITE_NULL:
                    break;
                case SQLITE_INTEGER:
                case SQLITE_FLOAT:
                    r.numbers[name] = sqlite3_column_double(s.get(), c);
                    break;
                default:
                    r.text[name] = s.text(c);
            }
        }
        out.push_back(std::move(r));
    }
    return out;
}

void ResultsStore::export_csv(const std::string& csv_path,
                              const std::vector<std::string>& keys) const {
    OutputFiles outputs;  // whole or not at all
    const std::string temp = outputs.add(csv_path, "--csv");
    std::ofstream out(temp);
    if (!out) throw InputError("command line", 0, "--csv", "cannot write '" + csv_path + "'");
    std::vector<std::string> cols;
    for (const std::string& c : columns())
        if (c != "config_yaml") cols.push_back(c);
    for (size_t i = 0; i < cols.size(); ++i) out << (i ? "," : "") << csv_field(cols[i]);
    out << "\n";
    std::string select = "SELECT ";
    for (size_t i = 0; i < cols.size(); ++i)
        select += (i ? ", " : "") + sql_quote_identifier(cols[i]);
    select += " FROM points";
    auto write_rows = [&](Statement& s) {
        while (s.step()) {
            for (int c = 0; c < int(cols.size()); ++c) {
                if (c) out << ",";
                switch (sqlite3_column_type(s.get(), c)) {
                    case SQLITE_NULL:
                        break;
                    case SQLITE_INTEGER:
                        out << sqlite3_column_int64(s.get(), c);
                        break;
                    case SQLITE_FLOAT:
                        out << shortest_text(sqlite3_column_double(s.get(), c));
                        break;
                    default:
                        out << csv_field(s.text(c));
                }
            }
            out << "\n";
        }
    };
    if (keys.empty()) {
        Statement s(m_db, select + " ORDER BY sweep, point_index, key");
        write_rows(s);
    } else {
        Statement s(m_db, select + " WHERE key = ?");
        for (const std::string& k : keys) {
            sqlite3_reset(s.get());
            s.bind(1, k);
            write_rows(s);
        }
    }
    out.close();
    if (!out) throw InputError("command line", 0, "--csv", "error writing '" + csv_path + "'");
    outputs.commit();
}

}  // namespace sfx

#include "sweeps/store_compare.h"

#include <cstdlib>
#include <set>

#include "base/input_error.h"

namespace sfx {
namespace {

bool is_input_column(const std::string& c) {
    return c.rfind("workload.", 0) == 0 || c.rfind("hw.", 0) == 0 || c == "fidelity";
}
// Bookkeeping, not metrics.
bool is_metric_column(const std::string& c) {
    return !is_input_column(c) && c != "point_index" && c != "key" && c != "sfx_version" &&
           c != "sweep" && c != "started_at" && c != "finished_at" && c != "config_yaml";
}

bool matches(const ResultsStore::RowValues& row, const Selection& sel) {
    for (const auto& [column, value] : sel) {
        auto n = row.numbers.find(column);
        if (n != row.numbers.end()) {
            char* end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            if (end == value.c_str() || *end != '\0' || v != n->second) return false;
            continue;
        }
        auto t = row.text.find(column);
        if (t == row.text.end() || t->second != value) return false;
    }
    return true;
}

}  // namespace

Selection parse_selection(const std::string& text, const std::string& flag) {
    Selection out;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = text.find(',', start);
        const std::string part =
            text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        const size_t eq = part.find('=');
        if (eq == std::string::npos || eq == 0)
            throw InputError("command line", 0, flag,
                             "expected COLUMN=VALUE[,COLUMN=VALUE...], got '" + text + "'");
        out.emplace_back(part.substr(0, eq), part.substr(eq + 1));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

StoreComparison compare_store(const ResultsStore& store, const Selection& a, const Selection& b) {
    const std::vector<std::string> columns = store.columns();
    const std::set<std::string> known(columns.begin(), columns.end());
    std::set<std::string> selected;
    for (const auto* sel : {&a, &b})
        for (const auto& [column, value] : *sel) {
            (void)value;
            if (!known.count(column)) {
                // Name the store's own input columns, never a fixed example (which may be the
                // very column that is missing, as in a store of another program).
                std::string inputs;
                int listed = 0;
                for (const std::string& c : columns)
                    if (is_input_column(c) && listed++ < 8)
                        inputs += (inputs.empty() ? "" : ", ") + c;
                throw InputError(
                    "command line", 0, sel == &a ? "--a" : "--b",
                    "the store has no column '" + column + "'" +
                        (inputs.empty()
                             ? std::string(": it has no input columns at all")
                             : " (its input columns: " + inputs + (listed > 8 ? ", ...)" : ")")));
            }
            selected.insert(column);
        }
    // The identity of a row: every input column that neither selection names.
    std::vector<std::string> identity_columns;
    for (const std::string& c : columns)
        if (is_input_column(c) && !selected.count(c)) identity_columns.push_back(c);
    auto identity = [&](const ResultsStore::RowValues& r) {
        std::string id;
        for (const std::string& c : identity_columns) {
            auto n = r.numbers.find(c);
            auto t = r.text.find(c);
            id += c + "=" +
                  (n != r.numbers.end() ? std::to_string(n->second)
                   : t != r.text.end()  ? t->second
                                        : "NULL") +
                  "\n";
        }
        return id;
    };
    // Per identity, the metric sums and counts of each side.
    struct Side {
        std::map<std::string, double> sum;
        std::map<std::string, size_t> count;
        size_t rows = 0;
    };
    std::map<std::string, Side> side_a, side_b;
    StoreComparison out;
    for (const ResultsStore::RowValues& r : store.rows()) {
        for (int s = 0; s < 2; ++s) {
            if (!matches(r, s == 0 ? a : b)) continue;
            Side& side = (s == 0 ? side_a : side_b)[identity(r)];
            ++side.rows;
            ++(s == 0 ? out.rows_a : out.rows_b);
            for (const auto& [name, v] : r.numbers)
                if (is_metric_column(name)) {
                    side.sum[name] += v;
                    ++side.count[name];
                }
        }
    }
    if (out.rows_a == 0) throw InputError("command line", 0, "--a", "matches no stored row");
    if (out.rows_b == 0) throw InputError("command line", 0, "--b", "matches no stored row");
    // Mean over matched identities of each identity's mean: every combination weighs the same.
    std::map<std::string, double> sum_a, sum_b;
    std::map<std::string, size_t> n_a, n_b;
    for (const auto& [id, sa] : side_a) {
        auto it = side_b.find(id);
        if (it == side_b.end()) continue;
        ++out.matched;
        const Side& sb = it->second;
        for (const auto& [name, sum] : sa.sum) {
            auto bs = sb.sum.find(name);
            if (bs == sb.sum.end()) continue;
            sum_a[name] += sum / double(sa.count.at(name));
            sum_b[name] += bs->second / double(sb.count.at(name));
            ++n_a[name];
            ++n_b[name];
        }
    }
    if (out.matched == 0)
        throw InputError("command line", 0, "--b",
                         "no row of --b has the same other inputs (workload, hardware, fidelity) "
                         "as a row of --a");
    for (const auto& [name, sum] : sum_a) {
        out.mean_a[name] = sum / double(n_a[name]);
        out.mean_b[name] = sum_b[name] / double(n_b[name]);
    }
    return out;
}

}  // namespace sfx

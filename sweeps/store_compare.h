#pragma once
// Two selections from the results store compared: rows of A and B matched on every input
// column (workload.*, hw.*, fidelity) that neither selection names, then the mean of every
// metric over the matched rows of each side (`sfx compare --store DB --a ... --b ...`).

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sweeps/results_store.h"

namespace sfx {

// "hw.simd.width=8,workload.scene=atrium": column = value conditions, all of which must hold.
using Selection = std::vector<std::pair<std::string, std::string>>;
Selection parse_selection(const std::string& text, const std::string& flag);

struct StoreComparison {
    size_t rows_a = 0, rows_b = 0;  // rows each selection matched
    size_t matched = 0;             // input combinations present on both sides
    std::map<std::string, double> mean_a, mean_b;  // metric -> mean over the matched rows
};

// Throws InputError naming the flag if a selection names no column of the store or matches
// nothing, or if no row of A has a counterpart in B.
StoreComparison compare_store(const ResultsStore& store, const Selection& a, const Selection& b);

}  // namespace sfx

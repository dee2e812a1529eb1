#pragma once
// A node's clocks: G&R 3.3's critical paths, each given at the node it was stated for, scaled
// to a configuration's technology node by the node's gate delay ([SB17], the tech table's
// `gate_delay_vs_90nm`). A clock domain's node clock is the slowest of its paths' clocks. A clock
// the configuration does not write follows its node clock; a written clock is kept, and one
// above its node clock draws a warning that names the path. Latencies given in ns (caches,
// DRAM) stay in ns: only the cycle counts they round to move with the clock.

#include <string>
#include <vector>

#include "hw_model/hw_config.h"
#include "hw_model/tech_table.h"

namespace sfx {

struct ClockPath {
    const char* domain;         // "core_mhz" or "interconnect_mhz" (the ClockConfig key)
    const char* name;           // the units on the path
    double mhz;                 // single-cycle clock stated for it
    double node_nm;             // at this node
    double gate_delay_vs_90nm;  // that node's gate delay over the 90 nm node's ([SB17])
    const char* source;
};

// G&R 3.3's paths, in the order they are stated.
const std::vector<ClockPath>& clock_paths();

struct NodeClock {
    double mhz = 0;
    const ClockPath* path = nullptr;  // the slowest path of the domain at the node
};
// `domain`'s node clock at `tech`: min over its paths of mhz x path delay / node delay.
NodeClock node_clock(const std::string& domain, const TechTable& tech);

// Sets each clock not written to its node clock at `config.tech.node`; returns one warning per
// written clock above its node clock (none for a configuration with measured op costs: a CPU
// core's clock is measured, G&R's paths are not its paths).
std::vector<std::string> resolve_node_clocks(HwConfig& config);

}  // namespace sfx

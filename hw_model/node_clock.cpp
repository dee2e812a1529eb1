#include "hw_model/node_clock.h"

#include <cstdio>

namespace sfx {
namespace {

std::string number_text(const char* format, double v) {
    char text[32];
    std::snprintf(text, sizeof text, format, v);
    return text;
}

}  // namespace

const std::vector<ClockPath>& clock_paths() {
    // G&R 3.3: "The multiplexers are carefully sized to allow for single-cycle operation at a
    // frequency of 1 GHz. Likewise, the address fetch and execution units are guaranteed to be
    // synthesized at 1 GHz with 130 nm technology [11]. However, clocking the flexible
    // interconnect at the same frequency would require an aggressive design. We thus assume a
    // conservative frequency of 500 MHz at 90 nm to accommodate the flexible interconnect and
    // partitioning units."
    static const std::vector<ClockPath> paths = {
        // No node is stated for the multiplexers: the paper's node, 90 nm, assumed.
        {"interconnect_mhz", "multiplexers", 1000, 90, 1.0, "G&R 3.3 (node assumed: 90 nm)"},
        // 130 nm: [SB17] 130 nm delay fit at 1.3 V over the 90 nm fit at 1.2 V = 31.96 / 23.59
        // (hw_model/tech/scale_tech.py --factors).
        {"core_mhz", "address fetch and execution units", 1000, 130, 1.355, "G&R 3.3, their [11]"},
        {"interconnect_mhz", "flexible interconnect", 500, 90, 1.0, "G&R 3.3"},
        {"core_mhz", "partitioning units", 500, 90, 1.0, "G&R 3.3"},
    };
    return paths;
}

NodeClock node_clock(const std::string& domain, const TechTable& tech) {
    NodeClock out;
    for (const ClockPath& p : clock_paths()) {
        if (domain != p.domain) continue;
        const double mhz = p.mhz * (p.gate_delay_vs_90nm / tech.gate_delay_vs_90nm);
        if (!out.path || mhz < out.mhz) out = {mhz, &p};
    }
    return out;
}

std::vector<std::string> resolve_node_clocks(HwConfig& config) {
    const TechTable& tech = tech_table_for(config.tech.node, "tech.node");
    std::vector<std::string> warnings;
    auto resolve = [&](const char* domain, double& mhz, bool written) {
        const NodeClock limit = node_clock(domain, tech);
        if (!written) {
            mhz = limit.mhz;
            return;
        }
        if (mhz > limit.mhz && config.op_costs.empty()) {
            const ClockPath& p = *limit.path;
            warnings.push_back(config.name + ": clock." + domain + " " + number_text("%.6g", mhz) +
                               " MHz is above the " + number_text("%.0f", limit.mhz) +
                               " MHz its critical path allows at " + tech.name + ": " + p.name +
                               ", " + number_text("%g", p.mhz) + " MHz at " +
                               number_text("%g", p.node_nm) + " nm (" + p.source +
                               "), scaled by the node's gate delay ([SB17])");
        }
    };
    resolve("core_mhz", config.clock.core_mhz, config.clock.core_written);
    resolve("interconnect_mhz", config.clock.interconnect_mhz, config.clock.interconnect_written);
    return warnings;
}

}  // namespace sfx

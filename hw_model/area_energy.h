#pragma once
// Costing apart from counting: a pure evaluator that prices a configuration's units (area) and a
// frame's action counts (energy) with a technology table. Formulas (per unit):
//
//   SRAM macro of k KiB, p ports:  v(k) = v_ref * (k / ref_kib)^x, times 1 + (f - 1)(p - 1)
//     for the port factor f of that quantity (area, access energy, leakage)
//   per core      every unit below but a shared cache level is one per core (x cores.count)
//   ray_buffer    buffers x banks macros of bank_kib KiB, one port;
//                 energy = bank_reads x read + bank_writes x write
//   agu           count x addresses_per_cycle x (int32 adder + 32-bit register);
//                 energy = addresses x int32 add
//   simd          units x width lanes x (fp32 adder + fp32 multiplier): a lane instruction =
//                 one multiply and one add; energy = lane instructions that carry a ray x
//                 (fp32 add + fp32 mul) (idle lanes are predicated off: leakage only)
//   partition     width x comparators_per_lane 32-bit comparators; energy = compares x compare
//                 (the ids it moves are bank reads and writes of the ray buffer)
//   scratchpad    one macro of kib KiB with `ports` ports; energy = accesses x (read + write) / 2
//                 (mask words are written and read)
//   interconnect  width_words x mux_levels x 32-bit register (one pipeline register per level);
//                 energy = word hops x register
//   cache_<name>  per level (once if shared, else per core), CacheTech scaled by capacity;
//                 energy = lookups x lookup + fills x fill
//   dram          no area (off chip); energy = bytes x 8 x pJ/bit
//   leakage       every on-chip unit: leakage power x (busy + idle_leakage_fraction x idle)
//                 cycles at the core clock, idle = instances x frame cycles - busy (busy
//                 cycles are summed over cores and SIMD units); logic leakage = area x
//                 leakage_mw_per_mm2

#include <string>
#include <vector>

#include "hw_model/action_counts.h"
#include "hw_model/hw_config.h"
#include "hw_model/tech_table.h"

namespace sfx {

// SRAM macro primitives (exposed for tests).
double sram_area_mm2(const SramTech& t, double kib, uint32_t ports);
double sram_read_pj(const SramTech& t, double kib, uint32_t ports);
double sram_write_pj(const SramTech& t, double kib, uint32_t ports);
double sram_leakage_mw(const SramTech& t, double kib, uint32_t ports);

struct UnitCost {
    std::string unit;       // "ray_buffer", ..., "cache_l1", "dram"
    double area_mm2 = 0;    // 0 for dram
    double dynamic_mj = 0;  // per frame
    double leakage_mj = 0;  // per frame
    double energy_mj() const { return dynamic_mj + leakage_mj; }
};

struct AreaEnergy {
    std::vector<UnitCost> units;  // in the order of the formulas above
    double total_area_mm2() const;
    double total_energy_mj() const;
    double leakage_mj() const;
};

// Area per unit (energies zero): depends on the configuration alone.
AreaEnergy area_per_unit(const HwConfig& config, const TechTable& tech);
// Area and energy per unit of a frame of `frame_cycles` core cycles (wall clock: not summed
// over cores).
AreaEnergy evaluate_area_energy(const HwConfig& config, const ActionCounts& counts,
                                uint64_t frame_cycles, const TechTable& tech);

}  // namespace sfx

#include "hw_model/area_energy.h"

#include <algorithm>
#include <cmath>

namespace sfx {
namespace {

double scaled(double value, double kib, double ref_kib, double exponent) {
    return value * std::pow(kib / ref_kib, exponent);
}
double ports_factor(double factor, uint32_t ports) {
    return 1.0 + (factor - 1.0) * double(std::max(1u, ports) - 1);
}
constexpr double k_pj_to_mj = 1e-9;
constexpr double k_um2_to_mm2 = 1e-6;

}  // namespace

double sram_area_mm2(const SramTech& t, double kib, uint32_t ports) {
    return scaled(t.area_mm2, kib, t.ref_kib, t.area_exponent) *
           ports_factor(t.port_area_factor, ports);
}
double sram_read_pj(const SramTech& t, double kib, uint32_t ports) {
    return scaled(t.read_pj, kib, t.ref_kib, t.read_exponent) *
           ports_factor(t.port_energy_factor, ports);
}
double sram_write_pj(const SramTech& t, double kib, uint32_t ports) {
    return scaled(t.write_pj, kib, t.ref_kib, t.write_exponent) *
           ports_factor(t.port_energy_factor, ports);
}
double sram_leakage_mw(const SramTech& t, double kib, uint32_t ports) {
    return scaled(t.leakage_mw, kib, t.ref_kib, t.leakage_exponent) *
           ports_factor(t.port_leakage_factor, ports);
}

double AreaEnergy::total_area_mm2() const {
    double s = 0;
    for (const UnitCost& u : units) s += u.area_mm2;
    return s;
}
double AreaEnergy::total_energy_mj() const {
    double s = 0;
    for (const UnitCost& u : units) s += u.energy_mj();
    return s;
}
double AreaEnergy::leakage_mj() const {
    double s = 0;
    for (const UnitCost& u : units) s += u.leakage_mj;
    return s;
}

namespace {

// One unit's area, dynamic energy (pJ) and leakage power (mW), of all its instances, before
// leakage is turned into energy over the frame.
struct Priced {
    std::string unit;
    double area_mm2 = 0, dynamic_pj = 0, leakage_mw = 0;
    int busy_unit = -1;    // HwUnit whose busy cycles it has; -1: leaks for the whole frame
    double instances = 1;  // copies whose busy cycles are summed (cores, SIMD units)
};

std::vector<Priced> price(const HwConfig& c, const ActionCounts& n, const TechTable& t) {
    const LogicTech& l = t.logic;
    // Every unit but a shared cache level is one per core; the SIMD datapath one per unit.
    const double cores = double(c.cores.count);
    auto logic = [&](std::string unit, double um2_each, double instances, double pj, HwUnit u) {
        const double mm2 = um2_each * k_um2_to_mm2 * instances;
        return Priced{std::move(unit), mm2, pj, mm2 * l.leakage_mw_per_mm2, int(u), instances};
    };
    std::vector<Priced> p;
    const RayBufferConfig& rb = c.ray_buffer;
    const double bank_kib = double(rb.kib) / double(rb.banks);
    const double macros = double(rb.buffers) * double(rb.banks) * cores;
    p.push_back({"ray_buffer", macros * sram_area_mm2(t.sram, bank_kib, 1),
                 double(n.bank_reads) * sram_read_pj(t.sram, bank_kib, 1) +
                     double(n.bank_writes) * sram_write_pj(t.sram, bank_kib, 1),
                 macros * sram_leakage_mw(t.sram, bank_kib, 1), int(HwUnit::ray_buffer), cores});
    p.push_back(logic(
        "agu",
        double(c.agu.count) * c.agu.addresses_per_cycle * (l.int32_add_um2 + l.register32_um2),
        cores, double(n.agu_addresses) * l.int32_add_pj, HwUnit::agu));
    uint64_t lane_ops = 0;
    for (uint64_t v : n.simd_lane_ops) lane_ops += v;
    // A lane's datapath: one FPU (an adder and a multiplier) issuing an instruction a cycle;
    // on a cluster (datapath.issue: cluster, Mathew 9.3's classes) every function unit of
    // every class, each as wide as the SIMD unit: an FPU as above, an ALU as an integer
    // adder, a multiplier as an integer multiplier. Energy stays per instruction, each priced
    // as an FPU's add and multiply (an upper bound for ALU and multiplier instructions).
    const DatapathConfig& d = c.datapath;
    const double fpu_um2 = l.fp32_add_um2 + l.fp32_mul_um2;
    const double lane_um2 =
        d.issue == "cluster" ? double(d.fpu_units) * fpu_um2 + double(d.alu_units) * l.int32_add_um2 +
                                   double(d.mul_units) * l.int32_mul_um2
                             : fpu_um2;
    p.push_back(logic("simd", double(c.simd.width) * lane_um2, cores * c.simd.units,
                      double(lane_ops) * (l.fp32_add_pj + l.fp32_mul_pj), HwUnit::simd));
    p.push_back(logic("partition",
                      double(c.simd.width) * c.partition.comparators_per_lane * l.compare32_um2,
                      cores, double(n.partition_compares) * l.compare32_pj, HwUnit::partition));
    const ScratchpadConfig& sp = c.scratchpad;
    p.push_back(
        {"scratchpad", cores * sram_area_mm2(t.sram, sp.kib, sp.ports),
         double(n.scratchpad_accesses) *
             (sram_read_pj(t.sram, sp.kib, sp.ports) + sram_write_pj(t.sram, sp.kib, sp.ports)) / 2,
         cores * sram_leakage_mw(t.sram, sp.kib, sp.ports), int(HwUnit::scratchpad), cores});
    p.push_back(
        logic("interconnect",
              double(c.interconnect.width_words) * c.interconnect.mux_levels * l.register32_um2,
              cores, double(n.interconnect_word_hops) * l.register32_pj, HwUnit::interconnect));
    const CacheTech& ct = t.cache;
    for (size_t i = 0; i < c.scene_memory.caches.size() && i < ActionCounts::k_max_cache_levels;
         ++i) {
        const double kib = c.scene_memory.caches[i].kib;
        const double copies = c.scene_memory.caches[i].shared ? 1.0 : cores;
        p.push_back(
            {"cache_" + c.scene_memory.caches[i].name,
             copies * scaled(ct.area_mm2, kib, ct.ref_kib, ct.area_exponent),
             double(n.cache_accesses[i]) *
                     scaled(ct.lookup_pj, kib, ct.ref_kib, ct.lookup_exponent) +
                 double(n.cache_fills[i]) * scaled(ct.fill_pj, kib, ct.ref_kib, ct.fill_exponent),
             copies * scaled(ct.leakage_mw, kib, ct.ref_kib, ct.leakage_exponent), -1});
    }
    p.push_back({"dram", 0.0, double(n.dram_bytes) * 8.0 * t.dram_pj_per_bit, 0.0, -1});
    return p;
}

}  // namespace

AreaEnergy area_per_unit(const HwConfig& config, const TechTable& tech) {
    AreaEnergy r;
    for (const Priced& p : price(config, ActionCounts{}, tech))
        r.units.push_back({p.unit, p.area_mm2, 0, 0});
    return r;
}

AreaEnergy evaluate_area_energy(const HwConfig& config, const ActionCounts& counts,
                                uint64_t frame_cycles, const TechTable& tech) {
    const double cycle_s = 1.0 / (config.clock.core_mhz * 1e6);
    AreaEnergy r;
    for (const Priced& p : price(config, counts, tech)) {
        // Leakage power is of all instances; busy cycles are summed over them.
        double leaking_cycles = double(frame_cycles);
        if (p.busy_unit >= 0) {
            const double capacity = p.instances * double(frame_cycles);
            const double busy = std::min(double(counts.busy_cycles[size_t(p.busy_unit)]), capacity);
            leaking_cycles = (busy + tech.idle_leakage_fraction * (capacity - busy)) / p.instances;
        }
        // mW x s = mJ.
        r.units.push_back({p.unit, p.area_mm2, p.dynamic_pj * k_pj_to_mj,
                           p.leakage_mw * leaking_cycles * cycle_s});
    }
    return r;
}

}  // namespace sfx

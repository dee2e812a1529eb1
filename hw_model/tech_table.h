#pragma once
// A technology table: per-action energies and per-element areas at one process node, read from
// strict YAML (`hw_model/tech/*.tech.yaml`, parsed like hardware configurations: unknown keys,
// wrong types and out-of-range values name file, line and dotted key). Every key is required:
// a table with a missing number is an error, never a silent zero. The numbers and their sources
// live in the YAML files; the formulas that compose them into units live in area_energy.h.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sfx {

// A single-bank SRAM macro of 32-bit words (a ray-buffer bank, the scratchpad), CACTI-style:
// a value v at the reference size scales as v * (kib / ref_kib)^exponent; each port beyond the
// first multiplies by 1 + (port factor - 1) per extra port.
struct SramTech {
    double ref_kib = 0;
    double area_mm2 = 0;
    double area_exponent = 0;
    double read_pj = 0;  // one 32-bit word
    double read_exponent = 0;
    double write_pj = 0;
    double write_exponent = 0;
    double leakage_mw = 0;
    double leakage_exponent = 0;
    double port_area_factor = 0;  // two ports / one port
    double port_energy_factor = 0;
    double port_leakage_factor = 0;

    template <class V>
    void visit(V& v) {
        v.param("ref_kib", ref_kib, "KiB", "size the reference values are for", 0.001, 1e6);
        v.param("area_mm2", area_mm2, "mm2", "macro area at ref_kib", 0.0, 1e4);
        // At most 1: splitting a buffer into more banks never shrinks it (periphery per bank).
        v.param("area_exponent", area_exponent, "", "area ~ kib^x", 0.0, 1.0);
        v.param("read_pj", read_pj, "pJ", "energy of one 32-bit read at ref_kib", 0.0, 1e6);
        v.param("read_exponent", read_exponent, "", "read energy ~ kib^x", 0.0, 2.0);
        v.param("write_pj", write_pj, "pJ", "energy of one 32-bit write at ref_kib", 0.0, 1e6);
        v.param("write_exponent", write_exponent, "", "write energy ~ kib^x", 0.0, 2.0);
        v.param("leakage_mw", leakage_mw, "mW", "leakage power at ref_kib", 0.0, 1e6);
        v.param("leakage_exponent", leakage_exponent, "", "leakage ~ kib^x", 0.0, 2.0);
        v.param("port_area_factor", port_area_factor, "", "area with two ports / one", 1.0, 10.0);
        v.param("port_energy_factor", port_energy_factor, "", "access energy, two ports / one", 1.0,
                10.0);
        v.param("port_leakage_factor", port_leakage_factor, "", "leakage, two ports / one", 1.0,
                10.0);
    }
};

// A scene-data cache level (tags and data, line-wide accesses), scaled by capacity as SramTech.
struct CacheTech {
    double ref_kib = 0;
    double area_mm2 = 0;
    double area_exponent = 0;
    double lookup_pj = 0;  // one read access (tags and a line)
    double lookup_exponent = 0;
    double fill_pj = 0;  // one line written on a miss
    double fill_exponent = 0;
    double leakage_mw = 0;
    double leakage_exponent = 0;

    template <class V>
    void visit(V& v) {
        v.param("ref_kib", ref_kib, "KiB", "size the reference values are for", 0.001, 1e6);
        v.param("area_mm2", area_mm2, "mm2", "cache area at ref_kib", 0.0, 1e4);
        v.param("area_exponent", area_exponent, "", "area ~ kib^x", 0.0, 2.0);
        v.param("lookup_pj", lookup_pj, "pJ", "energy of one lookup at ref_kib", 0.0, 1e7);
        v.param("lookup_exponent", lookup_exponent, "", "lookup energy ~ kib^x", 0.0, 2.0);
        v.param("fill_pj", fill_pj, "pJ", "energy of one line fill at ref_kib", 0.0, 1e7);
        v.param("fill_exponent", fill_exponent, "", "fill energy ~ kib^x", 0.0, 2.0);
        v.param("leakage_mw", leakage_mw, "mW", "leakage power at ref_kib", 0.0, 1e6);
        v.param("leakage_exponent", leakage_exponent, "", "leakage ~ kib^x", 0.0, 2.0);
    }
};

// Datapath elements, 32 bits wide.
struct LogicTech {
    double fp32_add_pj = 0, fp32_add_um2 = 0;
    double fp32_mul_pj = 0, fp32_mul_um2 = 0;
    double int32_add_pj = 0, int32_add_um2 = 0;
    double int32_mul_pj = 0, int32_mul_um2 = 0;
    double compare32_pj = 0, compare32_um2 = 0;
    double register32_pj = 0, register32_um2 = 0;  // a 32-bit pipeline register
    double leakage_mw_per_mm2 = 0;                 // of logic area

    template <class V>
    void visit(V& v) {
        v.param("fp32_add_pj", fp32_add_pj, "pJ", "32-bit floating-point add", 0.0, 1e4);
        v.param("fp32_add_um2", fp32_add_um2, "um2", "32-bit floating-point adder", 0.0, 1e7);
        v.param("fp32_mul_pj", fp32_mul_pj, "pJ", "32-bit floating-point multiply", 0.0, 1e4);
        v.param("fp32_mul_um2", fp32_mul_um2, "um2", "32-bit floating-point multiplier", 0.0, 1e7);
        v.param("int32_add_pj", int32_add_pj, "pJ", "32-bit integer add", 0.0, 1e4);
        v.param("int32_add_um2", int32_add_um2, "um2", "32-bit integer adder", 0.0, 1e7);
        v.param("int32_mul_pj", int32_mul_pj, "pJ", "32-bit integer multiply", 0.0, 1e4);
        v.param("int32_mul_um2", int32_mul_um2, "um2", "32-bit integer multiplier", 0.0, 1e7);
        v.param("compare32_pj", compare32_pj, "pJ", "32-bit comparison", 0.0, 1e4);
        v.param("compare32_um2", compare32_um2, "um2", "32-bit comparator", 0.0, 1e7);
        v.param("register32_pj", register32_pj, "pJ", "32-bit register write and read", 0.0, 1e4);
        v.param("register32_um2", register32_um2, "um2", "32-bit register", 0.0, 1e7);
        v.param("leakage_mw_per_mm2", leakage_mw_per_mm2, "mW/mm2", "leakage of logic area", 0.0,
                1e5);
    }
};

struct TechTable {
    uint32_t version = 1;
    std::string name;
    double node_nm = 0;
    double vdd_v = 0;
    double gate_delay_vs_90nm = 0;  // a gate's delay over the 90 nm node's ([SB17] delay fits)
    SramTech sram;
    CacheTech cache;
    LogicTech logic;
    double dram_pj_per_bit = 0;
    double idle_leakage_fraction = 0;  // leakage an idle unit keeps (1: no power gating)

    template <class V>
    void visit(V& v) {
        v.param("version", version, "", "technology table format version", 1u, 1u);
        v.param("name", name, "", "table name");
        v.param("node_nm", node_nm, "nm", "process node", 1.0, 1000.0);
        v.param("vdd_v", vdd_v, "V", "supply voltage the energies are for", 0.1, 5.0);
        v.param("gate_delay_vs_90nm", gate_delay_vs_90nm, "",
                "gate delay over the 90 nm node's at 1.2 V (a critical path's clock scales by its "
                "inverse)",
                0.001, 100.0);
        v.group("sram", sram);
        v.group("cache", cache);
        v.group("logic", logic);
        v.param("dram_pj_per_bit", dram_pj_per_bit, "pJ/bit", "DRAM read energy", 0.0, 1e4);
        v.param("idle_leakage_fraction", idle_leakage_fraction, "",
                "share of a unit's leakage it keeps while idle (1: no power gating)", 0.0, 1.0);
    }
};

// Strict parsing; every key is required. Throws InputError(file, line, dotted key, message).
TechTable parse_tech_table(const std::string& yaml_text, const std::string& file_name);
TechTable load_tech_table(const std::string& path);
// The tables built into sfx (hw_model/tech/*.tech.yaml, embedded at build time).
std::vector<std::string> builtin_tech_names();
// Why `name_or_path` names no table (neither a built-in nor a readable file); empty if it does.
std::string unknown_tech_reason(const std::string& name_or_path);
// A built-in name ("90nm") or a path to a *.tech.yaml file; an unknown name is an InputError
// naming `file`, `line` and `key` (the option or configuration key that gave it).
TechTable resolve_tech_table(const std::string& name_or_path, const std::string& key = "--tech",
                             const std::string& file = "command line", int line = 0);
// The same, parsed once per name and process (a configuration's `tech.node`; thread-safe).
const TechTable& tech_table_for(const std::string& name_or_path, const std::string& key = "--tech",
                                const std::string& file = "command line", int line = 0);
// The default table (the paper's node, 90 nm).
const TechTable& default_tech_table();

}  // namespace sfx

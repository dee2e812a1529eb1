#pragma once
// The hardware configuration: one struct per unit, in-class defaults (the paper's machine,
// Gribble & Ramani 2008, Sec. 3.3), and one visit() per struct that names every parameter with
// its unit, description and valid range. That visit() is the single source of truth driving
// YAML parsing (strict), YAML dumping, flattened dotted names (result columns, sweep axes) and
// setting a parameter by its dotted path.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace sfx {

struct ClockConfig {
    double core_mhz = 500.0;
    double interconnect_mhz = 500.0;

    template <class V> void visit(V& v) {
        v.param("core_mhz", core_mhz, "MHz", "core (SIMD, address, partition) clock", 1.0, 1e5);
        v.param("interconnect_mhz", interconnect_mhz, "MHz",
                "interconnect clock (the paper: 500 MHz, conservative for 90 nm)", 1.0, 1e5);
    }
};

struct SimdConfig {
    uint32_t width = 16;

    template <class V> void visit(V& v) {
        v.param("width", width, "lanes", "SIMD lanes per operation", 1u, 64u);
    }
};

struct RayBufferConfig {
    uint32_t kib = 512;   // per buffer
    uint32_t buffers = 2;  // current and next generation
    uint32_t banks = 32;
    uint32_t line_words = 16;  // 32-bit words per bank line; widths that don't divide it stall
    uint32_t access_latency_cycles = 2;
    bool pipelined = true;
    std::string layout = "soa";  // ray records as structure of arrays (the paper) or array of structs

    uint32_t bank_kib() const { return banks ? kib / banks : 0; }

    template <class V> void visit(V& v) {
        v.param("kib", kib, "KiB", "size of one ray buffer", 1u, 1u << 20);
        v.param("buffers", buffers, "buffers", "ray buffers (current and next generation)", 2u, 8u);
        v.param("banks", banks, "banks", "banks per ray buffer; must divide kib", 1u, 1024u);
        v.param("line_words", line_words, "words", "32-bit words per bank line", 1u, 256u);
        v.param("access_latency_cycles", access_latency_cycles, "cycles",
                "bank access latency", 1u, 64u);
        v.param("pipelined", pipelined, "", "bank accesses overlap (one issue per cycle)");
        v.choice("layout", layout, {"soa", "aos"},
                 "ray records: soa puts a field of consecutive slots in consecutive banks; aos "
                 "puts slot * record words + field word in bank (that word mod banks)");
    }
};

struct AguConfig {
    uint32_t count = 32;  // the paper: one per bank
    uint32_t addresses_per_cycle = 1;

    template <class V> void visit(V& v) {
        v.param("count", count, "units", "address-generation units", 1u, 1024u);
        v.param("addresses_per_cycle", addresses_per_cycle, "addresses/cycle",
                "addresses each unit computes per cycle", 1u, 64u);
    }
};

struct ScratchpadConfig {
    uint32_t kib = 64;
    uint32_t ports = 2;  // the paper: dual-ported

    template <class V> void visit(V& v) {
        v.param("kib", kib, "KiB",
                "scratchpad capacity for intermediate results (area only: the timing model "
                "prices its ports, not its size)",
                1u, 1u << 16);
        v.param("ports", ports, "ports", "scratchpad ports", 1u, 8u);
    }
};

struct PartitionConfig {
    std::string kind = "in_place_compare";
    uint32_t lanes_per_cycle = 16;

    template <class V> void visit(V& v) {
        v.choice("kind", kind, {"in_place_compare"},
                 "partition algorithm (the paper: SIMD comparators, in place)");
        v.param("lanes_per_cycle", lanes_per_cycle, "lanes/cycle",
                "mask lanes the partition unit consumes per cycle", 1u, 1024u);
    }
};

struct InterconnectConfig {
    uint32_t mux_levels = 2;
    uint32_t width_words = 16;
    bool contention = true;

    template <class V> void visit(V& v) {
        v.param("mux_levels", mux_levels, "levels",
                "pipelined multiplexer levels data crosses once per operation", 1u, 16u);
        v.param("width_words", width_words, "words/cycle", "words moved per interconnect cycle",
                1u, 1024u);
        v.param("contention", contention, "", "model contention between address and data traffic");
    }
};

struct CacheLevelConfig {
    std::string name = "l1";
    uint32_t kib = 32;
    uint32_t line_bytes = 64;
    uint32_t ways = 8;
    uint32_t hit_latency_cycles = 4;

    template <class V> void visit(V& v) {
        v.param("name", name, "", "level name, used in stat names");
        v.param("kib", kib, "KiB", "capacity", 1u, 1u << 20);
        v.param("line_bytes", line_bytes, "bytes", "line size (a power of two)", 4u, 4096u);
        v.param("ways", ways, "ways", "associativity (pseudo-LRU replacement)", 1u, 64u);
        v.param("hit_latency_cycles", hit_latency_cycles, "cycles", "hit latency", 1u, 10000u);
    }
};

struct SceneMemoryConfig {
    // Bikker's hierarchy: 32 KiB / 256 KiB / 2 MiB, 8/8/16-way, 4:11:39:107 cycles.
    std::vector<CacheLevelConfig> caches = {{"l1", 32, 64, 8, 4},
                                            {"l2", 256, 64, 8, 11},
                                            {"l3", 2048, 64, 16, 39}};
    uint32_t dram_latency_cycles = 107;
    double dram_bandwidth_gbps = 25.6;

    template <class V> void visit(V& v) {
        v.list("caches", caches, "scene-data cache levels, nearest first");
        v.param("dram_latency_cycles", dram_latency_cycles, "cycles", "DRAM access latency", 1u,
                100000u);
        v.param("dram_bandwidth_gbps", dram_bandwidth_gbps, "GB/s", "DRAM bandwidth", 0.001, 1e4);
    }
};

// Latency of one operation on one group of lanes in the SIMD datapath (pipelined: a new group
// issues every cycle; the latency is paid once per dependent chain).
struct DatapathConfig {
    uint32_t box_test_cycles = 6;
    uint32_t triangle_test_cycles = 12;
    uint32_t sphere_test_cycles = 10;
    uint32_t shade_cycles = 8;
    uint32_t camera_cycles = 6;

    template <class V> void visit(V& v) {
        v.param("box_test_cycles", box_test_cycles, "cycles", "ray/box slab test", 1u, 1000u);
        v.param("triangle_test_cycles", triangle_test_cycles, "cycles", "ray/triangle test", 1u,
                1000u);
        v.param("sphere_test_cycles", sphere_test_cycles, "cycles", "ray/sphere test", 1u, 1000u);
        v.param("shade_cycles", shade_cycles, "cycles", "one shading filter step", 1u, 1000u);
        v.param("camera_cycles", camera_cycles, "cycles", "primary ray generation", 1u, 1000u);
    }
};

struct HwConfig {
    uint32_t version = 1;
    std::string name = "gr08";
    ClockConfig clock;
    SimdConfig simd;
    RayBufferConfig ray_buffer;
    AguConfig agu;
    ScratchpadConfig scratchpad;
    PartitionConfig partition;
    InterconnectConfig interconnect;
    SceneMemoryConfig scene_memory;
    DatapathConfig datapath;

    template <class V> void visit(V& v) {
        v.param("version", version, "", "configuration format version", 1u, 1u);
        v.param("name", name, "", "configuration name");
        v.group("clock", clock);
        v.group("simd", simd);
        v.group("ray_buffer", ray_buffer);
        v.group("agu", agu);
        v.group("scratchpad", scratchpad);
        v.group("partition", partition);
        v.group("interconnect", interconnect);
        v.group("scene_memory", scene_memory);
        v.group("datapath", datapath);
    }
};

// Strict parsing: unknown keys, wrong types and out-of-range values throw InputError naming
// file, line and dotted key. Cross-parameter rules are checked too (banks divide the buffer,
// cache sizes divide into sets, ...).
HwConfig load_hw_config(const std::string& path);
HwConfig parse_hw_config(const std::string& yaml_text, const std::string& file_name);
// Cross-parameter checks only (after programmatic changes, e.g. a sweep axis). `lines` maps
// dotted keys to the lines they were read from, for the message.
using HwLineMap = std::map<std::string, int>;
void check_hw_config(const HwConfig& config, const std::string& file_name,
                     const HwLineMap& lines = {});

// The fully resolved configuration as YAML: load(dump(c)) == c.
std::string dump_hw_config(const HwConfig& config);

struct HwParamInfo {
    std::string path;  // dotted, e.g. "ray_buffer.banks" or "scene_memory.caches[1].kib"
    std::string value;
    std::string unit;
    std::string description;
};
// Every parameter of a configuration, in declaration order.
std::vector<HwParamInfo> flatten_hw_config(const HwConfig& config);

// Sets one parameter by dotted path from YAML scalar text ("16", "true", "[..]" is not a
// scalar); throws InputError(file, line, path, ...) for an unknown path or a bad value.
void set_hw_param(HwConfig& config, const std::string& path, const std::string& value,
                  const std::string& file = "command line", int line = 0);

}  // namespace sfx

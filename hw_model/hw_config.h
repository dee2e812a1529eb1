#pragma once
// The hardware configuration: one struct per unit, in-class defaults (the paper's machine,
// Gribble & Ramani 2008, Sec. 3.3), and one visit() per struct that names every parameter with
// its unit, description and valid range. That visit() is the single source of truth driving
// YAML parsing (strict), YAML dumping, flattened dotted names (result columns, sweep axes) and
// setting a parameter by its dotted path.

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace YAML {
class Node;
}

namespace sfx {

// Every default below is the paper's machine (Gribble & Ramani 2008, "G&R" below) and names
// its source: a sentence of G&R, another reference, or "assumed" where no source gives a value
// (hw_model/presets/gr08.hw.yaml repeats each source beside the value).

// A clock not written in a configuration (file key, override, sweep axis) follows its node:
// the clock its critical path allows at `tech.node` (resolve_node_clocks, node_clock.h: G&R 3.3's
// paths scaled by the node's gate delay); at 90 nm both are the values below. A written clock is
// kept, and warned about when above that path's clock.
struct ClockConfig {
    double core_mhz = 500.0;  // G&R 3.3: "a conservative frequency of 500 MHz at 90 nm"
    double interconnect_mhz =
        500.0;  // G&R 3.3: the same 500 MHz "to accommodate the flexible interconnect"
    // Not parameters: whether each clock was written (so it does not follow the node).
    bool core_written = false, interconnect_written = false;

    template <class V>
    void visit(V& v) {
        v.param("core_mhz", core_mhz, "MHz",
                "core (SIMD, address, partition) clock; not written: its critical path's clock at "
                "tech.node",
                1.0, 1e5);
        v.param("interconnect_mhz", interconnect_mhz, "MHz",
                "interconnect clock (its own clock domain); not written: its critical path's "
                "clock at tech.node",
                1.0, 1e5);
    }
};

// The process node: its technology table prices area and energy, and its gate delay sets the
// clocks that are not written.
struct TechConfig {
    std::string node = "90nm";  // G&R 3.3: "500 MHz at 90 nm"

    template <class V>
    void visit(V& v) {
        v.param("node", node, "",
                "technology node: a built-in table (90nm, 45nm, 32nm, 22nm, 14nm, 10nm, 7nm; "
                "hw_model/tech/) or a *.tech.yaml file");
    }
};

struct SimdConfig {
    uint32_t width = 16;  // G&R Table 5 and 3.3 ("a SIMD width of 16")
    // G&R 3.3: the 32 banks "sustain 32 different SIMD data fetch operations at the same time",
    // built "to efficiently support a large number of SIMD units": 32 lanes of fetch per cycle
    // are two 16-wide units (docs/paper-reading.md checks this against Tables 1 and 6).
    uint32_t units = 2;

    template <class V>
    void visit(V& v) {
        v.param("width", width, "lanes", "SIMD lanes per unit", 1u, 64u);
        v.param("units", units, "units",
                "SIMD units per core; they share the core's banked ray buffers and address units",
                1u, 64u);
    }
};

struct CoreConfig {
    uint32_t count = 1;  // G&R 3.3 simulates one core; 5.2 proposes replicating it
    // G&R 3.3: the simulator is "similar to the SimpleScalar tool set" [5]; sim-outorder's
    // default register update unit holds 16 instructions (Burger & Austin 1997, -ruu:size 16),
    // fewer than one box-test group's (34, op_costs.cpp): no later op enters the window while
    // a partition is pending, so ops issue in order.
    uint32_t op_window = 1;

    template <class V>
    void visit(V& v) {
        v.param("count", count, "cores",
                "homogeneous cores, each with its own ray buffers, SIMD units and L1; tiles are "
                "scheduled across them; lower scene caches and DRAM bandwidth are shared",
                1u, 256u);
        v.param("op_window", op_window, "partitions",
                "out-of-order window across ops: an op is released once the op whose partition "
                "produced its stream is done, while fewer than this many partitions are pending "
                "(1: in order, every op waits for every earlier partition)",
                1u, 64u);
    }
};

struct RayBufferConfig {
    uint32_t kib = 512;        // G&R 3.3: "two buffers (512 KB each)"
    uint32_t buffers = 2;      // G&R 3.3: "for current and next-generation rays"
    uint32_t banks = 32;       // G&R 3.3: "banked into 32 16 KB buffers"
    uint32_t line_words = 16;  // G&R 4.1: alignment overhead at widths 8 and 12 "due to the
                               // larger line size", "minimal for a SIMD width of 16"
    uint32_t access_latency_cycles = 2;  // G&R 3.3: "Data access requires two cycles,
    bool pipelined = true;               //  but the operations are pipelined"
    std::string layout = "soa";          // G&R Fig. 5: one array per field (org_x, org_y, ...)
    // G&R 3.3: dedicated banked SRAM. "l1d": a CPU core's ray buffers live in memory and its
    // L1 data cache (kib: the L1D's size) holds what fits; the lanes' loads and stores are
    // priced inside the measured op costs (op_costs), so an l1d machine needs them.
    std::string storage = "banks";
    // 0: a slot is the ray record of the scene's features (hw_model/op_costs.h). l1d: the
    // bytes one ray slot of the native tracer occupies (what the L1D must hold per ray).
    uint32_t slot_bytes = 0;
    // l1d: the arrays a slot's bytes beyond its traversal record are spread over (the native
    // tracer's structure of arrays: a lane opens a page of each of them where a sparse stream's
    // lane opens pages of all: lane_page_bytes, hw_model/ray_buffer_model.h, which takes them
    // as of equal size, an assumption); 1: one array, as before it existed. A host file's 7 is
    // counted from the native tracer's code (stream_slot_arrays), not fitted.
    uint32_t slot_arrays = 1;
    // l1d: the 4 KiB pages the core's first-level data TLB maps (measured: `sfx calibrate
    // --describe-host` chases one line a page over more and more pages, measure_dtlb_pages in
    // hw_model/host_description.h); 0: not modelled. A lane that opens a page of a pass whose
    // slots span more pages than that pays beyond_tlb_per_lane_cycles (ray_buffer_model.h
    // beyond_tlb_share), hit or miss in the L1D.
    uint32_t dtlb_pages = 0;

    uint32_t bank_kib() const { return banks ? kib / banks : 0; }

    template <class V>
    void visit(V& v) {
        v.param("kib", kib, "KiB", "size of one ray buffer", 1u, 1u << 20);
        v.param("buffers", buffers, "buffers", "ray buffers (current and next generation)", 2u, 8u);
        v.param("banks", banks, "banks", "banks per ray buffer; must divide kib", 1u, 1024u);
        v.param("line_words", line_words, "words", "32-bit words per bank line", 1u, 256u);
        v.param("access_latency_cycles", access_latency_cycles, "cycles", "bank access latency", 1u,
                64u);
        v.param("pipelined", pipelined, "",
                "a bank accepts one request per cycle (else one per access latency)");
        v.choice("layout", layout, {"soa", "aos"},
                 "ray records: soa puts a field of consecutive slots in consecutive banks; aos "
                 "puts slot * record words + field word in bank (that word mod banks)");
        v.choice("storage", storage, {"banks", "l1d"},
                 "banks: dedicated banked buffers; l1d: the buffers live in memory behind a CPU "
                 "core's L1 data cache (kib = its size; loads priced by the measured op_costs)");
        v.param("slot_bytes", slot_bytes, "bytes",
                "bytes of one ray slot (0: the scene's ray record); sets the share of a pass's "
                "slots beyond an l1d buffer",
                0u, 1u << 16);
        v.param("slot_arrays", slot_arrays, "arrays",
                "arrays a slot's bytes beyond its traversal record are spread over (l1d; sets "
                "how often a dense stream's lane opens a page of one)",
                1u, 64u);
        v.param("dtlb_pages", dtlb_pages, "pages",
                "4 KiB pages the core's first-level data TLB maps (l1d; 0: not modelled)", 0u,
                1u << 20);
    }
};

struct AguConfig {
    uint32_t count = 32;  // G&R 3.3: "Each bank is also supported by an address generator unit"
    uint32_t addresses_per_cycle = 1;  // assumed: one integer add (field base + slot) per cycle
    // Assumed: G&R 3.3 says address and data computations "occur in parallel" without a depth;
    // two groups per SIMD unit lets one group's gathers overlap the previous one's compute.
    uint32_t queue_depth = 2;

    template <class V>
    void visit(V& v) {
        v.param("count", count, "units", "address-generation units per core", 1u, 1024u);
        v.param("addresses_per_cycle", addresses_per_cycle, "addresses/cycle",
                "addresses each unit computes per cycle (one per gathered or scattered lane word)",
                1u, 64u);
        v.param("queue_depth", queue_depth, "groups",
                "fetched lane groups the access side may run ahead of each SIMD unit", 1u, 1024u);
    }
};

struct ScratchpadConfig {
    uint32_t kib = 64;   // assumed: G&R 3.3 names "a dual ported scratch pad" without a size
    uint32_t ports = 2;  // G&R 3.3: "dual ported"

    template <class V>
    void visit(V& v) {
        v.param("kib", kib, "KiB",
                "scratchpad capacity for intermediate results (area only: the timing model "
                "prices its ports, not its size)",
                1u, 1u << 16);
        v.param("ports", ports, "ports", "scratchpad ports (filter masks pass through them)", 1u,
                8u);
    }
};

struct PartitionConfig {
    // G&R 3.3: "SIMD comparator units", in place. "compress": the SIMD unit itself writes each
    // group's passing ids, then its failing ones, as it executes the group (vpcompressd, or a
    // permutation table on AVX2: kernels/stream); no partition pass follows the op.
    std::string kind = "in_place_compare";
    uint32_t comparators_per_lane = 1;      // G&R 3.3: SIMD comparators, i.e. one per lane

    template <class V>
    void visit(V& v) {
        v.choice("kind", kind, {"in_place_compare", "compress"},
                 "partition algorithm (in_place_compare: SIMD comparators after the op, in "
                 "place; compress: two compress-stores per group on the SIMD unit, no pass after)");
        v.param("comparators_per_lane", comparators_per_lane, "comparators/lane",
                "mask lanes compared per cycle, per SIMD lane", 1u, 64u);
    }
};

struct InterconnectConfig {
    uint32_t mux_levels = 2;  // assumed: 32 banks reach a unit through two levels of muxes
    // G&R 3.3: the interconnect "sustains the bandwidth requirements of the address fetch and
    // execution units": one word from each of the 32 banks per cycle.
    uint32_t width_words = 32;
    bool contention = true;  // G&R 3.3: "contention on the interconnects ... is modeled"

    template <class V>
    void visit(V& v) {
        v.param("mux_levels", mux_levels, "levels",
                "pipelined multiplexer levels between a bank and a SIMD unit", 1u, 16u);
        v.param("width_words", width_words, "words/cycle",
                "words moved per interconnect cycle, shared by every unit of a core", 1u, 1024u);
        v.param("contention", contention, "",
                "transfers queue for the interconnect (false: unlimited bandwidth)");
    }
};

struct CacheLevelConfig {
    std::string name = "l1";
    uint32_t kib = 32;
    uint32_t line_bytes = 64;
    uint32_t ways = 8;
    double hit_latency_ns = 1.4;  // Bikker's L1 (SceneMemoryConfig below says how)
    bool shared = false;          // one instance for all cores (else one per core)
    // Lines others sharing the level fill into it per microsecond (a host's L3 on a shared
    // machine: its neighbours'), spread evenly over the sets, each evicting as this machine's
    // own fills do; 0: none (a machine of its own). Measured for a host (host_description.h).
    double foreign_fill_per_us = 0.0;
    // A line read from memory beyond this level (the last) brings the other line of its
    // 128-byte pair into it too: a host's adjacent-line prefetch, which fills the level with
    // lines a scene's sparse reads may never use. Measured for a host (measure_pair_fill,
    // host_description.h): on the Zen 4 VM (2026-12-04) the odd lines of 1 MiB, read first
    // after a chase of its even lines, took 13-22 ns a load against 147-150 ns from DRAM.
    // Default false: the presets' caches (Bikker's model, SceneMemoryConfig) fetch only what
    // is read.
    bool pair_fill = false;

    template <class V>
    void visit(V& v) {
        v.param("name", name, "", "level name, used in stat names");
        v.param("kib", kib, "KiB", "capacity", 1u, 1u << 20);
        v.param("line_bytes", line_bytes, "bytes", "line size (a power of two)", 4u, 4096u);
        v.param("ways", ways, "ways", "associativity (pseudo-LRU replacement)", 1u, 64u);
        v.param("hit_latency_ns", hit_latency_ns, "ns",
                "hit latency (rounded up to whole core cycles)", 0.01, 1e5);
        v.param("shared", shared, "", "one level shared by all cores (else private per core)");
        v.param("foreign_fill_per_us", foreign_fill_per_us, "lines/us",
                "lines others sharing the level fill into it (0: none; full and sampled fidelity)",
                0.0, 1e9);
        v.param("pair_fill", pair_fill, "",
                "a line read from beyond the last level brings its 128-byte pair's other line "
                "into it (a host's adjacent-line prefetch)");
    }
};

// A read from DRAM within a span of memory: what it costs grows with the span. Measured for a
// host (measure_dram_first_pass_ns, host_description.h: the first pass of a random chase over
// the span right after 256 MiB read elsewhere): 91 ns over 2 MiB, 169 ns over 16 MiB and 327 ns
// over 256 MiB on this project's AMD VM (docs/silicon-check-amd-1ah-02h-avx512-host-scalar.hw.yaml,
// 2026-11-28). What it grows with is the pages used since the read's page was last used, not
// the distance: on that VM (2026-11-28, first-pass chases after 256 MiB read elsewhere) reads
// alternating between two 1 MiB blocks 200 MiB apart cost 92 ns, as over one 2 MiB block
// (94 ns); over sixteen 64 KiB blocks 16 MiB apart, 99-103 ns; over 32 MiB, 182-195 ns; and
// over 256 MiB with each 4 KiB page's lines read in a row, 96 ns against 347 ns at random. The
// model prices each read by its page's recency (dram_latency_ns_after, hw_model/cache_model.h).
struct DramSpanLatency {
    double span_mib = 0.0;
    double latency_ns = 0.0;

    template <class V>
    void visit(V& v) {
        v.param("span_mib", span_mib, "MiB", "span of memory the reads fall in", 0.001, 1e9);
        v.param("latency_ns", latency_ns, "ns", "latency of a read from DRAM in that span", 0.01,
                1e6);
    }
};

struct SceneMemoryConfig {
    // Bikker (seed 000), Fig. 1: 32 KiB / 256 KiB / 2 MiB, 8/8/16-way, latencies 4:11:39:107
    // cycles of his Xeon X5670 at 2.93 GHz (Intel's specification), i.e. 1.4 / 3.8 / 13.3 /
    // 36.5 ns; L1 and L2 are per core on that chip, L3 is shared.
    std::vector<CacheLevelConfig> caches = {{"l1", 32, 64, 8, 1.4, false},
                                            {"l2", 256, 64, 8, 3.8, false},
                                            {"l3", 2048, 64, 16, 13.3, true}};
    double dram_latency_ns = 36.5;
    // Where given, a read from DRAM costs, instead of dram_latency_ns, the latency of a random
    // chase over twice the distinct 4 KiB pages its core used since it last used the read's page
    // (dram_latency_ns_after), and a page's first use the latency at the scene data's span
    // (SceneDataMap::span_bytes); interpolated in log-log between the spans (the nearest one's
    // beyond them), never beyond the scene's span. Empty (the default): dram_latency_ns for
    // every read, as Bikker's one latency.
    std::vector<DramSpanLatency> dram_latency_by_span;
    double dram_bandwidth_gbps = 25.6;  // assumed: three DDR3-1066 channels, an X5670 configuration
    // Assumed: G&R describe no prefetch. 0: an op's scene data is requested when it dispatches.
    uint32_t prefetch_depth = 0;
    // Assumed: G&R describe no prefetch. true: when an op is dispatched, the scene data of the
    // ops whose streams its partition produces (a node's children, a leaf's primitives) is
    // requested too.
    bool prefetch_children = false;
    // Where a lane's hit primitive is read from when its surface is computed (the emission
    // filter, OpKindInfo::reads_hit_primitive). Assumed "primitives": G&R's scene memory holds
    // one copy of each primitive, the one its intersection test fetched. "mesh": the native
    // tracer's surface_at reads the mesh's own arrays (a 16-byte triangle record indexed by
    // primitive, then its vertices), not the copies its leaf tests read in BVH order.
    std::string hit_reads = "primitives";

    template <class V>
    void visit(V& v) {
        v.list("caches", caches, "scene-data cache levels, nearest first");
        v.param("dram_latency_ns", dram_latency_ns, "ns",
                "DRAM access latency (where dram_latency_by_span is empty)", 0.01, 1e6);
        v.list("dram_latency_by_span", dram_latency_by_span,
               "DRAM latency by the span of the scene's data (empty: dram_latency_ns)");
        v.param("dram_bandwidth_gbps", dram_bandwidth_gbps, "GB/s",
                "DRAM bandwidth, shared by all cores", 0.001, 1e4);
        v.param("prefetch_depth", prefetch_depth, "ops",
                "stream operations ahead of dispatch whose scene data is requested early (the "
                "traversal order makes the next nodes known)",
                0u, 1024u);
        v.param("prefetch_children", prefetch_children, "",
                "request the scene data of the ops an op's partition feeds (a node's children, "
                "a leaf's primitives) when it is dispatched, or, where its scene data holds "
                "their address (a right child, a leaf's primitives), once that has arrived");
        v.choice("hit_reads", hit_reads, {"primitives", "mesh"},
                 "where a lane's hit primitive is read when its surface is computed: "
                 "primitives (the record its intersection test fetched) or mesh (separate "
                 "triangle and vertex arrays, as the native tracer's surface_at reads)");
    }
};

// The SIMD datapath: how a SIMD unit issues a filter's per-group body. Instruction counts,
// their classes and dependent chains come from the op table (hw_model/op_costs.cpp).
// `programmable`: filters are programs of SIMD instructions (G&R 3.3: filter tests
// "implemented as C++ functors" compiled for the SIMD architecture), issued one per cycle, the
// op's dependent-chain latency paid once per group before its mask is known.
// `pipelined`: fixed-function filter pipelines accept a group every `initiation_interval`
// cycles.
// `cluster`: the execution subsystem of G&R's refs [11] and [16] (the perception processor,
// Mathew's dissertation ch. 9): a VLIW cluster of function units by class running each filter
// as a modulo-scheduled loop over its lane groups (hardware modulo support, compiler-controlled
// dataflow). A new group starts every II cycles, II = max(resource bound: each class's
// instructions over its units, rounded up; recurrence bound: the loop-carried chain's latency),
// and a group's mask is known a schedule length after it starts (its dependent chain at each
// class's latency). modulo_schedule() in hw_model/op_costs.h computes both.
struct DatapathConfig {
    std::string issue = "cluster";
    uint32_t fp_latency_cycles = 2;    // assumed: a 90 nm single-precision adder or multiplier at
                                       // 500 MHz (2 ns per cycle) in two pipeline stages
                                       // (issue: programmable and pipelined)
    uint32_t initiation_interval = 1;  // assumed (issue: pipelined only): a group per cycle
    // issue: cluster. Mathew, "The Perception Processor" (PhD dissertation, Utah 2004), 9.3
    // "Function Units": "All ALU operations have single cycle latency", "All FPU operations have
    // 7 cycle latency", "Multiply units support 32-bit integer multiply operations with 3 cycle
    // latency"; each unit N lanes wide here (G&R 3.3: "N-wide SIMD operations").
    uint32_t alu_latency_cycles = 1;  // Mathew 9.3 (integer add, logic, compare, select)
    uint32_t fpu_latency_cycles = 7;  // Mathew 9.3 (float add, subtract, multiply, compare)
    uint32_t mul_latency_cycles = 3;  // Mathew 9.3 (32-bit integer multiply)
    // FITTED, one number for the three counts: on conference's theoretical maximum only (G&R
    // 4.2: 64 fps), atrium-ambient and temple held out. No source gives the paper's unit mix,
    // so every class is assumed to have as many units. The fit (conference 1024x1024, width
    // 16, tile 64, sampled; fps with stalls hidden for 16/24/32/48/64/72/84/96 units: 26.0,
    // 29.3, 48.1, 53.7, 53.7, 60.55, 60.65, 60.65) takes the fewest units at the least error:
    // 84, the glossy body's 84 FPU instructions, where every filter issues a group a cycle.
    uint32_t fpu_units = 84;
    uint32_t alu_units = 84;
    uint32_t mul_units = 84;

    template <class V>
    void visit(V& v) {
        v.choice("issue", issue, {"programmable", "pipelined", "cluster"},
                 "programmable: instruction count per group; pipelined: one group per "
                 "initiation interval; cluster: a modulo-scheduled loop on function units by "
                 "class");
        v.param("fp_latency_cycles", fp_latency_cycles, "cycles",
                "latency of one dependent floating-point step (programmable, pipelined)", 1u, 64u);
        v.param("initiation_interval", initiation_interval, "cycles",
                "cycles between groups entering a pipelined filter datapath", 1u, 64u);
        v.param("alu_units", alu_units, "units", "cluster: integer ALUs (add, logic, select)",
                1u, 1024u);
        v.param("alu_latency_cycles", alu_latency_cycles, "cycles", "cluster: ALU latency", 1u,
                64u);
        v.param("fpu_units", fpu_units, "units",
                "cluster: floating-point units (add, multiply, compare)", 1u, 1024u);
        v.param("fpu_latency_cycles", fpu_latency_cycles, "cycles", "cluster: FPU latency", 1u,
                64u);
        v.param("mul_units", mul_units, "units", "cluster: integer multipliers", 1u, 1024u);
        v.param("mul_latency_cycles", mul_latency_cycles, "cycles",
                "cluster: integer multiplier latency", 1u, 64u);
    }
};

// A CPU core's conditional-branch predictor (hw_model/branch_predictor.h). Fitted op costs come
// from microbenchmarks that repeat their ops, whose branches the core's predictor learns; a
// frame's traversals never repeat. With a predictor the model runs it over the traversal's
// branches (derived from the trace) and prices each misprediction it makes.
struct BranchPredictorConfig {
    // Assumed for the paper's machine: G&R describe SIMD filters over streams and a partition
    // unit, no branch predictor; its filters' outcomes become masks, not jumps. With
    // "unseen_ops" the model runs no predictor: every traversal op of a frame (whose traversals
    // never repeat) is one misprediction, and the costs below are an op's (unseen_ops_states).
    std::string kind = "none";
    // What one misprediction of the model's predictor costs the core, fitted by
    // `sfx calibrate --describe-host` on the branch microbenchmark (a synthetic scene of random
    // triangles: its traversal batches after themselves and after the others), never on
    // frames: the pipeline's refill, the overlap a miss loses in a traversal, and the branches
    // the replay leaves out.
    double mispredict_cycles = 0.0;
    // The same by the native tracer's loop that runs the mispredicted box test (one-ray,
    // few-ray, stream: TraversalLoop, kernels/trace.h), each fitted on the same microbenchmark's
    // batches split by the stage clock, where the model mispredicts in that loop; negative: not
    // fitted (the model mispredicts too little there), the pooled mispredict_cycles. On the Zen 4
    // VM (2026-12-04) the scenes' predictor batches, measured, cost 1.4-1.9x the pooled price a
    // modelled misprediction in the scalar one-ray loop and 0.2-0.5x in its stream loop: a one-ray
    // traversal's miss waits on its dependent node reads, a stream's overlaps other lanes' work.
    double one_ray_mispredict_cycles = -1.0, few_ray_mispredict_cycles = -1.0,
           stream_mispredict_cycles = -1.0;
    // What one misprediction of a box test costs in loop `loop` (size_t(TraversalLoop)); a
    // leaf test's, which the stage clock splits into no loop, costs mispredict_cycles.
    double mispredict_cycles_in(size_t loop) const {
        const double by_loop[] = {one_ray_mispredict_cycles, few_ray_mispredict_cycles,
                                  stream_mispredict_cycles};
        return loop < 3 && by_loop[loop] >= 0 ? by_loop[loop] : mispredict_cycles;
    }
    // What `total` mispredictions cost, of which `box_by_loop` are box tests' in each loop
    // (the rest, leaf tests', pooled; counts may be differences between two states).
    double price(double total, const std::array<double, 3>& box_by_loop) const {
        double cycles = 0.0, box = 0.0;
        for (size_t l = 0; l < 3; ++l) {
            cycles += box_by_loop[l] * mispredict_cycles_in(l);
            box += box_by_loop[l];
        }
        return cycles + (total - box) * mispredict_cycles;
    }

    template <class V>
    void visit(V& v) {
        v.choice("kind", kind, {"none", "tage", "unseen_ops"},
                 "branch predictor (none: no branches priced; tage: L-TAGE's TAGE run over the "
                 "traversal's branches, each misprediction priced; unseen_ops: each op of a "
                 "traversal not just run, a box test or a leaf test, priced as one "
                 "misprediction, hw_model/branch_predictor.h)");
        v.param("mispredict_cycles", mispredict_cycles, "cycles",
                "cost of one misprediction of the model's predictor (fitted on a "
                "microbenchmark)",
                0.0, 1e6);
        v.param("one_ray_mispredict_cycles", one_ray_mispredict_cycles, "cycles",
                "cost of one misprediction in the one-ray loop (fitted on the microbenchmark; "
                "negative: mispredict_cycles)",
                -1.0, 1e6);
        v.param("few_ray_mispredict_cycles", few_ray_mispredict_cycles, "cycles",
                "cost of one misprediction in the few-ray loop (fitted on the microbenchmark; "
                "negative: mispredict_cycles)",
                -1.0, 1e6);
        v.param("stream_mispredict_cycles", stream_mispredict_cycles, "cycles",
                "cost of one misprediction in the stream loop (fitted on the microbenchmark; "
                "negative: mispredict_cycles)",
                -1.0, 1e6);
    }
};

// A CPU core's measured cost of one kind of stream operation (priced by OpProfile in
// hw_model/op_costs.h, the one place an op is priced), fitted
// by `sfx calibrate --describe-host` on microbenchmarks of the native filters on synthetic
// streams, never on frames. An op of n lanes in g = ceil(n / simd.width) groups, p passing,
// b of its lanes paying for ray data beyond the L1D (their line not in it, and their slot in
// another 4 KiB page of the array the op reads than the lane before it's: the prefetchers
// cover the rest; the cycle level asks its caches, the fit and the closed form expect it,
// hw_model/ray_buffer_model.h beyond_cache_share), b2 of them beyond the L2 as well (the same
// with the L2's size), b1 lanes beyond the L1D that skip lines in a page the lane before opened
// (their slot's first line beyond the one after the lane before's last), t lanes that open a
// page beyond the first-level DTLB's reach (hit or miss in the L1D), and c
// failing lanes that ran its full test (a triangle test's failed
// candidates, StreamOp::failed_candidates), costs
//   per_op + per_group * g + per_lane * n + per_pass * p + per_fail * (n - p)
//   + per_minority_lane * m + beyond_l1_per_lane * b + beyond_l2_per_lane * b2
//   + beyond_l1_skipping_per_lane * b1 + beyond_tlb_per_lane * t + per_failed_candidate * c
//   cycles
// (the minority term: a filter that branches on each lane's outcome pays the branch
// predictor's misses, m = mispredicted_lanes in hw_model/op_costs.h: on outcomes in no order
// the lanes of the rarer outcome, min(p, n - p), as in the microbenchmarks, which time
// streams of mixed outcomes dealt at random, and of every lane passing and of none; on a
// frame's outcomes in runs, about one a change of outcome, if fewer),
// except an op of one lane when one_lane_cycles is given (not negative; a fitted 0 is a cost,
// since session 52: on an AMD Zen 4 VM the traversal fit gave AVX-512's one-lane box test 0,
// which priced it by the formula, 71 cycles, and the one-ray loop +44 to +121 %), for the
// kinds the loop runs (OpCostTable keeps it for those only): the native tracer runs a one-ray
// stream's whole subtree in its own loop (traverse_one: the ray's fields in registers, no
// partition), so its box, triangle and sphere tests cost one_lane_cycles each (the box test's
// fitted on one-ray traversals of the same synthetic scene, the leaf tests' timed on one lane
// by the one-ray loop's leaf code: on a lane that fails, plus one_lane_pass_cycles if it
// passes and one_lane_failed_candidate_cycles if it is a triangle test's failed candidate);
// and a box test of 2 to k_few_ray_lanes lanes
// when few_lane_cycles is given (not negative) and the back end runs the few-ray loop: on a back
// end of k_few_ray_min_width lanes or more the tracer runs such a stream in its few-ray loop
// (traverse_few, kernels/trace.h), not the stream loop, so its box tests cost few_lane_cycles each,
// fitted on few-ray traversals of that scene. The box test's per_op is fitted on traversals of
// longer streams too (a stream-loop op waits for the one before's output; the filter
// microbenchmarks' calls are independent, and a core overlaps them), its other terms on the filter
// microbenchmarks. The box test that enters the one-ray or the few-ray loop from the stream loop
// also costs one_ray_entry_cycles or few_ray_entry_cycles (whatever a loop's start and end cost
// beyond its box tests), fitted on traversals whose streams enter at the root and deep in the tree:
// from the root every subtree holds about as many box tests, and a frame's short streams start
// deep. Empty (every preset): ops are priced from instruction counts instead.
struct OpCostConfig {
    std::string op = "box_test";  // an op kind name (kernels/trace.h)
    double per_op_cycles = 0.0;
    double per_group_cycles = 0.0;
    double per_lane_cycles = 0.0;
    double per_pass_cycles = 0.0;
    double per_fail_cycles = 0.0;
    double per_minority_lane_cycles = 0.0;
    double beyond_l1_per_lane_cycles = 0.0;
    // What such a lane adds where its line is beyond the L2 too: fitted with the rest on the
    // microbenchmarks' 64 x 64 buffers (4096 slots, 1.35 MB: a quarter beyond a 1 MB L2; their
    // 32 x 32 ones fit in it). One term for both levels priced a 32-pixel tile's lanes (in the
    // L2) as dear as a 64-pixel tile's (partly in the L3): on an AMD Zen 5 VM (2026-12-05, AVX2,
    // 200-1024 lanes) a passing direct-light lane cost 218-219 cycles over 256 and 1024 slots
    // and 259-290 over 4096, the miss filter's 4.9-5.2 against 6.4-7.7. Fitted there (scalar /
    // AVX2 / AVX-512): the camera 409 / 246 / 210 cycles, the direct light 163 / 156 / 116, the
    // indirect bounce 466 / 311 / 462, the beyond-L1 terms falling to a few cycles (the camera's
    // 70 to 6 at AVX2); its fit's median error 6.6 to 1.3 %, the indirect bounce's 4.6 to 2.6 %.
    // Only a lane that opens a page pays (as beyond the L1D): priced on every lane whose line
    // the cache model's L2 missed, a frame's tile of 64 pixels, swept in slot order through an
    // LRU L2 smaller than it, missed nearly all (furnace 128 x 128: 78 K lanes of 327 K against 1
    // K at tile 32), 2.1 M cycles more where the host ran 0.1-0.3 M more. 0: not measured.
    double beyond_l2_per_lane_cycles = 0.0;
    // What a lane beyond the L1D costs in a page of its array that the lane before it opened
    // where it skips lines past the lane before's (lane_skips_lines: a next-line prefetch does
    // not bring its line; a lane on the next line or the same one pays nothing more): fitted
    // with the rest on the microbenchmarks' streams, whose many lanes of one buffer share pages
    // (200 of 1024 slots: about 20 lanes a page of a shading array, most of them skipping).
    // Since 2026-12-07: on the Intel Xeon VM of model 0xCF, without it, the fit priced the
    // shading ops 1-4 % over at 64 slots and 1-3 % under at 4096 (scalar), and furnace's
    // 64-pixel tiles at 64 x 64 came out 3 % cheaper than its 16-pixel ones where the host ran
    // them alike (the lambertian bounce +5 %; the slot arrays' 4 KiB offsets staggered, the
    // same); priced on every lane of an opened page (the same day's first form), the fit put
    // the streams of every slot of 4096 5-12 % over and those of 96-512 lanes 2-10 % under,
    // and cornell's and atrium's 64-pixel tiles 2-5 points dearer than the host ran them.
    double beyond_l1_skipping_per_lane_cycles = 0.0;
    // What a lane that opens a page of its array costs where the pass's slots span more pages
    // than the first-level DTLB maps (RayBufferConfig::dtlb_pages; the share of the slots beyond
    // its reach, beyond_tlb_share in hw_model/ray_buffer_model.h), whether or not the L1D holds
    // its line: fitted with the rest on the microbenchmarks, whose 4096-slot buffers (1.4 MB,
    // 340 pages) outrun a DTLB of 96 pages and whose smaller ones do not. Since 2026-12-08: on
    // the Intel Xeon VM of model 0xCF a chase of one line a page took 5 core cycles a load up to
    // 96 pages and 9-12 beyond (the second-level TLB's hit); without the term the scalar fit
    // priced 12 of 15 kinds' 4096-slot points under the measured (medians -0.4 to -3.9 %), with
    // it the medians lie within -1.3 to +1.1 % (the indirect bounce 10.7 cycles a lane, the
    // camera 7.1). A frame's
    // dense lanes open few pages: furnace 64 x 64 at tile 64 came out 0.07 points dearer
    // against tile 16 than without it. 0: not measured.
    double beyond_tlb_per_lane_cycles = 0.0;
    // The triangle test's: what a candidate that fails its full test (behind the ray's origin,
    // or beyond its hit so far) adds to a lane the float edge stage rejects, which the plain
    // microbenchmark's failing lanes are (its rays start from no hit: nearly every candidate
    // passes). Fitted (the median over its points) on the test's microbenchmark of failing
    // candidates, its points by turns behind their origin and beyond a closer hit, whose exits
    // differ (a Zen 5 VM at AVX2, 2026-12-02: 38-43 and 47-52 cycles a lane on streams of 16 to
    // 1024, against 65-97 where every candidate passes and 6-12 where none is one), and a
    // frame's secondary rays fail both ways (behind and beyond, a lane at the first bounce,
    // depth 3, tile 32: cornell 128x128 0.15 and 0.17; temple 64x64 0.11 and 0.10; conference
    // 128x128 0.12 and 0.06: the median of the two ways' points fits cornell and temple best). A
    // primary ray's candidates nearly all pass. A one-lane op pays
    // one_lane_failed_candidate_cycles instead.
    // 0: not measured.
    double per_failed_candidate_cycles = 0.0;
    // A one-lane op's cost (0: not measured, one lane costs the formula above). A leaf test's is
    // timed on one-lane calls of the one-ray loop's leaf code whose lane fails (a triangle
    // test's: the float edge stage rejects it), and the two below add to it what a lane that
    // passes, and a triangle test's candidate that fails its full test, cost more: a frame's
    // one-lane leaf tests are mostly secondary rays' that fail (temple 64x64 at the first
    // bounce, depth 3, tile 32: 0.19 of its lanes pass, 0.21 are failed candidates), and the
    // one-ray loop's leaf code took 47 TSC ticks on a rejected lane against 93-102 on a failed
    // candidate and 111 on a passing one (a Zen 5 VM at AVX2, 2026-12-02; fitted there, 61.9
    // cycles failing, 78.5 more passing, 55.7 more a failed candidate). Host files written
    // before 2026-12-02 hold the median over one-lane calls on random rays, and no extras.
    // All three fitted by sfx calibrate (fit_one_lane_by_outcome): medians over the one-lane
    // microbenchmark points (the synthetic scene's floor triangle and spheres, buffers of 64 to
    // 4096 slots) whose lane fails, whose lane passes, and (the triangle test's) whose lane is
    // a failed candidate, by turns behind its origin and beyond a closer hit; the extras as
    // their medians beyond the failing one's. No frame.
    double one_lane_cycles = -1.0;                  // negative: not measured, the formula applies
    double one_lane_pass_cycles = 0.0;              // a leaf test's (0: not measured)
    double one_lane_failed_candidate_cycles = 0.0;  // the triangle test's (0: not measured)
    double few_lane_cycles = -1.0;                  // negative: not measured, the formula applies
    double one_ray_entry_cycles = 0.0;  // the box test's: entering the one-ray loop (0: none)
    double few_ray_entry_cycles = 0.0;  // the box test's: entering the few-ray loop (0: none)
    // The box test's: what a traversal costs once besides its ops (the tracer's set-up of a
    // traversal job, its shared-origin check's first compare, the loop's start and end; where
    // the rays do share an origin the check's other lanes are shared_origin_per_lane_cycles),
    // carried by the box test it starts with (StreamOp::starts_traversal). Fitted with the loop
    // entries on the traversal microbenchmark's batches, each stream of which is one traversal.
    // Why: furnace's traversals are one box test and one leaf each, and timed by parts they cost
    // about 190 cycles more than their ops are priced, about 105 of it the traversal's set-up and
    // 70 the stage clock's own reads (an AMD Zen 4 VM at AVX2, session 57: 165 traversals, 103.4 k
    // cycles measured against 72.4 k priced). The fit gave 0 on every back end of that VM
    // (2026-12-04): a one-ray batch's traversals equal its one-ray loop entries and rise with
    // its box tests, so only the stream-loop batches tell a traversal apart, and there it is a
    // fraction of a percent. Default 0: not measured.
    double traversal_start_cycles = 0.0;
    // The box test's: the tracer's check that a traversal's rays share one origin
    // (shared_origin, kernels/stream/stream_kernels.h), per lane, where they do (StreamOp::
    // origin_shared: a pinhole camera's rays) and it reads every lane's origin; where they do
    // not it stops at the second, within traversal_start_cycles. Timed directly over a tile's
    // records by its own microbenchmark (sfx calibrate --describe-host): 3.00-3.02 cycles a lane
    // on every back end of an AMD Zen 4 VM (2026-12-04), where furnace's traversal at AVX2 and
    // AVX-512, tiles of 32 and 64, was 3.4-4.4 cycles a camera ray over its price without it.
    // Default 0: not measured.
    double shared_origin_per_lane_cycles = 0.0;
    // An op that reads each lane's hit primitive (the emission filter): the share of those
    // reads' latency beyond an L2 hit (hit_read_latency_hidden, hw_model/cache_model.h) that
    // the core does not overlap with other work, fitted
    // on the surface-read microbenchmark (scene arrays beyond the caches) through the same
    // cache model that prices the frames. 0: not measured (the reads cost what the
    // cache-resident microbenchmark saw).
    double hit_read_exposed_share = 0.0;
    // The box test's: the share of its node read's latency beyond an L1D hit that a CPU core's
    // one-ray and few-ray loops leave exposed. Those loops run one ray (or a few) down the
    // tree with every branch predicted, so an out-of-order core issues the next nodes' reads
    // before the current one has arrived (memory-level parallelism; Eyerman, Eeckhout,
    // Karkhanis & Smith, "A mechanistic performance model for superscalar out-of-order
    // processors", TOCS 2009), where the model otherwise serialises each read after its
    // parent's. Fitted by sfx calibrate (fit_node_read_exposed_share, sweeps/host_calibration.h)
    // on the branch microbenchmark's tile batches (20,000 random triangles) from DRAM against
    // the same batches from the caches, per loop, through the model's own timing of them (one
    // wide back end's, taken by the other: the same loops' code); the real scenes' batches and
    // frames are held out. 1: not measured (the whole latency, as
    // before 2026-12-02 and on a unit that waits for its node).
    double node_read_exposed_share = 1.0;
    // The camera's: what a thin-lens camera's ray adds to a pinhole's (a concentric disk
    // sample, the focus point and a normalize; kernels/camera.h), fitted on the camera's
    // microbenchmarks with a lens beside its pinhole ones; paid by every lane of a camera op on
    // a scene whose camera has an aperture (FeatureSet::thin_lens). 0: not measured. Fitted on
    // an AMD Zen 5 VM (2026-12-01): 96.9 / 98.0 / 95.5 cycles a ray (scalar / AVX2 / AVX-512)
    // with each ray set up in the camera's own loop (session 44), 72-76 with the set-up in a
    // loop of its own as the tracer runs it (session 45; run 27's scalar calibration, 130, was
    // an outlier); held out, atrium's camera stage there ran 78 cycles a ray above the pinhole
    // scenes' (stage clock, run 24 of docs/silicon-check-amd-1ah-02h-avx512.md): now within
    // about 5 %.
    double thin_lens_per_lane_cycles = 0.0;
    // The direct-light filter's: what a passing lane's light sample on a sphere adds to one on a
    // triangle (a uniform point on the sphere and its error bound, kernels/lights.h; a failing
    // lane costs the same on either, on a Zen 5 core at AVX2, 2026-12-01), fitted on the
    // filter's microbenchmarks with a sphere light beside its quad ones; paid by every passing
    // lane of its ops in proportion to the share of a scene's light samples that land on
    // spheres (FeatureSet::sphere_light_share: furnace's all, cornell's none). 0: not measured.
    // Fitted on an AMD Zen 5 VM (2026-12-01, run 27 of
    // docs/silicon-check-amd-1ah-02h-avx512.md): 95.8 / 95.8 / 104.8 cycles a passing lane (scalar
    // / AVX2 / AVX-512). Held out, furnace's frames (AVX2, 128x128, tile 32, the same session's
    // quick checks): its shading stage -16 % without it, -9 % with it (the emission filter's change
    // in that run lowers the prediction too, so this cost's own part is larger); the direct-light
    // op alone reads +13 %, but its prediction holds its shadow rays' set-up, which the frame's
    // stage clock books apart. Most of that difference was the jumps of offset_ray_origin on
    // the sign of each component of a sphere's normal (kernels/intersect.h), which a quad's
    // fixed normal predicts: refitted with the offset by bit operations, on the AMD Zen 4 VM
    // (2026-12-03, docs/silicon-check-amd-19h-11h-avx512.md), 0 / 9.1 / 2.4 cycles (scalar /
    // AVX2 / AVX-512; 80.1 / 82.8 / 81.2 there before), and furnace's shading stage reads
    // +0.4 / +2.9 / +3.2 % of its sum over the page's workloads.
    double sphere_light_per_pass_cycles = 0.0;
    // The emission filter's: what a lane whose hit is a sphere adds to one whose hit is a
    // triangle (its per_lane_cycles; negative where it saves: a sphere's surface is a normalize
    // and a re-projection, a triangle's three vertex reads behind its record, an interpolation
    // and a cross product, kernels/intersect.h surface_at), fitted on the filter's
    // microbenchmarks on sphere hits beside its triangle ones; paid by every lane of its ops in
    // proportion to the share of the scene's surface area on spheres
    // (FeatureSet::sphere_area_share). 0: not measured. Why: every host's page priced furnace's
    // emission filter (all its hits on a sphere) 37-48 % over the stage clock's, cornell's within
    // 8 % (docs/silicon-check-*.md, before 2026-12-03 the filter was timed on the synthetic
    // scene's hits, triangles and a sphere mixed). Fitted on an AMD Zen 4 VM (2026-12-03, the
    // synthetic scene's microbenchmarks only, docs/silicon-check-amd-19h-11h-avx512.md):
    // -19.7 / -24.8 / -20.1 cycles a lane (scalar / AVX2 / AVX-512) against 71.6 / 75.9 / 71.7
    // on a triangle hit. Held out, that page's frames: furnace's filter -2 to -4 % (+39 to +42 %
    // before), cornell's -6 to -12 % (-1 to -8 % before: the mixed microbenchmark had carried the
    // branch on the primitive's kind, mispredicted where a stream's kind changes, 0.10 times a
    // lane on cornell, about 19 cycles each; unpriced, about 3 % of its filter, the rest of the
    // miss unexplained).
    double sphere_hit_per_lane_cycles = 0.0;
    // What a call costs cold, as a frame makes it (a shading filter once per generation of a
    // tile, the tile's traversal and the other filters between two calls; a traversal after a
    // generation's filters), over the same call right after another (the microbenchmark points
    // call an op back to back), on the op's first group: a shading op's every call (none to a
    // material filter the sort placed) and the box test's where it starts a traversal (the
    // cycle-level model only, as traversal_start_cycles). Timed, never fitted on frames: pairs
    // of single calls, the first after a pass of a 16 x 16 tile, the mean difference, the
    // median over a few lengths (MicrobenchOptions::cold_call_lengths,
    // run_cold_traversal_microbenchmarks). Why: on an AMD Zen 5 VM (2026-12-05,
    // docs/silicon-check-amd-1ah-02h-avx512.md) cornell's and furnace's shading was priced
    // about 80 cycles an op further under at tile 16 than at 32 on every back end (cornell
    // 128 x 128 AVX2: 1314 K cycles under with 3275 ops, 1118 K with 921) and furnace's
    // traversal 27-29 % under at tile 16 against 10-13 % at 32 and 64, and the tile ranking
    // failed on such pairs. That host's shading calls took 0-195 cycles more cold (the depth
    // filter's least), a traversal's start 118 / 59 / 68 (scalar / AVX2 / AVX-512); priced so,
    // furnace's traversal at tile 16 came to 10-18 % under, the shading MAE from 11.8 / 11.0 /
    // 12.6 % to 11.5 / 10.4 / 9.8 %, and every cornell cell's tiles ranked right.
    // 0: not measured.
    double cold_call_cycles = 0.0;

    template <class V>
    void visit(V& v) {
        v.param("op", op, "", "op kind (kernels/trace.h k_op_kinds)");
        v.param("per_op_cycles", per_op_cycles, "cycles", "fixed cost of one op (call, setup)",
                0.0, 1e9);
        v.param("per_group_cycles", per_group_cycles, "cycles",
                "cost per group of simd.width lanes (vector gathers, test, compress)", 0.0, 1e9);
        v.param("per_lane_cycles", per_lane_cycles, "cycles",
                "cost per lane (per-ray scalar work)", 0.0, 1e9);
        v.param("per_pass_cycles", per_pass_cycles, "cycles",
                "cost per passing lane (work only passing rays do)", 0.0, 1e9);
        v.param("per_fail_cycles", per_fail_cycles, "cycles",
                "cost per failing lane (what a lane's cost loses when it passes): fitted by sfx "
                "calibrate on the op's microbenchmarks, 0 where a passing lane costs no less",
                0.0, 1e9);
        v.param("per_minority_lane_cycles", per_minority_lane_cycles, "cycles",
                "cost per lane of the op's rarer outcome (passing or failing): branch "
                "mispredictions on each lane's outcome",
                0.0, 1e9);
        v.param("beyond_l1_per_lane_cycles", beyond_l1_per_lane_cycles, "cycles",
                "extra cost per lane when the ray buffer is wholly beyond the L1D (scaled by "
                "the fraction beyond)",
                0.0, 1e9);
        v.param("beyond_l2_per_lane_cycles", beyond_l2_per_lane_cycles, "cycles",
                "what a lane beyond the L1D adds where its ray data is beyond the L2 too (0: not "
                "measured)",
                0.0, 1e9);
        v.param("beyond_l1_skipping_per_lane_cycles", beyond_l1_skipping_per_lane_cycles, "cycles",
                "cost per lane beyond the L1D that skips lines in a page of the array its op "
                "reads the lane before opened (fitted by sfx calibrate, 0: not measured)",
                0.0, 1e9);
        v.param("beyond_tlb_per_lane_cycles", beyond_tlb_per_lane_cycles, "cycles",
                "cost per lane that opens a page of its array where the pass's slots span more "
                "pages than the first-level DTLB maps (ray_buffer.dtlb_pages; fitted by sfx "
                "calibrate, 0: not measured)",
                0.0, 1e9);
        v.param("per_failed_candidate_cycles", per_failed_candidate_cycles, "cycles",
                "the triangle test's: extra cost per failing lane that ran the full test (a "
                "candidate behind the origin or beyond a closer hit; 0: not measured)",
                0.0, 1e9);
        v.param("one_lane_cycles", one_lane_cycles, "cycles",
                "cost of a one-lane box, triangle or sphere test in the one-ray traversal loop "
                "(negative: not measured; the formula above applies)",
                -1.0, 1e9);
        v.param("one_lane_pass_cycles", one_lane_pass_cycles, "cycles",
                "a leaf test's: what a one-lane op whose lane passes costs beyond one_lane_cycles "
                "(0: not measured)",
                0.0, 1e9);
        v.param("one_lane_failed_candidate_cycles", one_lane_failed_candidate_cycles, "cycles",
                "the triangle test's: what a one-lane op whose lane is a failed candidate costs "
                "beyond one_lane_cycles (0: not measured)",
                0.0, 1e9);
        v.param("few_lane_cycles", few_lane_cycles, "cycles",
                "cost of a box test of 2 to 4 lanes in the few-ray traversal loop of a back end "
                "of 8 lanes or more (negative: not measured; the formula above applies)",
                -1.0, 1e9);
        v.param("one_ray_entry_cycles", one_ray_entry_cycles, "cycles",
                "cost of entering the one-ray traversal loop from the stream loop, besides its "
                "ops (the box test that enters it carries it; 0: not measured)",
                0.0, 1e9);
        v.param("few_ray_entry_cycles", few_ray_entry_cycles, "cycles",
                "cost of entering the few-ray traversal loop from the stream loop, besides its "
                "ops (the box test that enters it carries it; 0: not measured)",
                0.0, 1e9);
        v.param("traversal_start_cycles", traversal_start_cycles, "cycles",
                "the box test's: cost of starting a traversal, besides its ops (the box test "
                "it starts with carries it; 0: not measured)",
                0.0, 1e9);
        v.param("shared_origin_per_lane_cycles", shared_origin_per_lane_cycles, "cycles",
                "the box test's: cost per lane of checking that a traversal's rays share one "
                "origin, where they do (the box test it starts with carries it; 0: not "
                "measured)",
                0.0, 1e9);
        v.param("hit_read_exposed_share", hit_read_exposed_share, "",
                "share of each lane's hit-primitive read latency beyond an L2 hit that is not "
                "overlapped (0: not measured)",
                0.0, 100.0);
        v.param("node_read_exposed_share", node_read_exposed_share, "",
                "the box test's: share of a node read's latency beyond an L1D hit that a CPU "
                "core's one-ray and few-ray loops leave exposed (1: not measured)",
                0.0, 1.0);
        v.param("thin_lens_per_lane_cycles", thin_lens_per_lane_cycles, "cycles",
                "the camera's: cost a thin-lens camera adds per ray over a pinhole (0: not "
                "measured)",
                0.0, 1e9);
        v.param("sphere_light_per_pass_cycles", sphere_light_per_pass_cycles, "cycles",
                "the direct-light filter's: cost a light sample on a sphere adds per passing lane "
                "over one on a triangle (0: not measured)",
                0.0, 1e9);
        v.param("sphere_hit_per_lane_cycles", sphere_hit_per_lane_cycles, "cycles",
                "the emission filter's: cost a lane whose hit is a sphere adds over one on a "
                "triangle, negative where it saves (0: not measured)",
                -1e9, 1e9);
        v.param("cold_call_cycles", cold_call_cycles, "cycles",
                "what a call costs cold (other filters and a traversal since its last) over a "
                "call right after another, on its first group: a shading op's every call, the "
                "box test's where it starts a traversal (0: not measured)",
                0.0, 1e9);
    }
};

struct HwConfig {
    uint32_t version = 1;
    std::string name = "gr08";
    TechConfig tech;
    ClockConfig clock;
    SimdConfig simd;
    CoreConfig cores;
    RayBufferConfig ray_buffer;
    AguConfig agu;
    ScratchpadConfig scratchpad;
    PartitionConfig partition;
    InterconnectConfig interconnect;
    SceneMemoryConfig scene_memory;
    DatapathConfig datapath;
    BranchPredictorConfig branch_predictor;
    std::vector<OpCostConfig> op_costs;  // measured per-op costs of a CPU core (host only)
    // Host only: the speed probe's cycles when the host was calibrated (sweeps/host_calibration.h
    // speed_probe_cycles), for a silicon check to see whether the machine still runs as then.
    double speed_probe_cycles = 0.0;

    template <class V>
    void visit(V& v) {
        v.param("version", version, "", "configuration format version", 1u, 1u);
        v.param("name", name, "", "configuration name");
        v.group("tech", tech);
        v.group("clock", clock);
        v.group("simd", simd);
        v.group("cores", cores);
        v.group("ray_buffer", ray_buffer);
        v.group("agu", agu);
        v.group("scratchpad", scratchpad);
        v.group("partition", partition);
        v.group("interconnect", interconnect);
        v.group("scene_memory", scene_memory);
        v.group("datapath", datapath);
        v.group("branch_predictor", branch_predictor);
        v.list("op_costs", op_costs,
               "measured per-op costs of a CPU core (sfx calibrate --describe-host); empty: "
               "priced from instruction counts");
        v.param("speed_probe_cycles", speed_probe_cycles, "cycles",
                "host only: the speed probe's microbenchmark cycles at calibration (0: not "
                "measured); a silicon check re-runs the probe against it",
                0.0, 1e15);
    }
};

// Strict parsing: unknown keys, wrong types and out-of-range values throw InputError naming
// file, line and dotted key. Cross-parameter rules are checked too (banks divide the buffer,
// cache sizes divide into sets, ...).
// Reads a *.hw.yaml file, or a shipped preset by name ("gr08": hw_model/presets/gr08.hw.yaml;
// SFX_PRESET_DIR overrides where presets are found).
HwConfig load_hw_config(const std::string& path);
std::vector<std::string> builtin_preset_names();
HwConfig parse_hw_config(const std::string& yaml_text, const std::string& file_name);
// The same from a parsed node (a section of a larger document; lines are the document's).
HwConfig hw_config_from_yaml(const YAML::Node& root, const std::string& file_name);
// Cross-parameter checks only (after programmatic changes, e.g. a sweep axis). `lines` maps
// dotted keys to the lines they were read from, for the message.
using HwLineMap = std::map<std::string, int>;
void check_hw_config(const HwConfig& config, const std::string& file_name,
                     const HwLineMap& lines = {});
// What the machine model can time: ray buffers in an L1D (storage l1d) only with measured op
// costs, which already hold the lanes' loads and stores; measured op costs only with l1d
// storage (with banks they would count the gathers twice). Throws an InputError naming the
// configuration and key.
void check_machine_model_config(const HwConfig& config);

// The fully resolved configuration as YAML: load(dump(c)) == c.
std::string dump_hw_config(const HwConfig& config);
// Its values only (no comments), as block YAML indented by `indent` spaces, written without
// yaml-cpp's emitter (a sweep's point keys): parse_hw_config of it (unindented) == config.
std::string hw_config_values_yaml(const HwConfig& config, size_t indent = 0);

struct HwParamInfo {
    std::string path;  // dotted, e.g. "ray_buffer.banks" or "scene_memory.caches[1].kib"
    std::string value;
    std::string unit;
    std::string description;
};
// Every parameter of a configuration, in declaration order.
std::vector<HwParamInfo> flatten_hw_config(const HwConfig& config);

// How rows of several configurations are told apart (sfx simulate): each one's `name`, else
// (when another configuration shares it) the file's stem, else "name #i"; and the parameters
// in which it differs from the first configuration, as "path=value".
struct ConfigLabel {
    std::string name;
    std::vector<std::string> differences;  // empty for the first
};
std::vector<ConfigLabel> label_configs(const std::vector<HwConfig>& configs,
                                       const std::vector<std::string>& sources);

// Sets one parameter by dotted path from YAML scalar text ("16", "true", "[..]" is not a
// scalar); throws InputError(file, line, path, ...) for an unknown path or a bad value.
void set_hw_param(HwConfig& config, const std::string& path, const std::string& value,
                  const std::string& file = "command line", int line = 0);

}  // namespace sfx

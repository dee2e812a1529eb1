#include "hw_model/analytic_model.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <vector>

#include "hw_model/cache_model.h"
#include "hw_model/op_costs.h"
#include "hw_model/ray_buffer_model.h"

namespace sfx {

TraceProfile::TraceProfile(const WorkloadShape& shape) : m_map(scene_data_map(shape)) {
    // Data sizes do not depend on the datapath latencies: any configuration's table will do.
    const OpCostTable costs(RayRecordLayout(shape.features), DatapathConfig{});
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        m_scene_bytes.push_back(costs[OpKind(k)].scene_bytes);
    // Nodes, triangles, spheres, then a few materials (shading ops name a material kind).
    const uint64_t bytes = m_map.address(OpKind::material_filter, 0) + 64 * m_map.material_bytes;
    const uint64_t words = bytes / k_line_bytes / 64 + 2;
    m_frame_lines.assign(words, 0);
    m_pass_lines.assign(words, 0);
}

bool TraceProfile::mark(std::vector<uint64_t>& bits, uint64_t line) {
    const uint64_t word = line >> 6, bit = uint64_t(1) << (line & 63);
    if (word >= bits.size()) bits.resize(word + 1, 0);
    if (bits[word] & bit) return false;
    bits[word] |= bit;
    return true;
}

void TraceProfile::begin_pass(const TilePass& p) {
    ++m_passes;
    m_previous = OpKind::count;
    m_slots = std::max(m_slots, p.slot_count);
    for (uint64_t w : m_pass_touched) m_pass_lines[w] = 0;
    m_pass_touched.clear();
}

void TraceProfile::op(const StreamOp& op) {
    Bucket& b = m_buckets[Key{op.generation > 0, op.kind, op.length}];
    ++b.ops;
    b.passed += op.pass_count;
    b.failed_candidates += op.failed_candidates;
    b.placed += placed_by_material_sort(op.kind, m_previous);
    m_previous = op.kind;
    b.mispredicted += mispredicted_lanes(
        op.pass_count, op.length, op.passed ? outcome_changes(op.passed, op.length) : op.length);
    const uint32_t bytes = m_scene_bytes[size_t(op.kind)];
    if (op.object == k_no_object || op.length == 0 || bytes == 0) return;
    ++b.fetches;
    ++m_footprint.fetches;
    const uint64_t address = m_map.address(op.kind, op.object);
    for (uint64_t line = address / k_line_bytes; line <= (address + bytes - 1) / k_line_bytes;
         ++line) {
        if (mark(m_pass_lines, line)) {
            ++m_footprint.pass_distinct;
            m_pass_touched.push_back(line >> 6);
        }
        m_footprint.frame_distinct += mark(m_frame_lines, line);
    }
}

void TraceProfile::end_pass(const TilePass&) {}

namespace {

// Truncated polynomial product: coefficients up to degree n.
std::vector<double> multiply(const std::vector<double>& a, const std::vector<double>& b, size_t n) {
    std::vector<double> c(n + 1, 0.0);
    for (size_t i = 0; i <= n; ++i)
        if (a[i] != 0.0)
            for (size_t j = 0; i + j <= n; ++j) c[i + j] += a[i] * b[j];
    return c;
}

std::vector<double> power(std::vector<double> base, uint32_t e, size_t n) {
    std::vector<double> result(n + 1, 0.0);
    result[0] = 1.0;
    while (e) {
        if (e & 1) result = multiply(result, base, n);
        base = multiply(base, base, n);
        e >>= 1;
    }
    return result;
}

}  // namespace

double expected_conflicts(uint32_t lanes, uint32_t banks) {
    if (lanes <= 1 || banks == 0) return 0.0;
    static std::mutex mutex;
    static std::map<std::pair<uint32_t, uint32_t>, double> cache;
    std::lock_guard<std::mutex> lock(mutex);
    const auto key = std::make_pair(lanes, banks);
    if (auto it = cache.find(key); it != cache.end()) return it->second;
    // P(max load <= m) = n! / B^n [x^n] (sum_{j<=m} x^j / j!)^B; E[max] = sum_m P(max > m).
    const size_t n = lanes;
    double log_scale = std::lgamma(double(n) + 1.0) - double(n) * std::log(double(banks));
    double expected_max = 0.0;
    for (uint32_t m = 0; m < lanes; ++m) {
        std::vector<double> base(n + 1, 0.0);
        double term = 1.0;
        for (uint32_t j = 0; j <= std::min<uint32_t>(m, lanes); ++j) {
            base[j] = term;
            term /= double(j + 1);
        }
        const double coefficient = power(base, banks, n)[n];
        const double p_le = coefficient > 0.0 ? std::exp(std::log(coefficient) + log_scale) : 0.0;
        expected_max += 1.0 - std::min(1.0, p_le);
    }
    const double needed = double((lanes + banks - 1) / banks);
    const double result = std::max(0.0, expected_max - needed);
    cache[key] = result;
    return result;
}

double expected_moved_ids(uint32_t length, double p) {
    // Id i passing moves unless every id before it passes; failing moves unless every id after
    // it fails: sum_i p (1 - p^i) + (1 - p)(1 - (1 - p)^(L - 1 - i)).
    if (length == 0 || p <= 0.0 || p >= 1.0) return 0.0;
    const double q = 1.0 - p, len = double(length);
    const double geo_p = (1.0 - std::pow(p, len)) / (1.0 - p);  // sum_{i<L} p^i
    const double geo_q = (1.0 - std::pow(q, len)) / (1.0 - q);
    return p * (len - geo_p) + q * (len - geo_q);
}

namespace {

// Expected cycles of one scene-data fetch. Per level of capacity C: a fetch that re-touches a
// line already fetched in this pass hits if the pass's working set fits (in proportion, if
// not); a first touch in the pass hits if the line survived from earlier passes, in
// proportion to how much of the frame's working set fits; the frame's first touches miss.
// The scene data a pass touches, on average (distinct lines).
double mean_pass_bytes(const TraceProfile& profile) {
    return TraceProfile::k_line_bytes * double(profile.footprint().pass_distinct) /
           double(std::max<uint64_t>(1, profile.passes()));
}

// Cycles of a line read from DRAM: its latency and its transfer at the channel's bandwidth.
double dram_read_cycles(const SceneMemoryConfig& memory, double core_mhz) {
    const double transfer =
        double(dram_line_bytes(memory)) / (memory.dram_bandwidth_gbps * 1000.0 / core_mhz);
    return double(ns_to_cycles(memory.dram_latency_ns, core_mhz)) + transfer;
}

double expected_fetch_cycles(const SceneMemoryConfig& memory, double core_mhz,
                             const TraceProfile& profile,
                             std::vector<double>* global_misses = nullptr) {
    const TraceProfile::Footprint& f = profile.footprint();
    const double fetches = double(f.fetches);
    const double pass_bytes = mean_pass_bytes(profile);
    const double frame_bytes = TraceProfile::k_line_bytes * double(f.frame_distinct);
    const double first_in_pass = double(f.pass_distinct), first_in_frame = double(f.frame_distinct);
    if (fetches == 0) return 0.0;
    const double compulsory = first_in_frame / fetches;
    const double first_touch = first_in_pass / fetches;
    double previous_miss = 1.0, cycles = 0.0;
    for (const CacheLevelConfig& level : memory.caches) {
        const double capacity = double(level.kib) * 1024.0;
        const double survives = std::min(1.0, capacity / frame_bytes);
        const double retouch_hits = std::min(1.0, capacity / pass_bytes);
        const double miss = compulsory + (first_touch - compulsory) * (1.0 - survives) +
                            (1.0 - first_touch) * (1.0 - retouch_hits);
        const double global_miss = std::min(previous_miss, std::max(0.0, miss));  // inclusive
        cycles +=
            (previous_miss - global_miss) * double(ns_to_cycles(level.hit_latency_ns, core_mhz));
        previous_miss = global_miss;
        if (global_misses) global_misses->push_back(global_miss);
    }
    return cycles + previous_miss * dram_read_cycles(memory, core_mhz);
}

// Expected cycles until the slowest of `lanes` reads of each lane's hit primitive arrives. The
// hit's lines were fetched by the intersection op that found it in this pass, so a read is a
// re-touch: it hits a level if the pass's working set fits (in proportion, if not). Fills
// `global_misses` (per level, one read's) when given.
double expected_hit_read_cycles(const SceneMemoryConfig& memory, double core_mhz,
                                const TraceProfile& profile, double lanes,
                                std::vector<double>* global_misses = nullptr) {
    const double pass_bytes = mean_pass_bytes(profile);
    double previous_miss = 1.0, previous_latency = 0.0, cycles = 0.0;
    auto beyond = [&](double miss, double latency) {
        // P(some lane reaches this level) x its extra latency over the nearer level's.
        cycles += (1.0 - std::pow(1.0 - previous_miss, lanes)) * (latency - previous_latency);
        previous_latency = latency;
        previous_miss = miss;
    };
    for (const CacheLevelConfig& level : memory.caches) {
        const double retouch_miss =
            pass_bytes > 0 ? 1.0 - std::min(1.0, double(level.kib) * 1024.0 / pass_bytes) : 0.0;
        const double global_miss = std::min(previous_miss, retouch_miss);  // inclusive
        beyond(global_miss, double(ns_to_cycles(level.hit_latency_ns, core_mhz)));
        if (global_misses) global_misses->push_back(global_miss);
    }
    beyond(0.0, dram_read_cycles(memory, core_mhz));
    return cycles;
}

}  // namespace

FrameTiming analytic_timing(const HwConfig& c, const WorkloadShape& shape,
                            const TraceProfile& profile, const TraceProfile* footprint) {
    const RayRecordLayout layout(shape.features);
    const OpCostTable costs(layout, c);
    costs.check_measured(shape.needed_kinds(), c.name);
    // A CPU core (storage l1d): the lanes' loads, stores and compress-stores are inside the
    // measured op costs, and so is an L1D hit on scene data.
    const bool l1d = c.ray_buffer.storage == "l1d";
    const RayBufferModel buffer(c.ray_buffer, layout.words(), std::max(1u, shape.slots()));
    const uint32_t n = c.simd.width;
    const uint32_t slots = std::max(1u, std::max(profile.slots(), shape.slots()));
    std::vector<double> global_misses;  // per cache level, for the action counts
    const TraceProfile& lines = footprint ? *footprint : profile;  // whose scene lines
    // DRAM's latency at this scene's span: a page's first use at the cycle level, which prices
    // later reads by their page's recency (dram_latency_ns_after), a sequence the closed form
    // does not keep; its error bar is measured against the cycle level.
    SceneMemoryConfig memory = c.scene_memory;
    memory.dram_latency_ns = dram_latency_ns_at(memory, scene_data_map(shape).span_bytes());
    const double fetch_cycles =
        std::max(0.0, expected_fetch_cycles(memory, c.clock.core_mhz, lines, &global_misses) -
                          double(scene_latency_in_costs(c)));
    const double words_per_core_cycle =
        double(c.interconnect.width_words) * c.clock.interconnect_mhz / c.clock.core_mhz;
    const double fill_bank =
        buffer.fill_cycles() +
        std::ceil(c.interconnect.mux_levels * c.clock.core_mhz / c.clock.interconnect_mhz);
    // Banks a group can reach: all of them for soa records; for aos records consecutive slots
    // step by the record size, reaching banks / gcd(record words, banks) of them.
    const uint32_t banks = c.ray_buffer.banks;
    const uint32_t reachable =
        c.ray_buffer.layout == "aos" ? banks / std::gcd(layout.words(), banks) : banks;
    // Conflict cycles of one access of `lanes` lanes: dense streams (consecutive slots) queue
    // only on unreachable banks; sparse ones behave like random slots over the reachable banks.
    auto group_conflicts = [&](uint32_t lanes, double sparsity) {
        const double needed = double((lanes + banks - 1) / banks);
        const double dense = double((lanes + reachable - 1) / reachable) - needed;
        const double random = expected_conflicts(lanes, reachable) +
                              double((lanes + reachable - 1) / reachable) - needed;
        return (1.0 - sparsity) * dense + sparsity * random;
    };
    FrameTiming t;
    t.passes = profile.passes();
    double total_cycles = 0.0;
    // Fractional sums in unit-cycles, rounded once at the end.
    StallCounts<double> stalls;
    // Expected action counts, summed fractionally and rounded once at the end (as the stalls).
    double bank_reads = 0, bank_writes = 0, addresses = 0, compares = 0, moved = 0,
           scratch_words = 0, word_hops = 0, fetches = 0, busy_units[k_hw_unit_count] = {},
           lane_reads = 0;
    double simd_instructions[k_op_kind_count] = {}, simd_lane_ops[k_op_kind_count] = {};
    const double units = double(std::max(1u, c.simd.units));
    const double agu_rate = double(c.agu.count) * c.agu.addresses_per_cycle;
    const double occupancy = c.ray_buffer.pipelined ? 1.0 : c.ray_buffer.access_latency_cycles;
    for (const auto& [key, bucket] : profile.buckets()) {
        const auto& [secondary, kind, length] = key;
        if (length == 0) continue;
        const OpProfile& p = costs[kind];
        const uint64_t mix_before = t.mix.total();
        const double ops = double(bucket.ops);
        const double pass_rate = double(bucket.passed) / (ops * double(length));
        const uint64_t groups = (uint64_t(length) + n - 1) / n;
        const double sparsity = std::max(0.0, 1.0 - double(length) / double(slots));
        const double gathers = double(p.gather_words.size());
        // Of the lanes beyond the L1D, those opening a page of the array the op reads pay
        // (lanes_opening_pages), here as expected of a stream of `length` random slots, and
        // those skipping lines in an opened page (lanes_skipping_lines) pay their own.
        const OpStage op_stage = stage_of(kind);
        const double beyond_l1 =
            slots_beyond_cache(c.ray_buffer, layout.bytes(), std::max(1u, shape.slots()), op_stage);
        // Beyond the L2 behind it too (the scene memory's second level).
        const double beyond_l2 =
            c.scene_memory.caches.size() > 1
                ? slots_beyond_cache(c.ray_buffer, layout.bytes(), std::max(1u, shape.slots()),
                                     op_stage, c.scene_memory.caches[1].kib)
                : 0.0;
        const uint32_t page_bytes = lane_page_bytes_of(c.ray_buffer, layout.bytes(), op_stage);
        const double opening_share = beyond_l1 > 0
                                         ? expected_lanes_opening_pages(length, slots, page_bytes) /
                                               double(std::min(length, slots))
                                         : 0.0;
        const double skipping_share =
            beyond_l1 > 0 ? expected_lanes_skipping_lines(length, slots, page_bytes) /
                                double(std::min(length, slots))
                          : 0.0;
        // Beyond the first-level DTLB's reach: every lane opening a page, in the L1D or not.
        const double beyond_tlb =
            c.ray_buffer.storage == "l1d"
                ? beyond_tlb_share(length, std::max(1u, shape.slots()),
                                   slot_bytes_of(c.ray_buffer, layout.bytes()), page_bytes,
                                   c.ray_buffer.dtlb_pages)
                : 0.0;
        // The cycle model's pipeline in closed form. Groups spread over the units; each round
        // of them costs the slowest of execution, the access side's issue, and the shared
        // address units and interconnect. An op that partitions holds the next op back: the
        // next op's first fetch, this op's last result and the partition are exposed.
        const double sharing = std::min(units, double(groups));
        const double rounds = std::ceil(double(groups) / sharing);
        double align = 0.0, conflict = 0.0, accesses = 0.0, round_sum = 0.0, addr_sum = 0.0,
               ic_sum = 0.0;
        double first_fetch = 0.0, scatter_addresses = 0.0, access_sum = 0.0, word_sum = 0.0;
        double busy_sum = 0.0;  // the op's issue cycles, all groups
        for (uint64_t g = 0; g < groups; ++g) {
            const uint32_t lanes = std::min<uint32_t>(n, length - uint32_t(g * n));
            // A one-lane op's pass is priced by the bucket's pass rate (rounded, one lane
            // would pass all or none of the bucket).
            const double passing = length == 1 ? pass_rate : double(std::lround(pass_rate * lanes));
            const double busy =
                p.issue_cycles(c.datapath, length,
                               uint32_t(std::lround(double(bucket.mispredicted) / ops)), lanes,
                               passing, g == 0, beyond_l1 * opening_share,
                               beyond_l2 * opening_share, double(bucket.failed_candidates) / ops,
                               beyond_l1 * skipping_share, beyond_tlb) +
                // A shading filter's call cold (a traversal's start is not priced here, as
                // its other start costs are not: the cycle-level model's).
                (g == 0 && op_stage == OpStage::shading ? p.cold_call_cycles() : 0.0);
            busy_sum += busy;
            if (l1d) {
                // A CPU core: nothing besides the measured cost; the groups run back to back.
                round_sum += busy;
                continue;
            }
            const RayBufferModel::Contiguous ids = buffer.access_contiguous(g * n, lanes);
            // Scatters of the passing lanes share the address units, interconnect and banks.
            const double scattering = std::round(pass_rate * lanes);
            const double scatter_words =
                scattering >= 1.0 ? scattering * double(p.scatter_words.size()) : 0.0;
            const double words = double(lanes) * gathers + scatter_words;
            const double conflicts = group_conflicts(lanes, sparsity) * occupancy;
            const double access =
                double(ids.cycles) + gathers * occupancy + conflicts +
                (scatter_words > 0 ? double(p.scatter_words.size()) * occupancy : 0.0);
            const double addresses = sharing * words / agu_rate;
            const double wires = sharing * words / words_per_core_cycle;
            round_sum += std::max({busy, access, addresses, wires});
            access_sum += access;
            word_sum += words;
            addr_sum += std::max(0.0, addresses - std::max(busy, access));
            ic_sum += std::max(0.0, wires - std::max({busy, access, addresses}));
            align += double(ids.alignment_cycles);
            conflict += conflicts;
            accesses += gathers;
            if (g == 0)
                first_fetch = double(ids.cycles) + std::ceil(double(lanes) / agu_rate) +
                              std::max(0.0, gathers - 1.0) + conflicts + double(buffer.latency()) +
                              (fill_bank - buffer.fill_cycles());
            if (scattering >= 1.0 && !p.scatter_words.empty()) {
                accesses += double(p.scatter_words.size());
                scatter_addresses += double(p.scatter_words.size());
            }
        }
        const double per_round = round_sum / double(groups);
        const double exec = rounds * per_round;
        const double busy = busy_sum / double(groups);  // the mean group's
        const double tail =
            l1d ? 0.0 : std::max(0.0, p.result_cycles(c.datapath, busy) - busy) + 1.0;
        double compare = 0.0, moves = 0.0, moved_ids = 0.0;
        if (p.partitions && c.partition.kind == "compress") {
            moved_ids = expected_moved_ids(length, pass_rate);  // written by the groups
        } else if (p.partitions) {
            compare = std::ceil(double(length) / (double(n) * c.partition.comparators_per_lane));
            moved_ids = expected_moved_ids(length, pass_rate);
            moves = std::ceil(moved_ids / n);
        }
        const double bubble = p.partitions && !l1d ? first_fetch + tail + compare + moves : 0.0;
        // Scene data is requested at dispatch (or prefetch_depth ops earlier; a prefetch of
        // children at least one op earlier, while the op that feeds it runs): what the first
        // fetch and the earlier ops do not cover shows.
        const double ahead =
            double(c.scene_memory.prefetch_depth) + (c.scene_memory.prefetch_children ? 1.0 : 0.0);
        const double fetch_stall =
            p.scene_bytes
                ? std::max(0.0, fetch_cycles - first_fetch - ahead * (exec + bubble)) *
                      double(bucket.fetches) / ops
                : 0.0;
        // Each lane's hit primitive (lane_scene_reads), requested at dispatch: the first
        // group waits for its slowest lane beyond its ray data; later groups find theirs.
        double lane_stall = 0.0;
        if (p.lane_scene_reads && !l1d) {
            lane_stall =
                std::max(0.0, expected_hit_read_cycles(memory, c.clock.core_mhz, lines,
                                                       double(std::min<uint32_t>(n, length))) -
                                  first_fetch);
            lane_reads += ops * double(length);
        } else if (p.lane_scene_reads) {
            // A CPU core works through its lanes in turn and leaves the measured share of each
            // read's latency beyond an L2 hit exposed (CoreModel::request_scene). Taken as
            // re-touches in the pass, as above, whichever array hit_reads names; a triangle's
            // mesh record and its vertices are two reads.
            const double reads = c.scene_memory.hit_reads == "mesh" && shape.triangles ? 2.0 : 1.0;
            const double beyond =
                std::max(0.0, expected_hit_read_cycles(memory, c.clock.core_mhz, lines, 1.0) -
                                  double(hit_read_latency_hidden(c)));
            lane_stall = p.cost.hit_read_exposed_share * double(length) * reads * beyond;
            lane_reads += ops * double(length) * reads;
        }
        const double memory_stall = fetch_stall + lane_stall;
        const double op_cycles = exec + bubble + memory_stall;

        // A CPU core's material filters after a generation's first cost nothing
        // (placed_by_material_sort): they are timed as no ops.
        const double timed = l1d && p.measured ? ops - double(bucket.placed) : ops;
        total_cycles += timed * op_cycles;
        // Action counts, as the cycle-level core model counts them.
        const double passed = double(bucket.passed);
        bank_reads += ops * (double(length) * (1.0 + gathers) + moved_ids);
        bank_writes += passed * double(p.scatter_words.size()) + ops * moved_ids +
                       (p.pushes_rays ? passed : 0.0);
        addresses += ops * word_sum;
        simd_instructions[size_t(kind)] += ops * double(groups) * p.compute_instructions;
        simd_lane_ops[size_t(kind)] += ops * double(length) * p.compute_instructions;
        compares += p.partitions ? ops * double(length) : 0.0;
        moved += ops * moved_ids;
        scratch_words += ops * double(groups);
        word_hops += ops * word_sum * c.interconnect.mux_levels;
        fetches += p.scene_bytes ? double(bucket.fetches) : 0.0;
        busy_units[size_t(HwUnit::ray_buffer)] += ops * access_sum;
        busy_units[size_t(HwUnit::agu)] += ops * word_sum / agu_rate;
        busy_units[size_t(HwUnit::simd)] += ops * double(groups) * busy;
        busy_units[size_t(HwUnit::partition)] += ops * (compare + moves);
        busy_units[size_t(HwUnit::scratchpad)] += ops * double(groups) / c.scratchpad.ports;
        busy_units[size_t(HwUnit::interconnect)] += ops * word_sum / words_per_core_cycle;
        // Unit-cycles: busy ones issue instructions; the rest are charged to their causes.
        const double busy_units = double(groups) * busy;
        const double fetch_excess = timed * sharing * std::max(0.0, exec - rounds * busy);
        const double excess_parts = std::max(1e-9, align + conflict + addr_sum + ic_sum);
        stalls.bank_conflict += fetch_excess * conflict / excess_parts;
        stalls.alignment += fetch_excess * align / excess_parts;
        stalls.address_fetch += fetch_excess * addr_sum / excess_parts;
        stalls.interconnect += fetch_excess * ic_sum / excess_parts;
        stalls.partition += timed * units * (compare + moves);
        stalls.scene_memory += timed * units * memory_stall;
        t.stages[secondary][uint32_t(stage_of(kind))].scene_memory_cycles +=
            uint64_t(std::llround(timed * units * memory_stall));
        stalls.pipeline_fill += timed * units * (p.partitions ? first_fetch + tail : 0.0);
        stalls.unit_idle += timed * ((units - sharing) * exec + sharing * rounds * busy - busy_units);
        StageTiming& stage = t.stages[secondary][uint32_t(stage_of(kind))];
        stage.ops += bucket.ops;
        stage.lanes += bucket.ops * length;
        stage.groups += bucket.ops * groups;
        stage.busy_cycles += uint64_t(std::llround(timed * busy_units));
        stage.stall_cycles += uint64_t(std::llround(timed * (op_cycles * units - busy_units)));
        t.mix.load += uint64_t(ops * double(groups) * double(1 + p.gather_words.size()) +
                               double(p.scene_bytes ? bucket.fetches : 0));
        t.mix.compute += uint64_t(ops * double(groups) * p.compute_instructions);
        t.mix.scatter_gather += uint64_t(std::llround(ops * accesses));
        t.mix.partition += uint64_t(ops * compare);
        if (p.partitions) {
            // G&R Fig. 5's mask store, for groups with a passing lane (independent lanes).
            double stored = 0.0;
            for (uint64_t g = 0; g < groups; ++g)
                stored += 1.0 - std::pow(1.0 - pass_rate,
                                         double(std::min<uint32_t>(n, length - uint32_t(g * n))));
            t.mix.store += uint64_t(ops * stored);
        }
        if (p.lane_scene_reads) {
            t.mix.load += uint64_t(ops * double(groups * p.lane_scene_words));
            t.mix.scatter_gather += uint64_t(ops * double(groups * p.lane_scene_words));
            addresses += ops * double(length) * p.lane_scene_words;
        }
        t.mix.store += uint64_t(ops * moves + ops * scatter_addresses);
        if (p.pushes_rays) t.mix.store += uint64_t(std::ceil(double(bucket.passed) / n));
        if (is_option_kind(kind)) t.mix.option += t.mix.total() - mix_before;
        t.field_accesses += uint64_t(std::llround(ops * accesses));
    }
    StallCycles::visit(t.stalls, stalls, [](const CounterInfo&, uint64_t& x, double y) {
        x = uint64_t(std::llround(y));
    });
    auto count = [](double v) { return uint64_t(std::llround(v)); };
    ActionCounts& a = t.actions;
    a.bank_reads = count(bank_reads);
    a.bank_writes = count(bank_writes);
    a.agu_addresses = count(addresses);
    for (uint32_t k = 0; k < k_op_kind_count; ++k) {
        a.simd_instructions[k] = count(simd_instructions[k]);
        a.simd_lane_ops[k] = count(simd_lane_ops[k]);
    }
    a.partition_compares = count(compares);
    a.partition_moves = count(moved);
    a.scratchpad_accesses = count(scratch_words);
    a.interconnect_word_hops = count(word_hops);
    // One line per fetch: level i is looked up by the fetches every nearer level missed; so
    // with the lanes' hit reads (one line each, at their re-touch misses).
    std::vector<double> lane_misses;
    if (lane_reads > 0)
        expected_hit_read_cycles(memory, c.clock.core_mhz, lines, 1.0, &lane_misses);
    double reaching = fetches + lane_reads;
    for (size_t i = 0; i < global_misses.size() && i < ActionCounts::k_max_cache_levels; ++i) {
        const double lane_missed = i < lane_misses.size() ? lane_reads * lane_misses[i] : 0.0;
        a.cache_accesses[i] = count(reaching);
        a.cache_fills[i] = count(fetches * global_misses[i] + lane_missed);
        reaching = fetches * global_misses[i] + lane_missed;
    }
    a.dram_bytes = count(reaching * dram_line_bytes(c.scene_memory));
    for (uint32_t u = 0; u < k_hw_unit_count; ++u) a.busy_cycles[u] = count(busy_units[u]);
    t.cycles = uint64_t(std::llround(total_cycles));
    return t;
}

}  // namespace sfx

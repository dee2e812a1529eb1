#include "hw_model/op_costs.h"

#include <algorithm>
#include <cmath>
#include <string_view>

#include "base/input_error.h"
#include "workloads/ray_layout.h"

namespace sfx {

RayRecordLayout::RayRecordLayout(const FeatureSet& features) : m_features(features) {
    for (const RayField& f : ray_record_fields(features)) {
        std::vector<uint32_t> words;
        for (uint32_t i = 0; i < (f.bytes + 3) / 4; ++i) words.push_back(m_words++);
        m_fields.emplace_back(f.name, std::move(words));
    }
}

const std::vector<uint32_t>& RayRecordLayout::field(const std::string& name) const {
    for (const auto& f : m_fields)
        if (f.first == name) return f.second;
    return m_none;
}

namespace {

std::vector<uint32_t> words_of(const RayRecordLayout& layout,
                               const std::vector<const char*>& names) {
    std::vector<uint32_t> out;
    for (const char* n : names)
        for (uint32_t w : layout.field(n)) out.push_back(w);
    return out;
}

}  // namespace

OpCostTable::OpCostTable(const RayRecordLayout& l, const DatapathConfig& d) {
    // `instructions`: SIMD instructions per lane group on ray data (Table 5's "comp"); `chain`:
    // the longest dependent chain of them, paid once per group at d.fp_latency_cycles per step
    // before the group's mask is known. Intersection counts are the floating-point, compare and
    // select operations of kernels/intersect.h's scalar code per lane (the box test is G&R
    // Fig. 5's slab test; the triangle test is watertight, with its plane distance in double).
    // Shading counts are estimates from kernels/materials.h and kernels/path.h, not exact.
    auto set = [&](OpKind k, const std::vector<const char*>& gather,
                   const std::vector<const char*>& scatter, UnitClassCounts body,
                   UnitClassCounts chain, uint32_t scene_bytes, UnitClassCounts recurrence = {}) {
        OpProfile& p = m_profiles[size_t(k)];
        p.gather_words = words_of(l, gather);
        p.scatter_words = words_of(l, scatter);
        p.body = body;
        p.chain = chain;
        p.recurrence = recurrence;
        p.compute_instructions = body.total();
        p.chain_steps = chain.total();
        p.latency_cycles = p.chain_steps * d.fp_latency_cycles;
        p.schedule = modulo_schedule(body, chain, recurrence, d);
        p.scene_bytes = scene_bytes;
        p.partitions = op_info(k).partitions;
        p.pushes_rays = op_info(k).pushes_rays;
        // Per lane: a triangle's vertices or a sphere (SceneDataMap's records), the larger
        // present, in words.
        const SceneDataMap records;
        p.lane_scene_reads = op_info(k).reads_hit_primitive;
        if (p.lane_scene_reads)
            p.lane_scene_words = uint32_t((l.features().triangles ? records.triangle_bytes
                                           : l.features().spheres ? records.sphere_bytes
                                                                  : 0) /
                                          4);
    };
    // Classes (issue: cluster; Mathew 9.3's function units): float add, subtract, multiply,
    // compare, min/max and convert, and (assumed, one instruction each: the perception
    // processor has no divider) divide and square root on FPUs; selects, logic, integer add,
    // compare and shift on ALUs; integer multiplies on multipliers: two per random number
    // (kernels/rng.h: a mix64 per number, two 64-bit multiplies; the camera draws four, a
    // lobe choice one, a Lambertian direct sample three, an indirect one two, a dielectric one,
    // a glossy sample three).
    // Written {fpu, alu, mul}. The box test per axis: two selects of the near and far plane
    // (ALU), two subtracts and two multiplies by the inverse direction (FPU), the far plane's
    // rounding multiply (FPU); then three max and three min (FPU), t_max's scale (FPU), two
    // compares (FPU) and their and (ALU): {24, 7, 0}; the table's 34 keeps three more (as it
    // did before classes), assumed {2, 1, 0}: {26, 8, 0}. Chain: select, subtract, multiply,
    // multiply, max, max, max, compare, and: {7, 2, 0}. The other kinds are split by the same rule from their counts;
    // the shading splits are estimates, as their totals are. Groups are independent iterations
    // (no recurrence) except where a filter carries state from group to group (noted there).
    // A ray record written whole: the camera and every shader that pushes a new ray.
    const auto whole_ray = {"origin",     "direction",     "inverse_direction",
                            "t_max",      "hit_primitive", "pixel_sample",
                            "throughput", "radiance",      "state"};
    const auto hit = {"origin",           "direction",    "hit_t",      "hit_primitive",
                      "hit_barycentrics", "pixel_sample", "throughput", "state"};
    // Scene bytes: a 32-byte BVH node, a triangle's three vertices (36), a sphere (16), a
    // 64-byte material record (hw_model/op_costs.h, SceneDataMap).
    set(OpKind::camera, {"pixel_sample"}, whole_ray, {10, 6, 8}, {4, 2, 2}, 0);
    set(OpKind::box_test, {"origin", "inverse_direction", "t_max"}, {}, {26, 8, 0}, {7, 2, 0}, 32);
    set(OpKind::triangle_test, {"origin", "direction", "t_max"},
        {"t_max", "hit_primitive", "hit_t", "hit_barycentrics"}, {72, 24, 0}, {9, 3, 0}, 36);
    set(OpKind::sphere_test, {"origin", "direction", "t_max"}, {"t_max", "hit_primitive", "hit_t"},
        {40, 11, 0}, {13, 3, 0}, 16);
    set(OpKind::shadow_filter, {"state", "hit_primitive", "throughput", "radiance"}, {"radiance"},
        {3, 2, 0}, {1, 1, 0}, 0);
    set(OpKind::miss_filter, {"hit_primitive", "throughput", "radiance"}, {"radiance"}, {3, 2, 0},
        {1, 1, 0}, 0);
    // The emission filter first computes the hits' surfaces (kernels/intersect.h surface_at:
    // the stream tracer does it just before this op, and the microbenchmark times it inside
    // it), reading each lane's hit primitive from the scene: a gather whose address differs
    // per lane. A triangle: w (2), the barycentric point (9 mul, 6 add), its error bound (the
    // same products' 9 abs on ALUs, 6 add, 3 mul), the normal (6 sub, a cross product of 6 mul
    // and 3 sub, a normalize of 3 mul, 2 add, sqrt, divide, 3 mul), the facing test (3 mul,
    // 2 add, a compare) and the facing normal (3 negates and 3 selects on ALUs): {57, 15, 0},
    // chain sub, mul, sub, mul, add, add, sqrt, divide, mul, then mul, add, add, compare, and
    // the select: {13, 1, 0}. A sphere: the hit point (3 mul, 3 add), its offset (3 sub), a
    // divide and 3 mul by the radius, the normalize (10), the re-projected point (3 mul, 3 add),
    // the error bound (6 abs, 3 add, 3 mul) and the facing as for a triangle: {41, 12, 0}, chain
    // {14, 1, 0}. The emission test beside it: {3, 3, 0}, chain {1, 2, 0}. A scene with both
    // runs both bodies under masks.
    {
        const FeatureSet& f = l.features();
        UnitClassCounts body{3, 3, 0}, chain{1, 2, 0};
        if (f.triangles) {
            body = {body.fpu + 57, body.alu + 15, 0};
            chain = {13, 1, 0};
        }
        if (f.spheres) {
            body = {body.fpu + 41, body.alu + 12, 0};
            chain = {14, 1, 0};
        }
        // What surface_at reads (a sphere also the origin and t, a triangle the barycentrics)
        // and the emission test, in the record's field order (workloads/ray_layout.cpp).
        std::vector<const char*> gather;
        if (f.spheres) gather.push_back("origin");
        if (f.triangles || f.spheres) gather.push_back("direction");
        gather.push_back("hit_primitive");
        if (f.spheres) gather.push_back("hit_t");
        if (f.triangles) gather.push_back("hit_barycentrics");
        gather.insert(gather.end(), {"hit_material", "throughput", "state"});
        set(OpKind::emission_filter, gather, {"radiance"}, body, chain, 64);
    }
    set(OpKind::depth_filter, {"state"}, {}, {0, 2, 0}, {0, 1, 0}, 0);
    set(OpKind::material_filter, {"hit_primitive", "hit_material"}, {}, {0, 2, 0}, {0, 1, 0}, 64);
    set(OpKind::ambient, {"throughput", "radiance"}, {"radiance"}, {6, 0, 0}, {2, 0, 0}, 64);
    set(OpKind::lambertian_choice, {"pixel_sample", "state"}, {}, {3, 7, 2}, {2, 2, 2}, 0);
    set(OpKind::lambertian_direct, hit, whole_ray, {72, 18, 6}, {12, 2, 2}, 36 + 64);
    set(OpKind::lambertian_indirect, hit, whole_ray, {46, 14, 4}, {10, 2, 2}, 64);
    set(OpKind::dielectric, hit, whole_ray, {54, 16, 2}, {12, 2, 2}, 64);
    set(OpKind::glossy, hit, whole_ray, {84, 20, 6}, {14, 2, 2}, 64);
    // AEPSA (kernels/stream/entry_point.cpp): counted from our code, not from the paper (its
    // costs are host times). The bounds fit the frustum in two sweeps over the stream: a sum of
    // normalized directions (3 mul, 2 add, a square root and 3 divides: 9), then per ray three
    // direction and three origin dot products (6 x 5), two slope divides and 10 min/max (42):
    // 51, with a longest chain of dot, divide, min (7). The frustum test is five plane tests,
    // each 3 selects, 3 products, 2 adds, a compare (11), and 4 ors (59); chain select, mul,
    // add, add, compare, 3 ors (8). It reads the node (32 bytes) and no ray data: the frustum
    // lives in the unit's registers.
    // The bounds are a running sum, min and max over the stream: an FPU step carried from group
    // to group.
    set(OpKind::frustum_bounds, {"origin", "direction"}, {}, {51, 0, 0}, {7, 0, 0}, 0, {1, 0, 0});
    set(OpKind::frustum_test, {}, {}, {30, 29, 0}, {4, 4, 0}, 32);
    // Hit-point reordering (kernels/stream/hit_point_reorder.h), counted from our code; the
    // paper gives only host times. The simplified hierarchy's filter is the box test plus a
    // compare and select keeping the nearest proxy entry (36, chain 10); the entry distance
    // is assumed to live in a per-ray scratch word priced as t_max. The key: the hit point
    // (3 mul, 3 add), grid coordinates (3 sub, 3 mul, 3 converts, 6 clamps), high and low cell
    // indices (6 shifts and masks, 4 multiply-adds), the two Z-curve table reads the paper
    // uses and a shift-or (4): 41, chain 12. A merge pass: per group, two key reads, a
    // compare, two selects, an id store and an index update (8, chain 3; assumed, the merge of
    // Sec. 5 is not given in instructions); keys and ids stay in the scratchpad.
    set(OpKind::reorder_lod_test, {"origin", "inverse_direction", "t_max"}, {}, {27, 9, 0},
        {8, 2, 0}, 32);
    set(OpKind::reorder_key, {"origin", "direction", "t_max"}, {}, {15, 22, 4}, {5, 5, 2}, 0);
    // The merge's index update feeds the next group's compare: three ALU steps carried.
    set(OpKind::reorder_sort, {}, {}, {0, 8, 0}, {0, 3, 0}, 0, {0, 3, 0});
    // RayGrid batching (kernels/stream/ray_grid.h, the tracer's grid_walk), counted from our
    // code; the paper gives only host time shares (47 % octree traversal, Sec. 4.1). A walk
    // step is the slab test (34, chain 9, as box_test) plus the walk's bookkeeping: at a cell,
    // two lexicographic (entry, cell) compares against the last and best cell and two selects
    // keeping the best (8); above the cut, the exit distance (3 sub, 3 mul, 3 scales, 2 min:
    // 11) and two compares against the best entry and the last entry (2): 47, chain 9 + 4
    // (exit, compare, and, select) = 13. Last entry, last and best cell live in two per-ray
    // scratch words priced as t_max. It reads the node (32 bytes). Enqueue: per ray, the
    // cell's queue tail (a load), the id store, the tail's increment and store, the compare
    // against the queue size and the select that hands a full queue on (6, chain 4: load,
    // add, compare, select); queues hold ray ids, as the paper allows (Sec. 3.2.3).
    set(OpKind::raygrid_walk, {"origin", "inverse_direction", "t_max"}, {"t_max"}, {35, 12, 0},
        {9, 4, 0}, 32);
    // A queue's tail (load, increment, store) is carried from group to group: three ALU steps.
    set(OpKind::raygrid_enqueue, {"t_max"}, {}, {0, 6, 0}, {0, 4, 0}, 0, {0, 3, 0});
}

OpCostTable::OpCostTable(const RayRecordLayout& layout, const HwConfig& config)
    : OpCostTable(layout, config.datapath) {
    for (uint32_t k = 0; k < k_op_kind_count; ++k) {
        OpProfile& p = m_profiles[k];
        // Compress: the unit stores the group's passing ids, then its failing ones.
        if (p.partitions && config.partition.kind == "compress") {
            p.compute_instructions += 2;
            p.body.alu += 2;
            p.schedule = modulo_schedule(p.body, p.chain, p.recurrence, config.datapath);
        }
        for (const OpCostConfig& c : config.op_costs)
            if (op_kind_named(c.op) == OpKind(k)) {
                p.measured = true;
                p.cost = c;
                // Short-loop costs only for what those loops run: a host file written before
                // session 52 gives 0.00 for every op, and 0 is now a cost. The one-ray loop runs
                // the box, triangle and sphere tests; the few-ray loop, on a back end wide
                // enough, the box test (runs_in_few_ray_loop).
                const OpKind kind = OpKind(k);
                if (kind != OpKind::box_test && kind != OpKind::triangle_test &&
                    kind != OpKind::sphere_test)
                    p.cost.one_lane_cycles = -1.0;
                if (!runs_in_few_ray_loop(kind, 2, config.simd.width))
                    p.cost.few_lane_cycles = -1.0;
                // A lens camera's rays cost more than a pinhole's (thin_lens_per_lane_cycles).
                if (layout.features().thin_lens)
                    p.cost.per_lane_cycles += c.thin_lens_per_lane_cycles;
                // A passing lane's light sample on a sphere costs more than one on a triangle.
                p.cost.per_pass_cycles +=
                    c.sphere_light_per_pass_cycles * layout.features().sphere_light_share;
                // A lane whose hit is a sphere costs other than one on a triangle.
                p.cost.per_lane_cycles +=
                    c.sphere_hit_per_lane_cycles * layout.features().sphere_area_share;
            }
    }
}

void OpCostTable::check_measured(const std::array<bool, k_op_kind_count>& needed,
                                 const std::string& config_name) const {
    bool any = false;
    for (const OpProfile& p : m_profiles) any |= p.measured;
    if (!any) return;
    for (uint32_t k = 0; k < k_op_kind_count; ++k)
        if (needed[k] && !m_profiles[k].measured)
            throw InputError(config_name, 0, "op_costs",
                             std::string("no measured cost for ") + k_op_kinds[k].name +
                                 ", which this workload runs (fit it with sfx calibrate "
                                 "--describe-host)");
}

namespace {

// Asked twice per lane group: a view's comparison with a literal of known length is two loads,
// where std::string's with a const char* was a strlen and a memcmp call (1.6 % of a profile).
bool programmable(const DatapathConfig& d) {
    return std::string_view(d.issue) == "programmable";
}
bool cluster(const DatapathConfig& d) {
    return std::string_view(d.issue) == "cluster";
}

uint32_t ceil_div(uint32_t a, uint32_t b) {
    return (a + b - 1) / b;
}

}  // namespace

ModuloSchedule modulo_schedule(const UnitClassCounts& body, const UnitClassCounts& chain,
                               const UnitClassCounts& recurrence, const DatapathConfig& d) {
    ModuloSchedule s;
    s.resource_ii = std::max({1u, ceil_div(body.fpu, d.fpu_units), ceil_div(body.alu, d.alu_units),
                              ceil_div(body.mul, d.mul_units)});
    s.recurrence_ii = recurrence.latency(d);
    s.ii = std::max(s.resource_ii, s.recurrence_ii);
    s.length = std::max(chain.latency(d), s.ii);
    return s;
}

double OpProfile::issue_cycles(const DatapathConfig& d, uint32_t length, uint32_t op_mispredicted,
                               uint32_t lanes, double passed, bool first, double beyond_l1,
                               double beyond_l2, double op_failed_candidates,
                               double beyond_l1_skipping, double beyond_tlb) const {
    if (!measured) {
        if (cluster(d)) return double(schedule.ii);
        return programmable(d) ? double(compute_instructions) : double(d.initiation_interval);
    }
    // A one-ray stream runs its whole subtree in the tracer's own loop (traverse_one).
    if (length == 1 && cost.one_lane_cycles >= 0)
        return cost.one_lane_cycles + cost.one_lane_pass_cycles * passed +
               cost.one_lane_failed_candidate_cycles * op_failed_candidates;
    // A stream of a few rays runs in the few-ray loop (traverse_few): one group, one cost.
    if (length >= 2 && length <= k_few_ray_lanes && cost.few_lane_cycles >= 0)
        return first ? cost.few_lane_cycles : 0.0;
    return (first ? cost.per_op_cycles : 0.0) + cost.per_group_cycles +
           cost.per_lane_cycles * lanes + cost.per_pass_cycles * passed +
           cost.per_fail_cycles * (lanes - passed) +
           cost.per_minority_lane_cycles * op_mispredicted * lanes / double(length) +
           cost.beyond_l1_per_lane_cycles * beyond_l1 * lanes +
           cost.beyond_l2_per_lane_cycles * beyond_l2 * lanes +
           cost.beyond_l1_skipping_per_lane_cycles * beyond_l1_skipping * lanes +
           cost.beyond_tlb_per_lane_cycles * beyond_tlb * lanes +
           cost.per_failed_candidate_cycles * op_failed_candidates * lanes / double(length);
}

double OpProfile::loop_entry_cycles(TraversalLoop loop) const {
    if (!measured) return 0.0;
    if (loop == TraversalLoop::one_ray) return cost.one_ray_entry_cycles;
    if (loop == TraversalLoop::few_ray) return cost.few_ray_entry_cycles;
    return 0.0;
}

double OpProfile::traversal_start_cycles() const {
    return measured ? cost.traversal_start_cycles : 0.0;
}

double OpProfile::cold_call_cycles() const {
    return measured ? cost.cold_call_cycles : 0.0;
}

double OpProfile::shared_origin_cycles(uint32_t lanes) const {
    // The check compares every lane after the first with the first.
    return measured && lanes > 1 ? cost.shared_origin_per_lane_cycles * double(lanes - 1) : 0.0;
}

double OpProfile::result_cycles(const DatapathConfig& d, double issue) const {
    if (measured) return issue;
    if (cluster(d)) return double(schedule.length);
    return programmable(d) ? std::max(issue, double(latency_cycles)) : double(latency_cycles);
}

SceneDataMap scene_data_map(const WorkloadShape& shape) {
    SceneDataMap map;
    map.nodes = shape.bvh_nodes;
    map.triangles = shape.triangles;
    map.spheres = shape.spheres;
    map.vertices = shape.vertices;
    map.node_leaf = shape.node_leaf;
    return map;
}

uint64_t SceneDataMap::address(OpKind kind, uint32_t object) const {
    if (object == k_no_object) return 0;
    const uint64_t triangles_base = nodes * node_bytes;
    const uint64_t spheres_base = triangles_base + triangles * triangle_bytes;
    const uint64_t materials_base = spheres_base + spheres * sphere_bytes;
    switch (kind) {
        case OpKind::box_test:
        case OpKind::frustum_test:
        case OpKind::reorder_lod_test:
        case OpKind::raygrid_walk:
            return uint64_t(object) * node_bytes;
        case OpKind::triangle_test:
            return triangles_base + uint64_t(object) * triangle_bytes;
        case OpKind::sphere_test:
            return spheres_base + (uint64_t(object) - triangles) * sphere_bytes;
        default:
            return materials_base + uint64_t(object) * material_bytes;
    }
}

uint64_t SceneDataMap::span_bytes() const {
    const uint64_t vertex_bytes = (vertices > 0 ? vertices : 3 * triangles) * 12;
    return nodes * node_bytes + triangles * (triangle_bytes + mesh_triangle_bytes) + vertex_bytes +
           spheres * sphere_bytes;
}

uint32_t SceneDataMap::hit_reads(uint32_t prim, bool mesh, Read out[2]) const {
    if (prim >= triangles) {
        out[0] = {address(OpKind::sphere_test, prim), uint32_t(sphere_bytes)};
        return 1;
    }
    if (!mesh) {
        out[0] = {address(OpKind::triangle_test, prim), uint32_t(triangle_bytes)};
        return 1;
    }
    // Far beyond the materials (room for every 32-bit material id), so no region overlaps.
    const uint64_t materials_base =
        nodes * node_bytes + triangles * triangle_bytes + spheres * sphere_bytes;
    const uint64_t mesh_base = materials_base + (uint64_t(1) << 32) * material_bytes;
    const uint64_t vertices_base = mesh_base + triangles * mesh_triangle_bytes;
    out[0] = {mesh_base + uint64_t(prim) * mesh_triangle_bytes, uint32_t(mesh_triangle_bytes)};
    out[1] = {vertices_base + uint64_t(prim) * triangle_bytes, uint32_t(triangle_bytes)};
    return 2;
}

uint64_t hit_latency_beyond(SceneMemoryModel& memory, const SceneDataMap& map, uint32_t core,
                            uint32_t prim, bool mesh, uint64_t now, uint64_t hidden) {
    SceneDataMap::Read reads[2];
    const uint32_t n = map.hit_reads(prim, mesh, reads);
    uint64_t beyond = 0;
    for (uint32_t r = 0; r < n; ++r) {
        uint64_t latency = 0;
        memory.read(core, reads[r].address, reads[r].bytes, now, &latency);
        beyond += latency - std::min(latency, hidden);
    }
    return beyond;
}

void warm_hit(SceneMemoryModel& memory, const SceneDataMap& map, uint32_t core, uint32_t prim,
              bool mesh) {
    SceneDataMap::Read reads[2];
    const uint32_t n = map.hit_reads(prim, mesh, reads);
    for (uint32_t r = 0; r < n; ++r) memory.warm(core, reads[r].address, reads[r].bytes);
}

}  // namespace sfx

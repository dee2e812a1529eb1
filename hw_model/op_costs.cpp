#include "hw_model/op_costs.h"

#include "workloads/ray_layout.h"

namespace sfx {

RayRecordLayout::RayRecordLayout(const FeatureSet& features) {
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
                               std::initializer_list<const char*> names) {
    std::vector<uint32_t> out;
    for (const char* n : names)
        for (uint32_t w : layout.field(n)) out.push_back(w);
    return out;
}

}  // namespace

OpCostTable::OpCostTable(const RayRecordLayout& l, const DatapathConfig& d) {
    auto set = [&](OpKind k, std::initializer_list<const char*> gather,
                   std::initializer_list<const char*> scatter, uint32_t instructions,
                   uint32_t latency, uint32_t scene_bytes, bool partitions) {
        OpProfile& p = m_profiles[size_t(k)];
        p.gather_words = words_of(l, gather);
        p.scatter_words = words_of(l, scatter);
        p.compute_instructions = instructions;
        p.latency_cycles = latency;
        p.scene_bytes = scene_bytes;
        p.partitions = partitions;
    };
    // A ray record written whole: the camera and every shader that pushes a new ray.
    const auto whole_ray = {"origin", "direction", "inverse_direction", "t_max", "hit_primitive",
                            "pixel_sample", "throughput", "radiance", "state"};
    // Instruction counts are SIMD instructions per lane group on ray data (Table 5's "comp"):
    // slab test 6 sub + 6 mul + 6 min/max + compare; watertight triangle ~30; and so on.
    set(OpKind::camera, {"pixel_sample"}, whole_ray, 24, d.camera_cycles, 0, false);
    set(OpKind::box_test, {"origin", "inverse_direction", "t_max"}, {}, 19, d.box_test_cycles, 32,
        true);
    set(OpKind::triangle_test, {"origin", "direction", "t_max"},
        {"t_max", "hit_primitive", "hit_t", "hit_barycentrics"}, 32, d.triangle_test_cycles, 36,
        false);
    set(OpKind::sphere_test, {"origin", "direction", "t_max"}, {"t_max", "hit_primitive", "hit_t"},
        22, d.sphere_test_cycles, 16, false);
    set(OpKind::shadow_filter, {"state", "hit_primitive", "throughput", "radiance"}, {"radiance"}, 5,
        d.shade_cycles, 0, true);
    set(OpKind::miss_filter, {"hit_primitive", "throughput", "radiance"}, {"radiance"}, 5,
        d.shade_cycles, 0, true);
    set(OpKind::emission_filter, {"hit_primitive", "hit_material", "state", "throughput"},
        {"radiance"}, 6, d.shade_cycles, 64, true);
    set(OpKind::depth_filter, {"state"}, {}, 2, d.shade_cycles, 0, true);
    set(OpKind::material_filter, {"hit_primitive", "hit_material"}, {}, 2, d.shade_cycles, 64, true);
    set(OpKind::ambient, {"throughput", "radiance"}, {"radiance"}, 6, d.shade_cycles, 64, false);
    set(OpKind::lambertian_choice, {"pixel_sample", "state"}, {}, 12, d.shade_cycles, 0, true);
    set(OpKind::lambertian_direct,
        {"origin", "direction", "hit_t", "hit_primitive", "hit_barycentrics", "pixel_sample",
         "throughput", "state"},
        whole_ray, 96, d.shade_cycles, 36 + 64, false);
    set(OpKind::lambertian_indirect,
        {"origin", "direction", "hit_t", "hit_primitive", "hit_barycentrics", "pixel_sample",
         "throughput", "state"},
        whole_ray, 64, d.shade_cycles, 64, false);
    set(OpKind::dielectric,
        {"origin", "direction", "hit_t", "hit_primitive", "hit_barycentrics", "pixel_sample",
         "throughput", "state"},
        whole_ray, 72, d.shade_cycles, 64, false);
    set(OpKind::glossy,
        {"origin", "direction", "hit_t", "hit_primitive", "hit_barycentrics", "pixel_sample",
         "throughput", "state"},
        whole_ray, 110, d.shade_cycles, 64, false);
}

uint64_t SceneDataMap::address(OpKind kind, uint32_t object) const {
    if (object == k_no_object) return 0;
    const uint64_t triangles_base = nodes * node_bytes;
    const uint64_t spheres_base = triangles_base + triangles * triangle_bytes;
    const uint64_t materials_base = spheres_base + spheres * sphere_bytes;
    switch (kind) {
        case OpKind::box_test: return uint64_t(object) * node_bytes;
        case OpKind::triangle_test: return triangles_base + uint64_t(object) * triangle_bytes;
        case OpKind::sphere_test:
            return spheres_base + (uint64_t(object) - triangles) * sphere_bytes;
        default: return materials_base + uint64_t(object) * material_bytes;
    }
}

}  // namespace sfx

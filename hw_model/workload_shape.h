#pragma once
// What a timing model must know of the workload besides the trace: the scene's features (they
// fix the ray record and which units exist) and the sizes of its data (they place scene data
// in memory). Built by whoever runs the tracer; the hardware model never sees the tracer.

#include <array>
#include <cstdint>

#include "kernels/trace.h"
#include "workloads/scene.h"

namespace sfx {

struct WorkloadShape {
    FeatureSet features;
    uint64_t triangles = 0;
    uint64_t spheres = 0;
    uint64_t bvh_nodes = 0;
    uint32_t tile = 32;  // tile edge: tile^2 ray slots per pass

    uint32_t slots() const { return tile * tile; }
    // The operation kinds this scene can emit: their function units are elaborated, no others.
    std::array<bool, k_op_kind_count> needed_kinds() const;
};

inline std::array<bool, k_op_kind_count> WorkloadShape::needed_kinds() const {
    std::array<bool, k_op_kind_count> k{};
    auto need = [&](OpKind kind, bool on) { k[size_t(kind)] = on; };
    const bool lights = features.light_count > 0;
    need(OpKind::camera, true);
    need(OpKind::box_test, true);
    need(OpKind::triangle_test, features.triangles);
    need(OpKind::sphere_test, features.spheres);
    need(OpKind::shadow_filter, lights);
    need(OpKind::miss_filter, true);
    need(OpKind::emission_filter, true);
    need(OpKind::depth_filter, true);
    need(OpKind::material_filter, true);
    need(OpKind::ambient, features.ambient);
    need(OpKind::lambertian_choice, features.lambertian);
    need(OpKind::lambertian_direct, features.lambertian && lights);
    need(OpKind::lambertian_indirect, features.lambertian);
    need(OpKind::dielectric, features.dielectric);
    need(OpKind::glossy, features.glossy);
    return k;
}

}  // namespace sfx

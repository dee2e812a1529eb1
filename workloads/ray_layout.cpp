#include "workloads/ray_layout.h"

namespace sfx {

std::vector<RayField> ray_record_fields(const FeatureSet& f) {
    std::vector<RayField> fields = {
        {"origin", 12, "3 x f32: every ray"},
        {"direction", 12, "3 x f32: every ray"},
        {"inverse_direction", 12,
         "3 x f32: the slab test runs per ray per node; stored, not recomputed"},
        {"t_max", 4, "f32: clips traversal; shrinks on every closer hit"},
        {"hit_primitive", 4, "u32 global primitive id (closest so far); ties go to the lower id"},
        {"hit_t", 4, "f32 distance of the closest hit"},
    };
    if (f.triangles)
        fields.push_back(
            {"hit_barycentrics", 8, "2 x f32 (u, v): triangle hits only; spheres shade from t"});
    if (f.material_kinds() > 1)
        fields.push_back({"hit_material", 4,
                          "u32: shading filters split the stream by material "
                          "without gathering it from the scene per ray"});
    fields.push_back({"pixel_sample", 8, "u32 pixel + u32 sample: the RNG key and the film slot"});
    fields.push_back({"throughput", 12,
                      "3 x f32 path weight; a shadow ray's pending radiance "
                      "overwrites it, since the path ends when the shadow ray resolves"});
    fields.push_back({"radiance", 12, "3 x f32 accumulated path radiance"});
    fields.push_back({"state", 4,
                      "u8 bounce, u8 kind (camera/extension/shadow), flags "
                      "(count_emission, front face), u8 spare"});
    return fields;
}

uint32_t ray_record_bytes(const FeatureSet& features) {
    uint32_t bytes = 0;
    for (const RayField& field : ray_record_fields(features)) bytes += field.bytes;
    return bytes;
}

}  // namespace sfx

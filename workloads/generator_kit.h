#pragma once
// What the scene generators share and nothing else includes: the parameter and material
// lookups of one call, small math, and each generator's registry entry (generators.cpp).

#include <algorithm>
#include <cmath>

#include "workloads/generators.h"

namespace sfx {

namespace generator_kit {
constexpr float k_pi = 3.14159265358979323846f;
inline float radians(float degrees) {
    return degrees * (k_pi / 180.f);
}

inline float smoothstep(float e0, float e1, float x) {
    const float t = std::min(1.f, std::max(0.f, (x - e0) / (e1 - e0)));
    return t * t * (3.f - 2.f * t);
}

// One generator call: its parameters (numbers, counts) and material roles by name.
struct Ctx {
    const GeneratorInput& in;
    SceneBuilder& b;
    double p(const char* name) const { return in.params.at(name); }
    uint32_t n(const char* name) const { return uint32_t(in.params.at(name)); }
    uint32_t m(const char* role) const { return in.materials.at(role); }
};

inline GeneratorParam P(const char* name, double value, double lo, double hi, bool integer,
                        const char* help) {
    return GeneratorParam{name, value, lo, hi, integer, help};
}
}  // namespace generator_kit
using namespace generator_kit;

namespace shapes {
// A unit icosphere subdivided `levels` times (20 * 4^levels triangles), built once per level
// (shapes.cpp): rocks use it, and generators size their budget by it.
struct IcoMesh {
    std::vector<Vec3> vertices;
    std::vector<uint32_t> indices;
};
const IcoMesh& icosphere(uint32_t levels);
}  // namespace shapes

// Each generator's registry entry, one file each (generator_<name>.cpp).
GeneratorInfo atrium_generator();
GeneratorInfo conference_generator();
GeneratorInfo temple_generator();

}  // namespace sfx

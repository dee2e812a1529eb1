// Deterministic hashing and value noise for generators (generators.h).

#include <cmath>

#include "base/hash.h"
#include "workloads/generators.h"

namespace sfx {

// ---- noise --------------------------------------------------------------------------------

float hash_float(uint64_t seed, uint64_t a, uint64_t b) {
    const uint64_t h =
        mix64(mix64(mix64(seed ^ 0x51ed270b27a3c3d1ull) ^ a) ^ (b * 0x9e3779b97f4a7c15ull));
    return float(h >> 40) * (1.f / 16777216.f);
}

float value_noise(uint64_t seed, float x, float y) {
    const float fx = std::floor(x), fy = std::floor(y);
    const int64_t ix = int64_t(fx), iy = int64_t(fy);
    float tx = x - fx, ty = y - fy;
    tx = tx * tx * (3.f - 2.f * tx);
    ty = ty * ty * (3.f - 2.f * ty);
    auto h = [&](int64_t i, int64_t j) { return hash_float(seed, uint64_t(i), uint64_t(j)); };
    const float a = h(ix, iy) + (h(ix + 1, iy) - h(ix, iy)) * tx;
    const float c = h(ix, iy + 1) + (h(ix + 1, iy + 1) - h(ix, iy + 1)) * tx;
    return a + (c - a) * ty;
}

}  // namespace sfx

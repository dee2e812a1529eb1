#pragma once
// Counter-based random numbers: a sample is a pure function of
// (seed, pixel, sample, bounce, dimension). There is no sequential state, so the order in
// which tracers, threads or tiles evaluate paths never changes a single number.

#include <cstdint>

#include "base/hash.h"

namespace sfx {

// Dimensions consumed per bounce; named so both tracers draw the same number for the same use.
enum class RngDim : uint32_t {
    pixel_x = 0,
    pixel_y,
    lens_u,
    lens_v,
    lobe_choice,       // Lambertian direct/indirect, dielectric reflect/refract, glossy lobe
    direction_u,
    direction_v,
    light_choice,
    light_u,
    light_v,
    light_w,
    count
};

constexpr uint32_t random_bits(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                               uint32_t dim) {
    uint64_t h = mix64(seed ^ 0x9e3779b97f4a7c15ull);
    h = mix64(h ^ ((uint64_t(pixel) << 32) | sample));
    h = mix64(h ^ ((uint64_t(bounce) << 32) | dim));
    return uint32_t(h >> 32);
}

// Uniform float in [0, 1): 24 random mantissa bits, exactly representable.
constexpr float random_float(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                             RngDim dim) {
    return float(random_bits(seed, pixel, sample, bounce, uint32_t(dim)) >> 8) *
           (1.0f / 16777216.0f);
}

// The key of one path: which numbers a path draws depends only on this.
struct PathKey {
    uint64_t seed = 0;
    uint32_t pixel = 0;
    uint32_t sample = 0;

    float uniform(uint32_t bounce, RngDim dim) const {
        return random_float(seed, pixel, sample, bounce, dim);
    }
};

}  // namespace sfx

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

// The hash of (seed, pixel, sample): the part of random_bits a path shares by all its numbers.
constexpr uint64_t path_hash(uint64_t seed, uint32_t pixel, uint32_t sample) {
    return mix64(mix64(seed ^ 0x9e3779b97f4a7c15ull) ^ ((uint64_t(pixel) << 32) | sample));
}

constexpr uint32_t random_bits_of_path(uint64_t path, uint32_t bounce, uint32_t dim) {
    return uint32_t(mix64(path ^ ((uint64_t(bounce) << 32) | dim)) >> 32);
}

constexpr uint32_t random_bits(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                               uint32_t dim) {
    return random_bits_of_path(path_hash(seed, pixel, sample), bounce, dim);
}

// Uniform float in [0, 1) from random bits: 24 mantissa bits, exactly representable.
constexpr float uniform_of_bits(uint32_t bits) {
    return float(bits >> 8) * (1.0f / 16777216.0f);
}

constexpr float random_float(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                             RngDim dim) {
    return uniform_of_bits(random_bits(seed, pixel, sample, bounce, uint32_t(dim)));
}

// The key of one path: which numbers a path draws depends only on (seed, pixel, sample). The
// key keeps their hash, computed once: a path draws about four numbers a bounce, and each
// would hash the three again (1 to 2 % of a path-traced frame on conference).
struct PathKey {
    uint64_t hash = path_hash(0, 0, 0);
    uint32_t pixel = 0;
    uint32_t sample = 0;

    constexpr PathKey() = default;
    constexpr PathKey(uint64_t seed, uint32_t pixel_, uint32_t sample_)
        : hash(path_hash(seed, pixel_, sample_)), pixel(pixel_), sample(sample_) {}

    constexpr float uniform(uint32_t bounce, RngDim dim) const {
        return uniform_of_bits(random_bits_of_path(hash, bounce, uint32_t(dim)));
    }
};

}  // namespace sfx

#pragma once
// Non-cryptographic hashing, for values that must be a pure function of their inputs: the
// SplitMix64 mixer behind the counter-based random numbers and procedural noise, and FNV-1a
// over bytes (what a trace header names its scene by). Point keys use SHA-256 instead
// (sweeps/sha256.h).

#include <cstddef>
#include <cstdint>

namespace sfx {

// SplitMix64 finaliser: a strong 64-bit mixer (Steele, Lea, Flood 2014).
constexpr uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// FNV-1a, 64-bit, fed byte by byte.
struct Fnv1a {
    uint64_t h = 0xcbf29ce484222325ull;
    void bytes(const void* p, size_t n) {
        const auto* b = static_cast<const uint8_t*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
    }
};

}  // namespace sfx

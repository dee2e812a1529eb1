#pragma once
// Width-generic SIMD lanes, written once (after Embree's vfloat<N> / vbool<N>):
//   vfloat<Width>, vint<Width>, vbool<Width>
// are `float`, `int32_t`, `bool` for Width 1 and GCC vector types (element-wise IEEE
// operations; a comparison gives 0 / -1 per lane) for Width 4, 8 and 16, so the reference
// tracer's one-ray code and the stream kernels share every line of ray math.
//
// Masks are values: any, none, popcount, bits, select. Gather and compress-store are
// operations of the type. Under __AVX512F__ (Width 16) and __AVX2__ (Width 8, and Width 4: the
// AVX2 kernels' short groups) they use the instructions (vpgatherdd/vgatherdps, vpcompressd, a
// permutation table); otherwise a portable loop with the same results.
//
// One rule keeps one binary safe on every machine (see kernels/simd/isa.h): each Width is
// used only in translation units compiled for its instruction set (16: AVX-512, 8 and 4: AVX2,
// 1: the default flags), and every function here is always inlined, so no out-of-line copy
// built with wider instructions can be picked by the linker for a narrower caller.
// Bit-identity: only IEEE add/sub/mul/div/sqrt/compare/select; no FMA (-ffp-contract=off), no
// approximate reciprocals.

#include <cstdint>

#if defined(__AVX512F__) || defined(__AVX2__)
#include <immintrin.h>
#endif

#define SFX_LANES_INLINE inline __attribute__((always_inline))

namespace sfx {

template <int Width>
struct LaneTypes {
    static_assert(Width == 4 || Width == 8 || Width == 16, "lane widths: 1, 4, 8, 16");
    typedef float Float __attribute__((vector_size(4 * Width)));
    typedef int32_t Int __attribute__((vector_size(4 * Width)));
    typedef Int Bool;  // a comparison's result: -1 (true) or 0 per lane
};
template <>
struct LaneTypes<1> {
    using Float = float;
    using Int = int32_t;
    using Bool = bool;
};

template <int Width>
using vfloat = typename LaneTypes<Width>::Float;
template <int Width>
using vint = typename LaneTypes<Width>::Int;
template <int Width>
using vbool = typename LaneTypes<Width>::Bool;

// One value in every lane.
template <int Width>
SFX_LANES_INLINE vfloat<Width> broadcast(float x) {
    if constexpr (Width == 1) {
        return x;
    } else {
        // An element loop would compile to Width masked inserts; say "broadcast".
#if defined(__AVX512F__)
        if constexpr (Width == 16) return vfloat<Width>(_mm512_set1_ps(x));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) return vfloat<Width>(_mm256_set1_ps(x));
        if constexpr (Width == 4) return vfloat<Width>(_mm_set1_ps(x));
#endif
        vfloat<Width> v;
        for (int l = 0; l < Width; ++l) v[l] = x;
        return v;
    }
}
template <int Width>
SFX_LANES_INLINE vint<Width> broadcast_int(int32_t x) {
    if constexpr (Width == 1) {
        return x;
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16) return vint<Width>(_mm512_set1_epi32(x));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) return vint<Width>(_mm256_set1_epi32(x));
        if constexpr (Width == 4) return vint<Width>(_mm_set1_epi32(x));
#endif
        vint<Width> v;
        for (int l = 0; l < Width; ++l) v[l] = x;
        return v;
    }
}

// Lane indices 0, 1, ..., Width-1.
template <int Width>
SFX_LANES_INLINE vint<Width> lane_index() {
    if constexpr (Width == 1) {
        return 0;
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16)
            return vint<Width>(
                _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) return vint<Width>(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        if constexpr (Width == 4) return vint<Width>(_mm_setr_epi32(0, 1, 2, 3));
#endif
        vint<Width> v;
        for (int l = 0; l < Width; ++l) v[l] = l;
        return v;
    }
}

// Per lane: m ? a : b.
template <class Mask, class Value>
SFX_LANES_INLINE Value select(Mask m, Value a, Value b) {
    return m ? a : b;
}

// Per-lane logic on masks (for Width 1 the operators of bool).
template <class Mask>
SFX_LANES_INLINE Mask mask_and(Mask a, Mask b) {
    if constexpr (sizeof(Mask) == 1)
        return a && b;
    else
        return a & b;
}
template <class Mask>
SFX_LANES_INLINE Mask mask_or(Mask a, Mask b) {
    if constexpr (sizeof(Mask) == 1)
        return a || b;
    else
        return a | b;
}
template <class Mask>
SFX_LANES_INLINE Mask mask_not(Mask a) {
    if constexpr (sizeof(Mask) == 1)
        return !a;
    else
        return ~a;
}

// The sign bit of each lane (true for -0 and -inf, as std::signbit).
template <int Width>
SFX_LANES_INLINE vbool<Width> sign_bit(vfloat<Width> x) {
    if constexpr (Width == 1) {
        return __builtin_signbit(x) != 0;
    } else {
        vint<Width> bits;
        __builtin_memcpy(&bits, &x, sizeof bits);
        return bits < 0;
    }
}

template <int Width>
SFX_LANES_INLINE vbool<Width> is_nan(vfloat<Width> x) {
    return x != x;
}

// |x| per lane (std::fabs: the sign bit cleared).
template <int Width>
SFX_LANES_INLINE vfloat<Width> magnitude(vfloat<Width> x) {
    if constexpr (Width == 1) {
        return __builtin_fabsf(x);
    } else {
        vint<Width> bits;
        __builtin_memcpy(&bits, &x, sizeof bits);
        bits &= 0x7fffffff;
        __builtin_memcpy(&x, &bits, sizeof bits);
        return x;
    }
}

// |x| with the sign bit of s per lane (std::copysign).
template <int Width>
SFX_LANES_INLINE vfloat<Width> copy_sign(vfloat<Width> x, vfloat<Width> s) {
    if constexpr (Width == 1) {
        return __builtin_copysignf(x, s);
    } else {
        vint<Width> xb, sb;
        __builtin_memcpy(&xb, &x, sizeof xb);
        __builtin_memcpy(&sb, &s, sizeof sb);
        xb = (xb & 0x7fffffff) | (sb & int32_t(0x80000000u));
        __builtin_memcpy(&x, &xb, sizeof xb);
        return x;
    }
}

// The correctly rounded square root per lane (IEEE, as std::sqrt; NaN for x < 0).
template <int Width>
SFX_LANES_INLINE vfloat<Width> square_root(vfloat<Width> x) {
    if constexpr (Width == 1) {
        return __builtin_sqrtf(x);
    } else {
#if defined(__AVX512F__)
        // maskz: GCC 12 warns of _mm512_sqrt_ps's undefined pass-through register.
        if constexpr (Width == 16)
            return vfloat<Width>(_mm512_maskz_sqrt_ps(__mmask16(0xffff), __m512(x)));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) return vfloat<Width>(_mm256_sqrt_ps(__m256(x)));
        if constexpr (Width == 4) return vfloat<Width>(_mm_sqrt_ps(__m128(x)));
#endif
        for (int l = 0; l < Width; ++l) x[l] = __builtin_sqrtf(x[l]);
        return x;
    }
}

// Bit l set iff lane l of the mask is true.
template <int Width>
SFX_LANES_INLINE uint32_t bits(vbool<Width> m) {
    if constexpr (Width == 1) {
        return uint32_t(m);
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16)
            return uint32_t(_mm512_cmplt_epi32_mask(__m512i(m), _mm512_setzero_si512()));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) return uint32_t(_mm256_movemask_ps(__m256(m)));
        if constexpr (Width == 4) return uint32_t(_mm_movemask_ps(__m128(m)));
#endif
        uint32_t r = 0;
        for (int l = 0; l < Width; ++l) r |= uint32_t(m[l] & 1) << l;
        return r;
    }
}

// The mask of the lanes whose bit is set.
template <int Width>
SFX_LANES_INLINE vbool<Width> from_bits(uint32_t b) {
    if constexpr (Width == 1) {
        return (b & 1u) != 0;
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16)
            return vbool<Width>(_mm512_maskz_mov_epi32(__mmask16(b), _mm512_set1_epi32(-1)));
#endif
        const vint<Width> one = broadcast_int<Width>(1);
        return ((broadcast_int<Width>(int32_t(b)) >> lane_index<Width>()) & one) == one;
    }
}

template <int Width>
SFX_LANES_INLINE bool any(vbool<Width> m) {
    return bits<Width>(m) != 0;
}
template <int Width>
SFX_LANES_INLINE bool none(vbool<Width> m) {
    return bits<Width>(m) == 0;
}
template <int Width>
SFX_LANES_INLINE uint32_t popcount(vbool<Width> m) {
    return uint32_t(__builtin_popcount(bits<Width>(m)));
}

// Unaligned load of Width 32-bit lanes.
template <int Width>
SFX_LANES_INLINE vint<Width> load_int(const uint32_t* p) {
    vint<Width> v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

// lane l = base[index[l]] (32-bit elements).
template <int Width>
SFX_LANES_INLINE vfloat<Width> gather(const float* base, vint<Width> index) {
    if constexpr (Width == 1) {
        return base[index];
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16)
            return vfloat<Width>(_mm512_mask_i32gather_ps(_mm512_setzero_ps(), __mmask16(0xffff),
                                                          __m512i(index), base, 4));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8)
            return vfloat<Width>(_mm256_i32gather_ps(base, __m256i(index), 4));
#endif
        vfloat<Width> v;
        for (int l = 0; l < Width; ++l) v[l] = base[index[l]];
        return v;
    }
}
// Fields (8 or 4) consecutive floats per lane, as Fields vectors: lane l of out[f] =
// base[index[l] + f]. Each lane's floats (aligned to their size) come by one load and a
// transpose makes them lanes, so a lane touches one cache line where Fields gathers would touch
// it Fields times; the same bits as gathers. At 16 lanes: 256-bit halves of lanes l and l + 4
// share a register, 4x4 transposes within 128-bit blocks, then one block shuffle per field (4
// fields read the 8 and keep half: that form is not yet measured on an AVX-512 host); at 8
// lanes: 128-bit quarters of lanes l and l + 4, one 4x4 transpose per 4 fields; at 4 lanes:
// one 4x4 transpose per 4 fields.
template <int Width, int Fields = 8>
SFX_LANES_INLINE void load_transposed(const float* base, const int32_t* index,
                                      vfloat<Width> out[Fields]) {
    static_assert(Fields == 4 || Fields == 8, "load_transposed: 4 or 8 fields");
    if constexpr (Width == 1) {
        for (int f = 0; f < Fields; ++f) out[f] = base[index[0] + f];
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16 && Fields == 4) {
            vfloat<Width> all[8];
            load_transposed<Width, 8>(base, index, all);
            for (int f = 0; f < 4; ++f) out[f] = all[f];
            return;
        }
        if constexpr (Width == 16) {
            auto row = [&](int a, int b) {  // a's 256 bits, then b's
                const vfloat<8> low = vfloat<8>(_mm256_load_ps(base + index[a]));
                const vfloat<8> high = vfloat<8>(_mm256_load_ps(base + index[b]));
                return __m512(__builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10,
                                                      11, 12, 13, 14, 15));
            };
            // The all-lanes masked forms (and a vector shuffle above): GCC 12's plain ones read
            // an "undefined" register that -Wmaybe-uninitialized reports.
            auto unpacklo = [](__m512 a, __m512 b) {
                return _mm512_mask_unpacklo_ps(a, 0xffff, a, b);
            };
            auto unpackhi = [](__m512 a, __m512 b) {
                return _mm512_mask_unpackhi_ps(a, 0xffff, a, b);
            };
            auto transpose4 = [&](__m512 r0, __m512 r1, __m512 r2, __m512 r3, __m512 u[4]) {
                const __m512 t0 = unpacklo(r0, r1), t1 = unpackhi(r0, r1);
                const __m512 t2 = unpacklo(r2, r3), t3 = unpackhi(r2, r3);
                u[0] = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
                u[1] = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
                u[2] = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
                u[3] = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
            };
            // u[k]'s 128-bit blocks: field k of lanes 0-3, field k + 4 of lanes 0-3, field k of
            // lanes 4-7, field k + 4 of lanes 4-7; v[k] the same for lanes 8-15.
            __m512 u[4], v[4];
            transpose4(row(0, 4), row(1, 5), row(2, 6), row(3, 7), u);
            transpose4(row(8, 12), row(9, 13), row(10, 14), row(11, 15), v);
            for (int k = 0; k < 4; ++k) {
                out[k] = vfloat<Width>(
                    _mm512_mask_shuffle_f32x4(u[k], 0xffff, u[k], v[k], _MM_SHUFFLE(2, 0, 2, 0)));
                out[k + 4] = vfloat<Width>(
                    _mm512_mask_shuffle_f32x4(u[k], 0xffff, u[k], v[k], _MM_SHUFFLE(3, 1, 3, 1)));
            }
            return;
        }
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) {
            for (int h = 0; h < Fields; h += 4) {
                auto row = [&](int a, int b) {
                    return _mm256_insertf128_ps(
                        _mm256_castps128_ps256(_mm_load_ps(base + index[a] + h)),
                        _mm_load_ps(base + index[b] + h), 1);
                };
                const __m256 r0 = row(0, 4), r1 = row(1, 5), r2 = row(2, 6), r3 = row(3, 7);
                const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
                const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
                out[h] = vfloat<Width>(_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)));
                out[h + 1] = vfloat<Width>(_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)));
                out[h + 2] = vfloat<Width>(_mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)));
                out[h + 3] = vfloat<Width>(_mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2)));
            }
            return;
        }
        if constexpr (Width == 4) {
            for (int h = 0; h < Fields; h += 4) {
                __m128 r0 = _mm_load_ps(base + index[0] + h), r1 = _mm_load_ps(base + index[1] + h);
                __m128 r2 = _mm_load_ps(base + index[2] + h), r3 = _mm_load_ps(base + index[3] + h);
                _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
                out[h] = vfloat<Width>(r0);
                out[h + 1] = vfloat<Width>(r1);
                out[h + 2] = vfloat<Width>(r2);
                out[h + 3] = vfloat<Width>(r3);
            }
            return;
        }
#endif
        for (int f = 0; f < Fields; ++f)
            for (int l = 0; l < Width; ++l) out[f][l] = base[index[l] + f];
    }
}

#if defined(__AVX2__)
// AVX2 has no compress: for each 8-bit mask, the indices of its set lanes in order, packed
// 4 bits each (Width-8 compress by permutation).
struct CompressTable8 {
    uint32_t packed[256];
    constexpr CompressTable8() : packed() {
        for (uint32_t m = 0; m < 256; ++m) {
            uint32_t p = 0, k = 0;
            for (uint32_t l = 0; l < 8; ++l)
                if (m >> l & 1u) p |= l << (4 * k++);
            packed[m] = p;
        }
    }
};
inline constexpr CompressTable8 k_compress_table8{};
#endif

// The paper's partition step: the lanes of `values` whose mask bit is set, packed to the
// front in lane order (the lanes past the popcount are don't-care).
template <int Width>
SFX_LANES_INLINE vint<Width> compress(uint32_t mask_bits, vint<Width> values) {
    if constexpr (Width == 1) {
        return values;
    } else {
#if defined(__AVX512F__)
        if constexpr (Width == 16)
            return vint<Width>(_mm512_maskz_compress_epi32(__mmask16(mask_bits), __m512i(values)));
#endif
#if defined(__AVX512F__) && defined(__AVX512VL__)
        if constexpr (Width == 8)
            return vint<Width>(_mm256_maskz_compress_epi32(__mmask8(mask_bits), __m256i(values)));
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) {  // by permutation table
            const __m256i shifts = _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28);
            const __m256i perm = _mm256_and_si256(
                _mm256_srlv_epi32(_mm256_set1_epi32(int(k_compress_table8.packed[mask_bits & 255])),
                                  shifts),
                _mm256_set1_epi32(7));
            return vint<Width>(_mm256_permutevar8x32_epi32(__m256i(values), perm));
        }
        if constexpr (Width == 4) {  // the 8-lane table's entries for masks below 16
            const __m128i perm = _mm_and_si128(
                _mm_srlv_epi32(_mm_set1_epi32(int(k_compress_table8.packed[mask_bits & 15])),
                               _mm_setr_epi32(0, 4, 8, 12)),
                _mm_set1_epi32(3));
            return vint<Width>(
                _mm_castps_si128(_mm_permutevar_ps(_mm_castsi128_ps(__m128i(values)), perm)));
        }
#endif
        vint<Width> packed = values;
        int k = 0;
        for (int l = 0; l < Width; ++l)
            if (mask_bits >> l & 1u) packed[k++] = values[l];
        return packed;
    }
}

// The number of lanes whose mask bit is set (bits past Width ignored).
template <int Width>
SFX_LANES_INLINE uint32_t mask_count(uint32_t mask_bits) {
    return uint32_t(__builtin_popcount(mask_bits & ((1u << Width) - 1u)));
}

// Stores compress(mask_bits, values) at out[0 .. popcount); returns the popcount. Writes all
// Width elements of out (the ones past the popcount are don't-care), so out needs Width
// elements of room.
template <int Width>
SFX_LANES_INLINE uint32_t compress_store(uint32_t mask_bits, vint<Width> values, uint32_t* out) {
    const vint<Width> packed = compress<Width>(mask_bits, values);
    __builtin_memcpy(out, &packed, sizeof packed);
    return mask_count<Width>(mask_bits);
}

// compress_store that writes out[0 .. popcount) only, by a masked store: for the end of a
// stream, where the elements past it belong to the streams around it.
template <int Width>
SFX_LANES_INLINE uint32_t compress_store_exact(uint32_t mask_bits, vint<Width> values,
                                               uint32_t* out) {
    const uint32_t count = mask_count<Width>(mask_bits);
    if constexpr (Width == 1) {
        if (count) *out = uint32_t(values);
        return count;
    } else {
        const vint<Width> packed = compress<Width>(mask_bits, values);
        [[maybe_unused]] const uint32_t first = (1u << count) - 1u;  // the lanes to store
#if defined(__AVX512F__)
        if constexpr (Width == 16) {
            _mm512_mask_storeu_epi32(out, __mmask16(first), __m512i(packed));
            return count;
        }
#endif
#if defined(__AVX512F__) && defined(__AVX512VL__)
        if constexpr (Width == 8) {
            _mm256_mask_storeu_epi32(out, __mmask8(first), __m256i(packed));
            return count;
        }
#endif
#if defined(__AVX2__)
        if constexpr (Width == 8) {
            const __m256i store = _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count)),
                                                     _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
            _mm256_maskstore_epi32(reinterpret_cast<int*>(out), store, __m256i(packed));
            return count;
        }
        if constexpr (Width == 4) {
            const __m128i store =
                _mm_cmpgt_epi32(_mm_set1_epi32(int(count)), _mm_setr_epi32(0, 1, 2, 3));
            _mm_maskstore_epi32(reinterpret_cast<int*>(out), store, __m128i(packed));
            return count;
        }
#endif
        for (uint32_t l = 0; l < count; ++l) out[l] = uint32_t(packed[l]);
        return count;
    }
}

// mask[l] = bit l of mask_bits, as bytes 0 / 1 (the trace's per-lane pass flags).
template <int Width>
SFX_LANES_INLINE void store_mask_bytes(uint32_t mask_bits, uint8_t* mask) {
#if defined(__AVX512BW__) && defined(__AVX512VL__)
    if constexpr (Width == 16) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(mask),
                         _mm_maskz_mov_epi8(__mmask16(mask_bits), _mm_set1_epi8(1)));
        return;
    }
#endif
    for (int l = 0; l < Width; ++l) mask[l] = uint8_t(mask_bits >> l & 1u);
}

// Bit l set iff mask[l] != 0 (Width bytes).
template <int Width>
SFX_LANES_INLINE uint32_t load_mask_bytes(const uint8_t* mask) {
#if defined(__AVX512BW__) && defined(__AVX512VL__)
    if constexpr (Width == 16)
        return uint32_t(_mm_test_epi8_mask(_mm_loadu_si128(reinterpret_cast<const __m128i*>(mask)),
                                           _mm_set1_epi8(-1)));
#endif
#if defined(__AVX2__)
    if constexpr (Width == 8) {
        uint64_t b;
        __builtin_memcpy(&b, mask, 8);
        return uint32_t(_mm_movemask_epi8(
                   _mm_cmpgt_epi8(_mm_cvtsi64_si128(int64_t(b)), _mm_setzero_si128()))) &
               255u;
    }
#endif
    uint32_t r = 0;
    for (int l = 0; l < Width; ++l) r |= uint32_t(mask[l] != 0) << l;
    return r;
}

}  // namespace sfx

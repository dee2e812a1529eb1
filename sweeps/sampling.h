#pragma once
// Sampled simulation (SMARTS-style): time a stratified random sample of a frame's tile passes at
// cycle level and extrapolate the frame, with a confidence interval.
//
// The sampling unit is one tile pass, exactly as the hardware schedules it (SIMD efficiency
// depends on which rays share a stream, so resolution and spp are never reduced). Units are
// numbered in execution order: unit = tile * spp + sample. This file holds the statistics,
// which need no tracer and no hardware model; sweeps/point_group.cpp drives them.

#include <cstdint>
#include <vector>

namespace sfx {

struct SamplingOptions {
    double fraction = 0.02;      // of the frame's tile passes, when no target error is given
    double target_error = 0.0;   // > 0: sample until every configuration's relative half-width
                                 // of frame cycles is at most this (or every pass is timed)
    double confidence = 0.997;   // two-sided level of the interval
    uint32_t strata = 8;
    uint32_t warmup_passes = 1;  // passes replayed into the scene caches before each sampled one
    // Full fidelity: other frames of the same workload (other_frame in kernels/render.h:
    // other seeds) rendered into the scene caches (no time, no counts) before the timed one; 0:
    // the timed frame starts from empty caches (the last warm frame is other_frame 1, the one
    // before it 2, ...). 2 predicts a frame that follows two renders of its workload, as the
    // silicon check's measured renders do.
    // As sampled fidelity's warm-up passes, they pass through the first core's private levels
    // and the shared ones (Accelerator::warm): another core's private levels start empty.
    uint32_t warm_frames = 0;
    uint32_t pilot_min_spp = 8;  // stratify by a pilot cost estimate from this spp on
    uint64_t seed = 1;
    // Analytic fidelity: share of tile passes also timed at cycle level to calibrate the
    // closed form on this very frame (0: uncalibrated, error unknown).
    double calibration_fraction = 0.02;
};

// Which stratum each unit belongs to.
struct Stratification {
    std::vector<uint32_t> stratum_of;  // per unit
    uint32_t strata = 0;

    std::vector<uint64_t> sizes() const;  // units per stratum
};

// Tiles sorted by a cost estimate (ties by tile index) and cut into equal-count groups; every
// pass of a tile falls in its tile's stratum.
Stratification stratify_tiles_by_cost(const std::vector<double>& tile_cost, uint32_t spp,
                                      uint32_t strata);
// Tiles cut into contiguous runs in raster order (image regions).
Stratification stratify_tiles_by_region(uint32_t tiles, uint32_t spp, uint32_t strata);

// Draws units without replacement, stratum by stratum in a seeded random order, keeping the
// allocation proportional to stratum sizes (and at least two per stratum where possible, so
// every stratum has a variance).
class StratifiedSampler {
public:
    StratifiedSampler(const Stratification& strata, uint64_t seed);
    // New units (sorted) that bring the sample to about `total` units.
    std::vector<uint32_t> grow_to(uint64_t total);
    uint64_t sampled() const { return m_sampled; }
    uint64_t population() const { return m_population; }

private:
    const Stratification& m_strata;
    std::vector<std::vector<uint32_t>> m_order;  // per stratum: its units, shuffled
    std::vector<uint64_t> m_taken;               // per stratum: how many are in the sample
    uint64_t m_sampled = 0, m_population = 0;
};

struct Estimate {
    double total = 0.0;       // estimated population total
    double half_width = 0.0;  // of the confidence interval for the total
    double degrees_of_freedom = 0.0;  // of the Student t the interval uses (Satterthwaite)
    uint64_t sampled = 0, population = 0;

    double relative() const { return total > 0.0 ? half_width / total : 0.0; }
};

// Stratified estimate of a population total from observed (unit, value) pairs, with the
// finite-population correction: Var = sum_h a_h s_h^2, a_h = N_h^2 (1 - n_h/N_h) / n_h. The
// interval is Student's t with Satterthwaite's effective degrees of freedom,
// (sum_h a_h s_h^2)^2 / sum_h (a_h s_h^2)^2 / (n_h - 1): with two or three passes per stratum
// a normal z is far too narrow; with many it is the normal interval.
Estimate estimate_total(const Stratification& strata, const std::vector<uint32_t>& units,
                        const std::vector<double>& values, double confidence);

// Two-sided standard-normal quantile: z with P(|Z| <= z) = confidence.
double normal_quantile_two_sided(double confidence);
// Two-sided Student t quantile: t with P(|T| <= t) = confidence for `degrees_of_freedom` > 0
// (need not be whole).
double student_t_quantile_two_sided(double confidence, double degrees_of_freedom);

}  // namespace sfx

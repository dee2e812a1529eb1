#include "sweeps/sampling.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "kernels/rng.h"

namespace sfx {

std::vector<uint64_t> Stratification::sizes() const {
    std::vector<uint64_t> n(strata, 0);
    for (uint32_t s : stratum_of) ++n[s];
    return n;
}

Stratification stratify_tiles_by_cost(const std::vector<double>& tile_cost, uint32_t spp,
                                      uint32_t strata) {
    const uint32_t tiles = uint32_t(tile_cost.size());
    strata = std::max(1u, std::min(strata, tiles));
    std::vector<uint32_t> order(tiles);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return tile_cost[a] < tile_cost[b]; });
    Stratification s;
    s.strata = strata;
    s.stratum_of.resize(size_t(tiles) * spp);
    for (uint32_t rank = 0; rank < tiles; ++rank) {
        const uint32_t stratum = uint32_t(uint64_t(rank) * strata / tiles);
        for (uint32_t sample = 0; sample < spp; ++sample)
            s.stratum_of[size_t(order[rank]) * spp + sample] = stratum;
    }
    return s;
}

Stratification stratify_tiles_by_region(uint32_t tiles, uint32_t spp, uint32_t strata) {
    std::vector<double> raster(tiles);
    std::iota(raster.begin(), raster.end(), 0.0);
    return stratify_tiles_by_cost(raster, spp, strata);
}

StratifiedSampler::StratifiedSampler(const Stratification& strata, uint64_t seed)
    : m_strata(strata), m_order(strata.strata), m_taken(strata.strata, 0) {
    for (uint32_t u = 0; u < strata.stratum_of.size(); ++u) m_order[strata.stratum_of[u]].push_back(u);
    m_population = strata.stratum_of.size();
    // Fisher-Yates with the counter-based generator: the sample depends on the seed only.
    for (uint32_t h = 0; h < strata.strata; ++h) {
        std::vector<uint32_t>& units = m_order[h];
        for (size_t i = units.size(); i > 1; --i) {
            const uint64_t r = random_bits(seed, h, uint32_t(i), 0, 0);
            std::swap(units[i - 1], units[size_t(r % i)]);
        }
    }
}

std::vector<uint32_t> StratifiedSampler::grow_to(uint64_t total) {
    total = std::min(total, m_population);
    std::vector<uint32_t> added;
    for (uint32_t h = 0; h < m_strata.strata; ++h) {
        const uint64_t size = m_order[h].size();
        if (size == 0) continue;
        uint64_t want = (total * size + m_population - 1) / m_population;  // proportional, rounded up
        want = std::min(size, std::max<uint64_t>(want, std::min<uint64_t>(2, size)));
        for (; m_taken[h] < want; ++m_taken[h], ++m_sampled) added.push_back(m_order[h][m_taken[h]]);
    }
    std::sort(added.begin(), added.end());
    return added;
}

namespace {
void check_confidence(double confidence) {
    if (!(confidence > 0.0 && confidence < 1.0))
        throw std::invalid_argument("confidence must lie in (0, 1)");
}
}  // namespace

double normal_quantile_two_sided(double confidence) {
    check_confidence(confidence);
    return boost::math::quantile(boost::math::complement(boost::math::normal_distribution<double>(),
                                                         (1.0 - confidence) / 2));
}

double student_t_quantile_two_sided(double confidence, double degrees_of_freedom) {
    check_confidence(confidence);
    if (!(degrees_of_freedom > 0.0))
        throw std::invalid_argument("degrees of freedom must be positive");
    return boost::math::quantile(boost::math::complement(
        boost::math::students_t_distribution<double>(degrees_of_freedom), (1.0 - confidence) / 2));
}

Estimate estimate_total(const Stratification& strata, const std::vector<uint32_t>& units,
                        const std::vector<double>& values, double confidence) {
    if (units.size() != values.size()) throw std::invalid_argument("units and values differ in size");
    const std::vector<uint64_t> sizes = strata.sizes();
    std::vector<double> sum(strata.strata, 0.0), sum2(strata.strata, 0.0);
    std::vector<uint64_t> n(strata.strata, 0);
    for (size_t i = 0; i < units.size(); ++i) {
        const uint32_t h = strata.stratum_of[units[i]];
        sum[h] += values[i];
        ++n[h];
    }
    for (size_t i = 0; i < units.size(); ++i) {
        const uint32_t h = strata.stratum_of[units[i]];
        const double d = values[i] - sum[h] / double(n[h]);
        sum2[h] += d * d;
    }
    Estimate e;
    e.population = strata.stratum_of.size();
    e.sampled = units.size();
    double variance = 0.0, dof_denominator = 0.0;
    for (uint32_t h = 0; h < strata.strata; ++h) {
        const double big_n = double(sizes[h]);
        if (big_n == 0.0) continue;
        if (n[h] == 0) throw std::invalid_argument("a stratum has no sampled unit");
        const double mean = sum[h] / double(n[h]);
        e.total += big_n * mean;
        if (n[h] >= 2) {
            const double s2 = sum2[h] / double(n[h] - 1);
            const double term = big_n * big_n * (1.0 - double(n[h]) / big_n) * s2 / double(n[h]);
            variance += term;
            dof_denominator += term * term / double(n[h] - 1);
        }
    }
    if (variance > 0.0) {
        e.degrees_of_freedom = variance * variance / dof_denominator;
        e.half_width =
            student_t_quantile_two_sided(confidence, e.degrees_of_freedom) * std::sqrt(variance);
    }
    return e;
}

}  // namespace sfx

#include "hw_model/op_cost_fit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "base/convergence.h"
#include "hw_model/cache_model.h"
#include "hw_model/op_costs.h"

namespace sfx {

double measured_op_cycles(const OpCostConfig& cost, uint32_t width, uint32_t lanes, uint32_t passed,
                          double beyond_l1, double beyond_l2, double failed_candidates,
                          double beyond_l1_skipping, double beyond_tlb) {
    OpProfile p;
    p.measured = true;
    p.cost = cost;
    const DatapathConfig datapath;  // unused by measured costs
    double cycles = 0.0;
    // The passing lanes go to the first groups (the sum is linear in them: any split prices
    // the same).
    for (uint32_t first = 0, left = passed; first < lanes; first += width) {
        const uint32_t n = std::min(width, lanes - first);
        const uint32_t pass = std::min(n, left);
        left -= pass;
        cycles +=
            p.issue_cycles(datapath, lanes, minority_lanes(passed, lanes), n, pass, first == 0,
                           beyond_l1, beyond_l2, failed_candidates, beyond_l1_skipping, beyond_tlb);
    }
    return cycles;
}

namespace {

// Columns of the cost formula for one sample (per op, group, lane, passing lane, minority
// lane, beyond L1, beyond L2, beyond L1 skipping lines in an opened page, beyond the DTLB,
// failing lane). The
// failing lanes' column is last: lanes, passing and failing lanes are dependent, so the solve gives
// it no pivot and 0 unless the passing lanes' cost would be negative and is dropped (a lane that
// passes costs less than one that fails: the scalar box test on an Intel Xeon VM, 2026-11-29, 24-27
// cycles a lane on streams that mostly pass and 38-47 on streams that mostly fail; fitted without
// it, 17 % median error).
constexpr int k_terms = 10;
std::array<double, k_terms> terms(const OpCostSample& s, uint32_t width) {
    return {1.0,
            double(lane_groups(s.lanes, width)),
            double(s.lanes),
            double(s.passed),
            double(minority_lanes(s.passed, s.lanes)),
            s.beyond_l1 * s.lanes,
            s.beyond_l2 * s.lanes,
            s.beyond_l1_skipping * s.lanes,
            s.beyond_tlb * s.lanes,
            double(s.lanes - s.passed)};
}

OpCostConfig from_coefficients(const std::string& op, const std::array<double, k_terms>& x) {
    OpCostConfig c;
    c.op = op;
    c.per_op_cycles = x[0];
    c.per_group_cycles = x[1];
    c.per_lane_cycles = x[2];
    c.per_pass_cycles = x[3];
    c.per_minority_lane_cycles = x[4];
    c.beyond_l1_per_lane_cycles = x[5];
    c.beyond_l2_per_lane_cycles = x[6];
    c.beyond_l1_skipping_per_lane_cycles = x[7];
    c.beyond_tlb_per_lane_cycles = x[8];
    c.per_fail_cycles = x[9];
    return c;
}

// Solves A x = b (A symmetric positive semi-definite, small) by Gaussian elimination with
// partial pivoting; a column with no pivot gets 0.
std::vector<double> solve(std::vector<std::vector<double>> a, std::vector<double> b) {
    const size_t n = b.size();
    std::vector<double> x(n, 0.0);
    std::vector<int> pivot_col(n, -1);
    size_t row = 0;
    for (size_t col = 0; col < n && row < n; ++col) {
        size_t best = row;
        for (size_t r = row; r < n; ++r)
            if (std::abs(a[r][col]) > std::abs(a[best][col])) best = r;
        if (std::abs(a[best][col]) < 1e-12) continue;
        std::swap(a[row], a[best]);
        std::swap(b[row], b[best]);
        for (size_t r = 0; r < n; ++r) {
            if (r == row) continue;
            const double f = a[r][col] / a[row][col];
            for (size_t c = col; c < n; ++c) a[r][c] -= f * a[row][c];
            b[r] -= f * b[row];
        }
        pivot_col[row] = int(col);
        ++row;
    }
    for (size_t r = 0; r < row; ++r) x[size_t(pivot_col[r])] = b[r] / a[r][size_t(pivot_col[r])];
    return x;
}

// Least squares on relative error of rows[s] . x = cycles[s] over the active columns, every
// coefficient non-negative: the most negative one is dropped and the rest refitted. The error
// is relative to `relative_to[s]` when given (a sample whose cycles are partly known).
template <size_t Terms>
std::array<double, Terms> fit_nonnegative(const std::vector<std::array<double, Terms>>& rows,
                                          const std::vector<double>& cycles,
                                          std::array<bool, Terms> active,
                                          const std::vector<double>* relative_to = nullptr) {
    std::array<double, Terms> x{};
    for (size_t round = 0; round < Terms; ++round) {
        std::vector<size_t> cols;
        for (size_t t = 0; t < Terms; ++t)
            if (active[t]) cols.push_back(t);
        const size_t m = cols.size();
        std::vector<std::vector<double>> ata(m, std::vector<double>(m, 0.0));
        std::vector<double> atb(m, 0.0);
        for (size_t s = 0; s < rows.size(); ++s) {
            // Relative error; below k_fit_resolution_cycles the clock's steps dominate a sample.
            const double w = 1.0 / std::max(relative_to ? (*relative_to)[s] : cycles[s],
                                            k_fit_resolution_cycles);
            for (size_t i = 0; i < m; ++i) {
                atb[i] += rows[s][cols[i]] * w * cycles[s] * w;
                for (size_t j = 0; j < m; ++j)
                    ata[i][j] += rows[s][cols[i]] * w * rows[s][cols[j]] * w;
            }
        }
        const std::vector<double> sol = solve(ata, atb);
        x.fill(0.0);
        int most_negative = -1;
        for (size_t i = 0; i < m; ++i) {
            x[cols[i]] = sol[i];
            if (sol[i] < 0 && (most_negative < 0 || sol[i] < x[size_t(most_negative)]))
                most_negative = int(cols[i]);
        }
        if (most_negative < 0) break;
        active[size_t(most_negative)] = false;
        x[size_t(most_negative)] = 0.0;
    }
    for (double& v : x) v = std::max(v, 0.0);
    return x;
}

// A sample's one-lane counts, its few-lane counts, its stream-loop counts, its loop entries and
// its traversals, as a row of the fit.
constexpr size_t k_entry_terms = 3 * k_op_kind_count;
constexpr size_t k_traversal_term = k_entry_terms + 2;
constexpr size_t k_short_terms = k_traversal_term + 1;
std::array<double, k_short_terms> short_stream_row(const OneLaneSample& s) {
    std::array<double, k_short_terms> row{};
    for (size_t k = 0; k < k_op_kind_count; ++k) {
        row[k] = double(s.ops[k]);
        row[k_op_kind_count + k] = double(s.few_ops[k]);
        row[2 * k_op_kind_count + k] = double(s.stream_ops[k]);
    }
    for (size_t l = 0; l < 2; ++l) row[k_entry_terms + l] = double(s.entries[l]);
    row[k_traversal_term] = double(s.traversals);
    return row;
}

}  // namespace

double short_stream_cycles(const ShortStreamCosts& costs, const OneLaneSample& s) {
    double cycles = s.stream_op_cycles;
    for (size_t k = 0; k < k_op_kind_count; ++k)
        cycles += double(s.ops[k]) * costs.one_lane[k] + double(s.few_ops[k]) * costs.few_lane[k] +
                  double(s.stream_ops[k]) * costs.stream_per_op[k];
    for (size_t l = 0; l < 2; ++l) cycles += double(s.entries[l]) * costs.entry[l];
    return cycles + double(s.traversals) * costs.traversal_start;
}

OpCostConfig fit_op_cost(const std::string& op, uint32_t width,
                         const std::vector<OpCostSample>& samples) {
    if (samples.empty()) throw std::invalid_argument("no microbenchmark samples for " + op);
    std::array<bool, k_terms> active;
    active.fill(true);
    // A column that never varies apart from the constant carries no information. The minority
    // column is told from the lane and pass columns only by streams of many lanes that all
    // pass and that none pass beside mixed ones (the shading filters' and leaf tests'
    // microbenchmarks).
    bool any_beyond = false, any_beyond_l2 = false, any_skipping = false, any_tlb = false,
         any_passed = false, any_failed = false, all_pass = false, none_pass = false, mixed = false;
    std::vector<std::array<double, k_terms>> rows;
    std::vector<double> cycles;
    for (const OpCostSample& s : samples) {
        any_beyond |= s.beyond_l1 > 0;
        any_beyond_l2 |= s.beyond_l2 > 0;
        any_skipping |= s.beyond_l1_skipping > 0;
        any_tlb |= s.beyond_tlb > 0;
        any_passed |= s.passed > 0;
        any_failed |= s.passed < s.lanes;
        all_pass |= s.lanes >= 8 && s.passed == s.lanes;
        none_pass |= s.lanes >= 8 && s.passed == 0;
        mixed |= s.passed > 0 && s.passed < s.lanes;
        rows.push_back(terms(s, width));
        cycles.push_back(s.cycles);
    }
    active[5] = any_beyond;
    active[6] = any_beyond_l2;
    active[7] = any_skipping;
    active[8] = any_tlb;
    active[4] = all_pass && none_pass && mixed;
    active[3] = any_passed;
    active[9] = any_passed && any_failed;
    return from_coefficients(op, fit_nonnegative(rows, cycles, active));
}

ShortStreamCosts fit_short_stream_cycles(const std::vector<OneLaneSample>& samples,
                                         const GivenFewRayCosts* given) {
    if (samples.empty()) throw std::invalid_argument("no short-stream traversal samples");
    constexpr size_t few_box = k_op_kind_count + size_t(OpKind::box_test);
    constexpr size_t few_entry = k_entry_terms + 1;
    constexpr size_t one_box = size_t(OpKind::box_test);
    std::array<bool, k_short_terms> active{};
    std::vector<std::array<double, k_short_terms>> rows;
    std::vector<double> loops, whole;
    auto add_row = [&](const std::array<double, k_short_terms>& row, double cycles,
                       const OneLaneSample& s) {
        for (size_t k = 0; k < k_short_terms; ++k) active[k] = active[k] || row[k] > 0;
        rows.push_back(row);
        loops.push_back(cycles - (given ? row[few_box] * given->few_lane_cycles +
                                              row[few_entry] * given->entry_cycles
                                        : 0.0));
        whole.push_back(s.cycles);
    };
    for (const OneLaneSample& s : samples) {
        const std::array<double, k_short_terms> row = short_stream_row(s);
        // What the one-ray and few-ray loops' ops took (the rest is priced by the formula),
        // its error relative to the whole sample's cycles, as short_stream_fit_error judges it.
        // The leaf tests' cycles by the stage clock where it split them off: priced by the
        // filter microbenchmarks instead (until 2026-12-05), they came out 13 % over the clock's
        // leaf share of the batches (AVX2, an AMD Zen 5 VM), and the fit took that off the
        // stream loop's per-op box cost (0-4 cycles at AVX2 and 7-10 at AVX-512, against 35-38
        // and 20-25 in the filters' independent calls; the stream loop priced 28 % under its
        // clocked share at AVX2).
        const double beyond_priced =
            s.cycles - s.stream_op_cycles +
            (s.leaf_cycles_clocked >= 0 ? s.leaf_op_cycles - s.leaf_cycles_clocked : 0.0);
        if (s.leaf_cycles_clocked < 0 || s.loop_cycles_clocked[0] < 0 ||
            s.loop_cycles_clocked[1] < 0) {
            add_row(row, beyond_priced, s);
            continue;
        }
        // By loop: each loop's columns against its clocked cycles less its priced
        // mispredictions; the stream loop's against the rest (the three sum to beyond_priced).
        const double nested = few_ray_one_lane_box_tests(s);
        std::array<double, k_short_terms> one_ray{}, few_ray{}, stream{};
        for (size_t k = 0; k < k_op_kind_count; ++k) {
            one_ray[k] = row[k];
            few_ray[k_op_kind_count + k] = row[k_op_kind_count + k];
            stream[2 * k_op_kind_count + k] = row[2 * k_op_kind_count + k];
        }
        one_ray[one_box] -= nested;
        few_ray[one_box] = nested;
        one_ray[k_entry_terms] = row[k_entry_terms];
        few_ray[few_entry] = row[few_entry];
        stream[k_traversal_term] = row[k_traversal_term];
        const double one_ray_cycles = s.loop_cycles_clocked[0] - s.loop_mispredicted_cycles[0],
                     few_ray_cycles = s.loop_cycles_clocked[1] - s.loop_mispredicted_cycles[1];
        add_row(one_ray, one_ray_cycles, s);
        add_row(few_ray, few_ray_cycles, s);
        add_row(stream, beyond_priced - one_ray_cycles - few_ray_cycles, s);
    }
    const bool few_measured = active[few_box];
    if (given) active[few_box] = active[few_entry] = false;
    std::array<double, k_short_terms> x = fit_nonnegative(rows, loops, active, &whole);
    if (given) {
        x[few_box] = given->few_lane_cycles;
        x[few_entry] = given->entry_cycles;
        active[few_box] = few_measured;
    }
    ShortStreamCosts costs;
    for (size_t k = 0; k < k_op_kind_count; ++k) {
        costs.one_lane[k] = x[k];
        costs.few_lane[k] = x[k_op_kind_count + k];
        costs.stream_per_op[k] = x[2 * k_op_kind_count + k];
        costs.stream_measured[k] = active[2 * k_op_kind_count + k];
        costs.one_lane_measured[k] = active[k];
        costs.few_lane_measured[k] = active[k_op_kind_count + k];
    }
    for (size_t l = 0; l < 2; ++l) costs.entry[l] = x[k_entry_terms + l];
    costs.traversal_start = x[k_traversal_term];
    return costs;
}

std::pair<double, double> short_stream_fit_error(const ShortStreamCosts& costs,
                                                 const std::vector<OneLaneSample>& samples) {
    std::vector<double> e;
    for (const OneLaneSample& s : samples)
        e.push_back(std::abs(short_stream_cycles(costs, s) - s.cycles) /
                    std::max(s.cycles, k_fit_resolution_cycles));
    if (e.empty()) return {0.0, 0.0};
    std::sort(e.begin(), e.end());
    return {e[e.size() / 2], e.back()};
}

namespace {
// The median over the samples with units (`units_of`) of their cycles beyond `base`'s price,
// per unit (negative where they cost less); 0 when there are none.
template <class Units>
double median_extra(const OpCostConfig& base, uint32_t width,
                    const std::vector<OpCostSample>& samples, Units units_of) {
    std::vector<double> extra;
    for (const OpCostSample& s : samples)
        if (const uint32_t units = units_of(s); units > 0)
            extra.push_back(
                (s.cycles - measured_op_cycles(base, width, s.lanes, s.passed, s.beyond_l1,
                                               s.beyond_l2, s.failed_candidates,
                                               s.beyond_l1_skipping, s.beyond_tlb)) /
                units);
    return extra.empty() ? 0.0 : median(extra);
}
}  // namespace

double fit_extra_per_passing_lane(const OpCostConfig& base, uint32_t width,
                                  const std::vector<OpCostSample>& variant_samples) {
    return std::max(0.0, median_extra(base, width, variant_samples,
                                      [](const OpCostSample& s) { return s.passed; }));
}

double fit_extra_per_failed_candidate(const OpCostConfig& base, uint32_t width,
                                      const std::vector<OpCostSample>& variant_samples) {
    return std::max(0.0, median_extra(base, width, variant_samples,
                                      [](const OpCostSample& s) { return s.failed_candidates; }));
}

double fit_cold_call_cycles(std::vector<double> differences) {
    if (differences.empty()) return 0.0;
    std::sort(differences.begin(), differences.end());
    const size_t n = differences.size();
    const double median =
        n % 2 ? differences[n / 2] : 0.5 * (differences[n / 2 - 1] + differences[n / 2]);
    return std::max(0.0, median);
}

double fit_extra_per_lane(const OpCostConfig& base, uint32_t width,
                          const std::vector<OpCostSample>& variant_samples) {
    return median_extra(base, width, variant_samples,
                        [](const OpCostSample& s) { return s.lanes; });
}

void fit_one_lane_by_outcome(OpCostConfig& cost, const std::vector<OpCostSample>& one_lane) {
    if (one_lane.empty()) return;
    std::vector<double> failing, passing, failed_candidate, every;
    for (const OpCostSample& s : one_lane) {
        (s.passed > 0              ? passing
         : s.failed_candidates > 0 ? failed_candidate
                                   : failing)
            .push_back(s.cycles);
        every.push_back(s.cycles);
    }
    cost.one_lane_cycles = median(failing.empty() ? every : failing);
    cost.one_lane_pass_cycles = cost.one_lane_failed_candidate_cycles = 0.0;
    if (failing.empty()) return;
    if (!passing.empty())
        cost.one_lane_pass_cycles = std::max(0.0, median(passing) - cost.one_lane_cycles);
    if (!failed_candidate.empty())
        cost.one_lane_failed_candidate_cycles =
            std::max(0.0, median(failed_candidate) - cost.one_lane_cycles);
}

std::pair<double, double> fit_error(const OpCostConfig& cost, uint32_t width,
                                    const std::vector<OpCostSample>& samples) {
    std::vector<double> e;
    for (const OpCostSample& s : samples)
        e.push_back(
            std::abs(measured_op_cycles(cost, width, s.lanes, s.passed, s.beyond_l1, s.beyond_l2,
                                        s.failed_candidates, s.beyond_l1_skipping, s.beyond_tlb) -
                     s.cycles) /
            std::max(s.cycles, k_fit_resolution_cycles));
    if (e.empty()) return {0.0, 0.0};
    std::sort(e.begin(), e.end());
    return {e[e.size() / 2], e.back()};
}

double modeled_hit_read_cycles(const HwConfig& host, const HitReadSample& sample) {
    SceneDataMap map;
    map.triangles = sample.triangles;
    SceneMemoryModel scene(host.scene_memory, host.clock.core_mhz, 1, nullptr, map.span_bytes());
    // The mesh as its construction wrote it, in order, then the earlier repetitions' hits.
    for (uint32_t prim = 0; prim < sample.triangles; ++prim) warm_hit(scene, map, 0, prim, true);
    for (uint32_t prim : sample.warm_prims) warm_hit(scene, map, 0, prim, true);
    const uint64_t hidden = hit_read_latency_hidden(host);
    double beyond = 0.0;
    for (uint32_t prim : sample.timed_prims)
        beyond += double(hit_latency_beyond(scene, map, 0, prim, true, 0, hidden));
    return beyond;
}

HitReadFit fit_hit_read_exposed_share(const HwConfig& host,
                                      const std::vector<HitReadSample>& samples) {
    if (samples.empty()) throw std::invalid_argument("no surface-read samples to fit");
    HitReadFit fit;
    double num = 0.0, den = 0.0;
    std::vector<double> floor;
    for (const HitReadSample& s : samples) {
        fit.modeled.push_back(modeled_hit_read_cycles(host, s));
        // Minimises sum ((share m - e) / f)^2, f the floored extra.
        const double f = std::max(s.extra_cycles, double(s.timed_prims.size()));
        floor.push_back(f);
        num += fit.modeled.back() * s.extra_cycles / (f * f);
        den += fit.modeled.back() * fit.modeled.back() / (f * f);
    }
    fit.share = den > 0 ? std::max(0.0, num / den) : 0.0;
    std::vector<double> errors;
    for (size_t i = 0; i < samples.size(); ++i)
        errors.push_back(std::abs(fit.share * fit.modeled[i] - samples[i].extra_cycles) /
                         floor[i]);
    std::sort(errors.begin(), errors.end());
    fit.error = {errors[errors.size() / 2], errors.back()};
    return fit;
}

}  // namespace sfx

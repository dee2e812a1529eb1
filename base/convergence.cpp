#include "base/convergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "base/input_error.h"

namespace sfx {

Convergence judge_convergence(const std::vector<double>& samples, const ConvergenceRule& rule) {
    Convergence c;
    c.samples = uint32_t(samples.size());
    if (samples.empty()) {
        c.spread = std::numeric_limits<double>::infinity();
        return c;
    }
    const size_t k = std::max<size_t>(rule.fastest, 1);
    std::vector<double> sorted = samples;
    const size_t kth = std::min(k, sorted.size()) - 1;
    std::nth_element(sorted.begin(), sorted.begin() + long(kth), sorted.end());
    const double kth_value = sorted[kth];
    c.fastest = *std::min_element(sorted.begin(), sorted.begin() + long(kth) + 1);
    if (samples.size() < k)
        c.spread = std::numeric_limits<double>::infinity();
    else
        c.spread = c.fastest > 0 ? kth_value / c.fastest - 1.0
                                 : (kth_value > 0 ? std::numeric_limits<double>::infinity() : 0.0);
    const size_t enough = std::min(rule.min_samples, rule.budget);
    c.converged = samples.size() >= enough && c.spread <= rule.tolerance;
    return c;
}

Convergence judge_parts_convergence(const std::vector<std::vector<double>>& parts,
                                    const ConvergenceRule& rule) {
    Convergence c;
    c.spread = std::numeric_limits<double>::infinity();
    if (parts.empty()) return c;
    c.samples = std::numeric_limits<uint32_t>::max();
    double kth_sum = 0.0;
    const size_t k = std::max<size_t>(rule.fastest, 1);
    bool every_kth = true;  // every part has a k-th fastest sample
    for (const std::vector<double>& part : parts) {
        c.samples = std::min(c.samples, uint32_t(part.size()));
        if (part.empty()) {
            every_kth = false;
            continue;
        }
        std::vector<double> sorted = part;
        const size_t kth = std::min(k, sorted.size()) - 1;
        std::nth_element(sorted.begin(), sorted.begin() + long(kth), sorted.end());
        c.fastest += *std::min_element(sorted.begin(), sorted.begin() + long(kth) + 1);
        kth_sum += sorted[kth];  // a part whose fastest is 0 still adds its k-th
        every_kth = every_kth && part.size() >= k;
    }
    if (every_kth)
        c.spread = c.fastest > 0 ? kth_sum / c.fastest - 1.0 : (kth_sum > 0 ? c.spread : 0.0);
    const size_t enough = std::min(rule.min_samples, rule.budget);
    c.converged = c.samples >= enough && c.spread <= rule.tolerance;
    return c;
}

double median(std::vector<double> samples) {
    if (samples.empty()) return 0.0;
    const auto middle = samples.begin() + long(samples.size() / 2);
    std::nth_element(samples.begin(), middle, samples.end());
    return *middle;
}

ConvergenceRule after_discarded(ConvergenceRule rule, uint32_t discarded) {
    rule.budget -= std::min(discarded, rule.budget);
    return rule;
}

bool needs_more_samples(const std::vector<double>& samples, const ConvergenceRule& rule) {
    if (samples.size() >= rule.budget) return false;
    if (samples.size() < rule.min_samples) return true;
    return !judge_convergence(samples, rule).converged;
}

std::string describe(const ConvergenceRule& rule) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "fastest %u of %u-%u samples within %g %%", rule.fastest,
                  std::min(rule.min_samples, rule.budget), rule.budget, 100 * rule.tolerance);
    return buf;
}

void check_rule(const ConvergenceRule& rule, const std::string& flag) {
    auto fail = [&](const std::string& what) { throw InputError("command line", 0, flag, what); };
    if (rule.budget < 1 || rule.budget > 1000) fail("the budget must be 1 to 1000 samples");
    if (rule.fastest < 1 || rule.fastest > rule.budget)
        fail("the fastest k samples must be 1 to the budget (" + std::to_string(rule.budget) + ")");
    if (rule.min_samples > rule.budget)
        fail("at least " + std::to_string(rule.min_samples) + " samples exceeds the budget (" +
             std::to_string(rule.budget) + ")");
    if (!(rule.tolerance >= 0.0 && rule.tolerance <= 1.0))
        fail("the tolerance must be 0 to 1 (a fraction: 0.03 is 3 %)");
}

}  // namespace sfx

// The convergence rule on synthetic samples: clean, bimodal (a shared virtual machine's fast
// and slow modes), drifting; and its bounds.

#include "base/convergence.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "base/input_error.h"

using namespace sfx;

namespace {

ConvergenceRule rule(uint32_t k, double tolerance, uint32_t min_samples, uint32_t budget) {
    ConvergenceRule r;
    r.fastest = k;
    r.tolerance = tolerance;
    r.min_samples = min_samples;
    r.budget = budget;
    return r;
}

// Samples taken one at a time while the rule asks for more.
std::vector<double> sample_until_done(const std::vector<double>& stream, const ConvergenceRule& r) {
    std::vector<double> taken;
    for (double v : stream) {
        if (!needs_more_samples(taken, r)) break;
        taken.push_back(v);
    }
    return taken;
}

}  // namespace

TEST_CASE("Convergence: clean samples converge after the minimum, on their fastest",
          "[convergence]") {
    const ConvergenceRule r = rule(3, 0.03, 5, 31);
    const std::vector<double> clean = {101, 100.5, 102, 100, 101.5, 100.8, 101, 100.2};
    const std::vector<double> taken = sample_until_done(clean, r);
    CHECK(taken.size() == 5);  // agreeing from the start: stops at the minimum
    const Convergence c = judge_convergence(taken, r);
    CHECK(c.converged);
    CHECK(c.fastest == 100);
    CHECK(c.spread == Approx(101.0 / 100 - 1));  // the third fastest of 101, 100.5, 102, 100, 101.5
    CHECK(c.samples == 5);
    // Fewer than the minimum: not yet, whatever the spread.
    CHECK_FALSE(judge_convergence({100, 100, 100}, r).converged);
    CHECK(needs_more_samples({100, 100, 100}, r));
}

TEST_CASE("Convergence: bimodal samples converge only once the fast mode holds k samples",
          "[convergence]") {
    const ConvergenceRule r = rule(3, 0.03, 5, 31);
    // The Intel host: three fast samples far apart (241, 263, 282 Mcycles), then a slow
    // mode of 500-725. The fastest three disagree by 17 %: no verdict on the fast mode.
    std::vector<double> bimodal = {241, 263, 282, 500, 725, 610, 540, 580,
                                   700, 650, 520, 690, 560, 600, 710};
    Convergence c = judge_convergence(bimodal, r);
    CHECK_FALSE(c.converged);
    CHECK(c.fastest == 241);
    CHECK(c.spread == Approx(282.0 / 241 - 1));
    CHECK(needs_more_samples(bimodal, r));
    // Out of budget: not converged, and no more samples asked for.
    const ConvergenceRule short_budget = rule(3, 0.03, 5, 15);
    CHECK_FALSE(needs_more_samples(bimodal, short_budget));
    CHECK_FALSE(judge_convergence(bimodal, short_budget).converged);
    // A fast mode that recurs: converges on it, not on the slow mode.
    bimodal.insert(bimodal.end(), {244, 243});
    c = judge_convergence(bimodal, r);
    CHECK(c.converged);
    CHECK(c.fastest == 241);
    // One fast outlier among a tight slow mode is no convergence either.
    CHECK_FALSE(judge_convergence({300, 600, 601, 602, 603, 604}, r).converged);
}

TEST_CASE("Convergence: drifting samples do not converge until the drift stops", "[convergence]") {
    const ConvergenceRule r = rule(3, 0.03, 5, 31);
    // Slowing down 5 % a sample (a neighbour's load rising): the fastest are the first, 5 %
    // apart, and they never agree.
    std::vector<double> slowing;
    for (int i = 0; i < 31; ++i) slowing.push_back(100 * std::pow(1.05, i));
    const std::vector<double> taken = sample_until_done(slowing, r);
    CHECK(taken.size() == 31);  // the whole budget
    CHECK_FALSE(judge_convergence(taken, r).converged);
    // Speeding up 5 % a sample (warming up), then steady: converges on the plateau.
    std::vector<double> warming;
    for (int i = 0; i < 8; ++i) warming.push_back(200 * std::pow(0.95, i));
    const double plateau = warming.back();
    for (int i = 0; i < 10; ++i) warming.push_back(plateau * (1.0 + 0.002 * (i % 3)));
    const std::vector<double> warmed = sample_until_done(warming, r);
    CHECK(warmed.size() == 10);  // the drift (its last sample on the plateau), then two more
    const Convergence c = judge_convergence(warmed, r);
    CHECK(c.converged);
    CHECK(c.fastest == Approx(plateau));
}

TEST_CASE("Convergence: degenerate rules and bad flags", "[convergence]") {
    CHECK_FALSE(judge_convergence({}, rule(3, 0.03, 5, 31)).converged);
    CHECK(std::isinf(judge_convergence({1, 2}, rule(3, 0.03, 1, 31)).spread));
    // k = 1, one sample: converged (the budget of a quick look).
    CHECK(judge_convergence({7}, rule(1, 0.0, 1, 1)).converged);
    // A budget below the minimum: the budget is the minimum.
    CHECK(judge_convergence({7, 7}, rule(2, 0.0, 5, 2)).converged);
    CHECK(describe(rule(3, 0.03, 7, 31)) == "fastest 3 of 7-31 samples within 3 %");
    CHECK_NOTHROW(check_rule(rule(3, 0.03, 7, 31), "--repeat"));
    CHECK_THROWS_AS(check_rule(rule(0, 0.03, 7, 31), "--fastest"), InputError);
    CHECK_THROWS_AS(check_rule(rule(3, 0.03, 7, 2), "--repeat"), InputError);
    CHECK_THROWS_AS(check_rule(rule(3, 0.03, 40, 31), "--min-repeat"), InputError);
    CHECK_THROWS_AS(check_rule(rule(3, 1.5, 7, 31), "--tolerance"), InputError);
    CHECK_THROWS_AS(check_rule(rule(3, std::nan(""), 7, 31), "--tolerance"), InputError);
    try {
        check_rule(rule(3, -0.1, 7, 31), "--tolerance");
    } catch (const InputError& e) {
        CHECK(e.key() == "--tolerance");
    }
}

TEST_CASE("Convergence: samples set aside spend the budget", "[convergence]") {
    const ConvergenceRule r = rule(3, 0.03, 7, 31);
    CHECK(after_discarded(r, 0).budget == 31);
    CHECK(after_discarded(r, 10).budget == 21);
    CHECK(after_discarded(r, 40).budget == 0);
    CHECK(after_discarded(r, 10).tolerance == r.tolerance);
    // Samples that never converge: 21 taken beside 10 set aside, then no more.
    std::vector<double> drift;
    for (int i = 0; i < 40; ++i) drift.push_back(100.0 * (i + 1));
    CHECK(sample_until_done(drift, after_discarded(r, 10)).size() == 21);
    CHECK_FALSE(needs_more_samples({}, after_discarded(r, 31)));
    // A budget spent below the minimum: what is left is the minimum.
    CHECK(judge_convergence({100, 100.5, 101, 101, 101}, after_discarded(r, 26)).converged);
    CHECK_FALSE(judge_convergence({100, 100.5, 101, 101, 101}, r).converged);
}

TEST_CASE("Convergence: a measurement in parts sums each part's fastest and k-th fastest",
          "[convergence]") {
    const ConvergenceRule r = rule(3, 0.03, 7, 31);
    // Two parts, each clean: their fastest sum 100 + 50, their third fastest 101 + 52.
    std::vector<std::vector<double>> parts = {{101, 100, 130, 101, 140, 150, 160},
                                              {52, 50, 51, 90, 95, 99, 52}};
    Convergence c = judge_parts_convergence(parts, r);
    CHECK(c.fastest == Approx(150.0));
    CHECK(c.spread == Approx(153.0 / 150.0 - 1.0));
    CHECK(c.samples == 7);
    CHECK(c.converged);
    // A part slowed in most renders (bimodal) spreads the sum beyond the tolerance.
    parts[1] = {50, 80, 80, 80, 80, 80, 80};
    c = judge_parts_convergence(parts, r);
    CHECK(c.fastest == Approx(150.0));
    CHECK(c.spread == Approx(181.0 / 150.0 - 1.0));
    CHECK_FALSE(c.converged);
    // A part with too few samples keeps the whole from converging, however close its fastest.
    parts[1] = {50, 50, 50};
    c = judge_parts_convergence(parts, r);
    CHECK(c.samples == 3);
    CHECK(c.spread == Approx(151.0 / 150.0 - 1.0));
    CHECK_FALSE(c.converged);
    parts[1] = {50, 50};
    c = judge_parts_convergence(parts, r);
    CHECK(std::isinf(c.spread));
    CHECK(c.fastest == Approx(150.0));  // still the sum of every part's fastest
    CHECK(c.samples == 2);
    CHECK_FALSE(c.converged);
    // A part whose fastest is 0 (a render's rest outside its parts, say) adds its k-th fastest.
    parts[1] = {0, 0, 3, 4, 5, 6, 7};
    c = judge_parts_convergence(parts, r);
    CHECK(c.fastest == Approx(100.0));
    CHECK(c.spread == Approx(104.0 / 100.0 - 1.0));
    CHECK_FALSE(c.converged);
    CHECK_FALSE(judge_parts_convergence({}, r).converged);
}

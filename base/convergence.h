#pragma once
// When a repeated measurement has converged: the one rule every timed thing in sfx repeats by
// (a render of `sfx calibrate --check`, a microbenchmark point of `--describe-host`). A
// shared machine only ever adds time, and a virtual machine's times are often bimodal (a fast
// mode and a slow one), so a measurement is its fastest sample, and it counts only once its
// `fastest` k samples agree within `tolerance`: the k-th fastest at most (1 + tolerance) x the
// fastest. It repeats until then, at least `min_samples` times (so that a first run of slow
// samples agreeing among themselves is less likely to end it) and at most `budget` times; one
// that ran out of budget did not converge and is shown so, never scored. The rule of pyperf
// and of Google Benchmark's repetitions, as a pure function of the samples.

#include <cstdint>
#include <string>
#include <vector>

namespace sfx {

struct ConvergenceRule {
    uint32_t fastest = 3;     // k: how many of the fastest samples must agree
    double tolerance = 0.03;  // the k-th fastest within (1 + tolerance) x the fastest
    uint32_t min_samples = 7;
    uint32_t budget = 31;  // samples at most
};

struct Convergence {
    bool converged = false;
    double fastest = 0.0;  // the measurement: the fastest sample (0 without samples)
    double spread = 0.0;   // k-th fastest / fastest - 1 (infinity with fewer than k samples)
    uint32_t samples = 0;
};

// The verdict on the samples so far (any order). Converged: at least min_samples samples (or
// the whole budget, if smaller) and a spread within the tolerance.
Convergence judge_convergence(const std::vector<double>& samples, const ConvergenceRule& rule);

// A measurement read as the sum of parts that each repeat (a frame's generations, each timed
// in every render over which the core was alone, sfx calibrate --check): its fastest the sum of
// each part's fastest sample, its spread the sum of each part's k-th fastest over that, less 1,
// its samples the fewest any part has. Converged as judge_convergence's sum would be: every part
// has enough samples and the spread is within the tolerance. No parts: not converged.
Convergence judge_parts_convergence(const std::vector<std::vector<double>>& parts,
                                    const ConvergenceRule& rule);
// The rule for samples beside which `discarded` more were taken and set aside (readings that
// cannot be trusted): each spent the budget as a sample does.
ConvergenceRule after_discarded(ConvergenceRule rule, uint32_t discarded);

// Whether to take another sample: fewer than min_samples, or not converged and budget left.
bool needs_more_samples(const std::vector<double>& samples, const ConvergenceRule& rule);

// The middle sample (the upper middle of an even count; 0 without samples): the typical
// reading where one interrupted sample must not move it.
double median(std::vector<double> samples);

// "fastest 3 of 7-31 samples within 3 %": how the rule reads on a page.
std::string describe(const ConvergenceRule& rule);

// Throws InputError naming `flag` unless 1 <= fastest <= budget, min_samples <= budget,
// 1 <= budget <= 1000 and 0 <= tolerance <= 1.
void check_rule(const ConvergenceRule& rule, const std::string& flag);

}  // namespace sfx

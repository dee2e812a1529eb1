#pragma once
// What running a sweep would cost, said before it runs (`sfx sweep --dry-run`): per fidelity,
// each group's functional render plus the timing of each of its points, plus the sweep
// machinery's cost per point, in CPU seconds.
//
// Both scale with the frame's work: paths (pixels x spp) x bounces (depth + 1) x the depth of
// the scene's BVH (log2 of its primitives). The rates per unit of work are measured on the
// reference host named by k_estimate_basis (the commands are in sweeps/README.md); a scene's
// materials and lights move the real figure, so the estimate is good to a factor of about 2.

#include <cstddef>
#include <vector>

#include "hw_model/prediction.h"
#include "sweeps/sweep.h"

namespace sfx {

struct FidelityEstimate {
    Fidelity fidelity = Fidelity::full;
    size_t points = 0;
    size_t groups = 0;
    double seconds = 0;  // CPU seconds on the reference host
};

// Where the rates come from, for the dry run's output.
extern const char* const k_estimate_basis;

// One entry per fidelity the sweep uses, in the order analytic, sampled, full.
std::vector<FidelityEstimate> estimate_host_seconds(const Sweep& sweep);

}  // namespace sfx

#pragma once
// Adaptive seeding for thin parts (issue: seeds where thin features need them; docs/sample-seeds.md,
// "Thin parts"). Uniform seeds leave parts thinner than about a spacing with too few seeds to close them;
// these functions find where the surface turns back on itself within a spacing, so that sample-seeds can
// choose more of its draws there.
#include <cstdint>
#include <vector>

#include "common/types.h"
#include "common/udf.h"

namespace voroudf {

/// The thickness of the part at each surface point p_i with unit normal n_i (either orientation): probing
/// at p ± s n for s = h·2^(−k/2), k = 0..7, the smallest s past the part's medial point and short of its
/// other sheet — d < 0.9 s there and the gradient turned back (g . (±n) < -0.5, so that a concave crease,
/// whose other face lies beside and not opposite, does not count) — gives the thickness 1.6 s (the other
/// sheet lies between s and 1.9 s away along the normal; every distance from 0.17 h to 1.9 h is seen).
/// Infinity where no probe sees one. 16 queries per point, in one batch.
std::vector<double> ProbeThickness(const Udf& udf, const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                   double h);

/// How much denser the seeds should be at each point, for a spacing of a third of the thickness where the
/// part is thin: w = (h / (t/3))² clamped to [1, max_boost] (at least 3.5 where ProbeThickness sees the
/// part, 1 elsewhere).
std::vector<double> ThinSeedWeights(const std::vector<double>& thickness, double h, double max_boost);

/// `count` indices chosen at random without replacement, index i with a chance growing with weight[i]
/// (Efraimidis-Spirakis keys from the counter-based stream (seed, i)); all of them if count >= size. In
/// increasing order.
std::vector<size_t> ChooseWeighted(const std::vector<double>& weight, size_t count, uint64_t seed);

}  // namespace voroudf

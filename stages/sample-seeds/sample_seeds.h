#pragma once
// Stage 1 (DESIGN.md; paper Sec. 3, "Initialize N seeds"): seeds uniform in the domain box, projected
// onto the zero set of the UDF.
#include <cstddef>
#include <cstdint>

#include "common/monitor.h"
#include "common/projection.h"
#include "common/udf.h"
#include "formats/seeds_io.h"

namespace voroudf {

struct SampleSeedsOptions {
  size_t count = 3000;          ///< points drawn (inside the band) before projection (--count)
  uint64_t seed = 0;            ///< RNG seed (--seed)
  /// Only draws with d(x) < band_rel * diagonal are kept (--band-rel; 0: the whole box, as in the paper).
  /// Why: an exact UDF maps the whole wedge outside a convex edge or corner onto that edge or corner, so
  /// box-uniform draws put a large share of seeds exactly on sharp features (44 % on fandisk, 12 % exact
  /// duplicates) where optimize-seeds can only slide them along the feature. Near the surface the
  /// projection is close to area-uniform.
  double band_rel = 0.01;
  /// Projected seeds closer than this (× diagonal) to an earlier one are dropped (--dedup-rel; 0: keep all).
  double dedup_rel = 1e-4;
  double proj_tol_rel = 1e-5;   ///< converged once d(x) < proj_tol_rel * domain diagonal (--proj-tol-rel)
  int proj_max_iters = 50;      ///< projection steps before a seed is dropped (--proj-max-iters)
  /// --proj-floor-rel: a seed at the bottom of a kink of d (common/projection.h) with d below this x diagonal
  /// has converged: learned and sampled fields have such a floor instead of zeros. 0: off.
  double proj_floor_rel = 1e-2;
  /// --proj-twin-factor: zero sheets closer than this x the field's measured floor are one surface
  /// (common/projection.h, MergeTwinSheets); exact fields have no floor. 0: off.
  double proj_twin_factor = kProjTwinFactor;
  /// --thin-boost B: a pool ceil(B) times larger, from which the count are chosen up to B times denser where
  /// the part is thinner than 2 spacings (ThinSeedWeights in thin_sizing.h), so flat parts give seeds to thin
  /// ones; 1: uniform, the paper.
  double thin_boost = 1.0;
  /// --spread-pool K: draw K x count points and keep the count of them farthest apart (farthest-point sampling,
  /// FarthestPointSubset in common/knn.h), so the seeds start evenly spaced and optimize-seeds' repulsion has
  /// less to do; 1: the paper's uniform draws. With thin_boost > 1, farthest apart in the thin parts' sizing.
  int spread_pool = 4;

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// Draws points uniformly in udf.Domain() (candidate i from the counter-based stream (seed, i), so the
/// result does not depend on the thread count) and keeps the first `count` with d < band_rel * diagonal
/// (all of them if band_rel = 0); projects each with x <- x - d(x) n(x) until d < proj_tol_rel * diagonal;
/// keeps the converged ones in draw order, without those within dedup_rel * diagonal of an earlier seed,
/// with their UDF value and gradient (rank 0: unknown until optimize-seeds). With thin_boost > 1 the draw is
/// ceil(thin_boost) x count and `count` of the converged ones are chosen, likelier where the part is thin;
/// with spread_pool > 1 it is spread_pool x count and the `count` farthest apart are chosen.
/// Throws NumericalError if no candidate falls in the band or none converged.
SeedCloud SampleSeeds(const Udf& udf, const SampleSeedsOptions& options, Monitor& monitor);

}  // namespace voroudf

#pragma once
// Stage 1 (DESIGN.md; paper Sec. 3, "Initialize N seeds"): seeds uniform in the domain box, projected
// onto the zero set of the UDF.
#include <cstddef>
#include <cstdint>

#include "common/monitor.h"
#include "common/udf.h"
#include "formats/seeds_io.h"

namespace voroudf {

struct SampleSeedsOptions {
  size_t count = 3000;          ///< seeds drawn before projection (--count)
  uint64_t seed = 0;            ///< RNG seed (--seed)
  double proj_tol_rel = 1e-5;   ///< converged once d(x) < proj_tol_rel * domain diagonal (--proj-tol-rel)
  int proj_max_iters = 50;      ///< projection steps before a seed is dropped (--proj-max-iters)

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// Draws `count` points uniformly in udf.Domain() (point i from the counter-based stream (seed, i), so the
/// result does not depend on the thread count), projects each with x <- x - d(x) n(x) until
/// d < proj_tol_rel * diagonal, and keeps the converged ones in draw order with their UDF value and
/// gradient (rank 0: unknown until optimize-seeds). Throws NumericalError if none converged.
SeedCloud SampleSeeds(const Udf& udf, const SampleSeedsOptions& options, Monitor& monitor);

}  // namespace voroudf

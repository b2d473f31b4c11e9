#pragma once
// Projection of points onto the zero set of a UDF, shared by sample-seeds, optimize-seeds and build-gvd.
#include <vector>

#include "common/monitor.h"
#include "common/udf.h"

namespace voroudf {

struct ProjectionOptions {
  double tolerance = 0.0;  ///< absolute: a point has converged once d(x) < tolerance
  int max_iterations = 50; ///< steps x <- x - d(x) n(x) before a point is given up
};

struct ProjectionResult {
  std::vector<char> converged;    ///< per point
  std::vector<double> distance;   ///< d at the final position
  std::vector<Vec3> gradient;     ///< n at the final position
  size_t num_converged = 0;
};

/// Moves every point by x <- x - d(x) n(x) until d(x) < tolerance (DESIGN.md, stage 1). An exact UDF needs
/// one step; sampled or learned fields need a few. Points whose gradient is zero, or that leave the domain
/// box by more than its diagonal, or that have not converged after max_iterations are marked unconverged
/// (their positions are left where the iteration stopped). Evaluations are batched over all active points.
/// \pre options.tolerance > 0
ProjectionResult ProjectToZeroSet(const Udf& udf, std::vector<Vec3>& points, const ProjectionOptions& options,
                                  Monitor& monitor);

}  // namespace voroudf

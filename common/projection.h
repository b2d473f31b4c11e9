#pragma once
// Projection of points onto the zero set of a UDF, shared by sample-seeds, optimize-seeds and build-gvd.
#include <vector>

#include "common/monitor.h"
#include "common/udf.h"

namespace voroudf {

struct ProjectionOptions {
  double tolerance = 0.0;  ///< absolute: a point has converged once d(x) < tolerance
  /// absolute: a point at the bottom of a kink of d whose value there is below this has converged too
  /// (0: only `tolerance` counts). Learned and sampled fields have such a floor instead of zeros.
  double floor_tolerance = 0.0;
  int max_iterations = 50; ///< steps x <- x - d(x) n(x) before a point is given up
};

struct ProjectionResult {
  std::vector<char> converged;    ///< per point
  std::vector<double> distance;   ///< d at the final position
  std::vector<Vec3> gradient;     ///< n at the final position
  size_t num_converged = 0;
  size_t num_at_floor = 0;        ///< of those, converged at a kink's bottom above `tolerance`
};

/// The stages' --proj-tol-rel, --proj-floor-rel and --proj-max-iters (relative to the domain diagonal) as
/// the absolute options for a domain of diagonal `diagonal`.
ProjectionOptions RelativeProjection(double diagonal, double tol_rel, double floor_rel, int max_iterations);

/// Throws UsageError naming the option unless tol_rel is in (0, 0.1), floor_rel in [0, 0.1) and
/// max_iterations at least 1.
void CheckRelativeProjection(double tol_rel, double floor_rel, int max_iterations);

/// --proj-floor-rel's help line, the same in every stage.
inline constexpr const char* kProjFloorRelHelp =
    "a kink's bottom with d below this x diagonal counts as on the zero set (learned/sampled fields' floor; 0: off)";

/// Moves every point by x <- x - d(x) n(x) until d(x) < tolerance (DESIGN.md, stage 1). An exact UDF needs
/// one step; sampled or learned fields need a few.
///
/// A field that does not reach zero (a learned UDF's positive floor, a grid's rounded kink, |d + e| with an
/// error e > 0) makes that step overshoot: the point lands on the far side, where the gradient is reversed,
/// and would oscillate. When a step reverses the gradient (n(x1) . n(x0) < 0) the point goes to the bottom
/// of the kink between x0 and x1 instead: for d(t) = e + |t - t0| along the step (unit slopes),
/// t0 = d0 - d1/2, i.e. x = x1 + (d1/2) n(x0), where d = e = d1/2. It has converged there when d(x) <
/// floor_tolerance. For an exact UDF the first step lands on the surface and this never applies.
///
/// Points whose gradient is zero, or that leave the domain box by more than its diagonal, or that have not
/// converged after max_iterations are marked unconverged (their positions are left where the iteration
/// stopped). Evaluations are batched over all active points.
/// \pre options.tolerance > 0
ProjectionResult ProjectToZeroSet(const Udf& udf, std::vector<Vec3>& points, const ProjectionOptions& options,
                                  Monitor& monitor);

}  // namespace voroudf

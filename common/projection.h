#pragma once
// Projection of points onto the zero set of a UDF, shared by sample-seeds, optimize-seeds and build-gvd.
#include <string>
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
  /// absolute: two zero sheets closer than this are one surface seen through a field error, and a point that
  /// converges on one of them moves to the ridge midway (MergeTwinSheets). 0: measured per call when
  /// twin_factor > 0, else off.
  double twin_within = 0.0;
  /// When twin_within is 0: twin_within = twin_factor x the 99th percentile of the floor values of the call's
  /// points, if at least kTwinMinFloorShare of the converged points converged at a floor (EstimateTwinWithin).
  /// 0: never merge.
  double twin_factor = 0.0;
};

struct ProjectionResult {
  std::vector<char> converged;    ///< per point
  std::vector<double> distance;   ///< d at the final position
  std::vector<Vec3> gradient;     ///< n at the final position
  size_t num_converged = 0;
  size_t num_at_floor = 0;        ///< of those, converged at a kink's bottom above `tolerance`
  double twin_within = 0.0;       ///< the twin separation used: given, measured from the floors, or 0 (none)
  size_t num_merged = 0;          ///< of the converged points, moved from a zero sheet to the ridge to its twin
};

/// The share of converged points at a floor from which the floors are taken for a measure of the field's error.
inline constexpr double kTwinMinFloorShare = 0.05;

/// The stages' --proj-tol-rel, --proj-floor-rel and --proj-max-iters (relative to the domain diagonal) as
/// the absolute options for a domain of diagonal `diagonal`.
ProjectionOptions RelativeProjection(double diagonal, double tol_rel, double floor_rel, int max_iterations);

/// Throws UsageError naming the option unless tol_rel is in (0, 0.1), floor_rel in [0, 0.1),
/// max_iterations at least 1 and twin_factor in [0, 10].
void CheckRelativeProjection(double tol_rel, double floor_rel, int max_iterations, double twin_factor = 0.0);

/// --proj-twin-factor's default and help line, the same in every stage.
inline constexpr double kProjTwinFactor = 2.5;
inline constexpr const char* kProjTwinFactorHelp =
    "zero sheets closer than this x the field's measured floor (99th percentile) are one surface: points go to "
    "the ridge between them (noisy fields; exact fields have no floor; 0: off)";

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
/// Then, when options.twin_within (given, or measured by EstimateTwinWithin) is positive, MergeTwinSheets.
/// \pre options.tolerance > 0
ProjectionResult ProjectToZeroSet(const Udf& udf, std::vector<Vec3>& points, const ProjectionOptions& options,
                                  Monitor& monitor);

/// The twin separation a field's floors imply: `factor` x the 99th percentile of the values at which points
/// converged at a kink's bottom, or 0 when fewer than kTwinMinFloorShare of the converged points (or fewer
/// than 16) did. Why the floors measure the twins: a field |d + e| with a smooth error e bottoms out at e where
/// e > 0 and has two zero sheets 2|e| apart where e < 0; for an error symmetric about 0 the separations are
/// distributed as twice the floors. An exact field has no floors and gets 0.
double EstimateTwinWithin(const ProjectionResult& result, double tolerance, double factor);

/// Where a field's zero set is a surface doubled by an error (|d + e| with e < 0: zeros at d = |e| either
/// side, a ridge of height |e| on the surface between them), moves each converged point that lies on a zero
/// sheet to the ridge: it probes x +- r u at r = within/4, within/2 and within (u: the unit gradient there);
/// a probe that has passed a twin sheet reads d < r cos 30° with its gradient within 60° of the probe's direction
/// (a single sheet reads about r, a sheet along the probe gives a gradient across it). From every such probe a
/// twin is found by projection (where the error varies along the normal the field rises slower than 1 on one
/// side, and a probe there passes although its projection comes back to the point's own sheet). Between a
/// point and its twin, t apart, the field rises from each sheet to a kink on the surface; the quarter points
/// measure the two slopes, and where both lie in [0.5, 1.5] (a ridge) the point moves to the ridge's top, where
/// the two lines meet: the surface itself when the error is linear along the line. The nearest such twin more
/// than 8 tolerances and less than `within` away wins. A point with no such twin still has its ridge where the
/// twins curve round an edge: along a line from the cylinder round a convex edge the field rises at 1 to the edge
/// and then falls slower than 0.5 (or stays level, along a face) towards a twin that may lie beyond `within`. So
/// where the near probe reads less than r cos 30° with the field's slope along the line in [-0.75, 0.3] there (a
/// fall at about 1 is a ridge between two sheets, left to the twin rule), the kink is where the rise from the
/// point (measured halfway to it, in [0.5, 1.5]) meets the line through the probe at that slope, and the point
/// moves to it when that is nearer than the probe (the slopes differing by at least 0.7) if the field there reads
/// that rise within 25 % (not a level stretch). Six evaluations per point probed, and a few more per candidate
/// twin or kink; `result` gets the new positions' values and gradients and counts them in num_merged. Sheets
/// closer than `within` that are really there (a wall thinner than the field's error) become one surface.
/// The stages' log line for a projection that merged twin sheets: "the field has a floor: ...", naming the
/// separation (absolute and x `diagonal`) and how many `what` (seeds, samples) moved.
std::string TwinSheetsSummary(const ProjectionResult& result, double diagonal, const std::string& what);

/// \pre within > 0
void MergeTwinSheets(const Udf& udf, std::vector<Vec3>& points, ProjectionResult& result, double tolerance,
                     double within);

}  // namespace voroudf

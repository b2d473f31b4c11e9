#include "common/projection.h"

#include <cmath>

#include "common/errors.h"

namespace voroudf {

ProjectionOptions RelativeProjection(double diagonal, double tol_rel, double floor_rel, int max_iterations) {
  ProjectionOptions options;
  options.tolerance = tol_rel * diagonal;
  options.floor_tolerance = floor_rel * diagonal;
  options.max_iterations = max_iterations;
  return options;
}

void CheckRelativeProjection(double tol_rel, double floor_rel, int max_iterations) {
  if (!(tol_rel > 0.0 && tol_rel < 0.1)) throw UsageError("--proj-tol-rel must be in (0, 0.1)");
  if (!(floor_rel >= 0.0 && floor_rel < 0.1)) throw UsageError("--proj-floor-rel must be in [0, 0.1)");
  if (max_iterations < 1) throw UsageError("--proj-max-iters must be at least 1");
}

ProjectionResult ProjectToZeroSet(const Udf& udf, std::vector<Vec3>& points, const ProjectionOptions& options,
                                  Monitor& monitor) {
  const size_t n = points.size();
  ProjectionResult result;
  result.converged.assign(n, 0);
  result.distance.assign(n, INFINITY);
  result.gradient.assign(n, Vec3::Zero());
  const Box domain = udf.Domain();
  const double escape = domain.Diagonal();

  std::vector<size_t> active(n);
  for (size_t i = 0; i < n; ++i) active[i] = i;
  // Per point: the gradient its last ordinary step followed (zero before the first), and whether the last
  // move went to a kink's bottom.
  std::vector<Vec3> stepped_along(n, Vec3::Zero());
  std::vector<char> at_kink(n, 0);
  std::vector<Vec3> batch;
  std::vector<double> d;
  std::vector<Vec3> g;
  // Iteration 0 only evaluates; iterations 1..max_iterations each take one step.
  for (int iter = 0; iter <= options.max_iterations && !active.empty(); ++iter) {
    batch.resize(active.size());
    for (size_t k = 0; k < active.size(); ++k) batch[k] = points[active[k]];
    udf.Evaluate(batch, d, g);
    std::vector<size_t> still;
    for (size_t k = 0; k < active.size(); ++k) {
      const size_t i = active[k];
      result.distance[i] = d[k];
      result.gradient[i] = g[k];
      if (d[k] < options.tolerance || (at_kink[i] && d[k] < options.floor_tolerance)) {
        result.converged[i] = 1;
        result.num_at_floor += d[k] >= options.tolerance;
        continue;
      }
      if (iter == options.max_iterations || !std::isfinite(d[k]) || g[k].squaredNorm() < 0.25) continue;
      if (!at_kink[i] && options.floor_tolerance > 0 && g[k].dot(stepped_along[i]) < 0) {
        points[i] += 0.5 * d[k] * stepped_along[i];  // back to the kink's bottom (see the header)
        at_kink[i] = 1;
      } else {
        points[i] -= d[k] * g[k];
        stepped_along[i] = g[k];
        at_kink[i] = 0;
      }
      if (!domain.Contains(points[i], escape)) continue;
      still.push_back(i);
    }
    active.swap(still);
    monitor.Debug("projection step " + std::to_string(iter) + ": " + std::to_string(active.size()) + " points moving");
  }
  for (char c : result.converged) result.num_converged += c ? 1 : 0;
  return result;
}

}  // namespace voroudf

#include "common/projection.h"

#include <cmath>

namespace voroudf {

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
      if (d[k] < options.tolerance) {
        result.converged[i] = 1;
        continue;
      }
      if (iter == options.max_iterations || !std::isfinite(d[k]) || g[k].squaredNorm() < 0.25) continue;
      points[i] -= d[k] * g[k];
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

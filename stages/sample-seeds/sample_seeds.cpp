#include "stages/sample-seeds/sample_seeds.h"

#include <cstdio>

#include "common/errors.h"
#include "common/projection.h"
#include "common/rng.h"

namespace voroudf {

void SampleSeedsOptions::Check() const {
  if (count == 0) throw UsageError("--count must be at least 1");
  if (count > 100000000) throw UsageError("--count must be at most 1e8");
  if (!(proj_tol_rel > 0.0 && proj_tol_rel < 0.1)) throw UsageError("--proj-tol-rel must be in (0, 0.1)");
  if (proj_max_iters < 1) throw UsageError("--proj-max-iters must be at least 1");
}

SeedCloud SampleSeeds(const Udf& udf, const SampleSeedsOptions& options, Monitor& monitor) {
  options.Check();
  const Box box = udf.Domain();
  monitor.Info("domain box [" + std::to_string(box.min.x()) + "," + std::to_string(box.min.y()) + "," +
               std::to_string(box.min.z()) + "] - [" + std::to_string(box.max.x()) + "," +
               std::to_string(box.max.y()) + "," + std::to_string(box.max.z()) + "], diagonal " +
               std::to_string(box.Diagonal()));
  std::vector<Vec3> points(options.count);
  for (size_t i = 0; i < options.count; ++i) {
    Rng rng(options.seed, i);
    for (int k = 0; k < 3; ++k) points[i][k] = rng.Uniform(box.min[k], box.max[k]);
  }
  ProjectionOptions proj;
  proj.tolerance = options.proj_tol_rel * box.Diagonal();
  proj.max_iterations = options.proj_max_iters;
  const ProjectionResult r = ProjectToZeroSet(udf, points, proj, monitor);

  SeedCloud seeds;
  seeds.Resize(r.num_converged);
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!r.converged[i]) continue;
    seeds.position[k] = points[i];
    seeds.normal[k] = r.gradient[i];
    seeds.udf[k] = r.distance[i];
    ++k;
  }
  const size_t dropped = points.size() - r.num_converged;
  char line[160];
  std::snprintf(line, sizeof line, "%zu of %zu seeds projected to d < %.3g; %zu dropped (not converged in %d steps)",
                r.num_converged, points.size(), proj.tolerance, dropped, proj.max_iterations);
  if (dropped > 0) monitor.Warn(line);
  else monitor.Info(line);
  if (r.num_converged == 0) throw NumericalError("no seed reached the surface of " + udf.Describe());
  return seeds;
}

}  // namespace voroudf

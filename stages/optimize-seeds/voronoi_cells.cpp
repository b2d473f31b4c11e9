#include "stages/optimize-seeds/voronoi_cells.h"

#include <algorithm>
#include <cmath>

#include "common/rng.h"

namespace voroudf {

CellSamples SampleVoronoiCells(const Udf& udf, const std::vector<Vec3>& seeds, const SeedIndex& index,
                               const CellSamplingOptions& options, uint64_t rng_seed, uint64_t round) {
  const size_t n = seeds.size();
  const size_t m_max = static_cast<size_t>(options.samples_per_cell);
  CellSamples cells;
  cells.radius.assign(n, 0.0);
  std::vector<std::vector<int>> neighbours(n);
  std::vector<Vec3> candidates(n * m_max);
  std::vector<size_t> accepted(n, 0);
  std::vector<uint64_t> draws(n, 0);

#pragma omp parallel
  {
    std::vector<int> knn, found;
    std::vector<Vec3> offsets;  // x_j − x_i of the cutting neighbours
    std::vector<double> half_sq;  // ‖x_j − x_i‖² / 2
#pragma omp for schedule(dynamic, 64)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      const Vec3& xi = seeds[i];
      index.Nearest(xi, options.radius_knn + 1, knn);
      double kth = 0.0;
      for (int j : knn) kth = std::max(kth, (seeds[static_cast<size_t>(j)] - xi).norm());
      const double r = options.radius_factor * kth;
      cells.radius[i] = r;
      // Slack on the search radius: PCL compares float distances.
      index.WithinRadius(xi, 2.0 * r * (1.0 + 1e-5) + 1e-12, found);
      offsets.clear();
      half_sq.clear();
      for (int j : found) {
        if (static_cast<size_t>(j) == i) continue;
        const Vec3 e = seeds[static_cast<size_t>(j)] - xi;
        if (e.squaredNorm() == 0.0) continue;  // a coincident seed shares the cell; it cuts nothing
        neighbours[i].push_back(j);
        offsets.push_back(e);
        half_sq.push_back(0.5 * e.squaredNorm());
      }
      if (r <= 0.0) continue;
      Rng rng(rng_seed, round * n + i);
      const uint64_t budget = m_max * static_cast<uint64_t>(options.max_draws_per_sample);
      size_t count = 0;
      uint64_t drawn = 0;
      while (count < m_max && drawn < budget) {
        ++drawn;
        // Uniform in the ball by rejection from its bounding cube (52 % kept; cheaper than trigonometry).
        const Vec3 q(rng.Uniform(-r, r), rng.Uniform(-r, r), rng.Uniform(-r, r));
        if (q.squaredNorm() > r * r) continue;
        // q is nearer x_i than x_j  ⇔  (x_j − x_i)ᵀq ≤ ‖x_j − x_i‖²/2; neighbours nearest first reject early.
        bool inside = true;
        for (size_t k = 0; k < offsets.size() && inside; ++k) inside = offsets[k].dot(q) <= half_sq[k];
        if (inside) candidates[i * m_max + count++] = xi + q;
      }
      accepted[i] = count;
      draws[i] = drawn;
    }
  }

  cells.neighbour_offset.assign(n + 1, 0);
  cells.sample_offset.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    cells.neighbour_offset[i + 1] = cells.neighbour_offset[i] + neighbours[i].size();
    cells.sample_offset[i + 1] = cells.sample_offset[i] + accepted[i];
    cells.draws += draws[i];
    if (accepted[i] < m_max) ++cells.short_cells;
  }
  cells.neighbour.reserve(cells.neighbour_offset[n]);
  cells.point.resize(cells.sample_offset[n]);
  for (size_t i = 0; i < n; ++i) {
    cells.neighbour.insert(cells.neighbour.end(), neighbours[i].begin(), neighbours[i].end());
    std::copy_n(candidates.begin() + static_cast<long>(i * m_max), accepted[i],
                cells.point.begin() + static_cast<long>(cells.sample_offset[i]));
  }
  udf.Evaluate(cells.point, cells.distance, cells.gradient);
  return cells;
}

}  // namespace voroudf

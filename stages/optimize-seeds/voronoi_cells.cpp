#include "stages/optimize-seeds/voronoi_cells.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "common/rng.h"
#include "stages/optimize-seeds/l1_tangent.h"

namespace voroudf {

namespace {

// The radius around x_i inside which any moved seed can change cell i: its cutting neighbours lie within
// 2R_i and its k-th nearest seed (which sets R_i) within R_i / radius_factor.
double InfluenceRadius(double r, const CellSamplingOptions& options) {
  return std::max(2.0, 1.0 / options.radius_factor) * r * (1.0 + 1e-5) + 1e-12;
}

}  // namespace

CellSamples SampleVoronoiCells(const Udf& udf, const std::vector<Vec3>& seeds, const SeedIndex& index,
                               const CellSamplingOptions& options, uint64_t rng_seed, uint64_t round,
                               const CellSamples* previous, const std::vector<Vec3>* previous_seeds) {
  const size_t n = seeds.size();
  const size_t m_max = static_cast<size_t>(options.samples_per_cell);
  CellSamples cells;
  cells.radius.assign(n, 0.0);
  std::vector<std::vector<int>> neighbours(n);
  std::vector<Vec3> candidates(n * m_max);
  std::vector<size_t> accepted(n, 0);
  std::vector<uint64_t> draws(n, 0);
  std::vector<char> short_draw(n, 0);  // the rejection budget ran out before M samples

  // Which cells must be redrawn: all, or (given the previous round) those with a moved seed within their
  // influence radius, before or after the move. Seeds appended since (indices at or above the previous
  // count) or removed from the end count as moved: appearing or vanishing changes a cell as a move does.
  std::vector<char> redo(n, 1);
  const bool incremental = previous && previous_seeds && previous->radius.size() == previous_seeds->size();
  if (incremental) {
    const size_t before = previous_seeds->size(), common = std::min(n, before);
    std::vector<char> moved(std::max(n, before), 1);
    for (size_t i = 0; i < common; ++i) moved[i] = seeds[i] != (*previous_seeds)[i];
#pragma omp parallel
    {
      std::vector<int> found;
#pragma omp for schedule(dynamic, 64)
      for (long li = 0; li < static_cast<long>(n); ++li) {
        const size_t i = static_cast<size_t>(li);
        if (moved[i]) continue;
        bool dirty = options.early_samples == 0 && !previous->early_kept.empty() && previous->early_kept[i];
        for (size_t k = previous->neighbour_offset[i]; k < previous->neighbour_offset[i + 1] && !dirty; ++k)
          dirty = moved[static_cast<size_t>(previous->neighbour[k])];
        if (!dirty) {
          index.WithinRadius(seeds[i], InfluenceRadius(previous->radius[i], options), found);
          for (int j : found) dirty = dirty || moved[static_cast<size_t>(j)];
        }
        redo[i] = dirty;
      }
    }
  }

  // With a pool, the cells' shapes are collected here and their samples chosen from it afterwards.
  std::vector<SamplePool::Cell> shapes(options.pool ? n : 0);
#pragma omp parallel
  {
    std::vector<int> knn, found;
    std::vector<Vec3> offsets;  // x_j − x_i of the cutting neighbours
    std::vector<double> half_sq;  // ‖x_j − x_i‖² / 2
#pragma omp for schedule(dynamic, 64)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      if (!redo[i]) {
        cells.radius[i] = previous->radius[i];
        neighbours[i].assign(previous->neighbour.begin() + static_cast<long>(previous->neighbour_offset[i]),
                             previous->neighbour.begin() + static_cast<long>(previous->neighbour_offset[i + 1]));
        continue;
      }
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
      if (options.pool) {
        shapes[i] = {xi, r, offsets, half_sq};
        continue;
      }
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
      short_draw[i] = count < m_max;
    }
  }

  std::vector<std::vector<SamplePool::PointId>> chosen;
  if (options.pool) {
    std::vector<uint64_t> examined;
    if (incremental && previous->pool_mark.size() == n) cells.pool_mark = previous->pool_mark;
    chosen = options.pool->Select(shapes, redo, m_max, static_cast<double>(m_max) * options.max_draws_per_sample,
                                  cells.pool_mark, &examined, static_cast<int>(round % static_cast<uint64_t>(options.pool->layers())));
    // In parallel: the pool's points lie far apart in memory, and one thread would wait on each.
#pragma omp parallel for schedule(static)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      if (!redo[i]) continue;
      accepted[i] = chosen[i].size();
      draws[i] = std::max<uint64_t>(examined[i], accepted[i]);
      short_draw[i] = accepted[i] < m_max;
      for (size_t k = 0; k < accepted[i]; ++k) candidates[i * m_max + k] = options.pool->Point(chosen[i][k]);
    }
  }

  // The UDF at the redrawn cells' candidates, in up to two batches: first the first `early_samples` of
  // each cell; a cell whose first samples already show one tangent plane clearly (rank 1 at the stricter
  // threshold early_rank_threshold) keeps just those, the others get the rest in the second batch.
  cells.early_kept.assign(n, 0);
  for (size_t i = 0; i < n; ++i)
    if (!redo[i] && !previous->early_kept.empty()) cells.early_kept[i] = previous->early_kept[i];
  std::vector<double> cand_d(n * m_max, 0.0);
  std::vector<Vec3> cand_g(n * m_max, Vec3::Zero());
  const size_t early = options.early_samples > 0 ? std::min(m_max, static_cast<size_t>(options.early_samples)) : m_max;
  auto evaluate = [&](size_t from, const std::function<bool(size_t)>& wanted) {
    std::vector<size_t> at;
    for (size_t i = 0; i < n; ++i)
      if (redo[i] && wanted(i))
        for (size_t k = from; k < std::min(accepted[i], from == 0 ? early : m_max); ++k) at.push_back(i * m_max + k);
    if (options.pool) {
      std::vector<SamplePool::PointId> ids(at.size());
      for (size_t k = 0; k < at.size(); ++k) ids[k] = chosen[at[k] / m_max][at[k] % m_max];
      cells.reused += at.size() - options.pool->Evaluate(udf, ids);
#pragma omp parallel for schedule(static)
      for (long k = 0; k < static_cast<long>(at.size()); ++k) {
        cand_d[at[static_cast<size_t>(k)]] = options.pool->Distance(ids[static_cast<size_t>(k)]);
        cand_g[at[static_cast<size_t>(k)]] = options.pool->Gradient(ids[static_cast<size_t>(k)]);
      }
      return;
    }
    std::vector<Vec3> points(at.size());
    for (size_t k = 0; k < at.size(); ++k) points[k] = candidates[at[k]];
    std::vector<double> d;
    std::vector<Vec3> g;
    udf.Evaluate(points, d, g);
    for (size_t k = 0; k < at.size(); ++k) {
      cand_d[at[k]] = d[k];
      cand_g[at[k]] = g[k];
    }
  };
  evaluate(0, [](size_t) { return true; });
  if (early < m_max) {
    std::vector<char> more(n, 0);
    for (size_t i = 0; i < n; ++i) {
      if (!redo[i] || accepted[i] <= early) continue;
      if (options.early_allowed && !(*options.early_allowed)[i]) {
        more[i] = 1;
        continue;
      }
      const TangentRank r = ComputeTangentRank(cand_g.data() + i * m_max, early, options.early_rank_threshold);
      if (r.rank == 1) {
        accepted[i] = early;
        cells.early_kept[i] = 1;
        ++cells.early_cells;
      } else {
        more[i] = 1;
      }
    }
    evaluate(early, [&](size_t i) { return more[i] != 0; });
  }

  // Assemble.
  cells.neighbour_offset.assign(n + 1, 0);
  cells.sample_offset.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const size_t count = redo[i] ? accepted[i] : previous->sample_offset[i + 1] - previous->sample_offset[i];
    cells.neighbour_offset[i + 1] = cells.neighbour_offset[i] + neighbours[i].size();
    cells.sample_offset[i + 1] = cells.sample_offset[i] + count;
    if (redo[i]) {
      cells.draws += draws[i];
      cells.drawn_samples += accepted[i];
      ++cells.redrawn;
    }
    if (redo[i] && short_draw[i]) ++cells.short_cells;
  }
  cells.neighbour.reserve(cells.neighbour_offset[n]);
  cells.point.resize(cells.sample_offset[n]);
  cells.distance.resize(cells.sample_offset[n]);
  cells.gradient.resize(cells.sample_offset[n]);
  for (size_t i = 0; i < n; ++i) {
    cells.neighbour.insert(cells.neighbour.end(), neighbours[i].begin(), neighbours[i].end());
    const long to = static_cast<long>(cells.sample_offset[i]);
    if (redo[i]) {
      const long from = static_cast<long>(i * m_max), count = static_cast<long>(accepted[i]);
      std::copy_n(candidates.begin() + from, count, cells.point.begin() + to);
      std::copy_n(cand_d.begin() + from, count, cells.distance.begin() + to);
      std::copy_n(cand_g.begin() + from, count, cells.gradient.begin() + to);
    } else {
      const long from = static_cast<long>(previous->sample_offset[i]);
      const long count = static_cast<long>(previous->sample_offset[i + 1]) - from;
      std::copy_n(previous->point.begin() + from, count, cells.point.begin() + to);
      std::copy_n(previous->distance.begin() + from, count, cells.distance.begin() + to);
      std::copy_n(previous->gradient.begin() + from, count, cells.gradient.begin() + to);
    }
  }
  return cells;
}

}  // namespace voroudf

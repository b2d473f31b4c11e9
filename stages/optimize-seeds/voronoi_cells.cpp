#include "stages/optimize-seeds/voronoi_cells.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <tuple>

#include "common/rng.h"
#include "stages/optimize-seeds/l1_tangent.h"

namespace voroudf {

namespace {

// The radius around x_i inside which any moved seed can change cell i: its cutting neighbours lie within
// 2R_i and its k-th nearest seed (which sets R_i) within R_i / radius_factor.
double InfluenceRadius(double r, const CellSamplingOptions& options) {
  return std::max(2.0, 1.0 / options.radius_factor) * r * (1.0 + 1e-5) + 1e-12;
}

// `v` resized for arrays whose every slot is about to be written. Growing past its capacity, it is released
// first (its contents would only be copied to be overwritten) and reserved with room for the next calls'
// slightly larger sizes (the feature steps alternate between the seeds and the seeds with trials).
template <typename T>
void ResizeForOverwrite(std::vector<T>& v, size_t size) {
  if (size > v.capacity()) {
    std::vector<T>().swap(v);
    v.reserve(size + size / 8);
  }
  v.resize(size);
}

// The neighbour and sample arrays sized by the offsets already set.
void SizeToOffsets(CellSamples& cells) {
  ResizeForOverwrite(cells.neighbour, cells.neighbour_offset.back());
  ResizeForOverwrite(cells.point, cells.sample_offset.back());
  ResizeForOverwrite(cells.distance, cells.sample_offset.back());
  ResizeForOverwrite(cells.gradient, cells.sample_offset.back());
}

// A spent result's arrays for a new one (its memory is reused): the sample and neighbour arrays keep their
// size, since their fillers write every slot; the per-cell arrays and the counts start afresh.
CellSamples Recycled(CellSamples& spare) {
  CellSamples cells = std::move(spare);
  spare = CellSamples{};
  cells.draws = cells.drawn_samples = 0;
  cells.short_cells = cells.redrawn = cells.early_cells = cells.reused = 0;
  cells.radius.clear();
  cells.neighbour_offset.clear();
  cells.sample_offset.clear();
  cells.pool_mark.clear();
  cells.early_kept.clear();
  return cells;
}

// Cell i's samples of `from` into `to` from sample `at` on (to's arrays already sized).
void CopyCellSamples(const CellSamples& from, size_t i, CellSamples& to, size_t at) {
  const long begin = static_cast<long>(from.sample_offset[i]);
  const long count = static_cast<long>(from.sample_offset[i + 1]) - begin;
  const long to_begin = static_cast<long>(at);
  std::copy_n(from.point.begin() + begin, count, to.point.begin() + to_begin);
  std::copy_n(from.distance.begin() + begin, count, to.distance.begin() + to_begin);
  std::copy_n(from.gradient.begin() + begin, count, to.gradient.begin() + to_begin);
}

// A call's working state: per cell, its neighbours and its samples: the pool's choice when there is one,
// else candidates drawn afresh (M slots each, `accepted` used) with their UDF values.
struct Draft {
  size_t n = 0, m_max = 0;
  std::vector<char> redo;  // the cell is sampled in this call (else kept from the previous one)
  std::vector<std::vector<int>> neighbours;
  std::vector<size_t> accepted;
  std::vector<uint64_t> draws;
  std::vector<char> short_draw;  // the rejection budget ran out before M samples
  std::vector<SamplePool::Cell> shapes;  // with a pool: the cells' shapes, their samples chosen afterwards
  std::vector<std::vector<SamplePool::PointId>> chosen;
  // Without a pool, M slots per cell (the caller's buffers, kept from call to call): only the accepted slots
  // are written (in parallel) and read.
  Vec3* candidates = nullptr;
  double* cand_d = nullptr;
  Vec3* cand_g = nullptr;
};

// Which cells must be redrawn: all, or (given the previous round) those with a moved seed within their
// influence radius, before or after the move. Seeds appended since (indices at or above the previous
// count) or removed from the end count as moved: appearing or vanishing changes a cell as a move does.
std::vector<char> CellsToRedraw(const std::vector<Vec3>& seeds, const SeedIndex& index,
                                const CellSamplingOptions& options, const CellSamples* previous,
                                const std::vector<Vec3>* previous_seeds) {
  const size_t n = seeds.size();
  std::vector<char> redo(n, 1);
  if (!previous) return redo;
  const size_t before = previous_seeds->size(), common = std::min(n, before);
  std::vector<char> moved(std::max(n, before), 1);
  for (size_t i = 0; i < common; ++i) moved[i] = seeds[i] != (*previous_seeds)[i];
#pragma omp parallel
  {
    std::vector<int> found;
#pragma omp for schedule(dynamic, 64)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      if (moved[i] || !(previous->radius[i] > 0.0)) continue;  // radius 0: no cell carried (CarryCells)
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
  return redo;
}

// Each redrawn cell's radius and cutting neighbours; without a pool its samples, by rejection from the
// ball's bounding cube; with one its shape, for SamplePool::Select. Kept cells take the previous ones.
void DrawCells(const std::vector<Vec3>& seeds, const SeedIndex& index, const CellSamplingOptions& options,
               uint64_t rng_seed, uint64_t round, const CellSamples* previous, CellSamples& cells, Draft& w) {
  const size_t n = w.n, m_max = w.m_max;
#pragma omp parallel
  {
    std::vector<int> knn, found;
    std::vector<Vec3> offsets;  // x_j − x_i of the cutting neighbours
    std::vector<double> half_sq;  // ‖x_j − x_i‖² / 2
#pragma omp for schedule(dynamic, 64)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      if (!w.redo[i]) {
        cells.radius[i] = previous->radius[i];
        w.neighbours[i].assign(previous->neighbour.begin() + static_cast<long>(previous->neighbour_offset[i]),
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
        w.neighbours[i].push_back(j);
        offsets.push_back(e);
        half_sq.push_back(0.5 * e.squaredNorm());
      }
      if (r <= 0.0) continue;
      if (options.pool) {
        w.shapes[i] = {xi, r, offsets, half_sq};
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
        if (inside) w.candidates[i * m_max + count++] = xi + q;
      }
      w.accepted[i] = count;
      w.draws[i] = drawn;
      w.short_draw[i] = count < m_max;
    }
  }
}

// With a pool: each redrawn cell's M lowest-mark pool points as its candidates.
void ChooseFromPool(const CellSamplingOptions& options, uint64_t round, bool incremental, const CellSamples* previous,
                    CellSamples& cells, Draft& w) {
  std::vector<uint64_t> examined;
  if (incremental && previous->pool_mark.size() == w.n) cells.pool_mark = previous->pool_mark;
  w.chosen = options.pool->Select(w.shapes, w.redo, w.m_max, static_cast<double>(w.m_max) * options.max_draws_per_sample,
                                  cells.pool_mark, &examined,
                                  static_cast<int>(round % static_cast<uint64_t>(options.pool->layers())));
  // In parallel: the pool's points lie far apart in memory, and one thread would wait on each.
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(w.n); ++li) {
    const size_t i = static_cast<size_t>(li);
    if (!w.redo[i]) continue;
    w.accepted[i] = w.chosen[i].size();
    w.draws[i] = std::max<uint64_t>(examined[i], w.accepted[i]);
    w.short_draw[i] = w.accepted[i] < w.m_max;
  }
}

// The UDF at candidates [from, to) of the cells `wanted` (from the pool's values where it has them).
void EvaluateCandidates(const Udf& udf, const CellSamplingOptions& options, size_t from, size_t to,
                        const std::function<bool(size_t)>& wanted, CellSamples& cells, Draft& w) {
  // Which candidates, cell by cell: counted, then listed in parallel (on one thread this was a tenth of
  // optimize-seeds' serial time).
  std::vector<size_t> first(w.n + 1, 0);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(w.n); ++li) {
    const size_t i = static_cast<size_t>(li), end = std::min(w.accepted[i], to);
    first[i + 1] = w.redo[i] && wanted(i) && end > from ? end - from : 0;
  }
  for (size_t i = 0; i < w.n; ++i) first[i + 1] += first[i];
  // With a pool the values stay in the pool, where Assemble reads them.
  std::vector<size_t> at(options.pool ? 0 : first[w.n]);
  std::vector<SamplePool::PointId> ids(options.pool ? first[w.n] : 0);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(w.n); ++li) {
    const size_t i = static_cast<size_t>(li);
    for (size_t k = 0; k < first[i + 1] - first[i]; ++k) {
      if (options.pool)
        ids[first[i] + k] = w.chosen[i][from + k];
      else
        at[first[i] + k] = i * w.m_max + from + k;
    }
  }
  if (options.pool) {
    cells.reused += ids.size() - options.pool->Evaluate(udf, ids);
    return;
  }
  std::vector<Vec3> points(at.size());
  for (size_t k = 0; k < at.size(); ++k) points[k] = w.candidates[at[k]];
  std::vector<double> d;
  std::vector<Vec3> g;
  udf.Evaluate(points, d, g);
  for (size_t k = 0; k < at.size(); ++k) {
    w.cand_d[at[k]] = d[k];
    w.cand_g[at[k]] = g[k];
  }
}

// The UDF at the redrawn cells' candidates, in up to two batches: first the first `early_samples` of
// each cell; a cell whose first samples already show one tangent plane clearly (rank 1 at the stricter
// threshold early_rank_threshold) keeps just those, the others get the rest in the second batch.
void EvaluateCells(const Udf& udf, const CellSamplingOptions& options, const CellSamples* previous, CellSamples& cells,
                   Draft& w) {
  const size_t n = w.n, m_max = w.m_max;
  cells.early_kept.assign(n, 0);
  for (size_t i = 0; i < n; ++i)
    if (!w.redo[i] && !previous->early_kept.empty()) cells.early_kept[i] = previous->early_kept[i];
  const size_t early = options.early_samples > 0 ? std::min(m_max, static_cast<size_t>(options.early_samples)) : m_max;
  EvaluateCandidates(udf, options, 0, early, [](size_t) { return true; }, cells, w);
  if (early == m_max) return;
  std::vector<char> more(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!w.redo[i] || w.accepted[i] <= early) continue;
    if (options.early_allowed && !(*options.early_allowed)[i]) {
      more[i] = 1;
      continue;
    }
    std::vector<Vec3> from_pool;
    if (options.pool)
      for (size_t k = 0; k < early; ++k) from_pool.push_back(options.pool->Gradient(w.chosen[i][k]));
    const TangentRank r = ComputeTangentRank(options.pool ? from_pool.data() : w.cand_g + i * m_max, early,
                                             options.early_rank_threshold);
    if (r.rank == 1) {
      w.accepted[i] = early;
      cells.early_kept[i] = 1;
      ++cells.early_cells;
    } else {
      more[i] = 1;
    }
  }
  EvaluateCandidates(udf, options, early, m_max, [&](size_t i) { return more[i] != 0; }, cells, w);
}

// The result in CSR form: the redrawn cells' samples, the kept cells' previous ones.
void Assemble(const CellSamples* previous, const Draft& w, const SamplePool* pool, CellSamples& cells) {
  const size_t n = w.n, m_max = w.m_max;
  cells.neighbour_offset.assign(n + 1, 0);
  cells.sample_offset.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const size_t count = w.redo[i] ? w.accepted[i] : previous->sample_offset[i + 1] - previous->sample_offset[i];
    cells.neighbour_offset[i + 1] = cells.neighbour_offset[i] + w.neighbours[i].size();
    cells.sample_offset[i + 1] = cells.sample_offset[i] + count;
    if (w.redo[i]) {
      cells.draws += w.draws[i];
      cells.drawn_samples += w.accepted[i];
      ++cells.redrawn;
    }
    if (w.redo[i] && w.short_draw[i]) ++cells.short_cells;
  }
  SizeToOffsets(cells);
  // In parallel: megabytes of samples, and the fresh pages they land on, would otherwise wait on one thread.
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(n); ++li) {
    const size_t i = static_cast<size_t>(li);
    std::copy(w.neighbours[i].begin(), w.neighbours[i].end(), cells.neighbour.begin() + static_cast<long>(cells.neighbour_offset[i]));
    const long to = static_cast<long>(cells.sample_offset[i]);
    if (w.redo[i] && pool) {
      for (size_t k = 0; k < w.accepted[i]; ++k) {
        const size_t at = static_cast<size_t>(to) + k;
        pool->Sample(w.chosen[i][k], &cells.point[at], &cells.distance[at], &cells.gradient[at]);
      }
    } else if (w.redo[i]) {
      const long from = static_cast<long>(i * m_max), count = static_cast<long>(w.accepted[i]);
      std::copy_n(w.candidates + from, count, cells.point.begin() + to);
      std::copy_n(w.cand_d + from, count, cells.distance.begin() + to);
      std::copy_n(w.cand_g + from, count, cells.gradient.begin() + to);
    } else {
      CopyCellSamples(*previous, i, cells, cells.sample_offset[i]);
    }
  }
}

}  // namespace

CellSamples SampleVoronoiCells(const Udf& udf, const std::vector<Vec3>& seeds, const SeedIndex& index,
                               const CellSamplingOptions& options, uint64_t rng_seed, uint64_t round,
                               const CellSamples* previous, const std::vector<Vec3>* previous_seeds,
                               CellSamplingBuffers* buffers) {
  CellSamplingBuffers local;
  CellSamplingBuffers& buf = buffers ? *buffers : local;
  Draft w;
  w.n = seeds.size();
  w.m_max = static_cast<size_t>(options.samples_per_cell);
  const bool incremental = previous && previous_seeds && previous->radius.size() == previous_seeds->size();
  w.redo = CellsToRedraw(seeds, index, options, incremental ? previous : nullptr, previous_seeds);
  w.neighbours.resize(w.n);
  // Without a pool, M slots per cell; resized, not cleared: a buffer of last call's size is not written over
  // twice (every slot that is read is written in this call). A pool's points and values are read from it.
  const size_t slots = options.pool ? 0 : w.n * w.m_max;
  ResizeForOverwrite(buf.candidate, slots);
  ResizeForOverwrite(buf.candidate_distance, slots);
  ResizeForOverwrite(buf.candidate_gradient, slots);
  w.candidates = buf.candidate.data();
  w.cand_d = buf.candidate_distance.data();
  w.cand_g = buf.candidate_gradient.data();
  w.accepted.assign(w.n, 0);
  w.draws.assign(w.n, 0);
  w.short_draw.assign(w.n, 0);
  w.shapes.resize(options.pool ? w.n : 0);
  CellSamples cells = Recycled(buf.spare);
  cells.radius.assign(w.n, 0.0);
  DrawCells(seeds, index, options, rng_seed, round, previous, cells, w);
  if (options.pool) ChooseFromPool(options, round, incremental, previous, cells, w);
  EvaluateCells(udf, options, previous, cells, w);
  Assemble(previous, w, options.pool, cells);
  return cells;
}

void CarryCells(const std::vector<Vec3>& seeds, const CellSamplingOptions& options, CellSamples& previous,
                std::vector<Vec3>& previous_seeds, CellSamples* spare) {
  const size_t n = seeds.size(), before = previous_seeds.size();
  // Previous seeds by exact position (ties by index), to find each seed's earlier self.
  std::vector<size_t> order(before);
  std::iota(order.begin(), order.end(), size_t{0});
  const auto key = [&](size_t k) { return std::tie(previous_seeds[k].x(), previous_seeds[k].y(), previous_seeds[k].z()); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return std::make_pair(key(a), a) < std::make_pair(key(b), b); });
  std::vector<long> old_of(n, -1), new_of(before, -1);
  for (size_t i = 0; i < n; ++i) {
    const auto at = std::tie(seeds[i].x(), seeds[i].y(), seeds[i].z());
    auto it = std::lower_bound(order.begin(), order.end(), at, [&](size_t k, const auto& v) { return key(k) < v; });
    for (; it != order.end() && key(*it) == at; ++it) {
      if (new_of[*it] >= 0) continue;
      new_of[*it] = static_cast<long>(i);
      old_of[i] = static_cast<long>(*it);
      break;
    }
  }
  std::vector<Vec3> gone;
  for (size_t k = 0; k < before; ++k)
    if (new_of[k] < 0) gone.push_back(previous_seeds[k]);
  const std::unique_ptr<SeedIndex> gone_index = gone.empty() ? nullptr : std::make_unique<SeedIndex>(gone);
  const bool marks = previous.pool_mark.size() == before, early = previous.early_kept.size() == before;
  CellSamples unused;
  CellSamples carried = Recycled(spare ? *spare : unused);
  carried.radius.assign(n, 0.0);
  carried.neighbour_offset.assign(n + 1, 0);
  carried.sample_offset.assign(n + 1, 0);
  if (marks) carried.pool_mark.assign(n, 0.0);
  if (early) carried.early_kept.assign(n, 0);
  std::vector<Vec3> carried_seeds(n, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
  // Which cells stay (in parallel), then their offsets, then their samples copied (in parallel): the copy is
  // megabytes, which one thread made everyone wait for.
  std::vector<char> kept(n, 0);
#pragma omp parallel
  {
    std::vector<int> found;
#pragma omp for schedule(dynamic, 64)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t i = static_cast<size_t>(li);
      if (old_of[i] < 0) continue;  // moved or new: NaN, no cell
      const size_t ku = static_cast<size_t>(old_of[i]);
      carried_seeds[i] = seeds[i];  // not moved, so the cells it cuts stay
      bool keep = true;
      for (size_t m = previous.neighbour_offset[ku]; keep && m < previous.neighbour_offset[ku + 1]; ++m)
        keep = new_of[static_cast<size_t>(previous.neighbour[m])] >= 0;
      if (keep && gone_index) {
        gone_index->WithinRadius(seeds[i], InfluenceRadius(previous.radius[ku], options), found);
        keep = found.empty();
      }
      kept[i] = keep;  // else radius 0: its own cell is redrawn
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t ku = kept[i] ? static_cast<size_t>(old_of[i]) : 0;
    carried.neighbour_offset[i + 1] = carried.neighbour_offset[i] +
        (kept[i] ? previous.neighbour_offset[ku + 1] - previous.neighbour_offset[ku] : 0);
    carried.sample_offset[i + 1] = carried.sample_offset[i] +
        (kept[i] ? previous.sample_offset[ku + 1] - previous.sample_offset[ku] : 0);
  }
  SizeToOffsets(carried);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(n); ++li) {
    const size_t i = static_cast<size_t>(li);
    if (!kept[i]) continue;
    const size_t ku = static_cast<size_t>(old_of[i]);
    carried.radius[i] = previous.radius[ku];
    if (marks) carried.pool_mark[i] = previous.pool_mark[ku];
    if (early) carried.early_kept[i] = previous.early_kept[ku];
    size_t to = carried.neighbour_offset[i];
    for (size_t m = previous.neighbour_offset[ku]; m < previous.neighbour_offset[ku + 1]; ++m)
      carried.neighbour[to++] = static_cast<int>(new_of[static_cast<size_t>(previous.neighbour[m])]);
    CopyCellSamples(previous, ku, carried, carried.sample_offset[i]);
  }
  if (spare) *spare = std::move(previous);
  previous = std::move(carried);
  previous_seeds = std::move(carried_seeds);
}

}  // namespace voroudf

#include "common/knn.h"

#include <flann/flann.hpp>
#include <omp.h>

#include <algorithm>
#include <memory>
#include <numeric>
#include <queue>

#include "common/errors.h"
#include "common/morton.h"

namespace voroudf {
namespace {

// flann::Matrix only points at memory it does not own: the rows live as long as the index. Scalar: double
// for evaluate's distances; float for the kNN graphs, whose queries wait on memory (half the bytes per point;
// coordinates in a unit box keep 7 digits, far below any sample spacing).
template <typename Scalar>
struct KdTree {
  using Index = flann::Index<flann::L2_Simple<Scalar>>;
  std::vector<Scalar> rows;
  std::unique_ptr<Index> index;

  KdTree(const std::vector<Vec3>& points, int leaf_size) : rows(3 * points.size()) {
    for (size_t i = 0; i < points.size(); ++i)
      for (int k = 0; k < 3; ++k) rows[3 * i + static_cast<size_t>(k)] = static_cast<Scalar>(points[i][k]);
    // A single kd-tree with exact search: randomised forests would make results depend on rand().
    index = std::make_unique<Index>(flann::Matrix<Scalar>(rows.data(), points.size(), 3),
                                    flann::KDTreeSingleIndexParams(leaf_size));
    index->buildIndex();
  }
};

flann::SearchParams ExactSearch() {
  flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED, 0.0f, true);
  params.cores = omp_get_max_threads();
  return params;
}

}  // namespace

std::vector<int> KNearestAmong(const std::vector<Vec3>& points, int k, int* k_out, Monitor& monitor,
                               const std::string& task_name) {
  const size_t n = points.size();
  const int kk = static_cast<int>(std::min<size_t>(static_cast<size_t>(std::max(k, 0)), n > 0 ? n - 1 : 0));
  *k_out = kk;
  std::vector<int> result(n * static_cast<size_t>(kk), -1);
  if (kk == 0) return result;
  const KdTree<float> tree(points, 12);
  // Blocks bound the memory of FLANN's result matrices; k + 1 because every point finds itself.
  const size_t block = 32768;
  const int kq = kk + 1;
  std::vector<size_t> idx(block * static_cast<size_t>(kq));
  std::vector<float> dist(block * static_cast<size_t>(kq));
  const flann::SearchParams params = ExactSearch();
  Task task(monitor, task_name, n);
  for (size_t begin = 0; begin < n; begin += block) {
    const size_t m = std::min(block, n - begin);
    flann::Matrix<float> queries(const_cast<float*>(tree.rows.data()) + 3 * begin, m, 3);
    flann::Matrix<size_t> mi(idx.data(), m, static_cast<size_t>(kq));
    flann::Matrix<float> md(dist.data(), m, static_cast<size_t>(kq));
    tree.index->knnSearch(queries, mi, md, static_cast<size_t>(kq), params);
#pragma omp parallel for schedule(static)
    for (long lq = 0; lq < static_cast<long>(m); ++lq) {
      const size_t q = static_cast<size_t>(lq), self = begin + q;
      int filled = 0;
      for (int j = 0; j < kq && filled < kk; ++j) {
        const size_t other = mi[q][static_cast<size_t>(j)];
        if (other == self || other >= n) continue;
        result[self * static_cast<size_t>(kk) + static_cast<size_t>(filled++)] = static_cast<int>(other);
      }
    }
    task.Advance(m);
  }
  return result;
}

std::vector<int> NearestIndices(const std::vector<Vec3>& data, const std::vector<Vec3>& queries, Monitor& monitor) {
  if (data.empty()) throw Error("NearestIndices: no data point");
  std::vector<int> nearest(queries.size(), -1);
  if (queries.empty()) return nearest;
  const KdTree<double> tree(data, 10);
  flann::SearchParams params = ExactSearch();
  params.sorted = false;
  const std::vector<size_t> order = MortonOrder(queries, BoundingBox(queries));
  const size_t block = 16384;
  std::vector<double> q(3 * block);
  std::vector<int> index(block);
  std::vector<double> dist2(block);
  for (size_t begin = 0; begin < queries.size(); begin += block) {
    const size_t end = std::min(queries.size(), begin + block);
    for (size_t i = begin; i < end; ++i)
      for (int k = 0; k < 3; ++k) q[3 * (i - begin) + static_cast<size_t>(k)] = queries[order[i]][k];
    flann::Matrix<double> qm(q.data(), end - begin, 3);
    flann::Matrix<int> im(index.data(), end - begin, 1);
    flann::Matrix<double> dm(dist2.data(), end - begin, 1);
    tree.index->knnSearch(qm, im, dm, 1, params);
    for (size_t i = begin; i < end; ++i) nearest[order[i]] = index[i - begin];
    monitor.Advance(end - begin);
  }
  return nearest;
}

std::vector<size_t> FarthestPointSubset(const std::vector<Vec3>& points, size_t count, double* covering_radius,
                                        const std::vector<double>* spacing) {
  const size_t n = points.size();
  // Keys are squared distances in the sizing metric, d² / spacing²; spacing <= 1 makes a key no smaller
  // than the raw squared distance, so the radius search below (raw distances up to the largest key) still
  // reaches every point a new taken point can come nearer to.
  const auto inv2 = [&](size_t i) { return spacing ? 1.0 / ((*spacing)[i] * (*spacing)[i]) : 1.0; };
  if (covering_radius) *covering_radius = 0.0;
  std::vector<size_t> taken;
  if (count >= n) {
    taken.resize(n);
    std::iota(taken.begin(), taken.end(), size_t{0});
    return taken;
  }
  if (count == 0) return taken;
  // FLANN has no incremental farthest-point query; the greedy loop is written here on its radius search.
  // d2[i]: squared distance from point i to the nearest taken point. A max-heap with lazy deletion holds
  // (d2, i) entries; an entry whose value is no longer d2[i] is stale and skipped.
  std::vector<double> d2(n);
  for (size_t i = 0; i < n; ++i) d2[i] = (points[i] - points[0]).squaredNorm() * inv2(i);
  using Entry = std::pair<double, size_t>;
  const auto lower = [](const Entry& a, const Entry& b) {  // larger distance first, then the lower index
    return a.first < b.first || (a.first == b.first && a.second > b.second);
  };
  std::vector<Entry> entries;  // every point but the first, which is taken
  for (size_t i = 1; i < n; ++i) entries.emplace_back(d2[i], i);
  std::priority_queue<Entry, std::vector<Entry>, decltype(lower)> heap(lower, std::move(entries));
  const KdTree<double> tree(points, 10);
  flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED, 0.0f, false);
  params.cores = 1;
  std::vector<std::vector<size_t>> found(1);
  std::vector<std::vector<double>> found_d2(1);
  taken.push_back(0);
  double last = 0.0;
  while (taken.size() < count && !heap.empty()) {
    const auto [d, i] = heap.top();
    heap.pop();
    if (d != d2[i]) continue;  // stale
    taken.push_back(i);
    last = d;
    d2[i] = 0.0;
    // Only points nearer to i than to every taken point change, and all of them lie within sqrt(d) of i:
    // d is the largest d2 left.
    Vec3 q = points[i];
    flann::Matrix<double> qm(q.data(), 1, 3);
    // FLANN takes the squared radius as a float: widened, so that rounding never drops a point.
    tree.index->radiusSearch(qm, found, found_d2, static_cast<float>(d * (1.0 + 1e-5)), params);
    for (size_t k = 0; k < found[0].size(); ++k) {
      const size_t j = found[0][k];
      const double dj = (points[j] - q).squaredNorm() * inv2(j);  // recomputed: the same value however FLANN rounds
      if (dj < d2[j]) {
        d2[j] = dj;
        heap.push({dj, j});
      }
    }
  }
  if (covering_radius) *covering_radius = std::sqrt(last);
  std::sort(taken.begin(), taken.end());
  return taken;
}

}  // namespace voroudf

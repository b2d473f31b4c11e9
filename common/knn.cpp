#include "common/knn.h"

#include <flann/flann.hpp>
#include <omp.h>

#include <algorithm>
#include <memory>

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
    for (size_t q = 0; q < m; ++q) {
      const size_t self = begin + q;
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

}  // namespace voroudf

#include "stages/optimize-seeds/seed_index.h"

#include <flann/flann.hpp>

#include <algorithm>

namespace voroudf {

// The kd-tree PCL's KdTreeFLANN<PointXYZ> builds — FLANN's single kd-tree over the float coordinates, 15
// points per leaf — and its searches, called through FLANN's one-query entry point (findNeighbors) with
// the result sets FLANN's own knnSearch and radiusSearch use, so the answers are PCL's, in PCL's order.
// Not through PCL: its nearestKSearch and radiusSearch go through FLANN's batch search, which opens an
// OpenMP parallel region for every query; optimize-seeds asks 1.3 M single queries per run at 2,500 seeds,
// each paying for a team and a futex wake (~1 s of a 6.5 s run on fandisk).
struct SeedIndex::Impl {
  using Tree = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;
  std::vector<float> rows;
  std::unique_ptr<Tree> tree;
  size_t size = 0;
};

SeedIndex::SeedIndex(const std::vector<Vec3>& points) : impl_(std::make_unique<Impl>()) {
  impl_->size = points.size();
  impl_->rows.resize(3 * points.size());
  for (size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) impl_->rows[3 * i + static_cast<size_t>(a)] = static_cast<float>(points[i][a]);
  impl_->tree = std::make_unique<Impl::Tree>(flann::Matrix<float>(impl_->rows.data(), points.size(), 3),
                                             flann::KDTreeSingleIndexParams(15));
  impl_->tree->buildIndex();
}

SeedIndex::~SeedIndex() = default;

namespace {
// PCL's search parameters: unlimited checks, exact (eps 0), sorted results.
const flann::SearchParams& Exact() {
  static const flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED, 0.0f, true);
  return params;
}
}  // namespace

void SeedIndex::Nearest(const Vec3& query, int k, std::vector<int>& indices) const {
  indices.clear();
  k = std::min(k, static_cast<int>(impl_->size));
  if (k <= 0) return;
  const float q[3] = {static_cast<float>(query.x()), static_cast<float>(query.y()), static_cast<float>(query.z())};
  // FLANN's knnSearch takes the simple result set up to its heap threshold (250 neighbours), the heap above.
  const size_t kk = static_cast<size_t>(k);
  thread_local std::vector<size_t> found;
  thread_local std::vector<float> squared;
  found.resize(kk);
  squared.resize(kk);
  size_t n = 0;
  if (kk > KNN_HEAP_THRESHOLD) {
    flann::KNNResultSet2<float> result(kk);
    impl_->tree->findNeighbors(result, q, Exact());
    n = std::min(result.size(), kk);
    result.copy(found.data(), squared.data(), n, true);
  } else {
    flann::KNNSimpleResultSet<float> result(kk);
    impl_->tree->findNeighbors(result, q, Exact());
    n = std::min(result.size(), kk);
    result.copy(found.data(), squared.data(), n, true);
  }
  indices.assign(found.begin(), found.begin() + static_cast<long>(n));
}

void SeedIndex::WithinRadius(const Vec3& query, double radius, std::vector<int>& indices) const {
  indices.clear();
  const float q[3] = {static_cast<float>(query.x()), static_cast<float>(query.y()), static_cast<float>(query.z())};
  flann::RadiusResultSet<float> result(static_cast<float>(radius * radius));
  impl_->tree->findNeighbors(result, q, Exact());
  const size_t n = result.size();
  if (n == 0) return;
  thread_local std::vector<size_t> found;
  thread_local std::vector<float> squared;
  found.resize(n);
  squared.resize(n);
  result.copy(found.data(), squared.data(), n, true);
  indices.assign(found.begin(), found.begin() + static_cast<long>(n));
}

}  // namespace voroudf

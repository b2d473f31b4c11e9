#pragma once
// Nearest-neighbour queries over the seeds: the kd-tree PCL's KdTreeFLANN builds, queried one point at a
// time through FLANN (seed_index.cpp says why not through PCL). FLANN's headers stay in seed_index.cpp.
#include <memory>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// A kd-tree over a fixed set of points. Queries are const and thread-safe (each call uses its own
/// result buffers), so they can run inside OpenMP loops. The tree holds float coordinates: its distances
/// are float-accurate; callers that need exact comparisons recompute them in double.
class SeedIndex {
 public:
  /// \pre points is not empty; the index keeps no reference to `points`.
  explicit SeedIndex(const std::vector<Vec3>& points);
  ~SeedIndex();
  SeedIndex(const SeedIndex&) = delete;
  SeedIndex& operator=(const SeedIndex&) = delete;

  /// The k nearest points to `query` (the query's own point included if it is indexed), nearest first;
  /// ties keep FLANN's deterministic order (PCL's). Returns fewer than k when the index is smaller.
  void Nearest(const Vec3& query, int k, std::vector<int>& indices) const;

  /// All points within `radius` of `query`, sorted by distance (nearest first).
  void WithinRadius(const Vec3& query, double radius, std::vector<int>& indices) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voroudf

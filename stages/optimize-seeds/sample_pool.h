#pragma once
// One fixed random point set from which every round's cell samples are taken, with the UDF values of the
// points already asked for (docs/optimize-seeds.md, "Sample pool"). Written by hand: no installed library
// draws a marked Poisson process lazily over a sparse grid.
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "common/rng.h"
#include "common/types.h"
#include "common/udf.h"

namespace voroudf {

/// A marked Poisson process: in every cube of a grid of side `bucket_size` fixed for the run, points
/// uniform in the cube arrive in increasing order of a mark u, at rate 1 per unit of u. Restricted to a
/// region A the process is again Poisson: given their number its points are independent and uniform in A,
/// and the marks are independent of the positions. So **the M points of lowest mark inside a cell are M
/// independent uniform points of the cell** — the paper's "M points sampled within its Voronoi cell" — and
/// a cell that changed little since the last round gets mostly the same points, whose UDF values are kept
/// here instead of asked again. The points depend on the user's seed and the grid alone, never on the order
/// in which cells ask or on the thread count.
///
/// With `layers` > 1 every point joins one of that many layers at random; each layer is again a Poisson
/// process, independent of the others (thinning), so rounds that take the layers in turn see independent
/// samples of a cell while each layer's UDF values are still reused.
class SamplePool {
 public:
  using PointId = uint64_t;  ///< bucket index << 32 | layer << 26 | point index in the bucket's layer

  /// \pre bucket_size > 0, 1 ≤ layers ≤ 64
  SamplePool(uint64_t seed, double bucket_size, int layers = 1);

  /// A cell: the ball B(centre, radius) cut by the half-spaces offset_kᵀ(q − centre) ≤ half_sq_k.
  struct Cell {
    Vec3 centre = Vec3::Zero();
    double radius = 0.0;
    std::vector<Vec3> offsets;
    std::vector<double> half_sq;
  };

  /// For every cell with wanted[i], the ids of its `m` lowest-mark points, in increasing mark; fewer when
  /// fewer than `m` of its points have a mark at which the ball's bounding cube holds `max_cube_points`
  /// points on average (the budget of rejection sampling). Grows the pool as far as the cells need; the
  /// per-cell search runs in parallel. marks: per cell, the mark of its m-th point (0: unknown or fewer),
  /// read as the first guess of how far to search and updated for the selected cells; it only sets the
  /// work, never the result. examined (optional): per cell, the pool points looked at. layer: which
  /// layer's points (0 ≤ layer < layers).
  std::vector<std::vector<PointId>> Select(const std::vector<Cell>& cells, const std::vector<char>& wanted, size_t m,
                                           double max_cube_points, std::vector<double>& marks,
                                           std::vector<uint64_t>* examined = nullptr, int layer = 0);

  /// Asks the UDF, in one batch, at those of `ids` not asked before (each once, in the order given).
  /// Returns how many were asked.
  size_t Evaluate(const Udf& udf, const std::vector<PointId>& ids);

  Vec3 Point(PointId id) const {
    const Entry_& e = Entry(id);
    return buckets_[id >> 32].origin + Vec3(e.offset[0], e.offset[1], e.offset[2]);
  }
  /// \pre Evaluate has seen `id`
  double Distance(PointId id) const { return values_[static_cast<size_t>(Entry(id).value)].distance; }
  const Vec3& Gradient(PointId id) const { return values_[static_cast<size_t>(Entry(id).value)].gradient; }

  int layers() const { return layers_; }
  size_t points() const;                              ///< generated so far
  size_t evaluated() const { return values_.size(); } ///< UDF values held
  size_t buckets() const { return buckets_.size(); }
  size_t bytes() const;                               ///< memory held, roughly

 private:
  // 20 bytes: the pool holds several points per UDF value asked. Single precision is exact for what the
  // samples need: the points are random anyway, and a mark is compared only with others of the same type.
  struct Entry_ {
    float offset[3];  // from the bucket's origin
    float mark;
    int32_t value;    // index into values_, −1: not asked yet
  };
  struct Bucket {
    Vec3 origin;
    Rng rng;
    float complete = 0.0f;         // every point of mark below this is generated
    double wanted = 0.0;           // while a Select grows it: the mark to complete it to (else 0)
    std::vector<std::vector<Entry_>> layer;  // per layer, increasing mark
  };
  struct Value {
    double distance;
    Vec3 gradient;
  };
  const Entry_& Entry(PointId id) const { return buckets_[id >> 32].layer[(id >> 26) & 0x3fu][id & 0x3ffffffu]; }
  Entry_& Entry(PointId id) { return buckets_[id >> 32].layer[(id >> 26) & 0x3fu][id & 0x3ffffffu]; }
  void Grow(Bucket& b, double mark) const;  // b complete up to `mark`

  uint64_t seed_;
  double h_;
  int layers_;
  std::vector<Bucket> buckets_;
  std::unordered_map<int64_t, uint32_t> index_;  // grid key -> position in buckets_
  std::vector<Value> values_;
  double fill_ = 0.5;  // last Select's 20th-percentile share of a ball that its cell fills: the first guess of a mark
};

}  // namespace voroudf

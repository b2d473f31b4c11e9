#pragma once
// One fixed random point set from which every round's cell samples are taken, with the UDF values of the
// points already asked for (docs/optimize-seeds.md, "Sample pool"). Written by hand: no installed library
// draws a marked Poisson process lazily over a sparse grid.
#include <cstddef>
#include <cstdint>
#include <memory>
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
  using PointId = uint64_t;  ///< bucket index << 40 | part << 28 | point index in the part (part: layer and sub-cube)

  /// \pre bucket_size > 0, 1 ≤ layers ≤ 64 (layers × 8 parts fit in kPartBits)
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

  Vec3 Point(PointId id) const { return PointOf(id, Entry(id)); }
  /// \pre Evaluate has seen `id`
  double Distance(PointId id) const { return ValueOf(Entry(id).value).distance; }
  const Vec3& Gradient(PointId id) const { return ValueOf(Entry(id).value).gradient; }
  /// Point, Distance and Gradient at once, from one look-up of the point's entry. \pre Evaluate has seen `id`
  void Sample(PointId id, Vec3* point, double* distance, Vec3* gradient) const {
    const Entry_& e = Entry(id);
    *point = PointOf(id, e);
    const Value& v = ValueOf(e.value);
    *distance = v.distance;
    *gradient = v.gradient;
  }

  int layers() const { return layers_; }
  size_t points() const;                              ///< generated so far
  size_t evaluated() const { return value_count_; }   ///< UDF values held
  size_t buckets() const { return buckets_.size(); }
  size_t bytes() const;                               ///< memory held, roughly

 private:
  // 20 bytes: the pool holds several points per UDF value asked. Single precision is exact for what the
  // samples need: the points are random anyway, and a mark is compared only with others of the same type.
  struct Entry_ {
    float offset[3];  // from the bucket's origin
    float mark;
    int32_t value;    // index of its UDF value, −1: not asked yet
  };
  struct Bucket {
    Vec3 origin;
    Rng rng;
    float complete = 0.0f;         // every point of mark below this is generated
    double wanted = 0.0;           // while a Select grows it: the mark to complete it to (else 0)
    // The points of every part (layer × kSubCubes + sub-cube) in one array, part p at [begin[p], begin[p + 1]),
    // each part in increasing mark: one block of memory per bucket, which a cell's scan streams through.
    std::vector<Entry_> entries;
    std::vector<uint32_t> begin;
    size_t Size(size_t part) const { return begin[part + 1] - begin[part]; }
    const Entry_* Part(size_t part) const { return entries.data() + begin[part]; }
  };
  struct Value {
    double distance;
    Vec3 gradient;
  };
  // A bucket's points are kept per sub-cube of a 2 × 2 × 2 split, each list in increasing mark, so that a cell
  // scans only the sub-cubes that meet its ball: with whole cubes, 4 of 5 points looked at lay outside the
  // cell's ball (fandisk, 2,500 seeds). The split changes no point, mark or layer, only where a point is kept.
  static constexpr int kSplit = 2;
  static constexpr int kSubCubes = kSplit * kSplit * kSplit;
  static constexpr int kIndexBits = 28, kPartBits = 12, kBucketShift = kIndexBits + kPartBits;
  static constexpr PointId kIndexMask = (PointId{1} << kIndexBits) - 1, kPartMask = (PointId{1} << kPartBits) - 1;
  const Entry_& Entry(PointId id) const {
    const Bucket& b = buckets_[id >> kBucketShift];
    return b.entries[b.begin[(id >> kIndexBits) & kPartMask] + (id & kIndexMask)];
  }
  Vec3 PointOf(PointId id, const Entry_& e) const {
    return buckets_[id >> kBucketShift].origin + Vec3(e.offset[0], e.offset[1], e.offset[2]);
  }
  Entry_& Entry(PointId id) {
    Bucket& b = buckets_[id >> kBucketShift];
    return b.entries[b.begin[(id >> kIndexBits) & kPartMask] + (id & kIndexMask)];
  }
  void Grow(Bucket& b, double mark) const;  // b complete up to `mark`
  std::vector<std::vector<uint32_t>> TouchedBuckets(const std::vector<Cell>& cells, const std::vector<char>& pending);
  uint64_t Scan(const Cell& cell, const std::vector<uint32_t>& touched, double t, int layer,
                std::vector<std::pair<double, PointId>>& found) const;
  void UpdateFill(const std::vector<double>& fill);
  void GrowForCells(const std::vector<size_t>& open, const std::vector<std::vector<uint32_t>>& touched,
                    const std::vector<double>& mark);
  static bool OutsideSomeHalfSpace(const Cell& cell, const Vec3& lo, double size);

  uint64_t seed_;
  double h_;
  int layers_;
  std::vector<Bucket> buckets_;
  std::unordered_map<int64_t, uint32_t> index_;  // grid key -> position in buckets_
  // The UDF values in blocks that never move: a growing vector copied its megabytes and faulted in fresh pages
  // on one thread at every doubling (a tenth of optimize-seeds' serial time on 2 threads); blocks are filled
  // in parallel and only appended.
  static constexpr int kValueBlockBits = 16;
  static constexpr size_t kValueMask = (size_t{1} << kValueBlockBits) - 1;
  Value& Slot(size_t v) { return value_blocks_[v >> kValueBlockBits][v & kValueMask]; }
  const Value& ValueOf(int32_t v) const {
    return value_blocks_[static_cast<size_t>(v) >> kValueBlockBits][static_cast<size_t>(v) & kValueMask];
  }
  std::vector<std::unique_ptr<Value[]>> value_blocks_;
  size_t value_count_ = 0;
  double fill_ = 0.5;  // last Select's 20th-percentile share of a ball that its cell fills: the first guess of a mark
};

}  // namespace voroudf

#include "common/morton.h"

#include <omp.h>
#include <parallel/algorithm>

#include <algorithm>
#include <cmath>
#include <utility>

namespace voroudf {
namespace {

// Spreads the low 21 bits of x so that two zero bits follow each one.
uint64_t Spread21(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

}  // namespace

uint64_t MortonCode(const Vec3& p, const Box& box) {
  if (!p.allFinite()) return 0;
  uint64_t code = 0;
  for (int c = 0; c < 3; ++c) {
    const double extent = box.max[c] - box.min[c];
    const double t = extent > 0 ? std::clamp((p[c] - box.min[c]) / extent, 0.0, 1.0) : 0.0;
    code |= Spread21(std::min<uint64_t>(static_cast<uint64_t>(t * 2097152.0), 2097151)) << c;
  }
  return code;
}

std::vector<size_t> MortonOrder(const Vec3* points, size_t count, const Box& box) {
  std::vector<std::pair<uint64_t, size_t>> keyed(count);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(count); ++i) keyed[i] = {MortonCode(points[i], box), i};
  // Keys are unique (the index breaks ties), so the parallel sort (libstdc++'s OpenMP parallel mode) gives
  // the same order as std::sort; large batches are sorted on every thread (5 % of optimize-seeds on one).
  if (count >= 65536 && omp_get_max_threads() > 1 && !omp_in_parallel())
    __gnu_parallel::sort(keyed.begin(), keyed.end());
  else
    std::sort(keyed.begin(), keyed.end());
  std::vector<size_t> order(count);
  for (size_t i = 0; i < count; ++i) order[i] = keyed[i].second;
  return order;
}

Box BoundingBox(const std::vector<Vec3>& points) {
  if (points.empty()) return Box{};
  Box box{points[0], points[0]};
  for (const Vec3& p : points) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  return box;
}

}  // namespace voroudf

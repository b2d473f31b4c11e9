#include "common/morton.h"

#include <omp.h>

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
  // Large batches are sorted on every thread (the sort is 5 % of optimize-seeds on one): one slice per
  // thread, then pairwise merges. Keys are unique (the index breaks ties), so the order is std::sort's
  // whatever the thread count. By hand: libstdc++'s parallel mode (__gnu_parallel::sort) does the same but
  // has a data race of its own that ThreadSanitizer reports (every thread writes its thread count).
  const int parts = count >= 65536 && !omp_in_parallel() ? std::min(omp_get_max_threads(), 64) : 1;
  std::vector<size_t> bound(static_cast<size_t>(parts) + 1);
  for (int k = 0; k <= parts; ++k) bound[static_cast<size_t>(k)] = count * static_cast<size_t>(k) / static_cast<size_t>(parts);
  const auto at = [&](int k) { return keyed.begin() + static_cast<long>(bound[static_cast<size_t>(k)]); };
#pragma omp parallel for schedule(static) if (parts > 1)
  for (int k = 0; k < parts; ++k) std::sort(at(k), at(k + 1));
  for (int width = 1; width < parts; width *= 2) {
#pragma omp parallel for schedule(static) if (parts > 1)
    for (int k = 0; k < parts; k += 2 * width)
      if (k + width < parts) std::inplace_merge(at(k), at(k + width), at(std::min(k + 2 * width, parts)));
  }
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

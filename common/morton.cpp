#include "common/morton.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
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

struct Keyed {
  uint64_t code;
  size_t index;
  bool operator<(const Keyed& o) const { return code < o.code || (code == o.code && index < o.index); }
};

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
  // Plain arrays, left uninitialised: their pages are first touched by the threads that fill them.
  const std::unique_ptr<Keyed[]> keyed(new Keyed[count]);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(count); ++i) keyed[i] = {MortonCode(points[i], box), static_cast<size_t>(i)};
  std::vector<size_t> order(count);
  // Batches from a few thousand points on are sorted on every thread (a serial sort was a tenth of
  // optimize-seeds' serial time on two threads): bucketed by the codes' leading bits, chunk by chunk, then
  // every bucket sorted on its own. Keys are unique (the index breaks ties), so the order is std::sort's
  // whatever the threads. By hand: libstdc++'s parallel mode (__gnu_parallel::sort) does the same but has a
  // data race of its own that ThreadSanitizer reports (every thread writes its thread count).
  if (count < 4096 || omp_in_parallel() || omp_get_max_threads() == 1) {
    std::sort(keyed.get(), keyed.get() + count);
    for (size_t i = 0; i < count; ++i) order[i] = keyed[i].index;
    return order;
  }
  uint64_t lo = ~uint64_t{0}, hi = 0;
#pragma omp parallel for schedule(static) reduction(min : lo) reduction(max : hi)
  for (long i = 0; i < static_cast<long>(count); ++i) {
    lo = std::min(lo, keyed[i].code);
    hi = std::max(hi, keyed[i].code);
  }
  // Up to 4,096 buckets of the code range; at most 16 chunks of the input count their buckets (chunks fixed
  // by the count, not the threads, so that the scatter is the same for any team).
  const size_t want_buckets = std::min<size_t>(4096, count / 8);
  int shift = 0;
  while (((hi - lo) >> shift) >= want_buckets) ++shift;
  const size_t buckets = static_cast<size_t>((hi - lo) >> shift) + 1;
  const auto bucket_of = [&](uint64_t code) { return static_cast<size_t>((code - lo) >> shift); };
  const size_t chunks = std::min<size_t>(16, (count + 4095) / 4096), chunk = (count + chunks - 1) / chunks;
  // Per chunk and bucket: its count, then where the chunk's next key of that bucket goes.
  std::vector<size_t> at(chunks * buckets, 0);
  const auto slot = [&](size_t c, size_t i) -> size_t& { return at[c * buckets + bucket_of(keyed[i].code)]; };
  const auto chunk_end = [&](size_t c) { return std::min(count, (c + 1) * chunk); };
#pragma omp parallel for schedule(static)
  for (long lc = 0; lc < static_cast<long>(chunks); ++lc)
    for (size_t c = static_cast<size_t>(lc), i = c * chunk; i < chunk_end(c); ++i) ++slot(c, i);
  std::vector<size_t> bucket_begin(buckets + 1, 0);
  for (size_t b = 0, total = 0; b < buckets; ++b) {
    bucket_begin[b] = total;
    for (size_t c = 0; c < chunks; ++c) {
      const size_t n = at[c * buckets + b];
      at[c * buckets + b] = total;
      total += n;
    }
  }
  bucket_begin[buckets] = count;
  const std::unique_ptr<Keyed[]> sorted(new Keyed[count]);
#pragma omp parallel for schedule(static)
  for (long lc = 0; lc < static_cast<long>(chunks); ++lc)
    for (size_t c = static_cast<size_t>(lc), i = c * chunk; i < chunk_end(c); ++i) sorted[slot(c, i)++] = keyed[i];
#pragma omp parallel for schedule(dynamic, 256)
  for (long b = 0; b < static_cast<long>(buckets); ++b) {
    std::sort(sorted.get() + bucket_begin[static_cast<size_t>(b)], sorted.get() + bucket_begin[static_cast<size_t>(b) + 1]);
    for (size_t i = bucket_begin[static_cast<size_t>(b)]; i < bucket_begin[static_cast<size_t>(b) + 1]; ++i)
      order[i] = sorted[i].index;
  }
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

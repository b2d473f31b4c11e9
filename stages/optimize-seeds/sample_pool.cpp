#include "stages/optimize-seeds/sample_pool.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "common/errors.h"
#include "common/morton.h"

namespace voroudf {
namespace {

constexpr int64_t kAxisBits = 21;
constexpr int64_t kAxisOffset = int64_t{1} << (kAxisBits - 1);

int64_t GridKey(int64_t x, int64_t y, int64_t z) {
  const int64_t mask = (int64_t{1} << kAxisBits) - 1;
  return (((x + kAxisOffset) & mask) << (2 * kAxisBits)) | (((y + kAxisOffset) & mask) << kAxisBits) |
         ((z + kAxisOffset) & mask);
}

// Squared distance from c to the cube [lo, lo + size]³.
double BoxGapSquared(const Vec3& c, const Vec3& lo, double size) {
  double gap_sq = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({lo[a] - c[a], 0.0, c[a] - (lo[a] + size)});
    gap_sq += d * d;
  }
  return gap_sq;
}

// The grid cubes that meet the ball B(c, r), in a fixed order (x, then y, then z).
template <typename Visit>
void ForBucketsInBall(const Vec3& c, double r, double h, Visit&& visit) {
  std::array<int64_t, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[static_cast<size_t>(a)] = static_cast<int64_t>(std::floor((c[a] - r) / h));
    hi[static_cast<size_t>(a)] = static_cast<int64_t>(std::floor((c[a] + r) / h));
  }
  for (int64_t x = lo[0]; x <= hi[0]; ++x)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t z = lo[2]; z <= hi[2]; ++z) {
        const Vec3 o(static_cast<double>(x) * h, static_cast<double>(y) * h, static_cast<double>(z) * h);
        if (BoxGapSquared(c, o, h) <= r * r) visit(GridKey(x, y, z), o);
      }
}

}  // namespace

// Whether the whole cube [lo, lo + size]³ lies outside one of the cell's half-spaces, so that none of its
// points can be in the cell. With a margin (a point's float offset may round a little past the cube, and
// the point test computes in its own order): a cube is skipped only when that cannot change a point's
// answer, so the selection stays the same to the bit.
bool SamplePool::OutsideSomeHalfSpace(const Cell& cell, const Vec3& lo, double size) {
  const Vec3 from = lo - cell.centre;
  const double slack = 1e-6 * size;
  for (size_t k = 0; k < cell.offsets.size(); ++k) {
    const Vec3& o = cell.offsets[k];
    double least = o.dot(from);
    for (int a = 0; a < 3; ++a) least += std::min(-slack * o[a], (size + slack) * o[a]);
    const double scale = o.norm() * (from.norm() + 2.0 * size);
    if (least - cell.half_sq[k] > 1e-9 * scale) return true;
  }
  return false;
}

SamplePool::SamplePool(uint64_t seed, double bucket_size, int layers) : seed_(seed), h_(bucket_size), layers_(layers) {}

size_t SamplePool::points() const {
  size_t total = 0;
  for (const Bucket& b : buckets_)
    total += b.entries.size();
  return total;
}

size_t SamplePool::bytes() const {
  size_t total = (value_blocks_.size() << kValueBlockBits) * sizeof(Value) + buckets_.capacity() * sizeof(Bucket) + index_.size() * 32;
  for (const Bucket& b : buckets_)
    total += b.entries.capacity() * sizeof(Entry_) + b.begin.capacity() * sizeof(uint32_t);
  return total;
}

void SamplePool::Grow(Bucket& b, double mark) const {
  const size_t parts = b.begin.size() - 1;
  std::vector<std::pair<uint32_t, Entry_>> fresh;  // (part, point), in increasing mark
  fresh.reserve(static_cast<size_t>(1.2 * std::max(0.0, mark - static_cast<double>(b.complete))) + 4);
  while (static_cast<double>(b.complete) < mark) {
    // Rate 1 per unit of mark: exponential gaps (in single precision, so that the stored mark is the one
    // the completeness test compares). Then the position, uniform in the cube.
    const float gap = static_cast<float>(-std::log1p(-b.rng.Uniform()));
    const double x = b.rng.Uniform(), y = b.rng.Uniform(), z = b.rng.Uniform();
    b.complete += std::max(gap, 1e-30f);
    // Each point joins one layer at random: the layers are independent Poisson processes (thinning).
    const size_t layer = layers_ > 1 ? static_cast<size_t>(b.rng.Below(static_cast<uint64_t>(layers_))) : 0;
    auto sub = [](double u) { return std::min(kSplit - 1, static_cast<int>(u * kSplit)); };
    const size_t part = layer * kSubCubes + static_cast<size_t>((sub(x) * kSplit + sub(y)) * kSplit + sub(z));
    fresh.push_back({static_cast<uint32_t>(part),
                     {{static_cast<float>(h_ * x), static_cast<float>(h_ * y), static_cast<float>(h_ * z)}, b.complete, -1}});
  }
  if (fresh.empty()) return;
  // Each part's new points after its old ones (a point keeps its index in its part, so ids stay valid).
  std::vector<uint32_t> added(parts, 0);
  for (const auto& f : fresh) ++added[f.first];
  std::vector<uint32_t> begin(parts + 1, 0);
  for (size_t p = 0; p < parts; ++p) {
    begin[p + 1] = begin[p] + static_cast<uint32_t>(b.Size(p)) + added[p];
  }
  std::vector<Entry_> entries(begin[parts]);
  std::vector<uint32_t> next(parts);
  for (size_t p = 0; p < parts; ++p) {
    std::copy(b.Part(p), b.Part(p) + b.Size(p), entries.begin() + begin[p]);
    next[p] = begin[p] + static_cast<uint32_t>(b.Size(p));
  }
  for (const auto& f : fresh) entries[next[f.first]++] = f.second;
  b.entries.swap(entries);
  b.begin.swap(begin);
}

// The buckets every wanted cell's ball meets, once (the balls do not change between a Select's passes):
// looked up in parallel, the missing ones then created serially in order of first use.
std::vector<std::vector<uint32_t>> SamplePool::TouchedBuckets(const std::vector<Cell>& cells,
                                                              const std::vector<char>& pending) {
  const size_t n = cells.size();
  std::vector<std::vector<uint32_t>> touched(n);
  std::vector<std::vector<std::pair<int64_t, Vec3>>> missing(n);
#pragma omp parallel for schedule(dynamic, 64)
  for (long li = 0; li < static_cast<long>(n); ++li) {
    const size_t i = static_cast<size_t>(li);
    if (!pending[i]) continue;
    ForBucketsInBall(cells[i].centre, cells[i].radius, h_, [&](int64_t key, const Vec3& origin) {
      const auto it = index_.find(key);
      if (it != index_.end())
        touched[i].push_back(it->second);
      else
        missing[i].emplace_back(key, origin);
    });
  }
  for (size_t i = 0; i < n; ++i)
    for (const auto& [key, origin] : missing[i]) {
      if (buckets_.size() >= (size_t{1} << (64 - kBucketShift))) throw NumericalError("sample pool: over 2^24 cubes");
      auto [it, inserted] = index_.try_emplace(key, static_cast<uint32_t>(buckets_.size()));
      if (inserted)
        buckets_.push_back({origin, Rng(seed_, static_cast<uint64_t>(key)), 0.0f, 0.0,
                            {}, std::vector<uint32_t>(static_cast<size_t>(layers_ * kSubCubes) + 1, 0)});
      touched[i].push_back(it->second);
    }
  return touched;
}

// Appends to `found` (mark, id) of the points of layer `layer` with mark below t in the buckets `touched`
// that lie in the cell (its ball, then its half-spaces); returns how many points it looked at.
uint64_t SamplePool::Scan(const Cell& cell, const std::vector<uint32_t>& touched, double t, int layer,
                          std::vector<std::pair<double, PointId>>& found) const {
  const double r2 = cell.radius * cell.radius;
  uint64_t seen = 0;
  for (uint32_t b : touched) {
    const Vec3 origin = buckets_[b].origin;
    if (OutsideSomeHalfSpace(cell, origin, h_)) continue;
    const double sub_size = h_ / kSplit, slack = 1e-6 * h_;
    for (int sub = 0; sub < kSubCubes; ++sub) {
      const Vec3 sub_origin = origin + sub_size * Vec3(sub / (kSplit * kSplit), (sub / kSplit) % kSplit, sub % kSplit);
      // Skipped only when no point of it can pass the tests below (with room for the float offsets'
      // rounding): the selection is the same as without the split.
      if (BoxGapSquared(cell.centre, sub_origin - Vec3::Constant(slack), sub_size + 2.0 * slack) > r2 * (1.0 + 1e-9))
        continue;
      const size_t part = static_cast<size_t>(layer * kSubCubes + sub);
      const Entry_* entries = buckets_[b].Part(part);
      const size_t size = buckets_[b].Size(part);
      for (size_t e = 0; e < size && entries[e].mark < t; ++e) {
        ++seen;
        // As Point(id) − centre, so that callers can check membership to the last bit.
        const Vec3 q = (origin + Vec3(entries[e].offset[0], entries[e].offset[1], entries[e].offset[2])) - cell.centre;
        if (q.squaredNorm() > r2) continue;
        bool inside = true;
        for (size_t k = 0; k < cell.offsets.size() && inside; ++k) inside = cell.offsets[k].dot(q) <= cell.half_sq[k];
        if (inside)
          found.emplace_back(entries[e].mark, (static_cast<PointId>(b) << kBucketShift) |
                                                  (static_cast<PointId>(part) << kIndexBits) | e);
      }
    }
  }
  return seen;
}

// fill_ from this Select's cells: a low quantile of the share of its ball each filled, so that most cells
// find their M in the next Select's first pass.
void SamplePool::UpdateFill(const std::vector<double>& fill) {
  std::vector<double> fills;
  for (double f : fill)
    if (f > 0.0) fills.push_back(f);
  if (!fills.empty()) {
    const size_t q = fills.size() / 5;
    std::nth_element(fills.begin(), fills.begin() + static_cast<long>(q), fills.end());
    fill_ = std::clamp(fills[q], 0.02, 1.0);
  }
}

// Every bucket an open cell needs complete to a higher mark is grown to the largest such mark.
void SamplePool::GrowForCells(const std::vector<size_t>& open, const std::vector<std::vector<uint32_t>>& touched,
                              const std::vector<double>& mark) {
  std::vector<uint32_t> short_buckets;  // those not yet complete to the mark a cell wants
  for (size_t i : open)
    for (uint32_t b : touched[i]) {
      Bucket& bucket = buckets_[b];
      if (static_cast<double>(bucket.complete) >= mark[i]) continue;
      // A part's index has kIndexBits; a mark that high (several GB in one cube) means seeds nearly coincide.
      if (!(mark[i] < 0.5 * static_cast<double>(kIndexMask)))
        throw NumericalError("sample pool: a cell needs over 2^27 points in one cube (seeds nearly coincide)");
      if (bucket.wanted == 0.0) short_buckets.push_back(b);
      bucket.wanted = std::max(bucket.wanted, mark[i]);
    }
#pragma omp parallel for schedule(dynamic, 64)
  for (long k = 0; k < static_cast<long>(short_buckets.size()); ++k) {
    Bucket& b = buckets_[short_buckets[static_cast<size_t>(k)]];
    Grow(b, b.wanted);
    b.wanted = 0.0;
  }
}

std::vector<std::vector<SamplePool::PointId>> SamplePool::Select(const std::vector<Cell>& cells,
                                                                 const std::vector<char>& wanted, size_t m,
                                                                 double max_cube_points,
                                                                 std::vector<double>& marks,
                                                                 std::vector<uint64_t>* examined, int layer) {
  const size_t n = cells.size();
  const double h3 = h_ * h_ * h_ * layers_;  // a layer's points: rate 1 / layers per bucket
  std::vector<std::vector<PointId>> out(n);
  std::vector<double> mark(n, 0.0), cap(n, 0.0), fill(n, -1.0);
  std::vector<char> pending(n, 0);
  marks.resize(n, 0.0);
  if (examined) examined->assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const double r = cells[i].radius;
    if (!wanted[i] || !(r > 0.0) || m == 0) continue;
    const double ball = 4.0 / 3.0 * M_PI * r * r * r;
    cap[i] = max_cube_points * h3 / (8.0 * r * r * r);
    // First guess: a little above the mark of the cell's M-th point last time, else from the typical fill.
    const double guess = marks[i] > 0.0 ? 1.2 * marks[i] : 1.25 * static_cast<double>(m) * h3 / (ball * fill_);
    mark[i] = std::min(cap[i], guess);
    pending[i] = 1;
  }
  // The cells in Morton order of their centres: neighbouring cells scan the same buckets, which are then
  // still in the cache (in the seeds' own order they are not, and the scan waits on memory).
  std::vector<Vec3> centres;
  std::vector<size_t> pending_index;
  for (size_t i = 0; i < n; ++i)
    if (pending[i]) {
      centres.push_back(cells[i].centre);
      pending_index.push_back(i);
    }
  std::vector<size_t> by_place;
  by_place.reserve(centres.size());
  for (size_t k : MortonOrder(centres, BoundingBox(centres))) by_place.push_back(pending_index[k]);
  const std::vector<std::vector<uint32_t>> touched = TouchedBuckets(cells, pending);
  for (;;) {
    std::vector<size_t> open;
    for (size_t i : by_place)
      if (pending[i]) open.push_back(i);
    if (open.empty()) break;
    GrowForCells(open, touched, mark);
#pragma omp parallel
    {
      std::vector<std::pair<double, PointId>> found;
#pragma omp for schedule(dynamic, 32)
      for (long li = 0; li < static_cast<long>(open.size()); ++li) {
        const size_t i = open[static_cast<size_t>(li)];
        const Cell& cell = cells[i];
        const double r2 = cell.radius * cell.radius, t = mark[i];
        found.clear();
        const uint64_t seen = Scan(cell, touched[i], t, layer, found);
        if (found.size() >= m || t >= cap[i]) {
          const size_t keep = std::min(m, found.size());
          std::nth_element(found.begin(), found.begin() + static_cast<long>(keep) - (keep > 0), found.end());
          std::sort(found.begin(), found.begin() + static_cast<long>(keep));
          out[i].resize(keep);
          for (size_t k = 0; k < keep; ++k) out[i][k] = found[k].second;
          marks[i] = keep == m ? found[keep - 1].first : 0.0;
          const double ball_points = t * (4.0 / 3.0 * M_PI * r2 * cell.radius) / h3;
          fill[i] = static_cast<double>(found.size()) / ball_points;
          pending[i] = 0;
        } else {
          // Too few: search to a higher mark, by the shortfall (at least 1.5×, at most 8× at a time).
          const double factor = 1.25 * static_cast<double>(m) / std::max<double>(1.0, static_cast<double>(found.size()));
          mark[i] = std::min(cap[i], t * std::clamp(factor, 1.5, 8.0));
        }
        if (examined) (*examined)[i] += seen;
      }
    }
  }
  UpdateFill(fill);
  return out;
}

size_t SamplePool::Evaluate(const Udf& udf, const std::vector<PointId>& ids) {
  // Which ids have no value yet, each once where it first occurs: every position k claims its entry with the
  // mark -(k + 2), the lowest k winning (a compare-and-swap loop, so the winner does not depend on the
  // threads); the entries lie far apart in memory, and this pass on one thread was a tenth of optimize-seeds'
  // serial time. Then the winners alone, in the order given.
  if (ids.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()) - 2)
    throw NumericalError("sample pool: over 2^31 points in one batch");
#pragma omp parallel for schedule(static)
  for (long k = 0; k < static_cast<long>(ids.size()); ++k) {
    int32_t* value = &Entry(ids[static_cast<size_t>(k)]).value;
    const int32_t claim = -static_cast<int32_t>(k) - 2;
    int32_t seen = __atomic_load_n(value, __ATOMIC_RELAXED);
    // -1: not asked; ≤ -2: claimed by position -(seen + 2); ≥ 0: has its value.
    while ((seen == -1 || (seen <= -2 && seen < claim)) &&
           !__atomic_compare_exchange_n(value, &seen, claim, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
    }
  }
  std::vector<char> first(ids.size(), 0);
#pragma omp parallel for schedule(static)
  for (long k = 0; k < static_cast<long>(ids.size()); ++k)
    first[static_cast<size_t>(k)] = Entry(ids[static_cast<size_t>(k)]).value == -static_cast<int32_t>(k) - 2;
  std::vector<PointId> ask;
  for (size_t k = 0; k < ids.size(); ++k)
    if (first[k]) ask.push_back(ids[k]);
  if (ask.empty()) return 0;
  std::vector<Vec3> points(ask.size());
#pragma omp parallel for schedule(static)
  for (long k = 0; k < static_cast<long>(ask.size()); ++k) points[static_cast<size_t>(k)] = Point(ask[static_cast<size_t>(k)]);
  std::vector<double> d;
  std::vector<Vec3> g;
  udf.Evaluate(points, d, g);
  const size_t base = value_count_;
  if (base + ask.size() > static_cast<size_t>(std::numeric_limits<int32_t>::max()))
    throw NumericalError("sample pool: over 2^31 UDF values");
  value_count_ += ask.size();
  const size_t block = size_t{1} << kValueBlockBits;
  while (value_blocks_.size() * block < value_count_) value_blocks_.emplace_back(new Value[block]);
#pragma omp parallel for schedule(static)
  for (long lk = 0; lk < static_cast<long>(ask.size()); ++lk) {
    const size_t k = static_cast<size_t>(lk), v = base + k;
    Entry(ask[k]).value = static_cast<int32_t>(v);
    Slot(v) = {d[k], g[k]};
  }
  return ask.size();
}

}  // namespace voroudf

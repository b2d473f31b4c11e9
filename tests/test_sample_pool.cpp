// The sample pool of optimize-seeds: a cell's lowest-mark points are uniform in the cell, the same cell
// gets the same points whoever else asks, a cell that moved a little keeps most of them, and the UDF is
// asked once per point. Then the whole stage: the same seeds' quality for a fraction of the queries.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>

#include "common/counting_udf.h"
#include "common/shapes.h"
#include "stages/optimize-seeds/optimize_seeds.h"
#include "stages/optimize-seeds/sample_pool.h"
#include "stages/sample-seeds/sample_seeds.h"

namespace voroudf {
namespace {

// A half ball {q : |q − c| ≤ r, (q − c).x ≤ 0}.
SamplePool::Cell HalfBall(const Vec3& centre, double r) {
  SamplePool::Cell cell;
  cell.centre = centre;
  cell.radius = r;
  cell.offsets = {Vec3(1, 0, 0)};
  cell.half_sq = {0.0};
  return cell;
}

std::vector<SamplePool::PointId> SelectOne(SamplePool& pool, const SamplePool::Cell& cell, size_t m) {
  std::vector<double> marks;
  return pool.Select({cell}, {1}, m, 1e4, marks).front();
}

TEST(SamplePool, TheLowestMarksAreUniformInTheCell) {
  // 400 half balls far apart: 40,000 samples. In a uniform half ball of radius r the share within r/2 of
  // the centre is 1/8, the mean of x is −3r/8 and of y and z 0 (standard errors ≈ 0.0017 and 0.0012 r).
  SamplePool pool(3, 0.7);
  const double r = 1.0;
  std::vector<SamplePool::Cell> cells;
  for (int k = 0; k < 400; ++k) cells.push_back(HalfBall(Vec3(5.3 * (k % 20), 5.1 * (k / 20), 0.37 * k), r));
  std::vector<double> marks;
  const auto chosen = pool.Select(cells, std::vector<char>(cells.size(), 1), 100, 1e4, marks);
  size_t total = 0, inner = 0;
  Vec3 mean = Vec3::Zero();
  for (size_t i = 0; i < cells.size(); ++i) {
    ASSERT_EQ(chosen[i].size(), 100u);
    std::set<SamplePool::PointId> distinct(chosen[i].begin(), chosen[i].end());
    EXPECT_EQ(distinct.size(), 100u);
    for (SamplePool::PointId id : chosen[i]) {
      const Vec3 q = pool.Point(id) - cells[i].centre;
      ASSERT_LE(q.norm(), r);
      ASSERT_LE(q.x(), 0.0);
      inner += q.norm() <= r / 2;
      mean += q;
      ++total;
    }
  }
  mean /= static_cast<double>(total);
  EXPECT_NEAR(static_cast<double>(inner) / static_cast<double>(total), 0.125, 0.008);
  EXPECT_NEAR(mean.x(), -3.0 * r / 8.0, 0.006);
  EXPECT_NEAR(mean.y(), 0.0, 0.006);
  EXPECT_NEAR(mean.z(), 0.0, 0.006);
}

TEST(SamplePool, ACellGetsTheSamePointsWhoeverElseAsksAndTheUdfOnce) {
  const auto sphere = MakeShape("sphere");
  auto usage = std::make_shared<UdfUsage>();
  const CountingUdf udf(MakeShape("sphere"), usage);
  const SamplePool::Cell cell = HalfBall(Vec3(0.5, 0.0, 0.0), 0.05);
  SamplePool alone(9, 0.03), crowded(9, 0.03);
  const auto a = SelectOne(alone, cell, 100);
  // Another pool first grows the same buckets for overlapping cells, to other marks.
  std::vector<double> marks;
  crowded.Select({HalfBall(Vec3(0.5, 0.04, 0.0), 0.08), HalfBall(Vec3(0.48, 0.0, 0.02), 0.02)}, {1, 1}, 300, 1e4, marks);
  const auto b = SelectOne(crowded, cell, 100);
  ASSERT_EQ(a.size(), 100u);
  ASSERT_EQ(b.size(), 100u);
  for (size_t k = 0; k < a.size(); ++k) EXPECT_EQ(alone.Point(a[k]), crowded.Point(b[k])) << "sample " << k;
  EXPECT_EQ(alone.Evaluate(udf, a), 100u);
  EXPECT_EQ(usage->queries.load(), 100u);
  EXPECT_EQ(alone.Evaluate(udf, SelectOne(alone, cell, 100)), 0u);
  EXPECT_EQ(usage->queries.load(), 100u);
  for (SamplePool::PointId id : a) EXPECT_NEAR(alone.Distance(id), sphere->Distance(alone.Point(id)), 1e-12);
}

// Records the points it is asked for, in order (batches are asked from one thread).
class RecordingUdf : public Udf {
 public:
  explicit RecordingUdf(std::shared_ptr<Udf> inner) : inner_(std::move(inner)) {}
  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    inner_->EvaluateChunk(points, count, distance, gradient);
  }
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    asked.insert(asked.end(), points, points + count);
    inner_->Evaluate(points, count, distance, gradient);
  }
  Box Domain() const override { return inner_->Domain(); }
  std::string Describe() const override { return "recording"; }
  mutable std::vector<Vec3> asked;

 private:
  std::shared_ptr<Udf> inner_;
};

TEST(SamplePool, ABatchWithRepeatsAsksEachPointOnceInTheOrderOfFirstUseOnAnyThreads) {
  // Overlapping cells name the same points: a batch of one cell's ids, then again backwards and interleaved
  // with a second cell's, asks every point once, in the order of its first place in the batch, whatever
  // the threads (the claims are made in parallel).
  const int threads = omp_get_max_threads();
  std::vector<std::vector<Vec3>> asked;
  for (int t : {1, 2, 4}) {
    omp_set_num_threads(t);
    SamplePool pool(5, 0.03);
    const auto a = SelectOne(pool, HalfBall(Vec3(0.5, 0.0, 0.0), 0.05), 1500);
    const auto b = SelectOne(pool, HalfBall(Vec3(0.5, 0.02, 0.0), 0.05), 1500);
    ASSERT_EQ(a.size(), 1500u);
    ASSERT_EQ(b.size(), 1500u);
    std::vector<SamplePool::PointId> ids(a.begin(), a.begin() + 500);
    for (size_t k = 0; k < b.size(); ++k) ids.push_back(k % 2 ? b[k] : a[a.size() - 1 - k]);
    ids.insert(ids.end(), a.rbegin(), a.rend());
    std::vector<SamplePool::PointId> first;
    for (SamplePool::PointId id : ids)
      if (std::find(first.begin(), first.end(), id) == first.end()) first.push_back(id);
    ASSERT_LT(first.size(), ids.size());
    RecordingUdf udf(MakeShape("sphere"));
    EXPECT_EQ(pool.Evaluate(udf, ids), first.size());
    ASSERT_EQ(udf.asked.size(), first.size());
    for (size_t k = 0; k < first.size(); ++k) ASSERT_EQ(udf.asked[k], pool.Point(first[k])) << "point " << k;
    EXPECT_EQ(pool.Evaluate(udf, ids), 0u);
    asked.push_back(udf.asked);
  }
  omp_set_num_threads(threads);
  EXPECT_EQ(asked[0], asked[1]);
  EXPECT_EQ(asked[0], asked[2]);
}

TEST(SamplePool, ACellThatMovedALittleKeepsMostOfItsSamples) {
  SamplePool pool(4, 0.03);
  const Vec3 c(0.1, 0.2, 0.3);
  const auto before = SelectOne(pool, HalfBall(c, 0.05), 100);
  auto shared = [&](const std::vector<SamplePool::PointId>& after) {
    size_t n = 0;
    for (SamplePool::PointId id : after) n += std::find(before.begin(), before.end(), id) != before.end();
    return n;
  };
  // Moved by 5 % of its radius, the half ball keeps ~96 % of its volume: most of the lowest marks stay.
  EXPECT_GE(shared(SelectOne(pool, HalfBall(c + Vec3(-0.0025, 0.0, 0.0), 0.05), 100)), 80u);
  // Moved by more than its diameter: nothing in common.
  EXPECT_EQ(shared(SelectOne(pool, HalfBall(c + Vec3(0.0, 0.11, 0.0), 0.05), 100)), 0u);
}

TEST(SamplePool, OptimizeSeedsAsksAFractionOfTheQueriesForSeedsAsGood) {
  const auto cube = MakeShape("cube");
  SampleSeedsOptions so;
  so.count = 600;
  so.seed = 2;
  const SeedCloud in = SampleSeeds(*cube, so, Monitor::Null());
  auto run = [&](const std::string& mode, uint64_t* queries, int layers = OptimizeSeedsOptions().pool_layers) {
    auto usage = std::make_shared<UdfUsage>();
    const CountingUdf udf(MakeShape("cube"), usage);
    OptimizeSeedsOptions o;
    o.cell_samples = mode;
    o.pool_layers = layers;
    const SeedCloud out = OptimizeSeeds(udf, in, o, Monitor::Null());
    *queries = usage->queries.load();
    return out;
  };
  uint64_t fresh_q = 0, pool_q = 0, one_layer_q = 0;
  const SeedCloud fresh = run("fresh", &fresh_q), pooled = run("pool", &pool_q), one_layer = run("pool", &one_layer_q, 1);
  // The default layers: each round's samples are new only where the cell changed or its layer was not asked
  // yet (0.38 of fresh's here with three layers: both keep the cells nothing changed, so fresh pays only for
  // the changed ones).
  EXPECT_LT(pool_q, fresh_q * 9 / 20) << "pool " << pool_q << " vs fresh " << fresh_q << " queries";
  EXPECT_LT(one_layer_q, fresh_q / 6) << "one layer " << one_layer_q << " vs fresh " << fresh_q << " queries";
  EXPECT_LT(one_layer_q, pool_q);
  // As good: every seed on the surface, all 8 corners found, as many seeds on the edges.
  auto corners = [&](const SeedCloud& s) {
    size_t n = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      EXPECT_LT(cube->Distance(s.position[i]), 1e-5 * cube->Domain().Diagonal());
      n += s.rank[i] == 3;
    }
    return n;
  };
  EXPECT_EQ(corners(fresh), 8u);
  EXPECT_EQ(corners(pooled), 8u);
  EXPECT_EQ(corners(one_layer), 8u);
  auto edge_seeds = [](const SeedCloud& s) { return std::count(s.rank.begin(), s.rank.end(), uint8_t{2}); };
  EXPECT_NEAR(static_cast<double>(edge_seeds(pooled)), static_cast<double>(edge_seeds(fresh)), 0.15 * edge_seeds(fresh));
}

}  // namespace
}  // namespace voroudf

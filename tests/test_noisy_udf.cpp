// noisy:OPTIONS:SPEC (common/noisy_udf.h) and projection onto fields with a floor (common/projection.h).
// The wrapper: the value error has the asked spread and is smooth, the gradient is
// turned by exactly the asked angle, the field is a function of the point alone (batching, order and threads
// do not change it; the seed does), no noise is the inner field bit for bit, and bad options are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "common/errors.h"
#include "common/noisy_udf.h"
#include "common/projection.h"
#include "common/rng.h"
#include "common/udf_spec.h"
#include "stages/sample-seeds/sample_seeds.h"

namespace voroudf {
namespace {

std::vector<Vec3> RandomPoints(size_t n, uint64_t seed) {
  Rng rng(seed, 1);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
  return p;
}

// A SPEC and its noisy: wrapping evaluated at the same points.
struct Pair {
  std::unique_ptr<Udf> exact, noisy;
  std::vector<double> d0, d1;
  std::vector<Vec3> g0, g1;
  Pair(const std::string& spec, const std::string& noise, const std::vector<Vec3>& points)
      : exact(OpenUdf(spec)), noisy(OpenUdf("noisy:" + noise + ":" + spec)) {
    exact->Evaluate(points, d0, g0);
    noisy->Evaluate(points, d1, g1);
  }
};

TEST(NoisyUdf, ValueErrorHasTheAskedSpreadAndIsSmooth) {
  const auto points = RandomPoints(20000, 3);
  const Pair f("shape:sphere", "value=1e-3,scale=0.05", points);
  const auto &exact = f.exact, &noisy = f.noisy;
  const auto &d0 = f.d0, &d1 = f.d1;
  const auto &g0 = f.g0, &g1 = f.g1;
  const double sigma = 1e-3 * exact->Domain().Diagonal();
  double sum = 0, sum2 = 0;
  int n = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (d0[i] < 10 * sigma) continue;  // away from the fold of |d + e|
    const double e = d1[i] - d0[i];
    sum += e, sum2 += e * e, ++n;
    EXPECT_EQ(g1[i], g0[i]);  // value noise alone leaves the gradient where d + e > 0
  }
  ASSERT_GT(n, 15000);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(sd / sigma, 1.0, 0.1);
  EXPECT_LT(std::abs(mean) / sigma, 0.1);
  // Smooth: 1e-4 of the correlation length apart, the error moves by a tiny fraction of sigma; 3 lengths
  // apart it is nearly independent.
  const double length = 0.05 * exact->Domain().Diagonal();
  double near_change = 0, far_corr = 0;
  int m = 0;
  for (size_t i = 0; i < 2000; ++i) {
    const Vec3 p = points[i];
    const Vec3 q = p + Vec3(1, 2, 3).normalized() * 1e-4 * length, r = p + Vec3(3, -1, 2).normalized() * 3 * length;
    if (exact->Distance(p) < 10 * sigma || exact->Distance(q) < 10 * sigma || exact->Distance(r) < 10 * sigma) continue;
    const double ep = noisy->Distance(p) - exact->Distance(p), eq = noisy->Distance(q) - exact->Distance(q),
                 er = noisy->Distance(r) - exact->Distance(r);
    near_change = std::max(near_change, std::abs(ep - eq));
    far_corr += ep * er / (sigma * sigma), ++m;
  }
  EXPECT_LT(near_change, 0.01 * sigma);
  EXPECT_LT(std::abs(far_corr / m), 0.1);
}

TEST(NoisyUdf, GradientIsTurnedByExactlyTheAskedAngle) {
  const auto points = RandomPoints(5000, 4);
  const Pair f("shape:cube", "grad=15", points);
  const auto &d0 = f.d0, &d1 = f.d1;
  const auto &g0 = f.g0, &g1 = f.g1;
  double turned_min = 180, turned_max = 0;
  Vec3 mean_turn = Vec3::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(d1[i], d0[i]);
    EXPECT_NEAR(g1[i].norm(), 1.0, 1e-12);
    const double deg = std::acos(std::clamp(g1[i].dot(g0[i]), -1.0, 1.0)) * 180 / M_PI;
    turned_min = std::min(turned_min, deg), turned_max = std::max(turned_max, deg);
    mean_turn += g1[i] - g0[i].dot(g1[i]) * g0[i];
  }
  EXPECT_NEAR(turned_min, 15.0, 1e-6);
  EXPECT_NEAR(turned_max, 15.0, 1e-6);
  EXPECT_LT(mean_turn.norm() / points.size(), 0.05);  // no preferred direction
}

TEST(NoisyUdf, AFunctionOfThePointAndTheSeedOnly) {
  const auto noisy = OpenUdf("noisy:value=3e-3,grad=30,seed=7:shape:three-discs");
  const auto points = RandomPoints(10000, 5);
  std::vector<double> whole;
  std::vector<Vec3> whole_g;
  noisy->Evaluate(points, whole, whole_g);
  for (size_t i = 0; i < points.size(); i += 997) {  // one at a time, in another order
    Vec3 g;
    const double d = noisy->Distance(points[points.size() - 1 - i], &g);
    EXPECT_EQ(d, whole[points.size() - 1 - i]);
    EXPECT_EQ(g, whole_g[points.size() - 1 - i]);
  }
  const auto other = OpenUdf("noisy:value=3e-3,grad=30,seed=8:shape:three-discs");
  std::vector<double> d2;
  std::vector<Vec3> g2;
  other->Evaluate(points, d2, g2);
  int differ = 0;
  for (size_t i = 0; i < points.size(); ++i) differ += d2[i] != whole[i];
  EXPECT_GT(differ, 9900);
}

TEST(NoisyUdf, NoNoiseIsTheInnerField) {
  const Pair f("shape:torus", "value=0,grad=0", RandomPoints(3000, 6));
  EXPECT_EQ(f.d0, f.d1);
  EXPECT_EQ(f.g0, f.g1);
  EXPECT_EQ(f.noisy->Domain().min, f.exact->Domain().min);
  EXPECT_NE(f.noisy->Describe().find("noisy"), std::string::npos);
  EXPECT_EQ(BaseUdfSpec("noisy:value=1e-3:noisy:grad=5:grid.npy"), "grid.npy");
}

TEST(NoisyUdf, BadOptionsAreRefused) {
  for (const char* spec : {"noisy:value=1e-3", "noisy:value=-1:shape:cube", "noisy:grad=91:shape:cube",
                           "noisy:scale=0:shape:cube", "noisy:sigma=1:shape:cube", "noisy:value=abc:shape:cube",
                           "noisy:seed=1.5:shape:cube", "noisy:value:shape:cube"})
    EXPECT_THROW(OpenUdf(spec), UsageError) << spec;
  EXPECT_THROW(OpenUdf("noisy:value=1e-3:shape:nothing"), InputError);
}

// d = |z| + floor: a sheet whose field never reaches zero, as a learned UDF's.
class FloorPlane : public Udf {
 public:
  explicit FloorPlane(double floor) : floor_(floor) {}
  void EvaluateChunk(const Vec3* p, size_t count, double* d, Vec3* g) const override {
    for (size_t i = 0; i < count; ++i) {
      d[i] = std::abs(p[i].z()) + floor_;
      g[i] = Vec3(0, 0, p[i].z() < 0 ? -1 : 1);
    }
  }
  Box Domain() const override { return {Vec3::Constant(-1), Vec3::Constant(1)}; }
  std::string Describe() const override { return "floor plane"; }

 private:
  double floor_;
};

TEST(Projection, ReachesTheBottomOfAFieldWithAFloorOnlyWhenAllowed) {
  const FloorPlane udf(1e-3);
  Rng rng(9, 0);
  std::vector<Vec3> start(500);
  for (auto& p : start) p = Vec3(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5), rng.Uniform(-0.3, 0.3));
  ProjectionOptions options;
  options.tolerance = 1e-9;
  std::vector<Vec3> points = start;
  EXPECT_EQ(ProjectToZeroSet(udf, points, options, Monitor::Null()).num_converged, 0u);  // it oscillates
  options.floor_tolerance = 2e-3;
  points = start;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_EQ(r.num_converged, start.size());
  EXPECT_EQ(r.num_at_floor, start.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT(std::abs(points[i].z()), 1e-12);
    EXPECT_EQ(points[i].x(), start[i].x());
  }
  options.floor_tolerance = 5e-4;  // below the floor: refused
  points = start;
  EXPECT_EQ(ProjectToZeroSet(udf, points, options, Monitor::Null()).num_converged, 0u);
}

TEST(Projection, SeedsOfANoisySphereAreKeptAndNearIt) {
  SampleSeedsOptions options;
  options.count = 1000;
  options.spread_pool = 1;  // every draw is a seed: the count tells how many projections converged
  const auto exact = OpenUdf("shape:sphere");
  std::vector<Vec3> points(1, Vec3(0.3, 0.2, 0.1));
  ProjectionOptions projection;
  projection.tolerance = 1e-5 * exact->Domain().Diagonal();
  projection.floor_tolerance = 1e-2 * exact->Domain().Diagonal();
  EXPECT_EQ(ProjectToZeroSet(*exact, points, projection, Monitor::Null()).num_at_floor, 0u);  // exact: never

  const auto noisy = OpenUdf("noisy:value=1e-3:shape:sphere");
  const double sigma = 1e-3 * noisy->Domain().Diagonal();
  const SeedCloud seeds = SampleSeeds(*noisy, options, Monitor::Null());
  EXPECT_GE(seeds.size(), 990u);  // without the floor rule about half are dropped
  for (size_t i = 0; i < seeds.size(); ++i) EXPECT_LT(std::abs(seeds.position[i].norm() - 0.5), 5 * sigma);
  options.proj_floor_rel = 0;
  EXPECT_LT(SampleSeeds(*noisy, options, Monitor::Null()).size(), 700u);
}

// |d + e| for the plane z = 0 with the error e = +a (a floor of height a) where x < 0, e = -a (two zero
// sheets at z = +-a, a ridge of height a on the plane between them) where x >= 0, plus `slope` z. Gradients as
// the noisy: wrapper gives them: the plane's, times the sign of d + e.
class FloorAndTwins final : public Udf {
 public:
  explicit FloorAndTwins(double a, bool floor_half = true, double slope = 0.0)
      : a_(a), floor_half_(floor_half), slope_(slope) {}
  void EvaluateChunk(const Vec3* p, size_t count, double* d, Vec3* g) const override {
    for (size_t i = 0; i < count; ++i) {
      const double z = p[i].z(), e = (floor_half_ && p[i].x() < 0 ? a_ : -a_) + slope_ * z;
      d[i] = std::abs(std::abs(z) + e);
      g[i] = Vec3(0, 0, (z < 0 ? -1.0 : 1.0) * (std::abs(z) + e < 0 ? -1.0 : 1.0));
    }
  }
  Box Domain() const override { return {Vec3::Constant(-1), Vec3::Constant(1)}; }
  std::string Describe() const override { return "floor and twins"; }

 private:
  double a_;
  bool floor_half_;
  double slope_;  // of the error along z
};

std::vector<Vec3> SlabPoints(size_t n, double half_height, uint64_t seed) {
  Rng rng(seed, 0);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5), rng.Uniform(-half_height, half_height));
  return p;
}

TEST(Projection, TwinSheetsOfAFieldWithAFloorGoToTheRidgeBetweenThem) {
  const double a = 2e-3;
  const FloorAndTwins udf(a);
  const std::vector<Vec3> start = SlabPoints(600, 0.05, 4);
  ProjectionOptions options;
  options.tolerance = 1e-9;
  options.floor_tolerance = 1e-2;
  std::vector<Vec3> points = start;
  const ProjectionResult plain = ProjectToZeroSet(udf, points, options, Monitor::Null());
  size_t on_twins = 0;
  for (size_t i = 0; i < points.size(); ++i)
    if (plain.converged[i] && start[i].x() >= 0) on_twins += std::abs(std::abs(points[i].z()) - a) < 1e-9;
  EXPECT_GT(on_twins, 250u);  // without merging: on a sheet a off the plane
  EXPECT_EQ(plain.num_merged, 0u);

  options.twin_factor = 2.5;
  points = start;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_NEAR(r.twin_within, 2.5 * a, 1e-12);  // every floor reads a
  EXPECT_EQ(r.num_converged, start.size());
  EXPECT_GT(r.num_merged, 250u);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT(std::abs(points[i].z()), 1e-9) << "point " << i << " started at " << start[i].transpose();
    EXPECT_NEAR(points[i].x(), start[i].x(), 1e-12);  // moved along the normal only
  }
}

// FloorAndTwins with an error that varies along the normal, e = -+a + c z (c = 0.2): below the plane the
// field rises at 1 - c = 0.8 < cos 30° away from its zero sheet, so a probe there reads like one that has
// passed a twin although none lies beyond it. The sheets lie at z = a / 1.2 and -a / 0.8, their midpoint
// at -0.21 a, the ridge's top (the kink of |z|) on the plane.
TEST(Projection, TwinSheetsWhoseErrorVariesAlongTheNormalGoToTheRidgeFromBothSides) {
  const double a = 2e-3;
  const FloorAndTwins udf(a, true, 0.2);
  const std::vector<Vec3> start = SlabPoints(600, 0.05, 7);
  ProjectionOptions options;
  options.tolerance = 1e-6;  // Newton converges by 0.2 a step on slopes of 1.2 and 0.8
  options.floor_tolerance = 1e-2;
  options.twin_factor = 2.5;
  std::vector<Vec3> points = start;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_EQ(r.num_converged, start.size());
  size_t below = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (start[i].x() < 0) continue;
    below += start[i].z() < 0;
    // On the ridge's top, the plane itself: not on either sheet (0.83 a above, 1.25 a below) nor midway
    // between them (-0.21 a).
    EXPECT_NEAR(points[i].z(), 0.0, 0.02 * a) << "point " << i << " started at " << start[i].transpose();
  }
  EXPECT_GT(below, 100u);
}

// |d - a| for d the distance to the boundary of the quarter space x <= 0, y <= 0 (a convex 90° edge on the z
// axis): twin sheets a off each face, joined outside the edge by a cylinder of radius a around it.
class EdgeWithTwins final : public Udf {
 public:
  explicit EdgeWithTwins(double a) : a_(a) {}
  void EvaluateChunk(const Vec3* p, size_t count, double* d, Vec3* g) const override {
    for (size_t i = 0; i < count; ++i) {
      const double x = p[i].x(), y = p[i].y();
      double dist;
      Vec3 grad;
      if (x >= 0 && y >= 0) {
        dist = std::hypot(x, y);
        grad = dist > 0 ? Vec3(x / dist, y / dist, 0) : Vec3(1, 0, 0);
      } else if (x >= 0 || y >= 0) {
        dist = x >= 0 ? x : y;
        grad = x >= 0 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
      } else {
        dist = std::min(-x, -y);
        grad = -x < -y ? Vec3(-1, 0, 0) : Vec3(0, -1, 0);
      }
      d[i] = std::abs(dist - a_);
      g[i] = (dist < a_ ? -1.0 : 1.0) * grad;
    }
  }
  Box Domain() const override { return {Vec3::Constant(-1), Vec3::Constant(1)}; }
  std::string Describe() const override { return "edge with twins"; }

 private:
  double a_;
};

// A point on the cylinder has no twin along its gradient unless it lies within 15° of the bisector: beyond
// the edge the line runs into the solid at sin(45° - φ) from the nearer face, a slope below 0.5, or along a
// face. The ridge's top along the line is still the edge, where the field stops rising at 1.
TEST(Projection, TwinSheetsRoundAnEdgeGoToTheEdge) {
  const double a = 2e-3;
  const EdgeWithTwins udf(a);
  Rng rng(11, 0);
  std::vector<Vec3> start;
  for (int k = 0; k < 200; ++k) {
    const double phi = rng.Uniform(2.0, 88.0) * M_PI / 180.0, r = rng.Uniform(1.2, 2.0) * a;
    start.emplace_back(r * std::cos(phi), r * std::sin(phi), rng.Uniform(-0.5, 0.5));
  }
  ProjectionOptions options;
  options.tolerance = 1e-9;
  options.floor_tolerance = 1e-2;
  options.twin_within = 5.0 * a;
  std::vector<Vec3> points = start;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_EQ(r.num_converged, start.size());
  EXPECT_EQ(r.num_merged, start.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT(std::hypot(points[i].x(), points[i].y()), 0.02 * a) << "point " << i << " started at " << start[i].transpose();
    EXPECT_NEAR(points[i].z(), start[i].z(), 1e-12);
  }
}

TEST(Projection, AnExactFieldsThinWallIsNotMergedForItHasNoFloor) {
  const double a = 2e-3;
  const FloorAndTwins udf(a, false);  // two real sheets 2a apart, no floor anywhere
  std::vector<Vec3> points = SlabPoints(400, 0.05, 5);
  ProjectionOptions options;
  options.tolerance = 1e-9;
  options.floor_tolerance = 1e-2;
  options.twin_factor = 2.5;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_EQ(r.twin_within, 0.0);
  EXPECT_EQ(r.num_merged, 0u);
  for (size_t i = 0; i < points.size(); ++i) EXPECT_NEAR(std::abs(points[i].z()), a, 1e-9);
}

// |z| + f0 + c z: a floor whose error varies along the normal, as a learned field's or noisy: one does.
class SlantedFloor final : public Udf {
 public:
  void EvaluateChunk(const Vec3* p, size_t count, double* d, Vec3* g) const override {
    for (size_t i = 0; i < count; ++i) {
      d[i] = std::abs(p[i].z()) + 1e-3 + 0.2 * p[i].z();
      g[i] = Vec3(0, 0, p[i].z() < 0 ? -1 : 1);
    }
  }
  Box Domain() const override { return {Vec3::Constant(-1), Vec3::Constant(1)}; }
  std::string Describe() const override { return "slanted floor"; }
};

TEST(Projection, AKinksBottomFoundFromALongStepIsRefined) {
  // From 0.02-0.1 away the first bracket is long and the error's slope puts its bottom up to 6e-3 off;
  // the refined bracket is a few times the floor long.
  const SlantedFloor udf;
  std::vector<Vec3> points = SlabPoints(300, 0.1, 6);
  for (auto& p : points) p.z() = (p.z() < 0 ? -0.02 : 0.02) + p.z() * 0.8;
  ProjectionOptions options;
  options.tolerance = 1e-9;
  options.floor_tolerance = 1e-2;
  const ProjectionResult r = ProjectToZeroSet(udf, points, options, Monitor::Null());
  EXPECT_EQ(r.num_at_floor, points.size());
  for (const Vec3& p : points) EXPECT_LT(std::abs(p.z()), 5e-4);
}

TEST(Projection, TwinMergingBringsANoisySpheresSeedsNearer) {
  // noisy:value=1e-3: the seeds' mean distance from the sphere, with the default --proj-twin-factor and off.
  const auto noisy = OpenUdf("noisy:value=1e-3:shape:sphere");
  const double sigma = 1e-3 * noisy->Domain().Diagonal();
  SampleSeedsOptions options;
  options.count = 1500;
  auto mean_error = [&] {
    const SeedCloud seeds = SampleSeeds(*noisy, options, Monitor::Null());
    double sum = 0.0;
    for (const Vec3& p : seeds.position) sum += std::abs(p.norm() - 0.5);
    return sum / static_cast<double>(seeds.size()) / sigma;
  };
  const double merged = mean_error();
  options.proj_twin_factor = 0.0;
  const double apart = mean_error();
  EXPECT_LT(merged, 0.25);
  EXPECT_GT(apart, 0.35);
}

}  // namespace
}  // namespace voroudf

// sample-seeds: the library on every built-in shape, and the real executable end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/errors.h"
#include "common/knn.h"
#include "common/rng.h"
#include "common/shapes.h"
#include "formats/seeds_io.h"
#include "stages/sample-seeds/sample_seeds.h"
#include "stages/sample-seeds/thin_sizing.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

const char* kShapes[] = {"sphere", "cube", "disc", "hemisphere", "crossing-planes", "sphere-disc", "three-discs", "torus", "sphere-ring"};

TEST(SampleSeeds, EverySeedIsOnTheSurfaceForEveryShape) {
  for (const char* name : kShapes) {
    const auto udf = MakeShape(name);
    SampleSeedsOptions options;
    options.count = 400;
    options.seed = 11;
    const SeedCloud seeds = SampleSeeds(*udf, options, Monitor::Null());
    // Exact fields project in one step: nothing is dropped.
    EXPECT_EQ(seeds.size(), options.count) << name;
    const double tol = options.proj_tol_rel * udf->Domain().Diagonal();
    for (size_t i = 0; i < seeds.size(); ++i) {
      EXPECT_LT(udf->Distance(seeds.position[i]), tol) << name << " seed " << i;
      EXPECT_NEAR(seeds.normal[i].norm(), 1.0, 1e-9);
      EXPECT_EQ(seeds.rank[i], kRankUnknown);
    }
  }
}

TEST(SampleSeeds, SeedsCoverTheWholeSurface) {
  // Uniform draws projected onto the sphere: every octant gets seeds.
  const auto udf = MakeShape("sphere");
  SampleSeedsOptions options;
  options.count = 800;
  const SeedCloud seeds = SampleSeeds(*udf, options, Monitor::Null());
  int octant[8] = {0};
  for (const Vec3& p : seeds.position) ++octant[(p.x() > 0) + 2 * (p.y() > 0) + 4 * (p.z() > 0)];
  for (int c : octant) EXPECT_GT(c, 60);
}

// Seeds on a sharp edge of the cube have two coordinates at +-0.5.
double FractionOnCubeEdges(const SeedCloud& seeds) {
  size_t on_edge = 0;
  for (const Vec3& p : seeds.position) {
    int at_face = 0;
    for (int k = 0; k < 3; ++k) at_face += std::abs(std::abs(p[k]) - 0.5) < 1e-9;
    on_edge += at_face >= 2;
  }
  return static_cast<double>(on_edge) / static_cast<double>(seeds.size());
}

TEST(SampleSeeds, TheBandKeepsSeedsOffTheSharpEdges) {
  const auto udf = MakeShape("cube");
  SampleSeedsOptions options;
  options.count = 2000;
  options.spread_pool = 1;  // the draws themselves (the farthest-point choice takes extreme points first)
  options.band_rel = 0.0;  // the whole box: every draw in an edge's outer wedge lands on the edge
  const double whole_box = FractionOnCubeEdges(SampleSeeds(*udf, options, Monitor::Null()));
  options.band_rel = 0.01;
  const SeedCloud banded = SampleSeeds(*udf, options, Monitor::Null());
  const double band = FractionOnCubeEdges(banded);
  // Expected shares: the edges' outer wedges over the faces' two-sided slabs, ~0.8 % for a band of
  // 0.01 x diagonal; the whole box gives ~8 % here (more on shapes with more convex edges).
  EXPECT_GT(whole_box, 0.05);
  EXPECT_LT(band, 0.02);
  EXPECT_LT(band, whole_box / 4);
  EXPECT_EQ(banded.size(), options.count);
  // The band draws are spread by area: every face of the cube gets about a sixth.
  int per_face[6] = {0};
  for (const Vec3& p : banded.position) {
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(p[i]) > std::abs(p[k])) k = i;
    ++per_face[2 * k + (p[k] > 0)];
  }
  for (int c : per_face) EXPECT_NEAR(c, 2000 / 6.0, 80);
}

TEST(SampleSeeds, DuplicatesAreDropped) {
  // Whole-box draws outside a cube corner all project onto the corner itself.
  const auto udf = MakeShape("cube");
  SampleSeedsOptions options;
  options.count = 3000;
  options.band_rel = 0.0;
  options.spread_pool = 1;  // the farthest-point choice would take one point per corner
  const SeedCloud seeds = SampleSeeds(*udf, options, Monitor::Null());
  EXPECT_LT(seeds.size(), options.count);
  const double radius = options.dedup_rel * udf->Domain().Diagonal();
  for (size_t i = 0; i < seeds.size(); ++i)
    for (size_t j = i + 1; j < seeds.size(); ++j)
      ASSERT_GE((seeds.position[i] - seeds.position[j]).norm(), radius);
}

bool OnRing(const Vec3& p) { return p.norm() > 0.42; }  // shape:sphere-ring: sphere radius 0.35, ring 0.45..0.51

TEST(ThinParts, TheProbeFindsTheRingsThicknessAndNothingElse) {
  const auto ring = MakeShape("sphere-ring");
  SampleSeedsOptions options;
  options.count = 2000;
  const SeedCloud seeds = SampleSeeds(*ring, options, Monitor::Null());
  // h = 0.05: the probes reach 0.05, the gap of 0.1 between sphere and ring is not seen (that needs s > 0.1 / 1.9).
  const std::vector<double> t = ProbeThickness(*ring, seeds.position, seeds.normal, 0.05);
  int ring_points = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (OnRing(seeds.position[i])) {
      ++ring_points;
      // The tube is 0.06 across along every normal; the first probe to see it is s in (0.06/1.9, √2 · 0.06/1.9].
      EXPECT_GE(t[i], 1.6 * 0.06 / 1.9 - 1e-9) << seeds.position[i].transpose();
      EXPECT_LE(t[i], 1.6 * std::sqrt(2.0) * 0.06 / 1.9 + 1e-9) << seeds.position[i].transpose();
    } else {
      EXPECT_TRUE(std::isinf(t[i])) << seeds.position[i].transpose();  // 0.7 across
    }
  }
  EXPECT_GT(ring_points, 100);
  // A cube's faces meet its neighbours beside, not opposite: no concave or convex edge is a thin part (h = 0.4:
  // the probes reach 0.4, short of the opposite face's 1 / 1.9).
  const auto cube = MakeShape("cube");
  const SeedCloud cube_seeds = SampleSeeds(*cube, options, Monitor::Null());
  for (double thickness : ProbeThickness(*cube, cube_seeds.position, cube_seeds.normal, 0.4)) EXPECT_TRUE(std::isinf(thickness));
  // With h = 0.8 the probes see the opposite face, 1 away, from the middle of a face (nearer its edges a side
  // face is nearest at the probes): thickness in (1.6 / 1.9, 1.6].
  const std::vector<double> wide = ProbeThickness(*cube, cube_seeds.position, cube_seeds.normal, 0.8);
  int middle = 0;
  for (size_t i = 0; i < cube_seeds.size(); ++i) {
    Eigen::Index axis = 0;
    cube_seeds.normal[i].cwiseAbs().maxCoeff(&axis);
    Vec3 lateral = cube_seeds.position[i].cwiseAbs();
    lateral[axis] = 0.0;
    if (lateral.maxCoeff() > 0.25) continue;
    ++middle;
    EXPECT_GT(wide[i], 1.6 / 1.9);
    EXPECT_LE(wide[i], 1.6);
  }
  EXPECT_GT(middle, 100);
}

TEST(ThinParts, TheBoostMovesSeedsToTheRingAndKeepsTheCount) {
  const auto ring = MakeShape("sphere-ring");
  SampleSeedsOptions options;
  options.count = 700;
  auto ring_share = [&](const SeedCloud& s) {
    size_t n = 0;
    for (const Vec3& p : s.position) n += OnRing(p);
    return static_cast<double>(n) / static_cast<double>(s.size());
  };
  options.spread_pool = 1;
  const SeedCloud uniform = SampleSeeds(*ring, options, Monitor::Null());
  options.thin_boost = 4;
  const SeedCloud boosted = SampleSeeds(*ring, options, Monitor::Null());
  EXPECT_EQ(boosted.size(), options.count);
  EXPECT_NEAR(ring_share(uniform), 0.27, 0.05);  // the ring's share of the area
  EXPECT_GT(ring_share(boosted), 1.5 * ring_share(uniform));
  const SeedCloud again = SampleSeeds(*ring, options, Monitor::Null());
  EXPECT_EQ(again.position, boosted.position);
  options.spread_pool = 4;  // farthest apart in the thin parts' sizing: as many on the ring, evenly spaced
  const SeedCloud spread = SampleSeeds(*ring, options, Monitor::Null());
  EXPECT_EQ(spread.size(), options.count);
  EXPECT_GT(ring_share(spread), 1.5 * ring_share(uniform));
  // Weighted choice: heavier indices are chosen more often, and exactly `count` of them.
  std::vector<double> w(1000, 1.0);
  for (size_t i = 500; i < 1000; ++i) w[i] = 4.0;
  const std::vector<size_t> chosen = ChooseWeighted(w, 200, 3);
  ASSERT_EQ(chosen.size(), 200u);
  EXPECT_TRUE(std::is_sorted(chosen.begin(), chosen.end()));
  EXPECT_GT(std::count_if(chosen.begin(), chosen.end(), [](size_t i) { return i >= 500; }), 140);
}

TEST(SampleSeeds, BadOptionsAreUsageErrors) {
  SampleSeedsOptions options;
  options.count = 0;
  EXPECT_THROW(options.Check(), UsageError);
  options.count = 10;
  options.proj_tol_rel = 0;
  EXPECT_THROW(options.Check(), UsageError);
  options.proj_tol_rel = 1e-5;
  options.thin_boost = 0.5;
  EXPECT_THROW(options.Check(), UsageError);
  options.thin_boost = 2;  // with the spread pool: farthest apart in the thin parts' sizing
  EXPECT_NO_THROW(options.Check());
  options.spread_pool = 1;
  EXPECT_NO_THROW(options.Check());
  options.spread_pool = 0;
  EXPECT_THROW(options.Check(), UsageError);
}

// Farthest-point sampling the plain way: O(n) per pick.
std::vector<size_t> NaiveFarthest(const std::vector<Vec3>& p, size_t count, const std::vector<double>& spacing = {}) {
  auto metric = [&](size_t i, size_t j) {
    return (p[i] - p[j]).squaredNorm() / (spacing.empty() ? 1.0 : spacing[i] * spacing[i]);
  };
  std::vector<double> d(p.size());
  for (size_t i = 0; i < p.size(); ++i) d[i] = metric(i, 0);
  std::vector<size_t> taken{0};
  while (taken.size() < count) {
    size_t best = 0;
    for (size_t i = 1; i < p.size(); ++i)
      if (d[i] > d[best]) best = i;  // ties: the lower index
    taken.push_back(best);
    for (size_t i = 0; i < p.size(); ++i) d[i] = std::min(d[i], metric(i, best));
  }
  std::sort(taken.begin(), taken.end());
  return taken;
}

TEST(Spread, FarthestPointSubsetIsTheGreedyChoiceAndCoversAtItsRadius) {
  Rng rng(7, 0);
  std::vector<Vec3> points(3000);
  for (Vec3& p : points) p = Vec3(rng.Uniform(0, 1), rng.Uniform(0, 1), rng.Uniform(0, 0.2));
  points.push_back(points[10]);  // a duplicate is never taken while distinct points are left
  double radius = 0.0;
  const std::vector<size_t> taken = FarthestPointSubset(points, 250, &radius);
  EXPECT_EQ(taken, NaiveFarthest(points, 250));
  ASSERT_EQ(taken.size(), 250u);
  EXPECT_TRUE(std::is_sorted(taken.begin(), taken.end()));
  EXPECT_GT(radius, 0.0);
  double nearest_pair = INFINITY;
  for (size_t a = 0; a < taken.size(); ++a)
    for (size_t b = a + 1; b < taken.size(); ++b)
      nearest_pair = std::min(nearest_pair, (points[taken[a]] - points[taken[b]]).norm());
  EXPECT_GE(nearest_pair, radius - 1e-12);  // no two taken points are nearer than the radius ...
  for (const Vec3& p : points) {            // ... and every point lies within it of one
    double d = INFINITY;
    for (size_t t : taken) d = std::min(d, (points[t] - p).norm());
    EXPECT_LE(d, radius + 1e-12);
  }
  EXPECT_EQ(FarthestPointSubset(points, 5000).size(), points.size());
  // In a sizing metric (distances from points with x < 0.3 divided by 0.5), on a plane: the same greedy
  // choice, and about 1/0.5² = 4 times as dense there as elsewhere.
  for (Vec3& p : points) p.z() = 0.0;
  std::vector<double> spacing(points.size());
  for (size_t i = 0; i < points.size(); ++i) spacing[i] = points[i].x() < 0.3 ? 0.5 : 1.0;
  const std::vector<size_t> sized = FarthestPointSubset(points, 250, nullptr, &spacing);
  EXPECT_EQ(sized, NaiveFarthest(points, 250, spacing));
  const double dense = static_cast<double>(std::count_if(sized.begin(), sized.end(), [&](size_t i) { return points[i].x() < 0.3; }));
  EXPECT_NEAR(dense / 0.3 / ((250.0 - dense) / 0.7), 4.0, 1.0);
}

TEST(Spread, TheSpreadPoolStartsTheSeedsEvenlySpacedOnTheSurface) {
  const auto udf = MakeShape("torus");
  SampleSeedsOptions options;
  options.count = 600;
  options.seed = 3;
  options.spread_pool = 1;
  const SeedCloud uniform = SampleSeeds(*udf, options, Monitor::Null());
  options.spread_pool = 4;
  const SeedCloud spread = SampleSeeds(*udf, options, Monitor::Null());
  ASSERT_EQ(spread.size(), options.count);
  const double tol = options.proj_tol_rel * udf->Domain().Diagonal();
  for (const Vec3& p : spread.position) EXPECT_LT(udf->Distance(p), tol);
  // Uniform points on a surface have a nearest-neighbour CV of about 0.52; a farthest-point subset of 4x
  // as many has most pairs near its covering radius.
  EXPECT_GT(test::NearestNeighbourCv(uniform.position), 0.4);
  EXPECT_LT(test::NearestNeighbourCv(spread.position), 0.2);
  EXPECT_EQ(SampleSeeds(*udf, options, Monitor::Null()).position, spread.position);
}

class SampleSeedsExe : public ::testing::Test {
 protected:
  std::vector<std::string> Args(const std::string& shape, const std::string& out, const std::string& seed = "5") {
    return {"--udf", "shape:" + shape, "--count", "300", "--seed", seed, "-o", out};
  }
  TempDir dir_;
};

TEST_F(SampleSeedsExe, WritesSeedsOnTheSurfaceForEveryShape) {
  for (const char* name : kShapes) {
    const std::string out = dir_ / (std::string(name) + ".ply");
    const auto r = RunProgram("sample-seeds", Args(name, out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.out.empty()) << "stdout is for machine-readable results only";
    const SeedCloud seeds = ReadSeeds(out);
    EXPECT_EQ(seeds.size(), 300u);
    const auto udf = MakeShape(name);
    // float32 storage adds up to ~1e-7 to the 1e-5 * diagonal tolerance.
    const double tol = 1e-5 * udf->Domain().Diagonal() + 1e-6;
    for (const Vec3& p : seeds.position) EXPECT_LT(udf->Distance(p), tol) << name;
  }
}

TEST_F(SampleSeedsExe, SameSeedSameBytesWhateverTheThreadCount) {
  auto a = Args("three-discs", dir_ / "a.ply");
  auto b = Args("three-discs", dir_ / "b.ply");
  b.insert(b.end(), {"--threads", "1"});
  auto c = Args("three-discs", dir_ / "c.ply", "6");
  ASSERT_EQ(RunProgram("sample-seeds", a).exit_code, 0);
  ASSERT_EQ(RunProgram("sample-seeds", b).exit_code, 0);
  ASSERT_EQ(RunProgram("sample-seeds", c).exit_code, 0);
  EXPECT_EQ(test::ReadBytes(dir_ / "a.ply"), test::ReadBytes(dir_ / "b.ply"));
  EXPECT_NE(test::ReadBytes(dir_ / "a.ply"), test::ReadBytes(dir_ / "c.ply"));
}

TEST_F(SampleSeedsExe, ProvenanceAndAscii) {
  auto args = Args("cube", dir_ / "s.ply");
  args.push_back("--ascii");
  const auto r = RunProgram("sample-seeds", args);
  ASSERT_EQ(r.exit_code, 0);
  // The echo of the options can be pasted back: flags appear bare, never as "--ascii true".
  EXPECT_NE(r.err.find("--ascii"), std::string::npos);
  EXPECT_EQ(r.err.find("--ascii true"), std::string::npos) << r.err;
  const std::string text = test::ReadBytes(dir_ / "s.ply");
  EXPECT_NE(text.find("format ascii 1.0"), std::string::npos);
  EXPECT_NE(text.find("comment voroudf seeds 1"), std::string::npos);
  EXPECT_NE(text.find("comment stage sample-seeds"), std::string::npos);
  EXPECT_NE(text.find("comment udf shape:cube"), std::string::npos);
  EXPECT_NE(text.find("--count 300"), std::string::npos);
  EXPECT_NE(text.find("--seed 5"), std::string::npos);
}

struct Failure {
  std::vector<std::string> args;
  int exit_code;
  const char* message;
};

TEST_F(SampleSeedsExe, FailuresExitWithTheDocumentedCodeAndLeaveNoFile) {
  const std::string out = dir_ / "out.ply";
  const std::vector<Failure> failures = {
      {{"--udf", "shape:sphere", "--count", "0", "-o", out}, kExitUsage, "--count must be at least 1"},
      {{"--udf", "shape:sphere", "--count", "ten", "-o", out}, kExitUsage, "--count"},
      {{"--udf", "shape:sphere", "--no-such-flag", "-o", out}, kExitUsage, "no-such-flag"},
      {{"--udf", "shape:sphere", "--count", "10"}, kExitUsage, "--output is required"},
      {{"--udf", "shape:pyramid", "--count", "10", "-o", out}, kExitBadInput, "unknown built-in shape"},
      {{"--udf", "field.xyz", "--count", "10", "-o", out}, kExitBadInput, "expected shape:NAME"},
      {{"--udf", "noisy:value=-1:shape:cube", "--count", "10", "-o", out}, kExitUsage, "value= must be in [0, 1]"},
      {{"--udf", "noisy:grad=15", "--count", "10", "-o", out}, kExitUsage, "expected noisy:OPTIONS:SPEC"},
      {{"--udf", "noisy:grad=15:shape:pyramid", "--count", "10", "-o", out}, kExitBadInput, "unknown built-in shape"},
      {{"--udf", "shape:sphere", "--count", "10", "--thin-boost", "0.5", "-o", out}, kExitUsage, "--thin-boost"},
      {{"--udf", "shape:sphere", "--count", "10", "-o", dir_ / "no/such/dir/s.ply"}, kExitFailure, "does not exist"},
      {{"--udf", "shape:sphere", "--count", "10", "-o", dir_.path()}, kExitFailure, "is a directory"},
  };
  for (const auto& f : failures) {
    const auto r = RunProgram("sample-seeds", f.args);
    EXPECT_EQ(r.exit_code, f.exit_code) << r.err;
    EXPECT_NE(r.err.find(f.message), std::string::npos) << r.err;
    EXPECT_TRUE(dir_.List().empty()) << "a failed run left a file behind";
    // One clear line: the error is the last line of stderr and starts with the program name.
    const auto last = r.err.rfind("sample-seeds: error:");
    ASSERT_NE(last, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n', last), r.err.size() - 1);
  }
}

TEST_F(SampleSeedsExe, HelpExplainsTheOptions) {
  const auto r = RunProgram("sample-seeds", {"--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--udf", "--count", "--seed", "--threads", "--output", "--proj-tol-rel", "--ascii", "--quiet",
                           "--thin-boost", "--proj-floor-rel", "noisy:"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
  for (const auto& [name, description] : ShapeCatalog()) EXPECT_NE(r.out.find(name), std::string::npos) << name;
}

}  // namespace
}  // namespace voroudf

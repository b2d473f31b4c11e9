// End to end: the real executables sample-seeds -> optimize-seeds -> build-gvd -> thin-mesh on built-in shapes,
// and properties of the final mesh computed here (closedness, Euler characteristic, distance to the surface,
// triangle quality, sharp corners, non-manifold curves).
//
// The sphere, cube, crossing-planes and sphere-disc tests run the whole chain with the real optimize-seeds
// (skipped if its executable is not built): the cube's corners and the non-manifold curves need it. The
// torus, disc and hemisphere use seeds spread by a greedy minimum-distance filter of sample-seeds' output
// (independent of the optimiser). The non-manifold tests hold for most seeds, not all (docs/thin-mesh.md
// "Known limits").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

#include "common/mesh_topology.h"
#include "common/shapes.h"
#include "formats/mesh_io.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

bool HaveOptimizer() { return test::Exists(std::string(VOROUDF_BIN_DIR) + "/optimize-seeds"); }

/// Keeps seeds in file order unless one already kept is closer than `min_dist` (grid hashing). Test fixture
/// only: a stand-in for optimize-seeds' spacing, not an optimiser (seeds stay where sample-seeds put them).
SeedCloud SpreadSeeds(const SeedCloud& in, double min_dist) {
  std::unordered_map<uint64_t, std::vector<size_t>> grid;
  auto cell = [&](const Vec3& p, int dx, int dy, int dz) {
    const auto c = [&](double v, int o) { return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / min_dist)) + o + 100000); };
    return (c(p.x(), dx) << 42) | (c(p.y(), dy) << 21) | c(p.z(), dz);
  };
  SeedCloud out;
  for (size_t i = 0; i < in.size(); ++i) {
    const Vec3& p = in.position[i];
    bool free = true;
    for (int dx = -1; dx <= 1 && free; ++dx)
      for (int dy = -1; dy <= 1 && free; ++dy)
        for (int dz = -1; dz <= 1 && free; ++dz) {
          const auto it = grid.find(cell(p, dx, dy, dz));
          if (it == grid.end()) continue;
          for (size_t k : it->second)
            if ((out.position[k] - p).norm() < min_dist) free = false;
        }
    if (!free) continue;
    grid[cell(p, 0, 0, 0)].push_back(out.size());
    out.position.push_back(p);
    out.normal.push_back(in.normal[i]);
    out.udf.push_back(in.udf[i]);
    out.rank.push_back(in.rank[i]);
  }
  return out;
}

struct Chain {
  TriangleMesh mesh;
  TopologyStats topo;
  EdgeFaces edges;
  bool optimized = false;
  std::string log;
};

/// Runs the chain on shape:NAME: with optimize-seeds when `optimize`, otherwise with `count` draws spread to
/// min distance `spread_rel` x diagonal.
Chain RunChain(const TempDir& dir, const std::string& shape, int count, double spread_rel, bool optimize = false) {
  Chain c;
  const std::string udf = "shape:" + shape;
  auto run = [&](const std::string& program, const std::vector<std::string>& args) {
    const auto r = RunProgram(program, args);
    c.log += r.err;
    EXPECT_EQ(r.exit_code, 0) << program << " on " << shape << ":\n" << r.err;
    return r.exit_code == 0;
  };
  if (!run("sample-seeds", {"--udf", udf, "--count", std::to_string(count), "--seed", "1", "-o", dir / "seeds0.ply"}))
    return c;
  c.optimized = optimize;
  if (c.optimized) {
    if (!run("optimize-seeds", {"--udf", udf, "-i", dir / "seeds0.ply", "-o", dir / "seeds.ply"})) return c;
  } else {
    const SeedCloud spread = SpreadSeeds(ReadSeeds(dir / "seeds0.ply"), spread_rel * MakeShape(shape)->Domain().Diagonal());
    WriteSeeds(dir / "seeds.ply", spread, Provenance{"test-spread", "", udf});
  }
  if (!run("build-gvd", {"--udf", udf, "-i", dir / "seeds.ply", "-o", dir / "thick.ply", "--labels", dir / "labels.ply"}))
    return c;
  if (!run("thin-mesh", {"--udf", udf, "-i", dir / "thick.ply", "-o", dir / "mesh.ply", "--nm-edges", dir / "nm.ply"}))
    return c;
  c.mesh = ReadMeshPly(dir / "mesh.ply");
  c.topo = ComputeTopology(c.mesh);
  c.edges = BuildEdgeFaces(c.mesh.faces);
  std::printf("%s (%s seeds): V %zu F %zu boundary %zu non-manifold %zu components %zu chi %lld\n", shape.c_str(),
              c.optimized ? "optimised" : "spread", c.topo.num_vertices, c.topo.num_faces, c.topo.boundary_edges,
              c.topo.nonmanifold_edges, c.topo.components, c.topo.euler);
  return c;
}

double MeanQuality(const TriangleMesh& m) {
  double sum = 0;
  for (const Tri& t : m.faces) sum += TriangleQuality(m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]);
  return m.faces.empty() ? 0.0 : sum / static_cast<double>(m.faces.size());
}

/// Number of closed loops formed by the boundary edges (each boundary vertex has exactly two of them).
size_t BoundaryLoops(const Chain& c) {
  std::unordered_map<int, std::vector<int>> next;
  for (size_t e = 0; e < c.edges.edges.size(); ++e)
    if (c.edges.faces[e].size() == 1) {
      next[c.edges.edges[e][0]].push_back(c.edges.edges[e][1]);
      next[c.edges.edges[e][1]].push_back(c.edges.edges[e][0]);
    }
  for (const auto& [v, n] : next)
    if (n.size() != 2) return 0;  // not a set of simple loops
  std::unordered_map<int, bool> seen;
  size_t loops = 0;
  for (const auto& [v, n] : next) {
    if (seen[v]) continue;
    ++loops;
    std::vector<int> stack{v};
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      if (seen[u]) continue;
      seen[u] = true;
      for (int w : next[u]) stack.push_back(w);
    }
  }
  return loops;
}

void ExpectOnSurface(const Chain& c, const std::string& shape) {
  const auto udf = MakeShape(shape);
  // Seeds are projected to 1e-5 x diagonal and stored as float32.
  const double tol = 2e-5 * udf->Domain().Diagonal();
  for (const Vec3& v : c.mesh.vertices) ASSERT_LT(udf->Distance(v), tol) << shape;
}

class ChainTest : public ::testing::Test {
 protected:
  using ExtraOptions = std::map<std::string, std::vector<std::string>>;  // program -> its extra options
  bool ClosesTheSphereRing(int seed, const std::string& count, const ExtraOptions& extra);
  TempDir dir_;
};

TEST_F(ChainTest, SphereIsAClosedManifoldOfGoodTriangles) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  const Chain c = RunChain(dir_, "sphere", 800, 0.0, true);
  ASSERT_FALSE(c.mesh.faces.empty());
  EXPECT_EQ(c.topo.nonmanifold_edges, 0u);
  EXPECT_EQ(c.topo.boundary_edges, 0u);
  EXPECT_EQ(c.topo.components, 1u);
  EXPECT_EQ(c.topo.euler, 2);
  ExpectOnSurface(c, "sphere");
  const double tq = MeanQuality(c.mesh);
  std::printf("sphere: mean triangle quality %.3f\n", tq);
  EXPECT_GE(tq, 0.75);
}

TEST_F(ChainTest, TorusKeepsItsHandle) {
  const Chain c = RunChain(dir_, "torus", 3000, 0.012);
  EXPECT_EQ(c.topo.nonmanifold_edges, 0u);
  EXPECT_EQ(c.topo.boundary_edges, 0u);
  EXPECT_EQ(c.topo.euler, 0);
  ExpectOnSurface(c, "torus");
}

TEST_F(ChainTest, DiscAndHemisphereHaveOneBoundaryLoop) {
  for (const std::string shape : {"disc", "hemisphere"}) {
    TempDir dir;
    const Chain c = RunChain(dir, shape, 3000, 0.016);
    EXPECT_EQ(c.topo.nonmanifold_edges, 0u) << shape;
    EXPECT_EQ(c.topo.euler, 1) << shape;
    EXPECT_EQ(c.topo.components, 1u) << shape;
    EXPECT_EQ(BoundaryLoops(c), 1u) << shape;
    ExpectOnSurface(c, shape);
  }
}

TEST_F(ChainTest, CubeIsClosedAndKeepsItsCorners) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  // The corners need the optimiser: sample-seeds draws near the surface, so no seed starts on a corner; the
  // L1 step pulls the nearest ones there (rank 3) and the thinning must keep them.
  const Chain c = RunChain(dir_, "cube", 3000, 0.0, /*optimize=*/true);
  EXPECT_EQ(c.topo.nonmanifold_edges, 0u);
  EXPECT_EQ(c.topo.boundary_edges, 0u);
  EXPECT_EQ(c.topo.euler, 2);
  ExpectOnSurface(c, "cube");
  const double tol = 1e-3 * MakeShape("cube")->Domain().Diagonal();
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5, (k & 4) ? 0.5 : -0.5);
    double best = INFINITY;
    for (const Vec3& v : c.mesh.vertices) best = std::min(best, (v - corner).norm());
    EXPECT_LT(best, tol) << "corner " << corner.transpose();
  }
}

/// Distance from p to the closest point of the segment [a, b].
double SegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

/// Non-manifold edges exist, lie within `tol` of the curve (distance function `curve`), and cover it: sampled
/// along `param` (a point of the curve for t in [0, 1]), no gap between covered parameters exceeds `max_gap`.
template <typename CurveDistance, typename CurvePoint>
void ExpectNonManifoldCurve(const Chain& c, CurveDistance curve, CurvePoint param, double tol, double max_gap_len,
                            double curve_len, const char* shape) {
  std::vector<std::array<Vec3, 2>> nm;
  for (size_t e = 0; e < c.edges.edges.size(); ++e)
    if (c.edges.faces[e].size() >= 3) nm.push_back({c.mesh.vertices[c.edges.edges[e][0]], c.mesh.vertices[c.edges.edges[e][1]]});
  ASSERT_GT(nm.size(), 0u) << shape << ": no non-manifold edge";
  size_t far = 0;
  for (const auto& s : nm) {
    const double d = std::max(curve(s[0]), std::max(curve(s[1]), curve(0.5 * (s[0] + s[1]))));
    far += d > tol ? 1 : 0;
  }
  EXPECT_EQ(far, 0u) << shape << ": non-manifold edges away from the true curve (of " << nm.size() << ")";
  // Coverage: the parameters of the curve within tol of some non-manifold edge.
  const int samples = 2000;
  double gap = 0, worst = 0;
  for (int i = 0; i <= samples; ++i) {
    const Vec3 p = param(static_cast<double>(i) / samples);
    bool covered = false;
    for (const auto& s : nm)
      if (SegmentDistance(p, s[0], s[1]) < tol) {
        covered = true;
        break;
      }
    gap = covered ? 0 : gap + curve_len / samples;
    worst = std::max(worst, gap);
  }
  std::printf("%s: %zu non-manifold edges, longest uncovered stretch of the curve %.4f\n", shape, nm.size(), worst);
  EXPECT_LT(worst, max_gap_len) << shape;
}

// With optimised seeds: the curve seeds sit on the line, so every branching edge lies on it. Robustness
// (docs/thin-mesh.md "Known limits"): of 13 crossing-planes runs (1k-3k seeds, several --seed), 11 meet
// these criteria; the others have a fold one or two spacings from the line.
TEST_F(ChainTest, CrossingPlanesKeepTheirNonManifoldLine) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  const Chain c = RunChain(dir_, "crossing-planes", 3000, 0.0, true);
  const double diag = MakeShape("crossing-planes")->Domain().Diagonal();
  const double spacing = 0.016 * diag;
  // The line x = z = 0, |y| <= 0.5.
  auto dist = [](const Vec3& p) { return std::hypot(p.x(), p.z()) + std::max(0.0, std::abs(p.y()) - 0.5); };
  auto point = [](double t) { return Vec3(0.0, -0.5 + t, 0.0); };
  ExpectNonManifoldCurve(c, dist, point, 0.1 * spacing, 4 * spacing, 1.0, "crossing-planes");
  // Every branching edge has exactly the four half-planes' faces.
  for (size_t e = 0; e < c.edges.edges.size(); ++e) EXPECT_LE(c.edges.faces[e].size(), 4u);
  ExpectOnSurface(c, "crossing-planes");
}

// shape:fold's 35° crease (below the 44° the paper's rank test sees; optimize-seeds' two-plane test finds it):
// the mesh follows it with a chain of edges on the crease, and stays one disc.
TEST_F(ChainTest, FoldKeepsItsShallowCreaseAsAChainOfEdges) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  const Chain c = RunChain(dir_, "fold", 2000, 0.0, true);
  EXPECT_EQ(c.topo.nonmanifold_edges, 0u);
  EXPECT_EQ(c.topo.euler, 1);
  EXPECT_EQ(BoundaryLoops(c), 1u);
  ExpectOnSurface(c, "fold");
  double length = 0;
  for (const Edge& e : c.edges.edges) length += (c.mesh.vertices[e[1]] - c.mesh.vertices[e[0]]).norm();
  const double spacing = length / static_cast<double>(c.edges.edges.size());  // the mean edge length
  auto on_crease = [&](const Vec3& p) { return std::hypot(p.x(), p.z()) < 0.1 * spacing; };
  std::vector<std::array<Vec3, 2>> crease;
  for (const Edge& e : c.edges.edges)
    if (on_crease(c.mesh.vertices[e[0]]) && on_crease(c.mesh.vertices[e[1]]))
      crease.push_back({c.mesh.vertices[e[0]], c.mesh.vertices[e[1]]});
  // Every point of the crease within 0.1 spacing of an edge along it, but for a spacing at either end.
  double worst = 0;
  for (int i = 0; i <= 1000; ++i) {
    const Vec3 p(0.0, -0.5 + spacing + (1.0 - 2 * spacing) * i / 1000.0, 0.0);
    double best = INFINITY;
    for (const auto& s : crease) best = std::min(best, SegmentDistance(p, s[0], s[1]));
    worst = std::max(worst, best);
  }
  std::printf("fold: %zu edges on the crease, farthest crease point %.4f (spacing %.4f)\n", crease.size(), worst,
              spacing);
  EXPECT_LT(worst, 0.1 * spacing) << crease.size() << " edges on the crease";
}

// shape:feature-prism's sharp edges, each known in closed form (the edges of ShapeMesh): the share of each
// within 0.1 mean edge length of a mesh edge (evaluate's feature recall, per edge). The concave edge (at the
// L's inner corner), the chamfer's short top and bottom edges between two close corners and the two top and
// bottom edges meeting at 20° at the spike are traced; so is most of the spike's vertical edge, where the
// solid is thinner than a spacing (0.35 × the distance from it) — and only there the mesh has defects
// (non-manifold and boundary edges: the thin-feature limit, docs/thin-mesh.md "Known limits"). How much of
// the spike's edge is traced depends on the draw: over sample-seeds --seed 1-8, 0.92-1.0 (with 50 L-BFGS
// iterations per repulsion round, before 2026-12-08: 0.19-0.90, mean 0.63; with the paper's curve step and
// no chain filling, 0.24-0.98). So does the share of the concave corner's edges towards the spike: over
// --seed 1-6, 0.85-0.96 (0.87-0.97 with 50 L-BFGS iterations).
TEST_F(ChainTest, FeaturePrismTracesItsConcaveShortAndNarrowEdges) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  const Chain c = RunChain(dir_, "feature-prism", 2500, 0.0, true);
  ExpectOnSurface(c, "feature-prism");
  double length = 0;
  for (const Edge& e : c.edges.edges) length += (c.mesh.vertices[e[1]] - c.mesh.vertices[e[0]]).norm();
  const double spacing = length / static_cast<double>(c.edges.edges.size());
  const Vec3 apex(-0.5, 0.5, 0.0);
  for (size_t e = 0; e < c.edges.edges.size(); ++e) {
    if (c.edges.faces[e].size() == 2) continue;
    const Vec3 mid = 0.5 * (c.mesh.vertices[c.edges.edges[e][0]] + c.mesh.vertices[c.edges.edges[e][1]]);
    EXPECT_LT(std::hypot(mid.x() - apex.x(), mid.y() - apex.y()), 2.5 * spacing)
        << "a defect away from the spike: " << c.edges.faces[e].size() << " faces at " << mid.transpose();
  }
  // The prism's edges: polygon vertex i at the bottom is i, at the top n + i (ShapeMesh's layout).
  const TriangleMesh ref = ShapeMesh("feature-prism");
  const int n = static_cast<int>(ref.vertices.size() / 2);
  auto traced = [&](int a, int b) {
    const Vec3 &pa = ref.vertices[static_cast<size_t>(a)], &pb = ref.vertices[static_cast<size_t>(b)];
    int hit = 0;
    const int samples = 200;
    for (int k = 0; k < samples; ++k) {
      const Vec3 p = pa + (pb - pa) * ((k + 0.5) / samples);
      double best = INFINITY;
      for (const Edge& e : c.edges.edges)
        best = std::min(best, SegmentDistance(p, c.mesh.vertices[e[0]], c.mesh.vertices[e[1]]));
      hit += best < 0.1 * spacing ? 1 : 0;
    }
    return static_cast<double>(hit) / samples;
  };
  const int chamfer = 1, concave = 4, spike = 5;  // FeaturePrismPolygon's chamfer start, D and F
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const double vertical = traced(i, n + i), bottom = traced(i, j), top = traced(n + i, n + j);
    std::printf("feature-prism corner %d: vertical edge %.2f, bottom edge to %d %.2f, top %.2f\n", i, vertical, j,
                bottom, top);
    if (i != spike) {
      EXPECT_GE(vertical, 0.95) << "vertical edge " << i;
    }
    EXPECT_GE(std::min(bottom, top), i + 1 == spike ? 0.8 : i == chamfer || i + 1 > spike ? 0.9 : 0.95)
        << "edges " << i << "-" << j;
  }
  EXPECT_GE(traced(concave, n + concave), 0.95) << "the concave edge";
  EXPECT_GE(traced(spike, n + spike), 0.8) << "the spike's edge";
}

// Robustness (docs/thin-mesh.md "Known limits"): of 12 sphere-disc runs (1k-3k seeds, several --seed), 10
// meet these criteria; the others have a small hole beside the equator.
TEST_F(ChainTest, SphereWithInnerDiscKeepsItsEquator) {
  // optimize-seeds snaps seeds onto the equator (rank 2), so the branching edges lie on it. At 2,000 seeds:
  // pipelines/nonmanifold-sweep.sh passes sphere-disc in 5 of 5 runs there, in 4 of 5 at 1,000.
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  const Chain c = RunChain(dir_, "sphere-disc", 2000, 0.0, true);
  const double diag = MakeShape("sphere-disc")->Domain().Diagonal();
  const double spacing = 0.016 * diag / std::sqrt(2.0);
  auto dist = [](const Vec3& p) { return std::hypot(std::hypot(p.x(), p.y()) - 0.5, p.z()); };
  auto point = [](double t) { return Vec3(0.5 * std::cos(2 * M_PI * t), 0.5 * std::sin(2 * M_PI * t), 0.0); };
  ExpectNonManifoldCurve(c, dist, point, 0.1 * spacing, 4 * spacing, M_PI, "sphere-disc");
  EXPECT_EQ(c.topo.boundary_edges, 0u);
  // Sphere (2) + disc (1) glued along a circle (0): chi = 3; every branching edge has exactly 3 faces.
  EXPECT_EQ(c.topo.euler, 3);
  for (size_t e = 0; e < c.edges.edges.size(); ++e) EXPECT_LE(c.edges.faces[e].size(), 3u);
  ExpectOnSurface(c, "sphere-disc");
}

// Issue #17's thin part: shape:sphere-ring is a sphere inside a ring whose tube (radius 0.03) is about one
// spacing of 700 uniform seeds around (docs/sample-seeds.md, "Thin parts"). The whole chain with default
// options must close the tube (the mesh: two closed components, the sphere and a torus, chi 2 + 0, no
// boundary or non-manifold edge) in a fair share of --seed 0-7. optimize-seeds --l1-curve-step free
// --feature-gap-max 0 (the paper's curve step, no chain filling) closes it in none of them, so the test fails
// without the feature chains.
// Runs the chain on shape:sphere-ring (a sphere inside a ring whose tube is 0.06 across) with `count` seeds
// and the programs' `extra` options; whether the mesh is the sphere and the closed torus (two components,
// χ = 2 + 0, no boundary or non-manifold edge).
bool ChainTest::ClosesTheSphereRing(int seed, const std::string& count, const ExtraOptions& extra) {
  const std::string udf = "shape:sphere-ring", s = std::to_string(seed);
  const std::string base = dir_ / ("ring-" + count + "-" + s + (extra.count("sample-seeds") ? "-boost" : ""));
  for (const auto& [program, args] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"sample-seeds", {"--count", count, "-o", base + "seeds0.ply"}},
           {"optimize-seeds", {"-i", base + "seeds0.ply", "-o", base + "seeds.ply"}},
           {"build-gvd", {"-i", base + "seeds.ply", "-o", base + "thick.ply"}},
           {"thin-mesh", {"-i", base + "thick.ply", "-o", base + "mesh.ply"}}}) {
    std::vector<std::string> all = {"--udf", udf, "-q"};
    if (program != "thin-mesh") all.insert(all.end(), {"--seed", s});  // thin-mesh draws nothing
    all.insert(all.end(), args.begin(), args.end());
    if (const auto it = extra.find(program); it != extra.end()) all.insert(all.end(), it->second.begin(), it->second.end());
    const auto r = RunProgram(program, all);
    EXPECT_EQ(r.exit_code, 0) << program << ":\n" << r.err;
    if (r.exit_code != 0) return false;
  }
  const TopologyStats t = ComputeTopology(ReadMeshPly(base + "mesh.ply"));
  return t.components == 2 && t.euler == 2 && t.boundary_edges == 0 && t.nonmanifold_edges == 0;
}

TEST_F(ChainTest, TheDefaultChainClosesTheSphereRingsThinTube) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  int closed_runs = 0;
  for (int seed = 0; seed < 8; ++seed) closed_runs += ClosesTheSphereRing(seed, "700", {});
  std::printf("sphere-ring, 700 seeds: tube closed in %d of 8 runs\n", closed_runs);
  // About half the draws close it (24 draws: 11 and 12 with two L1 solvers that agree within 1e-6 of the
  // diagonal, 2 and 4 of the first 8): which ones is chaotic, so the test asks for a rate that is not near 0.
  EXPECT_GE(closed_runs, 2);
}

// At 500 seeds uniform ones leave two or three round the tube, too few to close it; --thin-boost 6 puts
// about eight there (more than half the seeds), taken from the sphere, and the tube comes out closed (7 of
// --seed 0-7; which draws close is chaotic, as above, so the test asks for a rate). Both with optimize-seeds --curved-sheets, without which the tube's cells are rank 2 and its
// seeds a feature chain that thins itself out, and build-gvd --ball-shares seed, without which the tube's
// regions get fewer samples than the sphere's (7 of 8 closed, 3 of 8 at --thin-boost 4).
TEST_F(ChainTest, ThinBoostClosesTheTubeThatUniformSeedsCannot) {
  if (!HaveOptimizer()) GTEST_SKIP() << "optimize-seeds is not built";
  int uniform = 0, boosted = 0;
  for (int seed = 0; seed < 8; ++seed) {
    const ExtraOptions thin = {{"optimize-seeds", {"--curved-sheets", "true"}}, {"build-gvd", {"--ball-shares", "seed"}}};
    uniform += ClosesTheSphereRing(seed, "500", thin);
    ExtraOptions boost = thin;
    boost["sample-seeds"] = {"--thin-boost", "6"};
    boosted += ClosesTheSphereRing(seed, "500", boost);
  }
  std::printf("sphere-ring, 500 seeds: tube closed in %d of 8 runs from uniform seeds, %d of 8 with --thin-boost 6\n",
              uniform, boosted);
  EXPECT_LE(uniform, 1);
  EXPECT_GE(boosted, 5);
}

}  // namespace
}  // namespace voroudf

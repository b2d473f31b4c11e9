// build-gvd: the geodesic labelling against closed-form geodesics, the graph pruning, the dual triangles,
// determinism across thread counts, and the executable's handling of bad input.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <set>

#include "common/errors.h"
#include "common/mesh_topology.h"
#include "common/mesh_udf.h"
#include "common/rng.h"
#include "common/shapes.h"
#include "formats/labels_io.h"
#include "formats/mesh_io.h"
#include "stages/build-gvd/build_gvd.h"
#include "stages/build-gvd/geodesic_sweep.h"
#include "stages/sample-seeds/sample_seeds.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

SeedCloud Seeds(const Udf& udf, size_t count, uint64_t seed = 3) {
  SampleSeedsOptions o;
  o.count = count;
  o.seed = seed;
  return SampleSeeds(udf, o, Monitor::Null());
}

double GreatCircle(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return 0.5 * std::acos(c);
}

TEST(BuildGvd, LabelsAreTheGeodesicallyNearestSeedOnTheSphere) {
  const auto udf = MakeShape("sphere");
  const SeedCloud seeds = Seeds(*udf, 60);
  // The density is fixed here, not taken from the default: the bound on the paths' zigzag below is one of a
  // 12k-sample graph (6k samples: 1.42).
  BuildGvdOptions o;
  o.samples_per_seed = 200;
  const GvdResult r = BuildGvd(*udf, seeds, o, false, Monitor::Null());
  ASSERT_GT(r.samples.size(), 60u * 100u);
  EXPECT_EQ(r.stats.unreached, 0u);
  size_t agree = 0, close_calls = 0;
  double worst_ratio = 0;
  for (size_t s = 0; s < r.samples.size(); ++s) {
    const Vec3& p = r.samples.position[s];
    const int l = r.samples.label[s];
    ASSERT_GE(l, 0);
    // The true geodesic Voronoi label (great circles); ties within 3% are not held against the graph.
    double best = INFINITY, second = INFINITY;
    int best_i = -1;
    for (size_t i = 0; i < seeds.size(); ++i) {
      const double g = GreatCircle(p, seeds.position[i]);
      if (g < best) {
        second = best;
        best = g;
        best_i = static_cast<int>(i);
      } else if (g < second) {
        second = g;
      }
    }
    if (second - best < 0.03 * best) {
      ++close_calls;
      continue;
    }
    agree += (l == best_i) ? 1 : 0;
    // The graph distance is a path through samples: never shorter than the geodesic, and not much longer.
    const double g = GreatCircle(p, seeds.position[static_cast<size_t>(l)]);
    if (g > 0.1) worst_ratio = std::max(worst_ratio, r.samples.dist[s] / g);
    EXPECT_GE(r.samples.dist[s], 0.99 * g - 1e-6);  // chords are a little shorter than arcs
  }
  const size_t judged = r.samples.size() - close_calls;
  EXPECT_GT(static_cast<double>(agree), 0.99 * static_cast<double>(judged));
  EXPECT_LT(worst_ratio, 1.4);  // zigzag of a sparse kNN graph
}

// A graph in CSR form from an edge list (both directions).
struct CsrGraph {
  std::vector<size_t> offset;
  std::vector<int> adj;
};
CsrGraph Csr(size_t n, const std::vector<std::pair<int, int>>& edges) {
  CsrGraph g;
  std::vector<std::vector<int>> lists(n);
  for (const auto& [a, b] : edges) {
    lists[static_cast<size_t>(a)].push_back(b);
    lists[static_cast<size_t>(b)].push_back(a);
  }
  g.offset.push_back(0);
  for (const auto& l : lists) {
    g.adj.insert(g.adj.end(), l.begin(), l.end());
    g.offset.push_back(g.adj.size());
  }
  return g;
}

// Bellman-Ford to its fixed point, in the sweep's order of (distance, label): the least over all paths from
// the nodes with node_seed >= 0, with the sweep's arithmetic (a path's length summed in path order).
void LeastPathsByBellmanFord(const CsrGraph& g, const std::vector<Vec3>& node, const std::vector<int>& node_seed,
                             std::vector<double>* d_out, std::vector<int>* label_out) {
  const size_t n = node.size();
  std::vector<double>& d = *d_out;
  std::vector<int>& label = *label_out;
  d.assign(n, INFINITY);
  label.assign(n, -1);
  for (size_t i = 0; i < n; ++i)
    if (node_seed[i] >= 0) {
      d[i] = 0.0;
      label[i] = node_seed[i];
    }
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t u = 0; u < n; ++u)
      for (size_t a = g.offset[u]; a < g.offset[u + 1]; ++a) {
        const size_t v = static_cast<size_t>(g.adj[a]);
        const double dv = d[u] + (node[v] - node[u]).norm();
        if (dv < d[v] || (dv == d[v] && label[u] < label[v])) {
          d[v] = dv;
          label[v] = label[u];
          changed = true;
        }
      }
  }
}

// The sweep is an exact multi-source shortest-path labelling of its own graph: every node's distance equals,
// to the bit, the fixed point Bellman-Ford reaches over the written graph with the same arithmetic, and so
// does its label (the lower seed index where two are equally near).
TEST(BuildGvd, TheSweepIsExactShortestPathsOverItsGraph) {
  const auto udf = MakeShape("torus");
  const SeedCloud seeds = Seeds(*udf, 80);
  const GvdResult r = BuildGvd(*udf, seeds, BuildGvdOptions{}, true, Monitor::Null());
  const LabeledSamples& g = r.samples;
  const size_t n = g.size();
  ASSERT_GT(g.edges.size(), n);
  std::vector<int> node_seed(n, -1);
  size_t sources = 0;
  for (size_t i = 0; i < n; ++i)
    if (g.dist[i] == 0.0) {
      node_seed[i] = g.label[i];
      ++sources;
    }
  ASSERT_EQ(sources, seeds.size());
  std::vector<std::pair<int, int>> edges;
  for (const auto& e : g.edges) edges.emplace_back(e[0], e[1]);
  std::vector<double> d;
  std::vector<int> label;
  LeastPathsByBellmanFord(Csr(n, edges), g.position, node_seed, &d, &label);
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(g.dist[i], std::isfinite(d[i]) ? d[i] : -1.0) << "node " << i;
    ASSERT_EQ(g.label[i], label[i]) << "node " << i;
  }
}

// The sweep over ranges swept apart and joined gives the sequential sweep's answer for any number of
// ranges and threads, including every tie: on a unit grid the path lengths are exact integers, so a node
// halfway between two seeds is reached by both at the same distance and goes to the lower seed index.
TEST(GeodesicSweep, AnyNumberOfRangesGivesTheSameLeastPathsAndTies) {
  const int side = 40;
  std::vector<Vec3> node;
  std::vector<std::pair<int, int>> edges;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      node.emplace_back(x, y, 0.0);
      const int i = y * side + x;
      if (x + 1 < side) edges.emplace_back(i, i + 1);
      if (y + 1 < side && (x % 7 != 3 || y > 30)) edges.emplace_back(i, i + side);  // walls with a gap
    }
  node.emplace_back(100.0, 0.0, 0.0);  // unreached
  const size_t n = node.size();
  const CsrGraph g = Csr(n, edges);
  std::vector<int> node_seed(n, -1);
  const int sources[] = {5 * side + 5, 5 * side + 15, 25 * side + 10, 35 * side + 33, 12 * side + 38, 0};
  for (int s = 0; s < 6; ++s) node_seed[static_cast<size_t>(sources[s])] = 5 - s;
  std::vector<double> dist1;
  std::vector<int> label1;
  GeodesicSweep(g.offset, g.adj, node, node_seed, 1, &dist1, &label1, Monitor::Null());
  EXPECT_EQ(label1[n - 1], -1);
  EXPECT_TRUE(std::isinf(dist1[n - 1]));
  // Ties exist and went to the lower index: node (10, 5) is 5 from the seeds at (5, 5) and (15, 5).
  EXPECT_EQ(dist1[5 * side + 10], 5.0);
  EXPECT_EQ(label1[5 * side + 10], std::min(node_seed[5 * side + 5], node_seed[5 * side + 15]));
  const int threads = omp_get_max_threads();
  for (int t : {1, 3})
    for (size_t parts : {size_t{2}, size_t{3}, size_t{7}, size_t{64}, n}) {
      omp_set_num_threads(t);
      std::vector<double> dist;
      std::vector<int> label;
      GeodesicSweep(g.offset, g.adj, node, node_seed, parts, &dist, &label, Monitor::Null());
      EXPECT_EQ(dist, dist1) << parts << " ranges, " << t << " threads";
      EXPECT_EQ(label, label1) << parts << " ranges, " << t << " threads";
    }
  omp_set_num_threads(threads);
}

// Random points, each joined to its 6 nearest: the ranges cut paths that leave a range and come back, and
// the result is the least over all paths (the Bellman-Ford fixed point, to the bit) for any number of them.
TEST(GeodesicSweep, RangesJoinedGiveTheBellmanFordFixedPoint) {
  Rng rng(11, 0);
  const size_t n = 3000;
  std::vector<Vec3> node(n);
  for (Vec3& p : node) p = Vec3(rng.Uniform(), rng.Uniform(), 0.1 * rng.Uniform());
  std::vector<std::pair<int, int>> edges;
  for (size_t i = 0; i < n; ++i) {
    std::vector<std::pair<double, int>> near;
    for (size_t j = 0; j < n; ++j)
      if (j != i) near.emplace_back((node[j] - node[i]).squaredNorm(), static_cast<int>(j));
    std::partial_sort(near.begin(), near.begin() + 6, near.end());
    for (int k = 0; k < 6; ++k)
      if (static_cast<int>(i) < near[static_cast<size_t>(k)].second) edges.emplace_back(static_cast<int>(i), near[static_cast<size_t>(k)].second);
  }
  const CsrGraph g = Csr(n, edges);
  std::vector<int> node_seed(n, -1);
  for (int s = 0; s < 40; ++s) node_seed[static_cast<size_t>(rng.Below(n))] = s;
  std::vector<double> d;
  std::vector<int> label;
  LeastPathsByBellmanFord(g, node, node_seed, &d, &label);
  for (size_t parts : {size_t{1}, size_t{2}, size_t{5}, size_t{100}}) {
    std::vector<double> dist;
    std::vector<int> got;
    GeodesicSweep(g.offset, g.adj, node, node_seed, parts, &dist, &got, Monitor::Null());
    EXPECT_EQ(dist, d) << parts << " ranges";
    EXPECT_EQ(got, label) << parts << " ranges";
  }
}

TEST(BuildGvd, SeedsLabelThemselvesAndEveryDualTriangleIsDistinct) {
  const auto udf = MakeShape("sphere");
  const SeedCloud seeds = Seeds(*udf, 200);
  const GvdResult r = BuildGvd(*udf, seeds, BuildGvdOptions{}, true, Monitor::Null());
  size_t seed_nodes = 0;
  for (size_t s = 0; s < r.samples.size(); ++s)
    for (size_t i = 0; i < seeds.size(); ++i)
      if (r.samples.position[s] == seeds.position[i]) {
        ++seed_nodes;
        EXPECT_EQ(r.samples.label[s], static_cast<int>(i));
        EXPECT_EQ(r.samples.dist[s], 0.0);
      }
  EXPECT_EQ(seed_nodes, seeds.size());
  EXPECT_EQ(r.thick.vertices.size(), seeds.size());
  // Every dual triangle joins three distinct seeds and appears once.
  std::set<Tri> unique(r.thick.faces.begin(), r.thick.faces.end());
  EXPECT_EQ(unique.size(), r.thick.faces.size());
  for (const Tri& t : r.thick.faces) EXPECT_TRUE(t[0] < t[1] && t[1] < t[2]);
  // Every pruned edge in the graph passes both tests.
  const double eps = BuildGvdOptions{}.eps_udf_rel * udf->Domain().Diagonal();
  ASSERT_FALSE(r.samples.edges.empty());
  for (size_t e = 0; e < r.samples.edges.size(); e += 97) {
    const Vec3 a = r.samples.position[static_cast<size_t>(r.samples.edges[e][0])];
    const Vec3 b = r.samples.position[static_cast<size_t>(r.samples.edges[e][1])];
    EXPECT_LE(udf->Distance(0.5 * (a + b)), eps);
  }
}

TEST(BuildGvd, TheGraphDoesNotJumpBetweenSheetsAwayFromTheirIntersection) {
  // Crossing planes z = 0 and x = 0: a kept edge joins the two planes only near the line x = z = 0.
  const auto udf = MakeShape("crossing-planes");
  const SeedCloud seeds = Seeds(*udf, 300);
  const GvdResult r = BuildGvd(*udf, seeds, BuildGvdOptions{}, true, Monitor::Null());
  size_t across = 0;
  for (const auto& e : r.samples.edges) {
    const Vec3& a = r.samples.position[static_cast<size_t>(e[0])];
    const Vec3& b = r.samples.position[static_cast<size_t>(e[1])];
    const bool a_z = std::abs(a.z()) < 1e-6, b_z = std::abs(b.z()) < 1e-6;
    const bool a_x = std::abs(a.x()) < 1e-6, b_x = std::abs(b.x()) < 1e-6;
    if ((a_z && !a_x && b_x && !b_z) || (a_x && !a_z && b_z && !b_x)) {
      ++across;
      // Both ends within twice the UDF threshold of the line.
      const double eps = BuildGvdOptions{}.eps_udf_rel * udf->Domain().Diagonal();
      EXPECT_LT(std::min(std::hypot(a.x(), a.z()), std::hypot(b.x(), b.z())), 2.0 * eps + 1e-9);
    }
  }
  EXPECT_GT(across, 0u) << "the sheets must connect across the non-manifold line";
}

// Seeds on crossing-planes at spacing h: a row on the line x = z = 0 (rank 2), a grid on each of the four
// half-planes from `gap` away from the line (rank 1, the plane's normal).
SeedCloud CrossingSeeds(double h, double gap) {
  SeedCloud s;
  auto add = [&](const Vec3& p, const Vec3& n, uint8_t rank) {
    s.position.push_back(p);
    s.normal.push_back(n);
    s.udf.push_back(0.0);
    s.rank.push_back(rank);
  };
  for (double y = -0.45; y < 0.46; y += h) {
    add({0.0, y, 0.0}, {0.0, 0.0, 1.0}, kRankEdge);
    for (double t = gap; t < 0.46; t += h)
      for (double sign : {-1.0, 1.0}) {
        add({sign * t, y, 0.0}, {0.0, 0.0, 1.0}, kRankSheet);
        add({0.0, y, sign * t}, {1.0, 0.0, 0.0}, kRankSheet);
      }
  }
  return s;
}

// Samples on the plane z = 0 within 0.2 h of the crossing line, per unit width, over those 1-2 h from it
// (away from the squares' rims).
double DensityAtTheCrossing(const GvdResult& r, double h) {
  double near = 0.0, far = 0.0;
  for (const Vec3& p : r.samples.position) {
    if (std::abs(p.z()) > 1e-9 || std::abs(p.y()) > 0.3) continue;
    const double x = std::abs(p.x());
    if (x > 1e-9 && x < 0.2 * h) near += 1.0;
    if (x > 1.0 * h && x < 2.0 * h) far += 1.0;
  }
  return (near / (0.2 * h)) / (far / h);
}

TEST(BuildGvd, CurveSeedsSampleEverySheetEvenlyUpToTheCrossing) {
  // A ball around a seed on the line projects onto the nearer plane: each of the four half-planes gets a
  // 90-degree wedge, whose points land ever sparser towards the line. Drawn again in their tangent planes,
  // they cover each plane evenly up to the line, where the Voronoi vertices of the line's seeds are. The
  // sheet seeds start 4 spacings away, so that within 2 spacings of the line the samples are the line
  // seeds' (their balls reach 3 spacings: the 6th-nearest seed is 3 along the line).
  const auto udf = MakeShape("crossing-planes");
  const double h = 0.05;
  const SeedCloud seeds = CrossingSeeds(h, 4.0 * h);
  BuildGvdOptions ball;
  ball.curve_samples = "ball";
  const GvdResult with_ball = BuildGvd(*udf, seeds, ball, false, Monitor::Null());
  const GvdResult tangent = BuildGvd(*udf, seeds, BuildGvdOptions{}, false, Monitor::Null());
  EXPECT_EQ(with_ball.stats.samples_redrawn, 0u);
  EXPECT_GT(tangent.stats.samples_redrawn, 0u);
  const double ball_density = DensityAtTheCrossing(with_ball, h), tangent_density = DensityAtTheCrossing(tangent, h);
  EXPECT_LT(ball_density, 0.5) << "the ball's wedges thin out at the line";
  EXPECT_GT(tangent_density, 0.85) << "as dense at the line as 1-2 spacings away";
  EXPECT_LT(tangent_density, 1.5);
  // Every redrawn sample is on the surface, within the projection's tolerance.
  std::vector<double> d;
  std::vector<Vec3> g;
  udf->Evaluate(tangent.samples.position, d, g);
  const double tol = 1.01 * BuildGvdOptions{}.proj_tol_rel * udf->Domain().Diagonal();
  for (double v : d) ASSERT_LT(v, tol);
}

TEST(BuildGvd, OverPrunedGraphsLeaveUnreachedSamplesCounted) {
  const auto udf = MakeShape("sphere");
  const SeedCloud seeds = Seeds(*udf, 100);
  BuildGvdOptions o;
  o.eps_udf_rel = 1e-9;  // every edge between distinct points of the curved sphere bends off it by more
  EXPECT_THROW(BuildGvd(*udf, seeds, o, false, Monitor::Null()), NumericalError);
  o.eps_udf_rel = 5e-5;  // only the shortest edges survive: some samples are cut off from every seed
  const GvdResult r = BuildGvd(*udf, seeds, o, false, Monitor::Null());
  size_t minus_one = 0;
  for (size_t s = 0; s < r.samples.size(); ++s)
    if (r.samples.label[s] < 0) {
      ++minus_one;
      EXPECT_EQ(r.samples.dist[s], -1.0);
    }
  EXPECT_EQ(minus_one, r.stats.unreached);
  EXPECT_GT(r.stats.edges_pruned_udf, 0u);
}

// build-gvd queries a midpoint only when neither the Lipschitz bound from the edge's ends, min(d(a), d(b)) +
// |ab|/2, nor the one from the node nearest the midpoint, d(c) + |mid - c|, keeps the rise under eps_udf; the
// kept graph must still be exactly the edges whose midpoint is within eps_udf (checked here by querying all).
TEST(BuildGvd, KeptEdgesHaveTheirMidpointWithinEpsUdf) {
  const auto udf = MakeShape("sphere");
  const SeedCloud seeds = Seeds(*udf, 100);
  BuildGvdOptions o;
  o.eps_udf_rel = 2e-4;  // between the shortest and the longest edges' sagitta bounds: some edges go
  const GvdResult r = BuildGvd(*udf, seeds, o, true, Monitor::Null());
  ASSERT_FALSE(r.samples.edges.empty());
  EXPECT_GT(r.stats.edges_pruned_udf, 0u);
  const double eps = o.eps_udf_rel * udf->Domain().Diagonal();
  size_t long_kept = 0;
  for (const auto& e : r.samples.edges) {
    const Vec3 a = r.samples.position[static_cast<size_t>(e[0])], b = r.samples.position[static_cast<size_t>(e[1])];
    EXPECT_LE(udf->Distance(0.5 * (a + b)), eps);
    long_kept += 0.5 * (b - a).norm() > eps;  // edges the bound alone could not accept
  }
  EXPECT_GT(long_kept, 0u);
  // Where a node lies within eps_udf of the midpoint it settles the test: fewer midpoints asked than uncertain.
  EXPECT_GT(r.stats.midpoints_uncertain, 0u);
  EXPECT_LT(r.stats.midpoints_queried, r.stats.midpoints_uncertain);
}

// A closed plate [-0.4, 0.4]^2 x [-t/2, t/2] as a mesh UDF (12 triangles).
std::unique_ptr<Udf> Plate(double t) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back({(i & 1) ? 0.4 : -0.4, (i & 2) ? 0.4 : -0.4, (i & 4) ? 0.5 * t : -0.5 * t});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.faces.push_back({q[0], q[1], q[2]});
    m.faces.push_back({q[0], q[2], q[3]});
  }
  return std::make_unique<MeshUdf>(std::move(m), "plate");
}

// Graph edges from the plate's top face to its bottom face, away from the rims.
size_t EdgesThroughTheWall(const GvdResult& r, double t) {
  size_t through = 0;
  for (const auto& e : r.samples.edges) {
    const Vec3& a = r.samples.position[static_cast<size_t>(e[0])];
    const Vec3& b = r.samples.position[static_cast<size_t>(e[1])];
    const bool inner = std::max({std::abs(a.x()), std::abs(a.y()), std::abs(b.x()), std::abs(b.y())}) < 0.3;
    through += inner && std::abs(a.z() - b.z()) > 0.9 * t;
  }
  return through;
}

// A coarse graph (30 samples per seed) whose midpoint test (0.05 x diagonal) cannot see the plate's wall.
BuildGvdOptions PlateGraphOptions() {
  BuildGvdOptions o;
  o.samples_per_seed = 30;
  o.eps_udf_rel = 0.05;
  return o;
}

TEST(BuildGvd, TheGraphDoesNotCrossAWallThinnerThanItsReach) {
  // The wall (t = 0.045) is thinner than twice eps_udf (here 0.05 x diagonal), so no midpoint rises far
  // enough for the UDF test, and the graph's longest edges (30 samples per seed) are about 1.25 t, so the
  // edges through the wall are too oblique to the faces' normals for the one-end test (|cos| > 0.97): only
  // the both-ends test sees them (|cos| >= t / length > 0.8 at both ends).
  const double t = 0.045;
  const auto udf = Plate(t);
  const SeedCloud seeds = Seeds(*udf, 200);
  BuildGvdOptions o = PlateGraphOptions();
  o.eps_grad_both = 1.0;  // off
  o.eps_grad_wall = 1.0;  // off
  const GvdResult off = BuildGvd(*udf, seeds, o, true, Monitor::Null());
  EXPECT_GT(EdgesThroughTheWall(off, t), 100u) << "the setting must put edges through the wall";
  o.eps_grad_both = BuildGvdOptions{}.eps_grad_both;
  const GvdResult on = BuildGvd(*udf, seeds, o, true, Monitor::Null());
  EXPECT_EQ(EdgesThroughTheWall(on, t), 0u);
  EXPECT_GT(on.stats.edges_pruned_grad, off.stats.edges_pruned_grad);
  EXPECT_EQ(on.stats.unreached, 0u);  // each face stays connected to its own seeds
}

TEST(BuildGvd, TheGraphDoesNotJoinTwoParallelSheetsAtAnAngle) {
  // A thinner wall (t = 0.025) under the same graph: its edges through the wall are up to about 2 t long,
  // |cos| with the faces' normals down to 0.5 at both ends, which the both-ends test (0.8) lets through. Their
  // ends' normals are parallel: the wall test (0.4) cuts them, and with them every dual triangle that joined
  // a seed on the top face to one on the bottom face.
  const double t = 0.025;
  const auto udf = Plate(t);
  const SeedCloud seeds = Seeds(*udf, 200);
  BuildGvdOptions o = PlateGraphOptions();
  o.eps_grad_wall = 1.0;  // off
  const GvdResult off = BuildGvd(*udf, seeds, o, true, Monitor::Null());
  o.eps_grad_wall = BuildGvdOptions{}.eps_grad_wall;
  const GvdResult on = BuildGvd(*udf, seeds, o, true, Monitor::Null());
  auto across = [&](const GvdResult& r) {  // dual triangles with seeds on both faces, away from the rims
    size_t n = 0;
    for (const Tri& f : r.thick.faces) {
      bool top = false, bottom = false, inner = true;
      for (int v : f) {
        const Vec3& p = r.thick.vertices[static_cast<size_t>(v)];
        inner = inner && std::max(std::abs(p.x()), std::abs(p.y())) < 0.3;
        top = top || p.z() > 0.25 * t;
        bottom = bottom || p.z() < -0.25 * t;
      }
      n += inner && top && bottom;
    }
    return n;
  };
  EXPECT_GT(EdgesThroughTheWall(off, t), 100u) << "the setting must put edges through the wall";
  EXPECT_GT(across(off), 10u) << "the setting must let the regions leak through the wall";
  EXPECT_EQ(EdgesThroughTheWall(on, t), 0u);
  EXPECT_EQ(across(on), 0u);
  EXPECT_EQ(on.stats.unreached, 0u);
}

// The plane z = 0 seen through a field error, as a noisy or learned field shows it: where x < 0 a floor (d =
// |z| + a), where x >= 0 two zero sheets at z = +-a with a flat valley of height a/5 between them (no ridge
// of height a, so the projection's twin merge leaves them). With `floor` false, x < 0 has the two sheets too:
// an exact field of two real sheets 2a apart, no floor anywhere.
class TwinsBesideAFloor final : public Udf {
 public:
  TwinsBesideAFloor(double a, bool floor) : a_(a), floor_(floor) {}
  void EvaluateChunk(const Vec3* p, size_t count, double* d, Vec3* g) const override {
    for (size_t i = 0; i < count; ++i) {
      const double z = p[i].z(), up = z < 0 ? -1.0 : 1.0;
      if (floor_ && p[i].x() < 0) {
        d[i] = std::abs(z) + a_;
        g[i] = Vec3(0, 0, up);
      } else {
        d[i] = std::abs(z) >= a_ ? std::abs(z) - a_ : std::min(a_ - std::abs(z), 0.2 * a_);
        g[i] = Vec3(0, 0, std::abs(z) >= a_ ? up : -up);
      }
    }
  }
  Box Domain() const override { return {Vec3::Constant(-1), Vec3::Constant(1)}; }
  std::string Describe() const override { return "twins beside a floor"; }

 private:
  double a_;
  bool floor_;
};

// Graph edges from z = +a to z = -a (x in [0.1, 0.9], away from the seam at x = 0) that the wall test alone
// could cut: |cos(edge, gradient)| above eps_grad_wall at both ends.
size_t EdgesAcrossTheTwins(const GvdResult& r, double a, double wall) {
  size_t n = 0;
  for (const auto& e : r.samples.edges) {
    const Vec3& p = r.samples.position[static_cast<size_t>(e[0])];
    const Vec3& q = r.samples.position[static_cast<size_t>(e[1])];
    const bool far = std::min(p.x(), q.x()) > 0.1 && std::max(p.x(), q.x()) < 0.9;
    const bool across = std::abs(p.z() + q.z()) < 0.1 * a && std::abs(p.z() - q.z()) > 1.9 * a;
    n += far && across && 2 * a / (q - p).norm() > wall;
  }
  return n;
}

TEST(BuildGvd, SheetsCloserThanTheFieldsTwinSeparationAreNoWall) {
  // Where the field has floors, the projection measures its error (twin separation 2.5 a here): two sheets
  // closer than that are one surface seen through it, and the graph keeps its edges between them. On an
  // exact field (no floor, twin separation 0) the same two sheets are a wall, and the wall test cuts them.
  const double a = 2e-3;
  BuildGvdOptions o;
  o.samples_per_seed = 30;
  const TwinsBesideAFloor noisy(a, true), exact(a, false);
  const GvdResult kept = BuildGvd(noisy, Seeds(noisy, 300), o, true, Monitor::Null());
  EXPECT_GT(EdgesAcrossTheTwins(kept, a, o.eps_grad_wall), 50u);
  const GvdResult cut = BuildGvd(exact, Seeds(exact, 300), o, true, Monitor::Null());
  EXPECT_EQ(EdgesAcrossTheTwins(cut, a, o.eps_grad_wall), 0u);
}

TEST(BuildGvd, SameResultWhateverTheThreadCount) {
  const auto udf = MakeShape("three-discs");
  const SeedCloud seeds = Seeds(*udf, 300);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const GvdResult one = BuildGvd(*udf, seeds, BuildGvdOptions{}, true, Monitor::Null());
  omp_set_num_threads(std::max(2, threads));
  const GvdResult many = BuildGvd(*udf, seeds, BuildGvdOptions{}, true, Monitor::Null());
  omp_set_num_threads(threads);
  EXPECT_EQ(one.thick.faces, many.thick.faces);
  EXPECT_EQ(one.samples.position, many.samples.position);
  EXPECT_EQ(one.samples.label, many.samples.label);
  EXPECT_EQ(one.samples.dist, many.samples.dist);
  EXPECT_EQ(one.samples.edges, many.samples.edges);
}

// Seeds packed round shape:sphere-ring's thin tube (sample-seeds --thin-boost) have small balls: shared out by
// area they get few samples each, as many per seed with --ball-shares seed.
TEST(BuildGvd, BallSharesBySeedKeepTheSamplesPerRegionWhereSeedsAreDense) {
  const auto udf = MakeShape("sphere-ring");
  SampleSeedsOptions so;
  so.count = 500;
  so.thin_boost = 6;
  const SeedCloud seeds = SampleSeeds(*udf, so, Monitor::Null());
  auto ratio = [&](const std::string& shares) {  // mean samples per tube region / per sphere region
    BuildGvdOptions o;
    o.ball_shares = shares;
    const GvdResult r = BuildGvd(*udf, seeds, o, false, Monitor::Null());
    double tube = 0, sphere = 0, tube_seeds = 0, sphere_seeds = 0;
    for (const Vec3& p : seeds.position) (p.norm() > 0.42 ? tube_seeds : sphere_seeds) += 1;
    for (size_t i = 0; i < r.samples.size(); ++i)
      if (r.samples.label[i] >= 0) (seeds.position[static_cast<size_t>(r.samples.label[i])].norm() > 0.42 ? tube : sphere) += 1;
    return (tube / tube_seeds) / (sphere / sphere_seeds);
  };
  const double area = ratio("area"), per_seed = ratio("seed");
  std::printf("samples per tube region / per sphere region: %.2f by area, %.2f by seed\n", area, per_seed);
  EXPECT_LT(area, 0.4);
  EXPECT_GT(per_seed, 0.6);
}

// --curve-sample-weight: a curve seed's ball gets W times a sheet seed's samples of the same radius. On the
// sphere, with the seeds of the upper half marked as curve seeds (rank 2) and even spacing, the regions of the
// upper half then hold f + (1 - f) W times the samples they hold at W = 1 (against the lower half's, away from
// the equator), f the box share, and the draw counts exactly the weighted total.
TEST(BuildGvd, CurveSeedsGetTheirWeightOfTheBallSamples) {
  const auto udf = MakeShape("sphere");
  SeedCloud seeds = Seeds(*udf, 300);
  size_t curve = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    seeds.rank[i] = seeds.position[i].z() > 0.0 ? 2 : 1;
    curve += seeds.rank[i] == 2 ? 1 : 0;
  }
  auto ratio = [&](double weight) {  // mean samples per upper region / per lower region
    BuildGvdOptions o;
    o.curve_sample_weight = weight;
    const GvdResult r = BuildGvd(*udf, seeds, o, false, Monitor::Null());
    const double n = static_cast<double>(seeds.size()), unweighted = o.samples_per_seed * n;
    const double box = std::round(o.space_fraction * unweighted);
    const double expected = box + std::round((unweighted - box) * (n + (weight - 1.0) * static_cast<double>(curve)) / n);
    EXPECT_EQ(static_cast<double>(r.stats.samples_drawn), expected) << "weight " << weight;
    // Regions more than a ball's radius (about two spacings) from the equator: balls overlap their neighbours'.
    auto far = [&](size_t s) { return std::abs(seeds.position[s].z()) > 0.25; };
    double upper = 0, lower = 0, upper_seeds = 0, lower_seeds = 0;
    for (size_t s = 0; s < seeds.size(); ++s)
      if (far(s)) (seeds.rank[s] == 2 ? upper_seeds : lower_seeds) += 1;
    for (size_t i = 0; i < r.samples.size(); ++i) {
      if (r.samples.label[i] < 0) continue;
      const size_t s = static_cast<size_t>(r.samples.label[i]);
      if (far(s)) (seeds.rank[s] == 2 ? upper : lower) += 1;
    }
    return (upper / upper_seeds) / (lower / lower_seeds);
  };
  const double even = ratio(1.0), tripled = ratio(3.0);
  std::printf("samples per upper region / per lower region: %.2f at weight 1, %.2f at weight 3\n", even, tripled);
  // At weight 1 the curve seeds' tangent redraws spread a little wider than ball points (0.9); the weight
  // multiplies what each region gets by f + (1 - f) W = 2.5.
  EXPECT_NEAR(even, 1.0, 0.2);
  EXPECT_NEAR(tripled / even, 0.25 + 0.75 * 3.0, 0.3);
}

TEST(BuildGvd, BadOptionsAndEmptySeedsAreRefused) {
  BuildGvdOptions o;
  o.knn = 1;
  EXPECT_THROW(o.Check(), UsageError);
  o = BuildGvdOptions{};
  o.eps_grad = 0;
  EXPECT_THROW(o.Check(), UsageError);
  o = BuildGvdOptions{};
  o.eps_grad_both = 1.5;
  EXPECT_THROW(o.Check(), UsageError);
  o = BuildGvdOptions{};
  o.eps_grad_wall = 0;
  EXPECT_THROW(o.Check(), UsageError);
  o = BuildGvdOptions{};
  o.ball_shares = "volume";
  EXPECT_THROW(o.Check(), UsageError);
  o = BuildGvdOptions{};
  o.curve_sample_weight = 0;
  EXPECT_THROW(o.Check(), UsageError);
  const auto udf = MakeShape("sphere");
  EXPECT_THROW(BuildGvd(*udf, SeedCloud{}, BuildGvdOptions{}, false, Monitor::Null()), InputError);
}

class BuildGvdExe : public ::testing::Test {
 protected:
  TempDir dir_;
};

TEST_F(BuildGvdExe, WritesTheThickMeshLabelsAndGraphDeterministically) {
  ASSERT_EQ(RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "150", "-o", dir_ / "seeds.ply"}).exit_code, 0);
  for (const char* threads : {"1", "2"}) {
    const auto r = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir_ / "seeds.ply", "-o",
                                            dir_ / (std::string("thick") + threads + ".ply"), "--labels",
                                            dir_ / (std::string("labels") + threads + ".ply"), "--graph",
                                            "--threads", threads});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.out.empty());
  }
  EXPECT_EQ(test::ReadBytes(dir_ / "thick1.ply"), test::ReadBytes(dir_ / "thick2.ply"));
  EXPECT_EQ(test::ReadBytes(dir_ / "labels1.ply"), test::ReadBytes(dir_ / "labels2.ply"));
  const TriangleMesh thick = ReadMeshPly(dir_ / "thick1.ply");
  EXPECT_EQ(thick.vertices.size(), 150u);
  EXPECT_GT(thick.faces.size(), 250u);
  const LabeledSamples labels = ReadLabels(dir_ / "labels1.ply");
  EXPECT_GT(labels.size(), 150u * 50u);
  EXPECT_FALSE(labels.edges.empty());
}

TEST_F(BuildGvdExe, BadInputExitsThreeAndWritesNothing) {
  // A seeds file with no seeds.
  test::WriteBytes(dir_ / "empty.ply",
                   "ply\nformat ascii 1.0\ncomment voroudf seeds 1\nelement vertex 0\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n");
  auto r = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir_ / "empty.ply", "-o", dir_ / "thick.ply",
                                    "--labels", dir_ / "labels.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("build-gvd: error:"), std::string::npos);
  // A mesh given as seeds.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
  m.faces = {{0, 1, 2}};
  WriteMeshPly(dir_ / "mesh.ply", m, Provenance{"test", "", ""});
  r = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir_ / "mesh.ply", "-o", dir_ / "thick.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  // A bad option value: a usage error.
  r = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir_ / "empty.ply", "-o", dir_ / "thick.ply",
                               "--knn", "1"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(test::Exists(dir_ / "thick.ply"));
  EXPECT_FALSE(test::Exists(dir_ / "labels.ply"));
  EXPECT_EQ(dir_.List().size(), 2u);
}

}  // namespace
}  // namespace voroudf

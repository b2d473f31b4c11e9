// Mesh UDF (common/mesh_udf.h, common/triangle_bvh.h): the BVH against brute force over an independent
// point-triangle distance, gradients against finite differences, the conventions on the surface, STL soups
// against their welded OBJ, --udf-normalize, errors, and sample-seeds end to end on a mesh file.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <fstream>

#include "common/errors.h"
#include "common/mesh_udf.h"
#include "common/morton.h"
#include "common/rng.h"
#include "common/udf_spec.h"
#include "formats/mesh_io.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

// Independent of Ericson's regions: the plane projection when it falls inside the triangle (same-side
// tests with cross products), else the nearest of the three edges. Degenerate triangles: edges only.
double SegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}
double BruteTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  if (n.norm() > 1e-9 * (b - a).norm() * (c - a).norm()) {
    const Vec3 u = n.normalized();
    const Vec3 q = p - u.dot(p - a) * u;
    const bool inside = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
                        (a - c).cross(q - c).dot(n) >= 0;
    if (inside) return (p - q).norm();
  }
  return std::min({SegmentDistance(p, a, b), SegmentDistance(p, b, c), SegmentDistance(p, c, a)});
}
double BruteDistance(const TriangleMesh& m, const Vec3& p) {
  double best = INFINITY;
  for (const Tri& t : m.faces)
    best = std::min(best, BruteTriangleDistance(p, m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]));
  return best;
}

TriangleMesh Octahedron() {
  TriangleMesh m;
  m.vertices = {{0.5, 0, 0}, {-0.5, 0, 0}, {0, 0.5, 0}, {0, -0.5, 0}, {0, 0, 0.5}, {0, 0, -0.5}};
  m.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}
// An open, bumpy height field (boundary, curvature).
TriangleMesh OpenPatch(int n = 12) {
  TriangleMesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = -0.5 + double(i) / n, y = -0.5 + double(j) / n;
      m.vertices.emplace_back(x, y, 0.15 * std::sin(5 * x) * std::cos(4 * y));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * (n + 1) + j;
      m.faces.push_back({v, v + n + 1, v + 1});
      m.faces.push_back({v + 1, v + n + 1, v + n + 2});
    }
  return m;
}
// Three half-planes (squares) sharing the edge on the z axis: a non-manifold edge with 3 faces per edge.
TriangleMesh Book() {
  TriangleMesh m;
  m.vertices = {{0, 0, -0.5}, {0, 0, 0.5}};
  for (int page = 0; page < 3; ++page) {
    const double a = 2.0 * M_PI * page / 3.0 + 0.3;
    const int base = static_cast<int>(m.vertices.size());
    m.vertices.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), -0.5);
    m.vertices.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.5);
    m.faces.push_back({0, base, 1});
    m.faces.push_back({1, base, base + 1});
  }
  return m;
}
// Degenerate triangles beside good ones: collinear corners, a zero-length edge, a point, a duplicate face.
TriangleMesh WithDegenerates() {
  TriangleMesh m = Octahedron();
  const int b = static_cast<int>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {{0.2, 0.3, 0.1}, {0.4, 0.1, 0.2}, {0.6, -0.1, 0.3},  // collinear
                                       {-0.3, 0.2, 0.4}, {-0.1, -0.3, 0.2},                 // zero-length edge
                                       {0.1, 0.1, -0.3}});                                  // a point
  m.faces.push_back({b, b + 1, b + 2});
  m.faces.push_back({b + 3, b + 3, b + 4});
  m.faces.push_back({b + 5, b + 5, b + 5});
  m.faces.push_back(m.faces[2]);  // duplicate
  return m;
}
// A soup of random triangles of mixed sizes: exercises the traversal's pruning far more than a tidy mesh.
TriangleMesh RandomSoup(int count, uint64_t seed) {
  TriangleMesh m;
  Rng rng(seed, 0);
  for (int f = 0; f < count; ++f) {
    const Vec3 c(rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5), rng.Uniform(-0.5, 0.5));
    const double s = f % 10 == 0 ? 0.3 : 0.03;
    const int b = static_cast<int>(m.vertices.size());
    for (int k = 0; k < 3; ++k)
      m.vertices.push_back(c + s * Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)));
    m.faces.push_back({b, b + 1, b + 2});
  }
  return m;
}

// Random points: uniform in the domain, and near the surface (on a random face, pushed off by up to 2 %).
std::vector<Vec3> QueryPoints(const MeshUdf& udf, int count, uint64_t seed) {
  Rng rng(seed, 1);
  const Box d = udf.Domain();
  const TriangleMesh& m = udf.mesh();
  std::vector<Vec3> pts;
  for (int i = 0; i < count; ++i) {
    if (i % 2 == 0) {
      pts.emplace_back(rng.Uniform(d.min.x(), d.max.x()), rng.Uniform(d.min.y(), d.max.y()),
                       rng.Uniform(d.min.z(), d.max.z()));
    } else {
      const Tri& t = m.faces[rng.Below(m.faces.size())];
      double u = rng.Uniform(), v = rng.Uniform();
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const Vec3 on = m.vertices[t[0]] + u * (m.vertices[t[1]] - m.vertices[t[0]]) + v * (m.vertices[t[2]] - m.vertices[t[0]]);
      pts.push_back(on + 0.02 * d.Diagonal() * Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)));
    }
  }
  return pts;
}

void ExpectMatchesBruteForce(const TriangleMesh& mesh, const char* name) {
  const MeshUdf udf(mesh, name);
  const std::vector<Vec3> pts = QueryPoints(udf, 3000, 7);
  std::vector<double> d;
  std::vector<Vec3> g;
  udf.Evaluate(pts, d, g);
  for (size_t i = 0; i < pts.size(); ++i) {
    const double ref = BruteDistance(mesh, pts[i]);
    ASSERT_NEAR(d[i], ref, 1e-12) << name << " point " << i;
    ASSERT_NEAR(g[i].norm(), 1.0, 1e-12) << name;
    // x - d n is the closest point: it lies on the surface.
    ASSERT_NEAR(BruteDistance(mesh, pts[i] - d[i] * g[i]), 0.0, 1e-12) << name << " point " << i;
  }
}

TEST(MeshUdf, MatchesBruteForceOnClosedOpenNonManifoldAndDegenerateMeshes) {
  ExpectMatchesBruteForce(Octahedron(), "octahedron");
  ExpectMatchesBruteForce(OpenPatch(), "open patch");
  ExpectMatchesBruteForce(Book(), "book (non-manifold)");
  ExpectMatchesBruteForce(WithDegenerates(), "degenerates");
  ExpectMatchesBruteForce(RandomSoup(2000, 3), "random soup");
}

TEST(MeshUdf, ResultsDoNotDependOnBatchOrderOrTheTraversalHint) {
  // Large batches run in Morton order with each query starting from the previous hit; single queries
  // start from nothing. Medial-axis points (exact ties between faces) and on-surface points included.
  for (const TriangleMesh& mesh : {Octahedron(), Book(), RandomSoup(500, 8), WithDegenerates()}) {
    const MeshUdf udf(mesh, "m");
    std::vector<Vec3> pts = QueryPoints(udf, 6000, 12);
    for (int i = -10; i <= 10; ++i) {
      const double t = 0.05 * i;
      pts.insert(pts.end(), {Vec3(0, 0, t), Vec3(t, 0, 0), Vec3(0, t, 0), Vec3(t, t, 0), Vec3(t, t, t), Vec3(0, t, -t)});
    }
    pts.insert(pts.end(), mesh.vertices.begin(), mesh.vertices.end());
    std::vector<double> d;
    std::vector<Vec3> g;
    udf.Evaluate(pts, d, g);
    std::vector<Vec3> reversed(pts.rbegin(), pts.rend());
    std::vector<double> dr(pts.size());
    std::vector<Vec3> gr(pts.size());
    udf.EvaluateChunk(reversed.data(), reversed.size(), dr.data(), gr.data());
    for (size_t i = 0; i < pts.size(); ++i) {
      Vec3 g1;
      const double d1 = udf.Distance(pts[i], &g1);
      ASSERT_EQ(d[i], d1) << i << " " << pts[i].transpose();
      ASSERT_EQ(g[i], g1) << i << " " << pts[i].transpose();
      ASSERT_EQ(dr[pts.size() - 1 - i], d1) << i;
      ASSERT_EQ(gr[pts.size() - 1 - i], g1) << i;
    }
  }
}

TEST(Morton, LargeBatchesSortAsOneSortDoesOnAnyThreads) {
  // Clusters, exact repeats, points outside the box and non-finite ones: the order is by (code, index),
  // the same as std::sort's on one thread, whichever path (one sort, or buckets sorted on every thread).
  std::vector<Vec3> points;
  Rng rng(7, 0);
  for (int i = 0; i < 60000; ++i) {
    const double spread = i % 3 == 0 ? 1.0 : 1e-4;
    points.emplace_back(rng.Uniform(-spread, spread), rng.Uniform(-spread, spread), 0.3 * rng.Uniform());
    if (i % 97 == 0) points.push_back(points[static_cast<size_t>(i) / 2]);
  }
  points.emplace_back(NAN, 0.0, 0.0);
  points.emplace_back(5.0, -5.0, 5.0);
  const Box box{Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5)};
  std::vector<std::pair<uint64_t, size_t>> keyed;
  for (size_t i = 0; i < points.size(); ++i) keyed.emplace_back(MortonCode(points[i], box), i);
  std::sort(keyed.begin(), keyed.end());
  std::vector<size_t> expected;
  for (const auto& k : keyed) expected.push_back(k.second);
  const int threads = omp_get_max_threads();
  for (int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    EXPECT_EQ(MortonOrder(points, box), expected) << t << " threads";
    const std::vector<Vec3> few(points.begin(), points.begin() + 5000);
    std::vector<size_t> expected_few;
    for (size_t i : expected)
      if (i < few.size()) expected_few.push_back(i);
    EXPECT_EQ(MortonOrder(few, box), expected_few) << t << " threads";
  }
  omp_set_num_threads(threads);
}

TEST(MeshUdf, ClosestPointOnTriangleHandlesEveryRegionAndDegenerateInput) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(0.2, 0.2, 1), a, b, c).isApprox(Vec3(0.2, 0.2, 0)));
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(-1, -1, 0), a, b, c).isApprox(a));
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(2, -1, 0), a, b, c).isApprox(b));
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(0.5, -1, 3), a, b, c).isApprox(Vec3(0.5, 0, 0)));
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(1, 1, 0), a, b, c).isApprox(Vec3(0.5, 0.5, 0)));
  // Collinear, zero-length and point triangles: finite answers on the segment / at the point.
  const Vec3 q = ClosestPointOnTriangle(Vec3(0.5, 1, 0), a, b, Vec3(2, 0, 0));
  EXPECT_TRUE(q.isApprox(Vec3(0.5, 0, 0))) << q.transpose();
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(3, 1, 0), a, a, b).isApprox(b));
  EXPECT_TRUE(ClosestPointOnTriangle(Vec3(3, 1, 0), b, b, b).isApprox(b));
}

TEST(MeshUdf, GradientMatchesFiniteDifferencesAwayFromTheMedialAxis) {
  const TriangleMesh mesh = OpenPatch();
  const MeshUdf udf(mesh, "patch");
  const std::vector<Vec3> pts = QueryPoints(udf, 2000, 9);
  const double h = 1e-6;
  int checked = 0;
  for (const Vec3& p : pts) {
    Vec3 g;
    const double d = udf.Distance(p, &g);
    if (d < 1e-3) continue;
    Vec3 fd;
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = h * Vec3::Unit(k);
      fd[k] = (udf.Distance(p + e) - udf.Distance(p - e)) / (2 * h);
    }
    // On the medial axis the central difference averages two directions and is shorter than 1.
    if (std::abs(fd.norm() - 1.0) > 1e-4) continue;
    ++checked;
    EXPECT_LT((g - fd).norm(), 1e-5) << p.transpose();
  }
  EXPECT_GT(checked, 1800);
}

TEST(MeshUdf, OnTheSurfaceTheGradientIsTheTriangleNormal) {
  const TriangleMesh mesh = Octahedron();
  const MeshUdf udf(mesh, "octahedron");
  Rng rng(4, 4);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Tri& t = mesh.faces[f];
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    const Vec3 n = (b - a).cross(c - a).normalized();
    for (int s = 0; s < 20; ++s) {
      const double u = 0.1 + 0.4 * rng.Uniform(), v = 0.1 + 0.4 * rng.Uniform();
      const Vec3 p = a + u * (b - a) + v * (c - a);
      Vec3 g;
      const double d = udf.Distance(p, &g);
      EXPECT_LT(d, 1e-15);
      EXPECT_NEAR(std::abs(g.dot(n)), 1.0, 1e-12) << "face " << f;
    }
  }
  // A vertex exactly on the surface: still a unit vector (the normal of one of its faces).
  Vec3 g;
  EXPECT_EQ(udf.Distance(mesh.vertices[4], &g), 0.0);
  EXPECT_NEAR(g.norm(), 1.0, 1e-12);
  // A mesh made of one degenerate (collinear) triangle: on it, a deterministic unit vector orthogonal to it.
  TriangleMesh seg;
  seg.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  seg.faces = {{0, 1, 2}};
  const MeshUdf segment_udf(seg, "segment");
  const double d = segment_udf.Distance(Vec3(0.5, 0, 0), &g);
  EXPECT_EQ(d, 0.0);
  EXPECT_NEAR(g.norm(), 1.0, 1e-12);
  EXPECT_NEAR(g.x(), 0.0, 1e-12);
  Vec3 g2;
  segment_udf.Distance(Vec3(0.5, 0, 0), &g2);
  EXPECT_EQ(g, g2);
  // Just off a face, the tiny offset's side is kept.
  const Vec3 n0 = (mesh.vertices[2] - mesh.vertices[0]).cross(mesh.vertices[4] - mesh.vertices[0]).normalized();
  const Vec3 centre = (mesh.vertices[0] + mesh.vertices[2] + mesh.vertices[4]) / 3.0;
  udf.Distance(centre - 1e-14 * n0, &g);
  EXPECT_NEAR(g.dot(n0), -1.0, 1e-9);
}

// Binary STL of every face separately (a soup), with one face repeated.
void WriteStl(const std::string& path, const TriangleMesh& m) {
  std::string bytes(80, ' ');
  std::vector<Tri> faces = m.faces;
  faces.push_back(faces[0]);
  const uint32_t n = static_cast<uint32_t>(faces.size());
  bytes.append(reinterpret_cast<const char*>(&n), 4);
  for (const Tri& t : faces) {
    float rec[12] = {0};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) rec[3 + 3 * k + c] = static_cast<float>(m.vertices[t[k]][c]);
    bytes.append(reinterpret_cast<const char*>(rec), sizeof rec);
    bytes.append(2, '\0');
  }
  test::WriteBytes(path, bytes);
}
void WriteObj(const std::string& path, const TriangleMesh& m) {
  std::ofstream out(path);
  out.precision(17);
  for (const Vec3& v : m.vertices) out << "v " << v.x() << " " << v.y() << " " << v.z() << "\n";
  for (const Tri& t : m.faces) out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

TEST(MeshUdf, StlSoupGivesTheSameFieldAsTheWeldedObj) {
  TempDir dir;
  TriangleMesh mesh = OpenPatch(8);
  for (Vec3& v : mesh.vertices) v = v.cast<float>().cast<double>();  // exactly representable in STL's float32
  WriteStl(dir / "soup.stl", mesh);
  WriteObj(dir / "mesh.obj", mesh);
  const auto stl = OpenUdf(dir / "soup.stl");
  const auto obj = OpenUdf(dir / "mesh.obj");
  EXPECT_EQ(stl->Domain().min, obj->Domain().min);
  EXPECT_EQ(stl->Domain().max, obj->Domain().max);
  Rng rng(5, 5);
  const Box box = obj->Domain();
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p(rng.Uniform(box.min.x(), box.max.x()), rng.Uniform(box.min.y(), box.max.y()),
                 rng.Uniform(box.min.z(), box.max.z()));
    Vec3 gs, go;
    const double ds = stl->Distance(p, &gs), dob = obj->Distance(p, &go);
    ASSERT_NEAR(ds, dob, 1e-14) << p.transpose();
    if (ds > 1e-9) {
      ASSERT_LT((gs - go).norm(), 1e-9);
    }
  }
}

TEST(MeshUdf, DomainIsTheBboxPlusTenPercentAndNormalizeMapsToTheUnitFrame) {
  TriangleMesh mesh = Octahedron();
  for (Vec3& v : mesh.vertices) v = 40.0 * v + Vec3(100, -7, 3);  // extent 40, centre (100,-7,3)
  const MeshUdf raw(mesh, "raw");
  EXPECT_TRUE(raw.Domain().min.isApprox(Vec3(76, -31, -21)));
  EXPECT_TRUE(raw.Domain().max.isApprox(Vec3(124, 17, 27)));
  MeshUdfOptions o;
  o.normalize = true;
  const MeshUdf unit(mesh, "unit", o);
  EXPECT_TRUE(unit.Domain().min.isApprox(Vec3::Constant(-0.6)));
  EXPECT_TRUE(unit.Domain().max.isApprox(Vec3::Constant(0.6)));
  // The same field, scaled: d_unit(x) = d_raw(c + 40 x) / 40; the unit octahedron has d = |x|_1 - 0.5 scaled.
  Rng rng(6, 6);
  for (int i = 0; i < 200; ++i) {
    const Vec3 x(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
    EXPECT_NEAR(unit.Distance(x), raw.Distance(Vec3(100, -7, 3) + 40.0 * x) / 40.0, 1e-12);
  }
  EXPECT_NEAR(unit.Distance(Vec3(0, 0, 0)), 0.5 / std::sqrt(3.0), 1e-12);
}

TEST(MeshUdf, BadMeshesAreInputErrors) {
  TempDir dir;
  EXPECT_THROW(OpenUdf(dir / "missing.obj"), InputError);
  test::WriteBytes(dir / "empty.obj", "v 0 0 0\nv 1 0 0\n");
  EXPECT_THROW(OpenUdf(dir / "empty.obj"), InputError);
  test::WriteBytes(dir / "point.obj", "v 1 1 1\nf 1 1 1\n");
  EXPECT_THROW(OpenUdf(dir / "point.obj"), InputError);
  test::WriteBytes(dir / "garbage.off", "hello\n");
  EXPECT_THROW(OpenUdf(dir / "garbage.off"), InputError);
}

TEST(MeshUdf, NonFiniteQueriesGiveNanAndZeroGradient) {
  const MeshUdf udf(Octahedron(), "octahedron");
  Vec3 g;
  EXPECT_TRUE(std::isnan(udf.Distance(Vec3(NAN, 0, 0), &g)));
  EXPECT_EQ(g, Vec3::Zero());
}

TEST(MeshUdfExe, SampleSeedsRunsOnAMeshFile) {
  TempDir dir;
  const TriangleMesh mesh = Book();
  WriteObj(dir / "book.obj", mesh);
  const auto r = RunProgram("sample-seeds", {"--udf", dir / "book.obj", "--count", "500", "--seed", "3", "-o", dir / "seeds.ply"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("domain"), std::string::npos) << "the log states the domain box: " << r.err;
  const SeedCloud seeds = ReadSeeds(dir / "seeds.ply");
  EXPECT_GT(seeds.size(), 450u);
  for (const Vec3& p : seeds.position) EXPECT_LT(BruteDistance(mesh, p), 1e-5 * 1.7 + 1e-6);
  // --udf-normalize: the same mesh scaled by 1000 gives seeds in the unit frame.
  TriangleMesh big = mesh;
  for (Vec3& v : big.vertices) v *= 1000.0;
  WriteObj(dir / "big.obj", big);
  const auto n = RunProgram("sample-seeds", {"--udf", dir / "big.obj", "--udf-normalize", "--count", "500", "--seed", "3",
                                             "-o", dir / "unit.ply"});
  ASSERT_EQ(n.exit_code, 0) << n.err;
  const SeedCloud unit = ReadSeeds(dir / "unit.ply");
  EXPECT_GT(unit.size(), 450u);
  for (const Vec3& p : unit.position) EXPECT_LE(p.cwiseAbs().maxCoeff(), 0.61);
  // A missing mesh: exit 3, no output.
  const auto bad = RunProgram("sample-seeds", {"--udf", dir / "nope.stl", "-o", dir / "x.ply"});
  EXPECT_EQ(bad.exit_code, 3) << bad.err;
  EXPECT_FALSE(test::Exists(dir / "x.ply"));
}

}  // namespace
}  // namespace voroudf

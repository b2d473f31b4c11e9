// evaluate: every metric on meshes whose answer is known in closed form or by hand, and the real executable.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "common/errors.h"
#include "common/rng.h"
#include "formats/mesh_io.h"
#include "stages/evaluate/crossings.h"
#include "stages/evaluate/evaluate.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

// ---- meshes built by hand ----

// The square [0,1]^2 at height z, split into n x n cells of two triangles.
TriangleMesh Square(int n, double z = 0.0) {
  TriangleMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.emplace_back(double(i) / n, double(j) / n, z);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m.faces.push_back({a, b, d});
      m.faces.push_back({a, d, c});
    }
  return m;
}

TriangleMesh Tetrahedron() {
  return {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
}

// Torus of radii R, r on an n x m grid (closed, genus 1).
TriangleMesh Torus(int n, int m, double R = 1.0, double r = 0.3) {
  TriangleMesh t;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      t.vertices.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = i * m + (j + 1) % m, d = ((i + 1) % n) * m + (j + 1) % m;
      t.faces.push_back({a, b, d});
      t.faces.push_back({a, d, c});
    }
  return t;
}

// The surface of the cube [-0.5,0.5]^3, each side an n x n grid, sides welded together.
TriangleMesh Cube(int n) {
  TriangleMesh c;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const TriangleMesh sq = Square(n);
      const int base = static_cast<int>(c.vertices.size());
      for (const Vec3& p : sq.vertices) {
        Vec3 q;
        q[axis] = side - 0.5;
        q[(axis + 1) % 3] = p.x() - 0.5;
        q[(axis + 2) % 3] = p.y() - 0.5;
        c.vertices.push_back(q);
      }
      for (const Tri& t : sq.faces) c.faces.push_back({base + t[0], base + t[1], base + t[2]});
    }
  return WeldVertices(c, 1e-9);
}

// Icosphere of radius 0.5: the icosahedron, each face split into 4 `levels` times, projected to the sphere.
TriangleMesh Sphere(int levels) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh s{{{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                  {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}},
                 {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2},
                  {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5},
                  {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}}};
  for (int l = 0; l < levels; ++l) {
    std::vector<Tri> faces;
    for (const Tri& t : s.faces) {
      int mid[3];
      for (int k = 0; k < 3; ++k) {
        mid[k] = static_cast<int>(s.vertices.size());
        s.vertices.push_back(0.5 * (s.vertices[t[k]] + s.vertices[t[(k + 1) % 3]]));
      }
      faces.push_back({t[0], mid[0], mid[2]});
      faces.push_back({t[1], mid[1], mid[0]});
      faces.push_back({t[2], mid[2], mid[1]});
      faces.push_back({mid[0], mid[1], mid[2]});
    }
    s.faces = faces;
    s = WeldVertices(s, 1e-9);  // midpoints of shared edges were made twice
  }
  for (Vec3& p : s.vertices) p = 0.5 * p.normalized();
  return s;
}

// `pages` unit squares sharing the spine x = y = 0, z in [0,1] (3+ pages: one non-manifold edge), moved by `shift`.
TriangleMesh Book(int pages, const Vec3& shift = Vec3::Zero()) {
  TriangleMesh b;
  b.vertices = {Vec3(0, 0, 0) + shift, Vec3(0, 0, 1) + shift};
  for (int k = 0; k < pages; ++k) {
    const double a = 2 * M_PI * k / pages;
    const Vec3 out(std::cos(a), std::sin(a), 0);
    const int o0 = static_cast<int>(b.vertices.size());
    b.vertices.push_back(out + shift);
    b.vertices.push_back(out + Vec3(0, 0, 1) + shift);
    b.faces.push_back({0, o0, o0 + 1});
    b.faces.push_back({0, o0 + 1, 1});
  }
  return b;
}

TriangleMesh Transformed(const TriangleMesh& m, double scale, const Vec3& shift) {
  TriangleMesh t = m;
  for (Vec3& p : t.vertices) p = scale * p + shift;
  return t;
}

// Both meshes' faces over both vertex sets, sharing no vertex: two parts modelled separately.
TriangleMesh Parts(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh m = a;
  const int base = static_cast<int>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const Tri& t : b.faces) m.faces.push_back({base + t[0], base + t[1], base + t[2]});
  return m;
}

Metrics Eval(const TriangleMesh& mesh, const TriangleMesh& ref, EvaluateOptions options = {}) {
  return Evaluate(mesh, ref, options, Monitor::Null());
}

// For the metrics that do not depend on the surface samples (TQ, TD, NM-CD, counts): keeps the suite quick.
EvaluateOptions Few() {
  EvaluateOptions o;
  o.samples = 5000;
  return o;
}

// ---- TQ ----

TEST(EvaluateTq, EquilateralIsOneDegenerateIsZeroRightIsoscelesByHand) {
  const double h = std::sqrt(3.0) / 2;
  const TriangleMesh equilateral{{{0, 0, 0}, {1, 0, 0}, {0.5, h, 0}}, {{0, 1, 2}}};
  EXPECT_NEAR(MeanTriangleQuality(equilateral), 1.0, 1e-12);
  // A collinear face is degenerate and counts as 0 in the mean.
  TriangleMesh with_degenerate = equilateral;
  with_degenerate.vertices.emplace_back(2, 0, 0);
  with_degenerate.faces.push_back({0, 1, 3});
  EXPECT_NEAR(MeanTriangleQuality(with_degenerate), 0.5, 1e-12);
  // Legs 1, hypotenuse sqrt2: (6/sqrt3) * (1/2) / ((2 + sqrt2)/2 * sqrt2) = 0.71744...
  const TriangleMesh right{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}};
  const double expected = 6 / std::sqrt(3.0) * 0.5 / ((2 + std::sqrt(2.0)) / 2 * std::sqrt(2.0));
  EXPECT_NEAR(MeanTriangleQuality(right), expected, 1e-12);
  EXPECT_NEAR(expected, 0.717439, 1e-6);
  EXPECT_EQ(MeanTriangleQuality(TriangleMesh{}), 0.0);
  // Scale-free, as it is evaluated in the normalised frame: the grid square's right triangles.
  EXPECT_NEAR(Eval(Square(4), Square(4)).mesh.tq, expected, 1e-12);
}

// ---- TD (Euler characteristic) ----

TEST(EvaluateTd, EulerOfTetrahedronIsTwoOfTorusZeroAfterWelding) {
  EXPECT_EQ(WeldedTopology(Tetrahedron(), 1e-7).euler, 2);
  EXPECT_EQ(WeldedTopology(Torus(12, 8), 1e-7).euler, 0);
  EXPECT_EQ(WeldedTopology(Square(3), 1e-7).euler, 1);
  // One vertex per face corner (as STL-like exports write): welding restores chi = 2.
  const TriangleMesh tet = Tetrahedron();
  TriangleMesh soup;
  for (const Tri& t : tet.faces) {
    const int base = static_cast<int>(soup.vertices.size());
    for (int v : t) soup.vertices.push_back(tet.vertices[v]);
    soup.faces.push_back({base, base + 1, base + 2});
  }
  EXPECT_EQ(ComputeTopology(soup).euler, 4);  // 12 - 12 + 4 unwelded
  EXPECT_EQ(WeldedTopology(soup, 1e-7).euler, 2);
  // An unreferenced vertex does not count.
  soup.vertices.emplace_back(5, 5, 5);
  EXPECT_EQ(WeldedTopology(soup, 1e-7).euler, 2);

  const Metrics m = Eval(Tetrahedron(), Torus(12, 8), Few());
  EXPECT_EQ(m.mesh.topology.euler, 2);
  EXPECT_EQ(m.ref.topology.euler, 0);
  EXPECT_EQ(m.td, 2);
  EXPECT_EQ(Eval(soup, Tetrahedron(), Few()).td, 0);
}

TEST(EvaluateTd, WeldingToleranceIsInTheNormalisedFrame) {
  // Two triangles whose shared corners differ by 5e-8 of the reference size: welded whatever the units.
  for (double scale : {1e-3, 1.0, 1e4}) {
    const double eps = 5e-8 * scale;
    const TriangleMesh split{{{0, 0, 0}, {scale, 0, 0}, {0, scale, 0}, {scale + eps, 0, 0}, {eps, scale, 0}, {scale, scale, 0}},
                             {{0, 1, 2}, {3, 5, 4}}};
    const Metrics m = Eval(split, Transformed(Square(1), scale, Vec3::Zero()), Few());
    EXPECT_EQ(m.mesh.topology.euler, 1) << scale;
    EXPECT_EQ(m.mesh.topology.boundary_edges, 4u) << scale;
    EXPECT_EQ(m.td, 0) << scale;
  }
}

// ---- frame ----

TEST(EvaluateFrame, ReferenceBoxIsCentredWithLargestExtentOne) {
  const TriangleMesh ref = Transformed(Torus(16, 8), 3.0, Vec3(10, -4, 2));  // extent 7.8 x 7.8 x 1.8
  const Frame f = ReferenceFrame(ref);
  const TriangleMesh n = ApplyFrame(f, ref);
  Vec3 lo = n.vertices[0], hi = n.vertices[0];
  for (const Vec3& p : n.vertices) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  EXPECT_NEAR((hi - lo).maxCoeff(), 1.0, 1e-12);
  EXPECT_NEAR((hi + lo).norm(), 0.0, 1e-12);
  EXPECT_NEAR(f.ref_diagonal, (hi - lo).norm(), 1e-12);
  EXPECT_NEAR(f.ref_diagonal, std::sqrt(2.0 + std::pow(0.6 / 2.6, 2)), 1e-3);
}

TEST(EvaluateFrame, MetricsDoNotDependOnTheUnitsOrPlacement) {
  const Metrics a = Eval(Cube(6), Sphere(3));
  const Vec3 shift(100, -3, 7);
  const Metrics b = Eval(Transformed(Cube(6), 250.0, shift), Transformed(Sphere(3), 250.0, shift));
  EXPECT_NEAR(a.cd_x1e3, b.cd_x1e3, 1e-9 * a.cd_x1e3);
  EXPECT_NEAR(a.hd_x1e3, b.hd_x1e3, 1e-9 * a.hd_x1e3);
  EXPECT_NEAR(a.mesh.tq, b.mesh.tq, 1e-12);
  EXPECT_EQ(a.td, b.td);
  EXPECT_GT(a.cd_x1e3, 10.0);  // a cube and its inscribed sphere really differ
}

// ---- sampling and point-set distances ----

TEST(EvaluateSampling, AreaUniformOnTheFacesWithTheirNormalsAndThreadIndependent) {
  // Two disjoint rectangles of areas 1 and 3 (the first split in two triangles, plus a zero-area face).
  const TriangleMesh m{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 5}, {3, 0, 5}, {3, 0, 6}, {0, 0, 6}, {2, 2, 2}},
                       {{0, 1, 2}, {0, 2, 3}, {8, 8, 8}, {4, 5, 6}, {4, 6, 7}}};
  omp_set_num_threads(1);
  const SurfaceSamples one = SampleSurface(m, 40000, 7, 0);
  omp_set_num_threads(2);
  const SurfaceSamples two = SampleSurface(m, 40000, 7, 0);
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_EQ(one.points.size(), 40000u);
  size_t low = 0;
  double sum_x_low = 0;
  for (size_t i = 0; i < one.points.size(); ++i) {
    EXPECT_EQ(one.points[i], two.points[i]);
    const Vec3& p = one.points[i];
    EXPECT_NE(p, Vec3(2, 2, 2)) << "the zero-area face got a sample";
    if (p.z() == 0) {
      ++low;
      sum_x_low += p.x();
      EXPECT_TRUE(p.x() >= 0 && p.x() <= 1 && p.y() >= 0 && p.y() <= 1);
      EXPECT_NEAR(std::abs(one.normals[i].z()), 1.0, 1e-12);
    } else {
      EXPECT_EQ(p.y(), 0);
      EXPECT_TRUE(p.x() >= 0 && p.x() <= 3 && p.z() >= 5 && p.z() <= 6);
      EXPECT_NEAR(std::abs(one.normals[i].y()), 1.0, 1e-12);
    }
  }
  // Binomial(40000, 1/4): sd 87.
  EXPECT_NEAR(double(low), 10000.0, 450.0);
  // Uniform inside the unit square (not biased to a corner of the triangles): mean x = 1/2, sd 0.0029.
  EXPECT_NEAR(sum_x_low / double(low), 0.5, 0.015);
  EXPECT_TRUE(SampleSurface(TriangleMesh{}, 10, 0, 0).points.empty());
  // Another stream gives other samples.
  EXPECT_NE(SampleSurface(m, 10, 7, 1u << 20).points[0], one.points[0]);
}

TEST(EvaluateSampling, NearestDistancesAreExactAgainstBruteForce) {
  // Clustered random points (planes and a line), the worst case for a kd-tree's pruning.
  std::vector<Vec3> a, b;
  for (uint64_t i = 0; i < 3000; ++i) {
    Rng r(3, i);
    const double u = r.Uniform(), v = r.Uniform(), w = r.Uniform();
    a.emplace_back(i % 3 == 0 ? Vec3(u, v, 0) : i % 3 == 1 ? Vec3(u, 0.5, v) : Vec3(u, 0.25, 0.25) + 0.01 * Vec3(0, v, w));
    b.emplace_back(Vec3(v, w, u * u));
  }
  b.resize(2000);
  const std::vector<double> d = NearestDistances(a, b, Monitor::Null());
  ASSERT_EQ(d.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& q : b) best = std::min(best, (a[i] - q).norm());
    ASSERT_EQ(d[i], best) << i;
  }
}

TEST(EvaluateSampling, ChamferAndHausdorffOfHandMadeSets) {
  const std::vector<Vec3> a{{0, 0, 0}, {1, 0, 0}}, b{{0, 0, 0.5}};
  const ChamferDistances c = Chamfer(a, b, Monitor::Null());
  EXPECT_NEAR(c.mean_ab, (0.5 + std::sqrt(1.25)) / 2, 1e-15);
  EXPECT_NEAR(c.mean_ba, 0.5, 1e-15);
  EXPECT_NEAR(c.max_ab, std::sqrt(1.25), 1e-15);
  EXPECT_NEAR(c.max_ba, 0.5, 1e-15);
  EXPECT_NEAR(c.SumOfMeans(), (0.5 + std::sqrt(1.25)) / 2 + 0.5, 1e-15);
  EXPECT_NEAR(c.MaxOfMaxima(), std::sqrt(1.25), 1e-15);
  EXPECT_THROW(Chamfer(a, {}, Monitor::Null()), NumericalError);
}

// ---- CD and HD ----

TEST(EvaluateCd, SquareAgainstAShiftedCopyGivesTheShift) {
  const double delta = 0.05;  // the square has extent 1, so the frame keeps lengths
  const Metrics m = Eval(Square(8, delta), Square(8));
  // Each sample's nearest neighbour is across the gap: sqrt(delta^2 + r^2), r ~ 1/sqrt(pi 1e5) in plane.
  EXPECT_NEAR(m.cd_x1e3, 2 * delta * 1e3, 0.003 * 2 * delta * 1e3);
  EXPECT_GE(m.cd_x1e3, 2 * delta * 1e3);
  // HD as a fraction of the reference diagonal sqrt2.
  EXPECT_NEAR(m.hd_x1e3, delta / std::sqrt(2.0) * 1e3, 0.03 * delta / std::sqrt(2.0) * 1e3);
  EXPECT_EQ(m.td, 0);
  EXPECT_EQ(m.nmcd_x1e3, 0.0);
  EXPECT_EQ(m.mesh.topology.boundary_edges, 32u);
}

TEST(EvaluateCd, MeshAgainstItselfIsAtTheSamplingFloor) {
  // Independent Poisson samples of density rho = N / A: the mean nearest-neighbour distance is
  // 1 / (2 sqrt rho), so the sum of the two means is sqrt(A / N). The unit square has A = 1.
  const Metrics m = Eval(Square(8), Square(8));
  const double floor_x1e3 = std::sqrt(1.0 / 100000) * 1e3;  // 3.16
  EXPECT_GT(m.cd_x1e3, 0.9 * floor_x1e3);
  EXPECT_LT(m.cd_x1e3, 1.15 * floor_x1e3);  // plus a little for the border
  EXPECT_LT(m.hd_x1e3, 15.0);
  EXPECT_EQ(m.td, 0);
  EXPECT_EQ(m.nmcd_x1e3, 0.0);
  EXPECT_EQ(m.ecd_x1e2, 0.0);  // a flat square has no edge point
  // More samples lower the floor as 1/sqrt(N).
  EvaluateOptions more;
  more.samples = 400000;
  EXPECT_NEAR(Eval(Square(8), Square(8), more).cd_x1e3, floor_x1e3 / 2, 0.15 * floor_x1e3 / 2);
}

// ---- exact distances (no sampling floor) ----

// Cube(n) with each side moved by `delta` along its outward normal, sides no longer sharing vertices.
TriangleMesh CubeSidesDisplaced(int n, double delta) {
  const TriangleMesh cube = Cube(n);
  TriangleMesh out;
  for (const Tri& t : cube.faces) {
    const Vec3 c = (cube.vertices[t[0]] + cube.vertices[t[1]] + cube.vertices[t[2]]) / 3;
    int axis = 0;
    c.cwiseAbs().maxCoeff(&axis);
    Vec3 shift = Vec3::Zero();
    shift[axis] = c[axis] > 0 ? delta : -delta;
    const int base = static_cast<int>(out.vertices.size());
    for (int v : t) out.vertices.push_back(cube.vertices[v] + shift);
    out.faces.push_back({base, base + 1, base + 2});
  }
  return out;
}

TEST(EvaluateExact, MeshAgainstItselfHasNoFloor) {
  for (const TriangleMesh& mesh : {Cube(6), Sphere(3), Book(3)}) {
    const Metrics m = Eval(mesh, mesh);
    EXPECT_LT(m.exact.cd_x1e3, 1e-3);
    EXPECT_LT(m.exact.hd_x1e3, 1e-3);
    EXPECT_LT(m.exact.p99_x1e3, 1e-3);
    EXPECT_LT(m.exact.ecd_x1e2, 1e-4);
    EXPECT_GT(m.cd_x1e3, 1.0) << "the sampled CD of the same pair sits on its floor";
  }
}

TEST(EvaluateExact, SidesDisplacedAlongTheirNormalsGiveTwiceTheDisplacement) {
  for (double delta : {0.002, 0.02}) {
    const Metrics m = Eval(CubeSidesDisplaced(6, delta), Cube(6));
    EXPECT_NEAR(m.exact.cd_x1e3, 2 * delta * 1e3, 0.01 * 2 * delta * 1e3) << delta;
    const double hd = delta / std::sqrt(3.0) * 1e3;  // the reference's diagonal is sqrt 3
    EXPECT_NEAR(m.exact.hd_x1e3, hd, 0.01 * hd);
    EXPECT_NEAR(m.exact.p99_x1e3, hd, 0.01 * hd);
    EXPECT_NEAR(m.exact.hd_ref_mesh_x1e3, hd, 0.01 * hd);
    EXPECT_NEAR(m.exact.hd_mesh_ref_x1e3, hd, 0.01 * hd);
  }
}

TEST(EvaluateExact, MissingFaceGivesItsInradiusOneSided) {
  // Square(4) without one right isosceles triangle of legs h = 1/4: a reference sample in the hole is
  // nearest to the hole's nearest edge (the neighbours are coplanar), at most the inradius h (2 - sqrt2)/2
  // away, and that distance averages r/3 over the triangle.
  const TriangleMesh ref = Square(4);
  TriangleMesh holed = ref;
  holed.faces.erase(holed.faces.begin() + 10);  // in cell (1, 1): every edge shared with a neighbour
  const double r = 0.25 * (2 - std::sqrt(2.0)) / 2, diagonal = std::sqrt(2.0);
  const Metrics m = Eval(holed, ref);
  EXPECT_LE(m.exact.hd_ref_mesh_x1e3, r / diagonal * 1e3 * (1 + 1e-9));
  EXPECT_GT(m.exact.hd_ref_mesh_x1e3, 0.95 * r / diagonal * 1e3);
  EXPECT_LT(m.exact.hd_mesh_ref_x1e3, 1e-9);
  EXPECT_EQ(m.exact.hd_x1e3, m.exact.hd_ref_mesh_x1e3);
  EXPECT_NEAR(m.exact.cd_x1e3, r / 3 / 32 * 1e3, 0.05 * r / 3 / 32 * 1e3);
}

TEST(EvaluateExact, NinetyNinthPercentileIgnoresOneStrayTriangle) {
  TriangleMesh stray = Square(8);
  const int base = static_cast<int>(stray.vertices.size());
  stray.vertices.insert(stray.vertices.end(), {{0.5, 0.5, 0.3}, {0.51, 0.5, 0.3}, {0.5, 0.51, 0.3}});
  stray.faces.push_back({base, base + 1, base + 2});
  const Metrics m = Eval(stray, Square(8));
  EXPECT_NEAR(m.exact.hd_x1e3, 0.3 / std::sqrt(2.0) * 1e3, 1e-6);
  EXPECT_LT(m.exact.p99_x1e3, 1e-6);
}

TEST(EvaluateExact, EdgeChamferMeasuresHowFarTheSharpEdgesMoved) {
  // The cube scaled by 1 + eps about its centre: every edge moves by eps/sqrt2 (half a diagonal of eps/2 per
  // axis), more near the corners on the scaled side only by O(eps^2).
  const double eps = 0.01;
  const Metrics m = Eval(Transformed(Cube(6), 1 + eps, Vec3::Zero()), Cube(6));
  const double moved = 0.5 * eps * std::sqrt(2.0);
  EXPECT_NEAR(m.exact.ecd_x1e2, 2 * moved * 1e2, 0.03 * 2 * moved * 1e2);
  EXPECT_NEAR(m.ref.sharp_length, 12.0, 1e-9);
  // A smooth mesh against the cube: its edges are stood in for by the origin.
  const Metrics none = Eval(Sphere(3), Cube(6));
  EXPECT_EQ(none.mesh.sharp_length, 0.0);
  EXPECT_GT(none.exact.ecd_x1e2, 2 * 0.5 * std::sqrt(2.0) * 1e2);
  EXPECT_EQ(Eval(Cube(6), Sphere(3)).exact.ecd_x1e2, 0.0) << "a reference without sharp edges";
}

TEST(EvaluateExact, SharpEdgesAreTheCreasesAndTheCrossings) {
  EXPECT_EQ(SharpEdges(Cube(3), 0.2).size(), 12u * 3);
  EXPECT_TRUE(SharpEdges(Sphere(2), 0.2).empty());
  EXPECT_TRUE(SharpEdges(Square(4), 0.2).empty()) << "a boundary is not a crease";
  EXPECT_EQ(SharpEdges(Book(4), 0.2).size(), 1u) << "pages at 90 degrees meet at the spine";
}

TEST(EvaluateFloor, IsTheReferenceAgainstItsOtherSamples) {
  EvaluateOptions o;
  o.floor = true;
  const Metrics self = Eval(Cube(6), Cube(6), o);
  ASSERT_TRUE(self.has_floor);
  // A mesh against itself under the sampled protocol is exactly its floor.
  EXPECT_EQ(self.floor.cd_x1e3, self.cd_x1e3);
  EXPECT_EQ(self.floor.hd_x1e3, self.hd_x1e3);
  EXPECT_EQ(self.floor.ecd_x1e2, self.ecd_x1e2);
  EXPECT_GT(self.floor.cd_x1e3, 5.0);  // about 7.7 for a cube at 100k samples (docs/evaluate.md)
  const Metrics other = Eval(Sphere(3), Cube(6), o);
  EXPECT_EQ(other.floor.cd_x1e3, self.floor.cd_x1e3) << "the floor depends on the reference only";
  EXPECT_FALSE(Eval(Cube(6), Cube(6)).has_floor);
}

// ---- feature recall ----

TEST(EvaluateFeatures, FeatureEdgesAreTheCreasesAndBranchingCurves) {
  EXPECT_EQ(FeatureEdges(Cube(3), 30).size(), 12u * 3);
  EXPECT_TRUE(FeatureEdges(Sphere(3), 30).empty()) << "an icosphere's dihedrals are a few degrees";
  EXPECT_TRUE(FeatureEdges(Square(4), 30).empty());
  EXPECT_EQ(FeatureEdges(Book(3), 30).size(), 1u) << "the spine of three pages is non-manifold";
  EXPECT_EQ(Corners(FeatureEdges(Cube(3), 30)).size(), 8u);
  EXPECT_EQ(BoundaryEdges(Square(4)).size(), 16u);
}

TEST(EvaluateFeatures, TheCubeTracesItsTwelveEdgesAndEightCornersTheSphereDoesNot) {
  const Metrics self = Eval(Cube(6), Cube(6));
  EXPECT_NEAR(self.features.feature_length, 12.0, 1e-9);
  EXPECT_EQ(self.features.recall, 1.0);
  EXPECT_EQ(self.features.corners, 8u);
  EXPECT_EQ(self.features.corners_matched, 8u);
  EXPECT_LT(self.features.feature_mean_x1e3, 1e-6);
  EXPECT_EQ(self.features.boundary_length, 0.0);
  const Metrics round = Eval(Sphere(3), Cube(6));
  EXPECT_LT(round.features.recall, 0.2);
  EXPECT_EQ(round.features.corners_matched, 0u);
  EXPECT_TRUE(std::isinf(round.features.feature_max_x1e3)) << "a smooth mesh has no feature edge to be near";
  // The untraced samples (--feature-misses): none on the cube itself; on the sphere, samples of the cube's
  // edges (two coordinates at ±0.5 in the normalised frame), as many as the recall leaves out.
  EXPECT_TRUE(self.features.missed.empty());
  ASSERT_FALSE(round.features.missed.empty());
  for (const Vec3& p : round.features.missed) {
    int on_faces = 0;
    for (int a = 0; a < 3; ++a) on_faces += std::abs(std::abs(p[a]) - 0.5) < 1e-9 ? 1 : 0;
    EXPECT_GE(on_faces, 2) << p.transpose();
  }
  EXPECT_NEAR(static_cast<double>(round.features.missed.size()) / 10000.0, 1.0 - round.features.recall, 2e-3);
}

TEST(EvaluateFeatures, ANotchInTheRimGivesItsDepth) {
  // Square(4) without its corner face (0, 1, 6): the rim 0-1 is replaced by the diagonal 0-6 and the edge
  // 1-6. The rim sample farthest from the mesh's rim is at x = 0.25 / (1 + 1/sqrt2), 0.1036 from both.
  TriangleMesh notched = Square(4);
  notched.faces.erase(notched.faces.begin());
  const Metrics m = Eval(notched, Square(4));
  EXPECT_NEAR(m.features.boundary_length, 4.0, 1e-9);
  const double depth = 0.25 / (1 + 1 / std::sqrt(2.0)) / std::sqrt(2.0);
  EXPECT_NEAR(m.features.boundary_max_x1e3, depth / std::sqrt(2.0) * 1e3, 0.01 * depth / std::sqrt(2.0) * 1e3);
  EXPECT_LT(m.features.boundary_recall, 1.0);
  EXPECT_GT(m.features.boundary_recall, 0.9);
  EXPECT_EQ(Eval(Square(4), Square(4)).features.boundary_recall, 1.0);
}

TEST(EvaluateFeatures, AnUnweldedSeamIsNotARimTwoRimsApartAre) {
  // Two squares side by side, 4 x 4 and 3 x 3 cells: along x = 1 their vertices do not match (a T-seam that
  // welding cannot close). The union is the 2 x 1 rectangle, whose rim is its outline; the seam is not one.
  TriangleMesh rectangle = Square(8);
  for (Vec3& p : rectangle.vertices) p.x() *= 2;
  auto seamed = [](double gap) {  // the right square spans x in [1 + gap, 2]
    TriangleMesh right = Square(3);
    for (Vec3& p : right.vertices) p.x() = 1 + gap + (1 - gap) * p.x();
    return Parts(Square(4), right);
  };
  const Metrics m = Eval(rectangle, seamed(0.0));
  EXPECT_NEAR(m.features.boundary_length, 6 * m.frame.scale, 0.01 * m.frame.scale);
  EXPECT_EQ(m.features.boundary_recall, 1.0);
  EXPECT_LT(m.features.boundary_max_x1e3, 1e-6);
  // A gap below the recall's tolerance is still a seam; four times that, two rims facing each other, which
  // the rectangle does not have.
  const double tolerance = m.features.tolerance / m.frame.scale;
  EXPECT_EQ(Eval(rectangle, seamed(0.2 * tolerance)).features.boundary_recall, 1.0);
  const Metrics apart = Eval(rectangle, seamed(4 * tolerance));
  EXPECT_NEAR(apart.features.boundary_length, (8 - 2 * 4 * tolerance) * apart.frame.scale, 0.01 * apart.frame.scale);
  EXPECT_NEAR(apart.features.boundary_recall, 0.75, 0.01);
}

// ---- ECD ----

TEST(EvaluateEcd, SphereReferenceHasNoEdgePointsSoEcdIsZero) {
  const Metrics m = Eval(Cube(8), Sphere(4));
  EXPECT_EQ(m.ref.edge_points, 0u);
  EXPECT_GT(m.mesh.edge_points, 0u);
  EXPECT_EQ(m.ecd_x1e2, 0.0);
}

TEST(EvaluateEcd, EdgePointsLieWithinTheRadiusOfTheCubeEdges) {
  // A cube against itself is not 0: at 100k samples (density 1.7e4 per unit area) a sample within 0.004 of
  // an edge has a neighbour on the other face with probability <= 1 - exp(-0.42), so edge points are ~20
  // per unit of edge length and the two independent sets are a few 1e-2 apart. 4x the samples: denser.
  const Metrics self = Eval(Cube(8), Cube(8));
  EXPECT_GT(self.ref.edge_points, 100u);
  EXPECT_GT(self.mesh.edge_points, 100u);
  EXPECT_GT(self.ecd_x1e2, 0.0);
  EXPECT_LT(self.ecd_x1e2, 10.0);
  EvaluateOptions more;
  more.samples = 400000;
  EXPECT_LT(Eval(Cube(8), Cube(8), more).ecd_x1e2, 0.5 * self.ecd_x1e2);
  const SurfaceSamples s = SampleSurface(Cube(8), 100000, 0, 0);
  for (const Vec3& p : EdgePoints(s, 0.004, 0.2, Monitor::Null())) {
    // Two coordinates within 0.004 of the faces at +-0.5.
    int near_face = 0;
    for (int k = 0; k < 3; ++k) near_face += std::abs(p[k]) > 0.5 - 0.004 - 1e-12;
    EXPECT_GE(near_face, 2) << p.transpose();
  }
}

TEST(EvaluateEcd, EdgePointsAreExactlyTheBruteForceDefinition) {
  // 4000 samples in a 0.03 box (about 10 neighbours each within 0.004) on 40 "faces" of random normals.
  SurfaceSamples s;
  std::vector<Vec3> face_normal;
  for (uint64_t f = 0; f < 40; ++f) {
    Rng r(9, 100000 + f);
    face_normal.push_back(Vec3(r.Uniform(-1, 1), r.Uniform(-1, 1), r.Uniform(-1, 1)).normalized());
  }
  for (uint64_t i = 0; i < 4000; ++i) {
    Rng r(9, i);
    s.points.emplace_back(r.Uniform(-0.015, 0.015), r.Uniform(-0.015, 0.015), r.Uniform(-0.015, 0.015));
    s.faces.push_back(static_cast<int>(r.Below(40)));
    s.normals.push_back(face_normal[s.faces.back()]);
  }
  std::vector<Vec3> expected;
  for (size_t i = 0; i < s.points.size(); ++i)
    for (size_t j = 0; j < s.points.size(); ++j)
      if ((s.points[i] - s.points[j]).norm() < 0.004 && std::abs(s.normals[i].dot(s.normals[j])) < 0.2) {
        expected.push_back(s.points[i]);
        break;
      }
  const std::vector<Vec3> got = EdgePoints(s, 0.004, 0.2, Monitor::Null());
  EXPECT_GT(expected.size(), 1000u);
  EXPECT_LT(expected.size(), 4000u);
  EXPECT_EQ(got, expected);
  // Without face ids every sample is its own group: same answer.
  s.faces.clear();
  EXPECT_EQ(EdgePoints(s, 0.004, 0.2, Monitor::Null()), expected);
}

TEST(EvaluateEcd, TinyMeshDoesNotExhaustMemory) {
  // A cube of side 1e-3 in the frame of a unit cube: all samples within 0.004 of one another (a radius
  // search listing every neighbour would need 20000^2 indices, 1.6 GB). Every sample has a sample of a
  // perpendicular face that close, so all are edge points. (Fewer samples than the default: the exact
  // nearest-neighbour search of CD is quadratic when all of a set is almost equidistant from a query.)
  EvaluateOptions o;
  o.samples = 20000;
  const Metrics m = Eval(Transformed(Cube(8), 1e-3, Vec3::Zero()), Cube(8), o);
  EXPECT_EQ(m.mesh.edge_points, 20000u);
  EXPECT_GT(m.ecd_x1e2, 70.0);  // the reference's edges are ~0.75 from the tiny cube
}

TEST(EvaluateEcd, MeshWithoutEdgePointsIsStoodInFor486PointsAtTheOrigin) {
  // Reference cube, mesh a sphere (no edge point): ECD = mean over the cube's edge points of |p| plus the
  // distance from the origin to the nearest of them. On the edges |p| = sqrt(1/2 + t^2), t in [-1/2, 1/2].
  const Metrics m = Eval(Sphere(4), Cube(8));
  EXPECT_EQ(m.mesh.edge_points, 0u);
  const auto F = [](double t) { return t / 2 * std::sqrt(0.5 + t * t) + 0.25 * std::log(t + std::sqrt(0.5 + t * t)); };
  const double mean_edge = F(0.5) - F(-0.5);  // 0.7623
  const double expected = (mean_edge + std::sqrt(0.5)) * 1e2;
  // Edge points sit up to 0.004 inside the edges: a little closer to the centre.
  EXPECT_NEAR(m.ecd_x1e2, expected, 0.01 * expected);
  EXPECT_LT(m.ecd_x1e2, expected);
}

// ---- NM-CD ----

TEST(EvaluateNmcd, ZeroAgainstItselfAndWithoutNonManifoldEdges) {
  const Metrics book = Eval(Book(3), Book(3), Few());
  EXPECT_EQ(book.nmcd_x1e3, 0.0);
  EXPECT_EQ(book.mesh.topology.nonmanifold_edges, 1u);
  EXPECT_EQ(book.ref.topology.nonmanifold_edges, 1u);
  EXPECT_GT(book.mesh.topology.nonmanifold_vertices, 0u);
  EXPECT_EQ(book.td, 0);
  EXPECT_EQ(Eval(Square(4), Sphere(2), Few()).nmcd_x1e3, 0.0);
}

TEST(EvaluateNmcd, InfiniteWhenOnlyOneSideHasNonManifoldEdges) {
  EXPECT_TRUE(std::isinf(Eval(Book(3), Book(2), Few()).nmcd_x1e3));  // two pages make a manifold sheet
  EXPECT_TRUE(std::isinf(Eval(Book(2), Book(4), Few()).nmcd_x1e3));
}

TEST(EvaluateNmcd, ShiftedSpineGivesTwiceTheShift) {
  const double delta = 0.02;
  const Metrics m = Eval(Book(3, Vec3(delta, 0, 0)), Book(3), Few());
  // In the frame the shift is delta * scale; every spine sample's nearest is its shifted twin.
  EXPECT_NEAR(m.nmcd_x1e3, 2 * delta * m.frame.scale * 1e3, 1e-9);
  EXPECT_NEAR(m.ref.nonmanifold_length, m.frame.scale, 1e-12);
  // Four pages: the spine is shared by 4 faces and still counts.
  EXPECT_NEAR(Eval(Book(4, Vec3(0, delta, 0)), Book(4), Few()).nmcd_x1e3,
              2 * delta * ReferenceFrame(Book(4)).scale * 1e3, 1e-9);
}

TEST(EvaluateNmcd, SamplesAreSpreadByLengthOverTheNonManifoldEdges) {
  // Two spines: one of length 1 and one of length 3 (a book stretched along z).
  TriangleMesh two = Book(3);
  const TriangleMesh tall = Transformed(Book(3), 1.0, Vec3(10, 0, 0));
  const int base = static_cast<int>(two.vertices.size());
  for (Vec3 p : tall.vertices) two.vertices.push_back(Vec3(p.x(), p.y(), 3 * p.z()));
  for (const Tri& t : tall.faces) two.faces.push_back({base + t[0], base + t[1], base + t[2]});
  double length = 0;
  const std::vector<Vec3> s = SampleNonManifoldEdges(two, 1000, &length);
  ASSERT_EQ(s.size(), 1000u);
  EXPECT_NEAR(length, 4.0, 1e-12);
  size_t on_tall = 0;
  for (const Vec3& p : s) {
    EXPECT_NEAR(p.y(), 0.0, 1e-12);
    on_tall += p.x() > 5;
  }
  EXPECT_EQ(on_tall, 750u);
  EXPECT_TRUE(SampleNonManifoldEdges(Square(2), 100, &length).empty());
  EXPECT_EQ(length, 0.0);
}

// ---- the reference's crossing curves ----

// Square(n) turned by `deg` degrees about the line y = 0.5, z = 0 (the x direction), then shifted along z.
TriangleMesh Turned(int n, double deg, double dz = 0.0) {
  TriangleMesh m = Square(n);
  const double c = std::cos(deg * M_PI / 180), s = std::sin(deg * M_PI / 180);
  for (Vec3& p : m.vertices) p = Vec3(p.x(), 0.5 + c * (p.y() - 0.5), s * (p.y() - 0.5) + dz);
  return m;
}

double Length(const CurveSegments& c) {
  double l = 0;
  for (const Edge& e : c.edges) l += (c.vertices[e[1]] - c.vertices[e[0]]).norm();
  return l;
}

TEST(EvaluateCrossings, TwoPartsCrossingBranchAlongTheirLineAtAnyAngleAboveTheFeatureAngle) {
  for (double deg : {35.0, 60.0, 90.0}) {
    // 5 x 5 against 3 x 3 cells: the line y = 0.5 runs through the first's cells and along none of its edges.
    const CurveSegments c = CrossingCurves(Parts(Square(5), Turned(3, deg)), 1e-7, 30.0);
    EXPECT_NEAR(Length(c), 1.0, 1e-9) << deg;
    for (const Vec3& p : c.vertices) {
      EXPECT_NEAR(p.y(), 0.5, 1e-9);
      EXPECT_NEAR(p.z(), 0.0, 1e-9);
    }
  }
  // Below the feature angle the two are one sheet to a mesher; crossing parts that share the line's
  // vertices (one welded mesh) have it as edges of 4 faces, which NonManifoldEdges reports instead.
  EXPECT_TRUE(CrossingCurves(Parts(Square(5), Turned(3, 20.0)), 1e-7, 30.0).edges.empty());
  EXPECT_TRUE(CrossingCurves(Book(4), 1e-7, 30.0).edges.empty());
}

TEST(EvaluateCrossings, AWallTouchingAFaceIsAJunctionASeamIsNot) {
  // A wall standing on the square along y = 0.5 (its top edge on the square, not through it): 3 half-sheets.
  // With 4 x 4 cells the line runs along the square's edges, with 5 x 5 through its cells.
  const TriangleMesh wall = Turned(3, 90.0, -0.5);  // y = 0.5, z in [-1, 0]
  for (int n : {4, 5}) EXPECT_NEAR(Length(CrossingCurves(Parts(Square(n), wall), 1e-7, 30.0)), 1.0, 1e-9) << n;
  // Two squares meeting at the line with vertices of their own (an unwelded crease or seam): 2 half-sheets.
  TriangleMesh half = Square(4);
  for (Vec3& p : half.vertices) p = Vec3(p.x(), 0.5 + 0.5 * p.y(), 0.5 * p.y());  // from y = 0.5 up and back
  TriangleMesh other = Square(3);
  for (Vec3& p : other.vertices) p = Vec3(p.x(), 0.5 * p.y(), 0.0);  // y in [0, 0.5]
  EXPECT_TRUE(CrossingCurves(Parts(other, half), 1e-7, 30.0).edges.empty());
  // A closed mesh has no crossing at all.
  EXPECT_TRUE(CrossingCurves(Cube(4), 1e-7, 30.0).edges.empty());
  EXPECT_TRUE(CrossingCurves(Sphere(3), 1e-7, 30.0).edges.empty());
}

TEST(EvaluateCrossings, AMeshThatBranchesWhereTheReferencesPartsCrossIsNotSpurious) {
  // The reference: two separate squares crossing at 90 degrees (no edge of 3+ faces). The mesh: the same
  // surface as one welded mesh, whose crossing line is an edge of 4 faces.
  const TriangleMesh ref = Parts(Square(5), Turned(3, 90.0));
  TriangleMesh mesh = Book(4, Vec3(0, 0, 0));  // four pages around the spine x = y = 0, z in [0, 1]
  for (Vec3& p : mesh.vertices) p = Vec3(p.z(), 0.5 + p.x(), p.y());  // spine along x at y = 0.5, z = 0
  EvaluateOptions union_curves = Few();
  const Metrics m = Eval(mesh, ref, union_curves);
  EXPECT_EQ(m.mesh.topology.nonmanifold_edges, 1u);
  EXPECT_EQ(m.spurious_nonmanifold_edges, 0u);
  EXPECT_NEAR(m.ref_crossing_length, m.frame.scale, 1e-9);
  EXPECT_LT(m.nmcd_x1e3, 0.1);  // both sample the same line, in other pieces: half a sample spacing at most
  // DESIGN.md's definition (edges of 3+ faces only) sees no branching in the reference.
  EvaluateOptions edges_only = Few();
  edges_only.ref_nm_curves = "edges";
  const Metrics e = Eval(mesh, ref, edges_only);
  EXPECT_TRUE(std::isinf(e.nmcd_x1e3));
  EXPECT_EQ(e.spurious_nonmanifold_edges, 1u);
  EXPECT_EQ(e.ref_crossing_length, 0.0);
  // A mesh branching elsewhere (farther than its median edge length, about 1 here): spurious either way.
  TriangleMesh off = mesh;
  for (Vec3& p : off.vertices) p += Vec3(0, 0, 3);
  EXPECT_EQ(Eval(off, ref, union_curves).spurious_nonmanifold_edges, 1u);
}

// An open cylinder of radius r along x (x in [0, 1]) with `facets` facets, lying on the plane z = lift: one
// ring vertex at its lowest point (y = 0.5, z = lift), so with lift 0 it touches Square(n) along that line.
TriangleMesh CylinderOnThePlane(int facets, double r, double lift) {
  TriangleMesh m;
  for (int end = 0; end < 2; ++end)
    for (int k = 0; k < facets; ++k) {
      const double a = -M_PI / 2 + 2 * M_PI * k / facets;
      m.vertices.emplace_back(end, 0.5 + r * std::cos(a), lift + r + r * std::sin(a));
    }
  for (int k = 0; k < facets; ++k) {
    const int a = k, b = (k + 1) % facets;
    m.faces.push_back({a, b, facets + b});
    m.faces.push_back({a, facets + b, facets + a});
  }
  return m;
}

TEST(EvaluateCrossings, APartLyingOnAnotherTangentiallyBranchesWhereNoTrianglesCross) {
  // Its facets leave the plane at 7.5 degrees: no line where two triangles cross above the feature angle.
  const TriangleMesh touching = Parts(Square(5), CylinderOnThePlane(24, 0.3, 0.0));
  EXPECT_TRUE(CrossingCurves(touching, 1e-7, 30.0).edges.empty());
  const std::vector<Vec3> at{Vec3(0.5, 0.5, 0.0), Vec3(0.3, 0.5, 0.0)}, along{Vec3(1, 0, 0), Vec3(1, 0, 0)};
  // Cut across the line: the plane leaves the disc twice, the cylinder twice, and the two touch.
  EXPECT_EQ(BranchesAcross(touching, at, along, 0.2, 0.002), std::vector<char>({1, 1}));
  // Lifted by 0.01 (more than `join`) the parts are apart: two pieces of 2 exits, no branch.
  const TriangleMesh apart = Parts(Square(5), CylinderOnThePlane(24, 0.3, 0.01));
  EXPECT_EQ(BranchesAcross(apart, at, along, 0.2, 0.002), std::vector<char>({0, 0}));
  // Manifold surfaces never branch: a plane, two parallel planes 0.05 apart, a cube's edge, a thin plate's rim.
  EXPECT_EQ(BranchesAcross(Square(5), at, along, 0.2, 0.002), std::vector<char>({0, 0}));
  EXPECT_EQ(BranchesAcross(Parts(Square(5), Square(5, 0.05)), at, along, 0.2, 0.002), std::vector<char>({0, 0}));
  EXPECT_EQ(BranchesAcross(Cube(4), {Vec3(0.1, 0.5, 0.5)}, {Vec3(1, 0, 0)}, 0.2, 0.002), std::vector<char>({0}));
  TriangleMesh plate = CubeSidesDisplaced(4, 0.0);
  for (Vec3& p : plate.vertices) p.z() *= 0.05;  // 0.05 thick, welded at the rims by Evaluate only
  EXPECT_EQ(BranchesAcross(WeldVertices(plate, 1e-9), {Vec3(0.1, 0.5, 0.0)}, {Vec3(1, 0, 0)}, 0.2, 0.002),
            std::vector<char>({0}));
}

TEST(EvaluateCrossings, ThePieceThroughARimLeavesOnceThroughASeamTwice) {
  const std::vector<Vec3> along_x{Vec3(1, 0, 0)}, along_y{Vec3(0, 1, 0)};
  EXPECT_EQ(ExitsThrough(Square(4), {Vec3(0.4, 0, 0)}, along_x, 0.1, 0.01), std::vector<size_t>{1});
  EXPECT_EQ(ExitsThrough(Square(4), {Vec3(0.4, 0.4, 0)}, along_x, 0.1, 0.01), std::vector<size_t>{2});
  EXPECT_EQ(ExitsThrough(Square(4), {Vec3(0.4, 0.4, 0.5)}, along_x, 0.1, 0.01), std::vector<size_t>{0});
  // A T-seam, and the same two squares 0.005 apart (joined) and 0.05 apart (two rims).
  for (double gap : {0.0, 0.005, 0.05}) {
    const TriangleMesh seam = Parts(Square(4), Transformed(Square(3), 1.0, Vec3(1 + gap, 0, 0)));
    EXPECT_EQ(ExitsThrough(seam, {Vec3(1, 0.4, 0)}, along_y, 0.1, 0.01), std::vector<size_t>{gap < 0.01 ? 2u : 1u})
        << gap;
  }
  // A crease: the second square folded up at 90 degrees along the seam.
  TriangleMesh up = Square(3);
  for (Vec3& p : up.vertices) p = Vec3(1, p.y(), p.x());
  EXPECT_EQ(ExitsThrough(Parts(Square(4), up), {Vec3(1, 0.4, 0)}, along_y, 0.1, 0.01), std::vector<size_t>{2});
}

TEST(EvaluateCrossings, AMeshThatBranchesWhereTheReferencesPartsTouchTangentiallyIsNotSpurious) {
  // The reference: a cylinder lying on a square, two parts. The mesh: the square with a fin standing on the
  // line they touch along, one welded mesh (edges of 3 faces along the line), cells 0.05.
  const TriangleMesh ref = Parts(Square(20), CylinderOnThePlane(24, 0.3, 0.0));
  TriangleMesh mesh = Square(20);
  const int base = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i <= 20; ++i) mesh.vertices.emplace_back(i / 20.0, 0.5, 0.05);
  for (int i = 0; i < 20; ++i) {
    const int a = 10 * 21 + i, b = a + 1;  // the square's vertices on y = 0.5
    mesh.faces.push_back({a, b, base + i + 1});
    mesh.faces.push_back({a, base + i + 1, base + i});
  }
  EvaluateOptions union_curves = Few();
  const Metrics m = Eval(mesh, ref, union_curves);
  EXPECT_EQ(m.mesh.topology.nonmanifold_edges, 20u);
  EXPECT_EQ(m.ref_crossing_length, 0.0);
  EXPECT_EQ(m.spurious_nonmanifold_edges, 0u);
  EvaluateOptions edges_only = Few();
  edges_only.ref_nm_curves = "edges";
  EXPECT_EQ(Eval(mesh, ref, edges_only).spurious_nonmanifold_edges, 20u);
  // The same mesh against the cylinder lifted off the square: every branching edge is spurious.
  EXPECT_EQ(Eval(mesh, Parts(Square(20), CylinderOnThePlane(24, 0.3, 0.02)), union_curves).spurious_nonmanifold_edges,
            20u);
}

// ---- errors, determinism, JSON ----

TEST(EvaluateErrors, BadMeshesAndOptionsAreTypedErrors) {
  EXPECT_THROW(Eval(Square(2), TriangleMesh{}), InputError);
  const TriangleMesh point{{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {{0, 1, 2}}};
  EXPECT_THROW(Eval(Square(2), point), InputError);
  const TriangleMesh flat_line{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {{0, 1, 2}}};
  EXPECT_THROW(Eval(Square(2), flat_line), InputError);  // a box but no area
  EXPECT_THROW(Eval(TriangleMesh{}, Square(2)), NumericalError);
  EXPECT_THROW(Eval(flat_line, Square(2)), NumericalError);
  TriangleMesh bad = Square(2);
  bad.faces[0][1] = 99;
  EXPECT_THROW(Eval(bad, Square(2)), InputError);
  EXPECT_THROW(Eval(Square(2), bad), InputError);
  EvaluateOptions o;
  o.samples = 0;
  EXPECT_THROW(o.Check(), UsageError);
  o = {};
  o.nm_samples = 0;
  EXPECT_THROW(o.Check(), UsageError);
}

TEST(EvaluateJson, SameBytesWhateverTheThreadCountAndInfIsAString) {
  omp_set_num_threads(1);
  const std::string one = MetricsJson(Eval(Book(3), Cube(6), Few()), Few(), "a.ply", "b.obj", -1);
  omp_set_num_threads(2);
  const std::string two = MetricsJson(Eval(Book(3), Cube(6), Few()), Few(), "a.ply", "b.obj", -1);
  omp_set_num_threads(omp_get_num_procs());
  EXPECT_EQ(one, two);
  EXPECT_EQ(one.back(), '\n');
  EXPECT_EQ(one.find('\n'), one.size() - 1) << "one line";
  EXPECT_NE(one.find("\"nmcd_x1e3\": \"inf\""), std::string::npos) << one;
  EXPECT_EQ(one.find("seconds"), std::string::npos);
  EXPECT_EQ(one.find("floor"), std::string::npos) << "floor keys only with --floor";
  EXPECT_EQ(one.rfind("{\"mesh\": \"a.ply\", \"reference\": \"b.obj\", \"samples\": 5000, ", 0), 0u) << one;
  // Fixed key order.
  size_t last = 0;
  for (const char* key : {"\"vertices\"", "\"faces\"", "\"cd_x1e3\"", "\"hd_x1e3\"", "\"ecd_x1e2\"", "\"tq\"", "\"td\"",
                          "\"nmcd_x1e3\"", "\"cd_exact_x1e3\"", "\"hd_exact_x1e3\"", "\"p99_exact_x1e3\"",
                          "\"hd_exact_ref_mesh_x1e3\"", "\"hd_exact_mesh_ref_x1e3\"", "\"ecd_exact_x1e2\"", "\"euler_mesh\"", "\"euler_ref\"", "\"nonmanifold_edges\"",
                          "\"nonmanifold_vertices\"", "\"boundary_edges\"", "\"components\"", "\"ref_vertices\"",
                          "\"ref_faces\"", "\"ref_tq\"", "\"ref_nonmanifold_edges\"", "\"ref_components\""}) {
    const size_t at = one.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    EXPECT_GT(at, last) << key;
    last = at;
  }
  const std::string timed = MetricsJson(Eval(Square(2), Square(2), Few()), Few(), "q\"\\.ply", "r", 1.5);
  EXPECT_NE(timed.find("\"seconds\": 1.5}"), std::string::npos) << timed;
  EXPECT_NE(timed.find("\"q\\\"\\\\.ply\""), std::string::npos) << timed;
}

// ---- the executable ----

class EvaluateExe : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteMeshPly(dir_ / "book3.ply", Book(3), Provenance{"test", "", ""});
    WriteMeshPly(dir_ / "book2.ply", Book(2), Provenance{"test", "", ""}, true);
    WriteMeshPly(dir_ / "empty.ply", TriangleMesh{{{0, 0, 0}}, {}}, Provenance{"test", "", ""});
    // The same three-page book as OBJ (1-based) and OFF.
    const TriangleMesh b = Book(3);
    std::string obj = "# book\n", off = "OFF\n" + std::to_string(b.vertices.size()) + " " + std::to_string(b.faces.size()) + " 0\n";
    for (const Vec3& p : b.vertices) {
      const std::string xyz = std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
      obj += "v " + xyz;
      off += xyz;
    }
    for (const Tri& t : b.faces) {
      obj += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
      off += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
    }
    std::string stl = "solid book\n";
    for (const Tri& t : b.faces) {
      stl += "facet normal 0 0 0\nouter loop\n";
      for (int v : t)
        stl += "vertex " + std::to_string(b.vertices[v].x()) + " " + std::to_string(b.vertices[v].y()) + " " +
               std::to_string(b.vertices[v].z()) + "\n";
      stl += "endloop\nendfacet\n";
    }
    test::WriteBytes(dir_ / "book3.stl", stl + "endsolid book\n");
    test::WriteBytes(dir_ / "book3.obj", obj);
    test::WriteBytes(dir_ / "book3.off", off);
    test::WriteBytes(dir_ / "garbage.off", "OFF\n4 2 0\n0 0 0\n1 0\n");
  }
  std::vector<std::string> Args(const std::string& mesh, const std::string& ref) {
    return {"-i", dir_ / mesh, "--reference", dir_ / ref, "--samples", "20000"};
  }
  TempDir dir_;
};

TEST_F(EvaluateExe, PrintsOneJsonLineReadsEveryFormatAndWritesAtomically) {
  for (const char* ref : {"book3.ply", "book3.obj", "book3.off", "book3.stl"}) {
    const auto r = RunProgram("evaluate", Args("book3.ply", ref));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"td\": 0, \"nmcd_x1e3\": 0,"), std::string::npos) << ref << ": " << r.out;
    EXPECT_NE(r.out.find("\"nonmanifold_edges\": 1,"), std::string::npos) << r.out;
  }
  auto args = Args("book2.ply", "book3.ply");
  const auto to_stdout = RunProgram("evaluate", args);
  ASSERT_EQ(to_stdout.exit_code, 0) << to_stdout.err;
  args.insert(args.end(), {"-o", dir_ / "m.json", "--threads", "1"});
  const auto to_file = RunProgram("evaluate", args);
  ASSERT_EQ(to_file.exit_code, 0) << to_file.err;
  EXPECT_TRUE(to_file.out.empty());
  EXPECT_EQ(test::ReadBytes(dir_ / "m.json"), to_stdout.out) << "same bytes with -o and --threads 1";
  for (const std::string& name : dir_.List()) EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;

  // The Python benchmark driver reads it; "inf" becomes float("inf").
  if (std::system("test -x /usr/bin/python3") == 0) {
    const std::string cmd = "/usr/bin/python3 -c \"import json,math,sys; d=json.load(open(sys.argv[1])); "
                            "sys.exit(0 if math.isinf(float(d['nmcd_x1e3'])) and d['td']==0 and d['samples']==20000 "
                            "else 1)\" " + dir_ / "m.json";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << test::ReadBytes(dir_ / "m.json");
  }
  auto timed = Args("book3.ply", "book3.ply");
  timed.insert(timed.end(), {"--timings", "--floor"});
  const std::string with_floor = RunProgram("evaluate", timed).out;
  EXPECT_NE(with_floor.find("\"seconds\": "), std::string::npos);
  for (const char* key : {"\"cd_floor_x1e3\"", "\"hd_floor_x1e3\"", "\"ecd_floor_x1e2\"", "\"cd_exact_x1e3\""})
    EXPECT_NE(with_floor.find(key), std::string::npos) << key << with_floor;
}

struct Failure {
  std::vector<std::string> args;
  int exit_code;
  const char* message;
};

TEST_F(EvaluateExe, FailuresExitWithTheDocumentedCodeAndOneLine) {
  const std::string out = dir_ / "m.json";
  const std::vector<Failure> failures = {
      {{"-i", dir_ / "book3.ply", "-o", out}, kExitUsage, "--reference is required"},
      {{"-i", dir_ / "book3.ply", "--reference", dir_ / "book3.ply", "--samples", "0", "-o", out}, kExitUsage, "--samples"},
      {{"-i", dir_ / "book3.ply", "--reference", dir_ / "none.ply", "-o", out}, kExitBadInput, "none.ply"},
      {{"-i", dir_ / "book3.ply", "--reference", dir_ / "garbage.off", "-o", out}, kExitBadInput, "garbage.off"},
      {{"-i", dir_ / "book3.ply", "--reference", dir_ / "empty.ply", "-o", out}, kExitBadInput, "reference: has no face"},
      {{"-i", dir_ / "empty.ply", "--reference", dir_ / "book3.ply", "-o", out}, kExitNumerical, "no face of non-zero area"},
      {{"-i", dir_ / "book3.ply", "--reference", dir_ / "book3.ply", "-o", dir_ / "no/dir/m.json"}, kExitFailure, "does not exist"},
  };
  for (const auto& f : failures) {
    const auto r = RunProgram("evaluate", f.args);
    EXPECT_EQ(r.exit_code, f.exit_code) << r.err;
    EXPECT_NE(r.err.find(f.message), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty());
    EXPECT_FALSE(test::Exists(out));
    const auto last = r.err.rfind("evaluate: error:");
    ASSERT_NE(last, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n', last), r.err.size() - 1);
  }
}

TEST_F(EvaluateExe, HelpExplainsTheOptions) {
  const auto r = RunProgram("evaluate", {"--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--input", "--reference", "--output", "--samples", "--nm-samples", "--edge-samples", "--floor",
                           "--seed", "--timings", "--threads"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

}  // namespace
}  // namespace voroudf

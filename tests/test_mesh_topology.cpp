// Mesh combinatorics on meshes built in code, where every count is known by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "common/face_cycles.h"
#include "common/mesh_topology.h"

namespace voroudf {
namespace {

TriangleMesh Tetrahedron() {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

// Torus as an n x m grid with wrap-around: chi = 0.
TriangleMesh Torus(int n, int m) {
  TriangleMesh t;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      t.vertices.emplace_back((1 + 0.3 * std::cos(v)) * std::cos(u), (1 + 0.3 * std::cos(v)) * std::sin(u),
                              0.3 * std::sin(v));
    }
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      t.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return t;
}

TEST(MeshTopology, TetrahedronIsClosedWithEulerTwo) {
  const TopologyStats s = ComputeTopology(Tetrahedron());
  EXPECT_EQ(s.num_vertices, 4u);
  EXPECT_EQ(s.num_edges, 6u);
  EXPECT_EQ(s.num_faces, 4u);
  EXPECT_EQ(s.euler, 2);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.nonmanifold_edges, 0u);
  EXPECT_EQ(s.nonmanifold_vertices, 0u);
  EXPECT_EQ(s.components, 1u);
}

TEST(MeshTopology, TorusHasEulerZero) {
  const TopologyStats s = ComputeTopology(Torus(12, 8));
  EXPECT_EQ(s.euler, 0);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.nonmanifold_vertices, 0u);
}

TEST(MeshTopology, ThreeSheetsOnOneEdge) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1, 0), Vec3(0.5, -1, 0), Vec3(0.5, 0, 1)};
  m.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const TopologyStats s = ComputeTopology(m);
  EXPECT_EQ(s.nonmanifold_edges, 1u);
  EXPECT_EQ(s.nonmanifold_vertices, 2u);
  EXPECT_EQ(s.boundary_edges, 6u);
  EXPECT_EQ(s.euler, 5 - 7 + 3);
}

TEST(MeshTopology, BowtieVertexIsNonManifold) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(-1, 0, 0), Vec3(-1, -1, 0)};
  m.faces = {{0, 1, 2}, {0, 3, 4}};
  const TopologyStats s = ComputeTopology(m);
  EXPECT_EQ(s.nonmanifold_edges, 0u);
  EXPECT_EQ(s.nonmanifold_vertices, 1u);
  EXPECT_EQ(s.components, 1u);
  int n = 0;
  EdgeConnectedComponents(m.faces, &n);
  EXPECT_EQ(n, 2);  // through edges the two triangles are apart
}

TEST(MeshTopology, WeldingJoinsSplitCornersAndDropsDegenerateFaces) {
  TriangleMesh soup;
  for (const Tri& t : Tetrahedron().faces) {
    const int base = static_cast<int>(soup.vertices.size());
    for (int v : t) soup.vertices.push_back(Tetrahedron().vertices[v] + Vec3::Constant(1e-9 * v));
    soup.faces.push_back({base, base + 1, base + 2});
  }
  soup.vertices.push_back(Vec3(5, 5, 5));                          // unreferenced
  soup.vertices.push_back(Vec3(0, 0, 0) + Vec3::Constant(2e-8));   // collapses onto vertex 0
  soup.faces.push_back({0, 13, 1});                                // degenerate after welding
  EXPECT_EQ(ComputeTopology(soup).euler, 13 - 14 + 5);  // 4 separate triangles plus a sliver on an edge
  const TriangleMesh w = WeldVertices(soup, 1e-7);
  EXPECT_EQ(w.vertices.size(), 4u);
  EXPECT_EQ(w.faces.size(), 4u);
  EXPECT_EQ(ComputeTopology(w).euler, 2);
}

TEST(MeshTopology, TriangleQuality) {
  EXPECT_NEAR(TriangleQuality(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, std::sqrt(3.0) / 2, 0)), 1.0, 1e-12);
  EXPECT_EQ(TriangleQuality(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)), 0.0);
  // Right isosceles: area 1/2, half-perimeter (2 + sqrt 2)/2, longest sqrt 2.
  EXPECT_NEAR(TriangleQuality(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)),
              6 / std::sqrt(3.0) * 0.5 / ((2 + std::sqrt(2.0)) / 2 * std::sqrt(2.0)), 1e-12);
}

TEST(MeshTopology, CanonicalOrderDependsOnTheGeometryAlone) {
  // A tetrahedron, and the same with its vertices renumbered, its faces reordered and rotated.
  const TriangleMesh a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  const int perm[4] = {2, 0, 3, 1};  // new index of old vertex k
  TriangleMesh b;
  b.vertices.resize(4);
  for (int k = 0; k < 4; ++k) b.vertices[perm[k]] = a.vertices[k];
  for (int f = 3; f >= 0; --f) {
    const Tri& t = a.faces[f];
    b.faces.push_back({perm[t[1]], perm[t[2]], perm[t[0]]});  // same orientation, another start
  }
  const TriangleMesh ca = CanonicalOrder(a), cb = CanonicalOrder(b);
  EXPECT_EQ(ca.vertices, cb.vertices);
  EXPECT_EQ(ca.faces, cb.faces);
  EXPECT_EQ(ComputeTopology(ca).euler, 2);
  EXPECT_EQ(ca.vertices[0], Vec3(0, 0, 0));
}

TEST(FaceComplex, FacesOfAClosedShellLieOnATwoCycleUntilItIsOpened) {
  // A tetrahedron on a flat fan: the shell's faces lie on a 2-cycle, the fan's do not.
  const std::vector<Tri> faces = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}, {0, 1, 4}, {0, 4, 5}};
  FaceComplex c(faces);
  for (int f = 0; f < 4; ++f) EXPECT_TRUE(c.OnLocalTwoCycle(f, 1)) << f;
  EXPECT_FALSE(c.OnLocalTwoCycle(4, 1));
  EXPECT_FALSE(c.OnLocalTwoCycle(5, 1));
  EXPECT_TRUE(c.HasFreeEdge(5));
  EXPECT_FALSE(c.HasFreeEdge(0));
  c.Remove(2);  // opened: no face of it is on a cycle any more, and (1, 2, 3) now has a free edge
  for (int f : {0, 1, 3}) EXPECT_FALSE(c.OnLocalTwoCycle(f, 1)) << f;
  EXPECT_TRUE(c.HasFreeEdge(3));
  // A shell wider than the rings searched is not seen: an octahedron from one face, at 0 rings (the face's
  // own vertices only), and seen at 1.
  const std::vector<Tri> octahedron = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  const FaceComplex o(octahedron);
  EXPECT_FALSE(o.OnLocalTwoCycle(0, 0));
  EXPECT_TRUE(o.OnLocalTwoCycle(0, 1));
}

TEST(FaceComplex, Gf2SpanOfEdgeSets) {
  EXPECT_TRUE(InGf2Span({0, 1, 2}, {{0, 3, 4}, {1, 3, 5}, {2, 4, 5}}));  // the other three faces of a tetrahedron
  EXPECT_FALSE(InGf2Span({0, 1, 2}, {{0, 3, 4}, {1, 3, 5}}));
  EXPECT_FALSE(InGf2Span({0, 1, 2}, {}));
}

}  // namespace
}  // namespace voroudf

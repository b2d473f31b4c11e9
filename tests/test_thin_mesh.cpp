// thin-mesh: the thinning rules on hand-made meshes (paper Sec. 3.4, Fig. 8) and the executable's handling of
// bad input. The field is shape:disc, whose UDF is |z| near the origin, so a face's centroid UDF is its height.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "common/errors.h"
#include "common/mesh_udf.h"
#include "common/mesh_topology.h"
#include "common/shapes.h"
#include "formats/mesh_io.h"
#include "formats/seeds_io.h"
#include "stages/thin-mesh/feature_chords.h"
#include "stages/thin-mesh/relax.h"
#include "stages/thin-mesh/rim_flaps.h"
#include "stages/thin-mesh/thin_mesh.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

std::set<Tri> SortedFaces(const TriangleMesh& mesh) {
  std::set<Tri> out;
  for (Tri t : mesh.faces) {
    std::sort(t.begin(), t.end());
    out.insert(t);
  }
  return out;
}

// The fins some tests stand on the disc are not in its field: step 6 would take their end faces for faces
// off the surface at a rim.
ThinMeshOptions FinNotInField() {
  ThinMeshOptions o;
  o.rim_flaps = false;
  return o;
}

ThinMeshOptions MinFaces(size_t n) {
  ThinMeshOptions o;
  o.min_component_faces = n;
  return o;
}

/// A flat tetrahedron over a, b, c, d at heights za..zd above the disc (Fig. 8).
TriangleMesh Tetrahedron(double za, double zb, double zc, double zd) {
  TriangleMesh m;
  m.vertices = {{-0.2, 0.0, za}, {0.2, 0.0, zb}, {0.0, -0.2, zc}, {0.0, 0.2, zd}};
  m.faces = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  return m;
}

TEST(ThinMesh, FlatTetrahedronLosesThePairWithTheHighestCentroidUdf) {
  const auto udf = MakeShape("disc");
  // c and d are lifted: faces acd and bcd (sharing cd) have the highest centroids and go; abc and abd stay.
  const TriangleMesh tet = Tetrahedron(0.0, 0.0, 0.01, 0.01);
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, tet, MinFaces(1), Monitor::Null(), &stats);
  ASSERT_EQ(out.faces.size(), 2u);
  EXPECT_EQ(out.vertices.size(), 4u);
  const std::set<Tri> faces = SortedFaces(out);
  EXPECT_TRUE(faces.count({0, 1, 2}) && faces.count({0, 1, 3}));
  EXPECT_EQ(stats.tetrahedra, 1u);
  EXPECT_EQ(stats.tetrahedra_thinned, 1u);
  EXPECT_EQ(stats.tetrahedra_left, 0u);

  // The other way round: a and b lifted, so abc and abd (sharing ab) go.
  const TriangleMesh out2 = ThinMesh(*udf, Tetrahedron(0.01, 0.01, 0.0, 0.0), MinFaces(1),
                                     Monitor::Null());
  const std::set<Tri> faces2 = SortedFaces(out2);
  ASSERT_EQ(faces2.size(), 2u);
  EXPECT_TRUE(faces2.count({0, 2, 3}) && faces2.count({1, 2, 3}));
}

TEST(ThinMesh, OnlyAPairOnAManifoldEdgeGoesWhenTheTetrahedronSitsInASurface) {
  const auto udf = MakeShape("disc");
  // Heights make abc + acd (sharing the outer edge ac) the highest pair. Alone, that pair goes (step 1).
  TriangleMesh tet = Tetrahedron(0.03, 0.0, 0.01, 0.0);
  ThinMeshOptions step1_only = MinFaces(1);
  step1_only.thinning = "paper";
  const std::set<Tri> alone = SortedFaces(ThinMesh(*udf, tet, step1_only, Monitor::Null()));
  EXPECT_EQ(alone, (std::set<Tri>{{0, 1, 3}, {1, 2, 3}}));
  // Inside a surface: a fan of faces around the quad a-c-b-d makes every outer edge non-manifold, so only the
  // pairs on the diagonals ab or cd may go; of those abc + abd has the higher UDF.
  TriangleMesh surface = tet;
  const int e = 4;
  surface.vertices.push_back({-0.3, -0.3, 0.0});  // 4
  surface.vertices.push_back({0.3, -0.3, 0.0});   // 5
  surface.vertices.push_back({0.3, 0.3, 0.0});    // 6
  surface.vertices.push_back({-0.3, 0.3, 0.0});   // 7
  // Outer ring: faces on ac, cb, bd, da plus faces closing the ring.
  surface.faces.insert(surface.faces.end(), {{0, 2, e}, {2, 1, e + 1}, {1, 3, e + 2}, {3, 0, e + 3},
                                              {2, e, e + 1}, {1, e + 1, e + 2}, {3, e + 2, e + 3}, {0, e + 3, e}});
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, surface, MinFaces(1), Monitor::Null(), &stats);
  const std::set<Tri> faces = SortedFaces(out);
  EXPECT_EQ(faces.size(), 10u);
  EXPECT_TRUE(faces.count({0, 2, 3}) && faces.count({1, 2, 3})) << "the pair on ab must go, not the one on ac";
  // The result is a disc: every edge manifold or boundary, Euler characteristic 1.
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.nonmanifold_edges, 0u);
  EXPECT_EQ(topo.euler, 1);
  EXPECT_EQ(topo.components, 1u);
}

/// A strip of `n` triangles along x at offset y0 (an isolated component of n faces).
void AddStrip(TriangleMesh& m, int n, double y0) {
  const int base = static_cast<int>(m.vertices.size());
  for (int k = 0; k < n / 2 + 2; ++k) {
    m.vertices.push_back({-0.4 + 0.05 * k, y0, 0.0});
    m.vertices.push_back({-0.4 + 0.05 * k, y0 + 0.05, 0.0});
  }
  for (int f = 0; f < n; ++f) {
    const int k = f / 2;
    if (f % 2 == 0) m.faces.push_back({base + 2 * k, base + 2 * k + 2, base + 2 * k + 1});
    else m.faces.push_back({base + 2 * k + 1, base + 2 * k + 2, base + 2 * k + 3});
  }
}

/// A flat nx x ny grid of cells of size 0.1 from (-0.3, -0.3), two faces per cell (diagonal 00-11).
/// Vertex (i, j) is j * (nx + 1) + i.
void AddGrid(TriangleMesh& m, int nx, int ny) {
  const int base = static_cast<int>(m.vertices.size());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.vertices.push_back({-0.3 + 0.1 * i, -0.3 + 0.1 * j, 0.0});
  auto v = [&](int i, int j) { return base + j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.faces.push_back({v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      m.faces.push_back({v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
}

int AddVertex(TriangleMesh& m, const Vec3& p) {
  m.vertices.push_back(p);
  return static_cast<int>(m.vertices.size()) - 1;
}

TEST(ThinMesh, AComponentOfNineFacesGoesOneOfTenStays) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddStrip(m, 9, -0.2);
  AddStrip(m, 10, 0.2);
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null(), &stats);
  EXPECT_EQ(out.faces.size(), 10u);
  for (const Vec3& v : out.vertices) EXPECT_GT(v.y(), 0.1) << "only the 10-face strip is left";
  EXPECT_EQ(stats.components_removed, 1u);
  EXPECT_EQ(stats.component_faces_removed, 9u);
  // The threshold is an option: with 11, both go.
  EXPECT_TRUE(ThinMesh(*udf, m, MinFaces(11), Monitor::Null()).faces.empty());
}

TEST(ThinMesh, AFinOnASurfaceGoesButNoHoleIsOpened) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);
  // A fin: one triangle standing on the diagonal of cell (2, 2), vertices 16 and 24, making it non-manifold.
  m.faces.push_back({16, 24, AddVertex(m, {-0.05, -0.05, 0.05})});
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null());
  EXPECT_EQ(out.faces.size(), 72u);
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.nonmanifold_edges, 0u);
  EXPECT_EQ(topo.euler, 1);

  // A residual bubble: a pyramid over cell (2, 2) makes its 4 border edges non-manifold, so its 2 faces and
  // the pyramid's 4 are two small components over the same loop. Removing both would open a hole; the
  // pyramid (higher UDF) goes, the cell's faces stay.
  TriangleMesh p;
  AddGrid(p, 6, 6);
  const int apex = AddVertex(p, {-0.05, -0.05, 0.02});
  for (const auto& [a, b] : std::vector<std::pair<int, int>>{{16, 17}, {17, 24}, {24, 23}, {23, 16}})
    p.faces.push_back({a, b, apex});
  ThinMeshStats stats;
  const TriangleMesh out2 = ThinMesh(*udf, p, ThinMeshOptions{}, Monitor::Null(), &stats);
  const TopologyStats t2 = ComputeTopology(out2);
  EXPECT_EQ(out2.faces.size(), 72u);
  EXPECT_EQ(t2.nonmanifold_edges, 0u);
  EXPECT_EQ(t2.boundary_edges, 24u);
  EXPECT_EQ(t2.euler, 1);
  EXPECT_EQ(stats.components_removed, 1u);
  for (const Vec3& v : out2.vertices) EXPECT_EQ(v.z(), 0.0) << "the pyramid is the side removed";
}

TEST(ThinMesh, ASheetPieceBetweenBranchingCurvesIsNotALayerAndStays) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);  // vertex (i, j) is j * 7 + i
  // Walls of height 0.1 stand on the outline of cells (2..3, 2..3): its 8 base edges branch, and the 8
  // grid faces inside are a small component bounded by them. Removing it leaves every base edge two faces
  // (the grid outside and the wall), so the paper's rule removes it and opens a hole under the walls; but
  // no face that stays lies near it (the grid outside is at 180 degrees, the wall at 90), so it is the
  // only surface there and stays.
  const std::vector<int> loop = {16, 17, 18, 25, 32, 31, 30, 23};
  std::vector<int> top;
  for (int v : loop) top.push_back(AddVertex(m, m.vertices[static_cast<size_t>(v)] + Vec3(0.0, 0.0, 0.1)));
  for (size_t k = 0; k < loop.size(); ++k) {
    const size_t n = (k + 1) % loop.size();
    m.faces.push_back({loop[k], loop[n], top[n]});
    m.faces.push_back({loop[k], top[n], top[k]});
  }
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null());
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(out.faces.size(), 72u + 16u);
  EXPECT_EQ(topo.nonmanifold_edges, 8u);
  EXPECT_EQ(topo.boundary_edges, 24u + 8u);  // the grid's outline and the walls' top
  EXPECT_EQ(topo.euler, 1);                  // a disc with an annulus glued along a loop

  for (const double angle : {180.0, 95.0}) {  // the paper's rule; a layer angle above the walls' 90
    ThinMeshOptions o;
    o.layer_angle_deg = angle;
    const TopologyStats t = ComputeTopology(ThinMesh(*udf, m, o, Monitor::Null()));
    EXPECT_EQ(t.nonmanifold_edges, 0u) << angle;
    EXPECT_EQ(t.euler, 0) << angle << ": the grid got a hole under the walls";
  }
}

TEST(ThinMesh, DuplicateAndDegenerateFacesNeverSurvive) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);
  m.faces.push_back({8, 0, 1});                 // same vertex set as face 0, other order
  m.faces.push_back({3, 3, 4});                 // repeated vertex
  m.vertices.push_back(m.vertices[5]);          // a coincident copy: zero area
  m.faces.push_back({5, static_cast<int>(m.vertices.size()) - 1, 6});
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null(), &stats);
  EXPECT_EQ(stats.duplicate_faces, 1u);
  EXPECT_EQ(stats.degenerate_faces, 2u);
  EXPECT_EQ(out.faces.size(), 72u);
  EXPECT_EQ(SortedFaces(out).size(), out.faces.size());
  for (const Tri& t : out.faces) EXPECT_GT(TriangleQuality(out.vertices[t[0]], out.vertices[t[1]], out.vertices[t[2]]), 0.0);
}

TEST(ThinMesh, ATriangularHoleIsClosedButNotTheOutline) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);  // 72 faces; the outline has 24 edges
  const Tri lost = m.faces[30];  // an interior face: its three edges become a cycle of boundary edges
  m.faces.erase(m.faces.begin() + 30);
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null(), &stats);
  EXPECT_EQ(stats.holes_closed, 1u);
  Tri sorted = lost;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_TRUE(SortedFaces(out).count(sorted));
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.boundary_edges, 24u);
  EXPECT_EQ(topo.euler, 1);

  // A lone triangle is a boundary loop of three edges that already has its face: nothing is added.
  TriangleMesh tri;
  tri.vertices = {{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}, {0.0, 0.1, 0.0}};
  tri.faces = {{0, 1, 2}};
  EXPECT_EQ(ThinMesh(*udf, tri, MinFaces(1), Monitor::Null()).faces.size(), 1u);
}

// A vertical fin standing on row 3 (the line y = 0) of AddGrid(m, 6, 6): vertices above (i, 3) at z = 0.1,
// two faces per cell i except the cells in `skip`. Returns the index of its first vertex.
int AddFinOnRow3(TriangleMesh& m, const std::set<int>& skip = {}) {
  const int base = static_cast<int>(m.vertices.size());
  for (int i = 0; i <= 6; ++i) m.vertices.push_back({-0.3 + 0.1 * i, 0.0, 0.1});
  for (int i = 0; i < 6; ++i) {
    if (skip.count(i)) continue;
    m.faces.push_back({21 + i, 22 + i, base + i + 1});
    m.faces.push_back({21 + i, base + i + 1, base + i});
  }
  return base;
}

// The 6 x 6 grid with the whole fin of AddFinOnRow3 standing on it, every face in place.
void ExpectGridWithWholeFin(const TriangleMesh& out) {
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.boundary_edges, 24u + 8u);  // the grid's outline and the fin's three free sides
  EXPECT_EQ(topo.nonmanifold_edges, 6u);     // row 3
  EXPECT_EQ(out.faces.size(), 72u + 12u);
}

TEST(ThinMesh, ANotchAtABranchingLineIsClosed) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);  // vertex (i, j) is j * 7 + i; row j = 3 is the line y = 0
  // A vertical fin standing on row 3 makes its edges branching (3 faces). The grid face (2,2)-(3,3)-(2,3)
  // is missing: vertex (2,2) has boundary edges to (3,3) and (2,3), whose edge keeps the fin's face and the
  // grid face above it. Step 5 puts the face back; the fin is untouched.
  AddFinOnRow3(m);
  const int v22 = 16, v33 = 24, v23 = 23;
  m.faces.erase(std::find(m.faces.begin(), m.faces.end(), Tri{v22, v33, v23}));
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, FinNotInField(), Monitor::Null(), &stats);
  EXPECT_EQ(stats.holes_closed, 1u);
  EXPECT_TRUE(SortedFaces(out).count({v22, v23, v33}));
  ExpectGridWithWholeFin(out);
}

TEST(ThinMesh, ASheetFaceMissingBetweenTwoBranchingEdgesIsRestored) {
  // The centre of three-discs: the origin and a point on each half-axis, and the twelve quadrant faces of
  // the three discs, so every edge from the origin carries four. One quadrant face of z = 0, between -x
  // and +y, is missing; its outer edge keeps the face beyond it: a free edge whose ends are joined to the
  // origin by branching edges, each one sheet short.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {0.1, 0, 0}, {-0.1, 0, 0}, {0, 0.1, 0}, {0, -0.1, 0}, {0, 0, 0.1}, {0, 0, -0.1}};
  const int px = 1, nx = 2, py = 3, ny = 4, pz = 5, nz = 6;
  const int quadrants[3][4] = {{px, py, nx, ny}, {px, pz, nx, nz}, {py, pz, ny, nz}};
  for (const auto& q : quadrants)
    for (int k = 0; k < 4; ++k) {
      const int a = q[k], b = q[(k + 1) % 4];
      if (!(a == py && b == nx)) m.faces.push_back({0, a, b});
      m.faces.push_back({a, b, AddVertex(m, m.vertices[a] + m.vertices[b])});  // the quadrant beyond
    }
  const auto udf = MakeShape("three-discs");
  ThinMeshOptions options = MinFaces(1);
  const TriangleMesh out = ThinMesh(*udf, m, options, Monitor::Null());
  EXPECT_TRUE(SortedFaces(out).count(SortedTri({0, nx, py})));
  EXPECT_EQ(ComputeTopology(out).euler, 1) << "a disc-like patch, as around the centre of three-discs";
  EXPECT_EQ(ComputeTopology(m).euler, 0);
  // With --thinning paper the gap stays.
  options.thinning = "paper";
  EXPECT_FALSE(SortedFaces(ThinMesh(*udf, m, options, Monitor::Null())).count(SortedTri({0, nx, py})));
}

TEST(ThinMesh, AFaceOverACrackAtABranchingLineIsSplit) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);  // vertex (i, j) is j * 7 + i; row j = 3 is the line y = 0
  // A vertical fin stands on row 3, but one of its faces spans (1,3)-(3,3) over the grid vertex (2,3): a
  // T-junction, with a boundary edge (1,3)-(3,3) and no fin face on (1,3)-(2,3), (2,3)-(3,3). Step 5 splits
  // that face at (2,3), so every edge of row 3 has its three faces and the crack is gone.
  const int base = AddFinOnRow3(m, {1, 2});
  const int v13 = 22, v23 = 23, v33 = 24;
  for (const Tri& t : std::vector<Tri>{{v13, base + 2, base + 1}, {v13, v33, base + 2}, {v33, base + 3, base + 2}})
    m.faces.push_back(t);
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, FinNotInField(), Monitor::Null(), &stats);
  EXPECT_EQ(stats.cracks_split, 1u);
  EXPECT_TRUE(SortedFaces(out).count({v13, v23, base + 2}));
  EXPECT_TRUE(SortedFaces(out).count({v23, v33, base + 2}));
  ExpectGridWithWholeFin(out);
}

TEST(ThinMesh, AFlapLeftDanglingByANotchIsCollapsedKeepingChi) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 12);  // vertex (i, j) is j * 7 + i
  // A vertical fin on column 3 (x = 0), 24 faces: its base edges branch. The grid face (2,5)-(3,6)-(2,6)
  // is missing and in its place the dual put a flap (2,5)-(3,6)-top(3,6): on the diagonal, leaning on the
  // fin's edge above (3,6), with a free edge (2,5)-top(3,6). Step 4 closes the notch at (2,6); the diagonal
  // then has 3 faces and the flap hangs from its free edge. Step 5 removes it: the mesh is the grid with
  // the fin.
  std::vector<int> top(13);
  for (int j = 0; j <= 12; ++j) top[static_cast<size_t>(j)] = AddVertex(m, {0.0, -0.3 + 0.1 * j, 0.1});
  for (int j = 0; j < 12; ++j) {
    m.faces.push_back({j * 7 + 3, (j + 1) * 7 + 3, top[static_cast<size_t>(j + 1)]});
    m.faces.push_back({j * 7 + 3, top[static_cast<size_t>(j + 1)], top[static_cast<size_t>(j)]});
  }
  const int v25 = 37, v36 = 45, v26 = 44;
  m.faces.erase(std::find(m.faces.begin(), m.faces.end(), Tri{v25, v36, v26}));
  m.faces.push_back({v25, v36, top[6]});
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, FinNotInField(), Monitor::Null(), &stats);
  EXPECT_EQ(stats.holes_closed, 1u);
  EXPECT_EQ(stats.flap_faces_removed, 1u);
  EXPECT_TRUE(SortedFaces(out).count({v25, v26, v36}));
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(out.faces.size(), 144u + 24u);
  EXPECT_EQ(topo.nonmanifold_edges, 12u);      // the fin's base
  EXPECT_EQ(topo.boundary_edges, 36u + 14u);   // the grid's outline and the fin's three free sides
  EXPECT_EQ(topo.euler, 1);  // the grid, a disc, with a disc (the fin) glued to it along a line

  // With --thinning paper neither step runs: the flap stays, one more branching edge, and the notch stays
  // open.
  ThinMeshOptions paper;
  paper.thinning = "paper";
  const TopologyStats p = ComputeTopology(ThinMesh(*udf, m, paper, Monitor::Null()));
  EXPECT_EQ(p.nonmanifold_edges, 13u);
  EXPECT_EQ(p.boundary_edges, 36u + 14u + 3u);
}

// The end of crossing-planes' branching line (the y axis, from y = -0.5) at `y0`: a seed on the line there and
// one further in, a seed of each of the four half-planes beside them, a rim seed of the +x and of the -z
// half-planes at y0, and a flap the dual put across the line: from the +x rim seed to the -z seed, through
// the line's end (the last face).
TriangleMesh LineEndWithAFlap(double y0) {
  TriangleMesh m;
  m.vertices = {{0, y0, 0},           {0, y0 + 0.1, 0}, {0.1, y0 + 0.05, 0},  {0.1, y0, 0},         // end, line, +x, +x rim
                {0, y0 + 0.05, -0.1}, {0, y0, -0.12},   {-0.1, y0 + 0.05, 0}, {0, y0 + 0.05, 0.1}};  // -z, -z rim, -x, +z
  m.faces = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {0, 4, 5}, {0, 1, 6}, {0, 1, 7}, {0, 3, 4}};
  return m;
}

TEST(ThinMesh, AFlapAcrossTheEndOfABranchingLineAtTheRimsIsRemoved) {
  const auto udf = MakeShape("crossing-planes");
  ThinMeshOptions options = MinFaces(1);
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, LineEndWithAFlap(-0.5), options, Monitor::Null(), &stats);
  EXPECT_EQ(stats.rim_flaps_removed, 1u);
  EXPECT_FALSE(SortedFaces(out).count({0, 3, 4}));
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.nonmanifold_edges, 1u) << "only the line's own edge, with its four sheets";
  // In the middle of the squares the same flap leaves the edge (end, +x rim) with one face where the +x
  // sheet goes on beyond it: no rim, the flap stays.
  const TriangleMesh mid = ThinMesh(*udf, LineEndWithAFlap(-0.1), options, Monitor::Null(), &stats);
  EXPECT_EQ(stats.rim_flaps_removed, 0u);
  EXPECT_TRUE(SortedFaces(mid).count({0, 3, 4}));
  // Off (or with --thinning paper), step 6 does not run.
  options.rim_flaps = false;
  EXPECT_TRUE(SortedFaces(ThinMesh(*udf, LineEndWithAFlap(-0.5), options, Monitor::Null())).count({0, 3, 4}));
}

/// A fin (one face to a new vertex out in the disc's plane) on every edge of `m`'s faces: every edge of the
/// shell then carries a third face, so no face pair of a tetrahedron shares a manifold edge (step 1 is stuck,
/// as on a branching curve) and every face is a component of its own.
TriangleMesh WithFins(TriangleMesh m) {
  std::set<std::pair<int, int>> edges;
  for (const Tri& t : m.faces)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  int n = 0;
  for (const auto& [a, b] : edges) {
    const Vec3 mid = 0.5 * (m.vertices[a] + m.vertices[b]);
    const int w = AddVertex(m, {mid.x() + 0.05 * ++n, mid.y() + 0.6, 0.0});
    m.faces.push_back({a, b, w});
  }
  return m;
}

/// A triangular bipyramid: the triangle a, b, c on the disc and apexes above and below its centre at
/// heights z_up and -z_down; six faces, no tetrahedron.
TriangleMesh Bipyramid(double z_up, double z_down) {
  TriangleMesh m;
  m.vertices = {{-0.2, -0.1, 0.0}, {0.2, -0.1, 0.0}, {0.0, 0.2, 0.0}, {0.0, 0.0, z_up}, {0.0, 0.0, -z_down}};
  m.faces = {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 1, 4}, {1, 2, 4}, {2, 0, 4}};
  return m;
}

// MinFaces(1) without steps 5b and 6: the fins of WithFins reach beyond the disc's field, off the surface at
// a rim, and some lie within the overlap angle of a shell face they stand on, like folds.
ThinMeshOptions ShellsOnly() {
  ThinMeshOptions o = MinFaces(1);
  o.rim_flaps = false;
  o.fold_flaps = false;
  return o;
}

TEST(ThinMesh, AStuckShellIsOpenedAtOneFaceOffTheSurfaceAndChiFallsByOne) {
  const auto udf = MakeShape("disc");
  // c and d lifted: acd and bcd have the highest centroids (0.1, above 0.1 x their longest edge 0.4);
  // acd comes first in face order. Removing it opens the shell, so bcd stays.
  for (const TriangleMesh& shell : {Tetrahedron(0.0, 0.0, 0.15, 0.15), Bipyramid(0.15, 0.05)}) {
    const TriangleMesh thick = WithFins(shell);
    const long long chi_before = ComputeTopology(thick).euler;
    ThinMeshStats stats;
    const TriangleMesh out = ThinMesh(*udf, thick, ShellsOnly(), Monitor::Null(), &stats);
    EXPECT_EQ(stats.tetrahedra_thinned, 0u) << "no pair shares a manifold edge";
    EXPECT_EQ(stats.shells_opened, 1u);
    EXPECT_EQ(stats.tetrahedra_left, 0u);
    ASSERT_EQ(out.faces.size(), thick.faces.size() - 1);
    const std::set<Tri> faces = SortedFaces(out);
    EXPECT_FALSE(faces.count(SortedTri(shell.faces[shell.faces.size() == 4 ? 2 : 0]))) << "the highest face goes";
    const TopologyStats topo = ComputeTopology(out);
    EXPECT_EQ(topo.euler, chi_before - 1) << "b2 falls by one, b1 stays";
    EXPECT_EQ(topo.boundary_edges, ComputeTopology(thick).boundary_edges) << "no edge left with one face";
  }
  // Off, or with --thinning paper, the shell stays closed.
  ThinMeshOptions off = ShellsOnly();
  off.shell_rings = 0;
  EXPECT_EQ(ThinMesh(*udf, WithFins(Tetrahedron(0.0, 0.0, 0.15, 0.15)), off, Monitor::Null()).faces.size(), 10u);
  off = ShellsOnly();
  off.thinning = "paper";
  EXPECT_EQ(ThinMesh(*udf, WithFins(Bipyramid(0.15, 0.05)), off, Monitor::Null()).faces.size(), 15u);
}

TEST(ThinMesh, AShellWhoseFacesAllLieOnTheSurfaceIsACavityAndStays) {
  // The same stuck tetrahedron, in the field of itself: every face on the zero set, so none is off it.
  const TriangleMesh thick = WithFins(Tetrahedron(0.0, 0.0, 0.15, 0.15));
  const MeshUdf udf(thick, "tetrahedron with fins");
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(udf, thick, ShellsOnly(), Monitor::Null(), &stats);
  EXPECT_EQ(stats.shells_opened, 0u);
  EXPECT_EQ(stats.tetrahedra_left, 1u);
  EXPECT_EQ(SortedFaces(out), SortedFaces(thick));
}

TEST(ThinMesh, OpeningShellsNeverOpensAHoleInAClosedSurface) {
  // A closed surface (the octahedron's 8 faces on the disc's field, its equator on the disc) with a bubble
  // glued into it: a tetrahedron on one of its faces, lifted off the field. The surface's own shell is
  // within one ring of every face too, but its faces off the surface are opened only while a bubble closes
  // them: the result keeps the octahedron closed and opens only the bubble.
  TriangleMesh m;
  m.vertices = {{0.2, 0, 0}, {0, 0.2, 0}, {-0.2, 0, 0}, {0, -0.2, 0}, {0, 0, 0.02}, {0, 0, -0.02}};
  for (int k = 0; k < 4; ++k) {
    m.faces.push_back({k, (k + 1) % 4, 4});
    m.faces.push_back({(k + 1) % 4, k, 5});
  }
  const int apex = AddVertex(m, {0.05, 0.05, 0.3});
  m.faces.insert(m.faces.end(), {{0, 1, apex}, {1, 4, apex}, {4, 0, apex}});  // a tetrahedron on face (0, 1, 4)
  for (int v : {0, 1, 4}) m.faces.push_back({v, apex, AddVertex(m, m.vertices[v] + Vec3(0.0, 0.0, 0.3))});  // fins
  const auto udf = MakeShape("disc");
  ThinMeshStats stats;
  const TriangleMesh out = ThinMesh(*udf, m, ShellsOnly(), Monitor::Null(), &stats);
  EXPECT_EQ(stats.tetrahedra_thinned, 0u);
  EXPECT_EQ(stats.shells_opened, 1u);
  const TopologyStats topo = ComputeTopology(out);
  EXPECT_EQ(topo.boundary_edges, ComputeTopology(m).boundary_edges) << "no hole opened";
  EXPECT_EQ(topo.euler, ComputeTopology(m).euler - 1) << "one closed surface left of the two shells";
  // The octahedron's 8 faces all stay.
  const std::set<Tri> kept = SortedFaces(out);
  for (size_t f = 0; f < 8; ++f) EXPECT_TRUE(kept.count(SortedTri(m.faces[f])));
}

TEST(ThinMesh, ManifoldComponentsAreOrientedConsistently) {
  const auto udf = MakeShape("disc");
  TriangleMesh m;
  AddGrid(m, 6, 6);
  std::swap(m.faces[3][0], m.faces[3][1]);
  std::swap(m.faces[8][1], m.faces[8][2]);
  const TriangleMesh out = ThinMesh(*udf, m, ThinMeshOptions{}, Monitor::Null());
  // Consistent orientation: every interior edge is used once in each direction.
  std::set<std::pair<int, int>> directed;
  for (const Tri& t : out.faces)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(directed.insert({t[k], t[(k + 1) % 3]}).second) << "edge used twice the same way";
}

TEST(ThinMesh, NonManifoldEdgesAreExtracted) {
  // Three triangles on one edge (a book with three pages) and one lone triangle.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}, {3, 3, 3}, {4, 3, 3}, {3, 4, 3}};
  m.faces = {{0, 1, 2}, {0, 1, 3}, {1, 0, 4}, {5, 6, 7}};
  const EdgeSet nm = NonManifoldEdges(m);
  ASSERT_EQ(nm.edges.size(), 1u);
  ASSERT_EQ(nm.vertices.size(), 2u);
  EXPECT_EQ(nm.vertices[0], m.vertices[0]);
  EXPECT_EQ(nm.vertices[1], m.vertices[1]);
}

TEST(ThinMesh, BadOptionsAreUsageErrors) {
  ThinMeshOptions o;
  o.degenerate_quality = -1;
  EXPECT_THROW(o.Check(), UsageError);
  ThinMeshOptions f;
  f.overlap_angle_deg = 90;
  EXPECT_THROW(f.Check(), UsageError);
  ThinMeshOptions t;
  t.thinning = "repair";
  EXPECT_THROW(t.Check(), UsageError);
  for (const double angle : {0.0, 181.0}) {
    ThinMeshOptions l;
    l.layer_angle_deg = angle;
    EXPECT_THROW(l.Check(), UsageError) << angle;
  }
}

// ---- step 7: tangential relaxation ----

// The surface of the cube [-0.5,0.5]^3, each side an n x n grid of two triangles per cell, welded, facing
// out; the vertices inside a side moved in its plane by up to `jitter` cells (fixed stream).
TriangleMesh CubeGrid(int n, double jitter) {
  TriangleMesh c;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-jitter / n, jitter / n);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int base = static_cast<int>(c.vertices.size());
      for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
          const bool inside = i > 0 && i < n && j > 0 && j < n;
          Vec3 q;
          q[axis] = side - 0.5;
          q[(axis + 1) % 3] = double(i) / n - 0.5 + (inside ? u(rng) : 0.0);
          q[(axis + 2) % 3] = double(j) / n - 0.5 + (inside ? u(rng) : 0.0);
          c.vertices.push_back(q);
        }
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const int a = base + j * (n + 1) + i, b = a + 1, d = a + n + 1, e = d + 1;
          if (side == 1) {
            c.faces.push_back({a, b, e});
            c.faces.push_back({a, e, d});
          } else {
            c.faces.push_back({a, e, b});
            c.faces.push_back({a, d, e});
          }
        }
    }
  return WeldVertices(c, 1e-9);
}

// A closed cylinder (radius r, |z| <= h) with `segments` vertices round each rim: caps as fans, the side as
// quads split in two; outward orientation.
TriangleMesh Cylinder(int segments, double r, double h) {
  TriangleMesh m;
  m.vertices.push_back(Vec3(0, 0, h));
  m.vertices.push_back(Vec3(0, 0, -h));
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    m.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), h));
    m.vertices.push_back(Vec3(r * std::cos(a), r * std::sin(a), -h));
  }
  for (int k = 0; k < segments; ++k) {
    const int t0 = 2 + 2 * k, b0 = t0 + 1, t1 = 2 + 2 * ((k + 1) % segments), b1 = t1 + 1;
    m.faces.push_back({0, t0, t1});
    m.faces.push_back({1, b1, b0});
    m.faces.push_back({t0, b0, b1});
    m.faces.push_back({t0, b1, t1});
  }
  return m;
}

TEST(FeatureChords, ACoarseCylindersRimChordsAreSplitOntoTheRimCircleKeepingTheTopology) {
  const double r = 0.3, h = 0.2;
  const MeshUdf udf(Cylinder(512, r, h), "fine cylinder");  // the rims: circles to within 3e-6 of r
  // Chords of 60 degrees, their sagitta 0.13 x their length; they lie in the caps' planes, so only the
  // sheets' planes, not the UDF at their midpoints, show them.
  TriangleMesh mesh = Cylinder(6, r, h);
  const TriangleMesh before = mesh;
  ChordSplitOptions on;
  on.enabled = true;
  const ChordSplitStats st = SplitFeatureChords(udf, mesh, on, 30.0, Monitor::Null());
  // Sharp: the 12 rim edges and the 6 side edges between the prism's faces (60 degrees), which lie on the
  // cylinder (their feature is themselves): chords, the rim edges only.
  EXPECT_EQ(st.sharp, 18u);
  EXPECT_EQ(st.chords, 12u);
  EXPECT_EQ(st.split, 12u);
  ASSERT_EQ(mesh.vertices.size(), before.vertices.size() + 12);
  ASSERT_EQ(mesh.faces.size(), before.faces.size() + 24);
  for (size_t v = before.vertices.size(); v < mesh.vertices.size(); ++v) {
    const Vec3& p = mesh.vertices[v];
    EXPECT_NEAR(std::hypot(p.x(), p.y()), r, 1e-4) << v;  // on the rim circle, not on the chord (0.87 r)
    EXPECT_NEAR(std::abs(p.z()), h, 1e-4) << v;
  }
  const TopologyStats a = ComputeTopology(before), b = ComputeTopology(mesh);
  EXPECT_EQ(b.euler, a.euler);
  EXPECT_EQ(b.boundary_edges, 0u);
  EXPECT_EQ(b.nonmanifold_edges, 0u);
  // Orientation kept: the signed volume grows by the slivers added between chords and arcs.
  auto volume = [](const TriangleMesh& m) {
    double v = 0.0;
    for (const Tri& t : m.faces) v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]])) / 6.0;
    return v;
  };
  EXPECT_GT(volume(mesh), volume(before));
  // Off (the default): nothing changes; a mesh whose sharp edges are straight (the cube's) has no chords.
  TriangleMesh same = before;
  SplitFeatureChords(udf, same, ChordSplitOptions{}, 30.0, Monitor::Null());
  EXPECT_EQ(same.faces, before.faces);
  const auto cube = MakeShape("cube");
  TriangleMesh box = CubeGrid(4, 0.5);
  const ChordSplitStats none = SplitFeatureChords(*cube, box, on, 30.0, Monitor::Null());
  EXPECT_GT(none.sharp, 0u);
  EXPECT_EQ(none.chords, 0u);
}

TEST(Relax, ASpheresTrianglesEvenOutOnTheSphereWithTheSameFaces) {
  const auto udf = MakeShape("sphere");
  TriangleMesh mesh = CubeGrid(8, 0.3);
  for (Vec3& p : mesh.vertices) p = 0.5 * p.normalized();
  const TriangleMesh before = mesh;
  const RelaxStats st = RelaxTangentially(*udf, mesh, RelaxOptions{}, Monitor::Null());
  // All but a few at the grid's 8 corners, where three sides meet and a jittered edge can exceed 30 degrees.
  EXPECT_GE(st.movable, mesh.vertices.size() - 8 * 4);
  EXPECT_EQ(mesh.faces, before.faces);
  const double tolerance = 1e-5 * udf->Domain().Diagonal();  // the projection's, as for the seeds
  for (const Vec3& p : mesh.vertices) EXPECT_NEAR(p.norm(), 0.5, tolerance);
  EXPECT_GT(MeanTriangleQuality(mesh), MeanTriangleQuality(before) + 0.03);
  // The same positions whatever the threads (every step from the previous one's positions).
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    TriangleMesh again = before;
    RelaxTangentially(*udf, again, RelaxOptions{}, Monitor::Null());
    EXPECT_EQ(again.vertices, mesh.vertices) << threads << " threads";
  }
  omp_set_num_threads(omp_get_num_procs());
  RelaxOptions off;
  off.iterations = 0;
  TriangleMesh same = before;
  RelaxTangentially(*udf, same, off, Monitor::Null());
  EXPECT_EQ(same.vertices, before.vertices);
}

TEST(Relax, ACubesEdgesAndCornersStayAndEveryOtherVertexStaysOnItsSide) {
  const auto udf = MakeShape("cube");
  TriangleMesh mesh = CubeGrid(6, 0.3);
  const TriangleMesh before = mesh;
  const RelaxStats st = RelaxTangentially(*udf, mesh, RelaxOptions{}, Monitor::Null());
  EXPECT_EQ(st.movable, 6u * 5 * 5) << "the vertices inside the sides";
  EXPECT_GT(st.moves, 0u);
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3 &p = mesh.vertices[v], &q = before.vertices[v];
    int on_side = 0;
    for (int k = 0; k < 3; ++k) on_side += std::abs(std::abs(q[k]) - 0.5) < 1e-12 ? 1 : 0;
    if (on_side >= 2) {
      EXPECT_EQ(p, q) << "a vertex on an edge of the cube moved";
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      if (std::abs(std::abs(q[k]) - 0.5) < 1e-12) EXPECT_NEAR(p[k], q[k], 1e-5 * udf->Domain().Diagonal()) << "left its side";
      else EXPECT_LT(std::abs(p[k]), 0.5) << "crossed an edge of the cube";
    }
  }
  EXPECT_GT(MeanTriangleQuality(mesh), MeanTriangleQuality(before) + 0.02);
}

TEST(Relax, RimAndBranchingVerticesStayTheSheetInsideMovesInItsPlane) {
  // A 6 x 6 grid on the disc's plane, its inside jittered, with a fin of one row of cells standing on its
  // middle line (the fin is not in the field: all its vertices lie on the rim or on the branching line).
  const auto udf = MakeShape("disc");
  const int n = 6;
  TriangleMesh sheet;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.3 * 0.6 / n, 0.3 * 0.6 / n);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool inside = i > 0 && i < n && j > 0 && j < n;
      const double x = 0.6 * i / n - 0.3 + (inside ? u(rng) : 0.0);
      const double y = 0.6 * j / n - 0.3 + (inside && j != n / 2 ? u(rng) : 0.0);  // the middle row on y = 0
      sheet.vertices.emplace_back(x, y, 0.0);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, d = a + n + 1, e = d + 1;
      sheet.faces.push_back({a, b, e});
      sheet.faces.push_back({a, e, d});
    }
  std::vector<int> spine;  // the grid's vertices on y = 0, by x
  for (size_t v = 0; v < sheet.vertices.size(); ++v)
    if (std::abs(sheet.vertices[v].y()) < 1e-12) spine.push_back(static_cast<int>(v));
  std::sort(spine.begin(), spine.end(), [&](int a, int b) { return sheet.vertices[static_cast<size_t>(a)].x() < sheet.vertices[static_cast<size_t>(b)].x(); });
  for (size_t k = 0; k + 1 < spine.size(); ++k) {
    const int top0 = static_cast<int>(sheet.vertices.size());
    sheet.vertices.push_back(sheet.vertices[static_cast<size_t>(spine[k])] + Vec3(0, 0, 0.1));
    sheet.vertices.push_back(sheet.vertices[static_cast<size_t>(spine[k + 1])] + Vec3(0, 0, 0.1));
    sheet.faces.push_back({spine[k], spine[k + 1], top0 + 1});
    sheet.faces.push_back({spine[k], top0 + 1, top0});
  }
  sheet = WeldVertices(sheet, 1e-9);
  const TriangleMesh before = sheet;
  const RelaxStats st = RelaxTangentially(*udf, sheet, RelaxOptions{}, Monitor::Null());
  EXPECT_EQ(st.movable, 5u * 4) << "inside the grid, off the branching line";
  EXPECT_GT(st.moves, 0u);
  const TopologyStats t = ComputeTopology(sheet);
  for (size_t v = 0; v < sheet.vertices.size(); ++v) {
    const Vec3 &p = sheet.vertices[v], &q = before.vertices[v];
    const bool rim_or_fin = std::abs(std::abs(q.x()) - 0.3) < 1e-12 || std::abs(std::abs(q.y()) - 0.3) < 1e-12 ||
                            std::abs(q.y()) < 1e-12 || q.z() != 0.0;
    if (rim_or_fin) EXPECT_EQ(p, q) << "a rim, branching or fin vertex moved";
    else EXPECT_NEAR(p.z(), 0.0, 1e-5 * udf->Domain().Diagonal());
  }
  EXPECT_EQ(ComputeTopology(before).nonmanifold_edges, t.nonmanifold_edges);
}

class ThinMeshExe : public ::testing::Test {
 protected:
  TempDir dir_;
};

TEST_F(ThinMeshExe, WritesMeshAndNonManifoldEdges) {
  TriangleMesh m;
  AddGrid(m, 6, 6);
  m.faces.push_back({16, 24, AddVertex(m, {-0.05, -0.05, 0.05})});  // a fin, kept with --min-component-faces 1
  WriteMeshPly(dir_ / "thick.ply", m, Provenance{"test", "", ""});
  const auto r = RunProgram("thin-mesh", {"--udf", "shape:disc", "-i", dir_ / "thick.ply", "-o", dir_ / "mesh.ply",
                                          "--nm-edges", dir_ / "nm.ply", "--min-component-faces", "1",
                                          "--rim-flaps", "false"});  // the fin is not in the field
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const TriangleMesh out = ReadMeshPly(dir_ / "mesh.ply");
  EXPECT_EQ(out.faces.size(), 73u);
  const std::string nm = test::ReadBytes(dir_ / "nm.ply");
  EXPECT_NE(nm.find("comment voroudf edges 1"), std::string::npos);
  EXPECT_NE(nm.find("element edge 1"), std::string::npos);
}

TEST_F(ThinMeshExe, BadInputExitsThreeAndWritesNothing) {
  // An index out of range.
  test::WriteBytes(dir_ / "bad.ply",
                   "ply\nformat ascii 1.0\ncomment voroudf mesh 1\nelement vertex 3\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  auto r = RunProgram("thin-mesh", {"--udf", "shape:disc", "-i", dir_ / "bad.ply", "-o", dir_ / "out.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_FALSE(test::Exists(dir_ / "out.ply"));
  // A seeds file given as the thick mesh.
  SeedCloud seeds;
  seeds.Resize(3);
  seeds.position = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
  WriteSeeds(dir_ / "seeds.ply", seeds, Provenance{"test", "", ""});
  r = RunProgram("thin-mesh", {"--udf", "shape:disc", "-i", dir_ / "seeds.ply", "-o", dir_ / "out.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("thin-mesh: error:"), std::string::npos);
  EXPECT_FALSE(test::Exists(dir_ / "out.ply"));
  // A bad option value.
  r = RunProgram("thin-mesh", {"--udf", "shape:disc", "-i", dir_ / "seeds.ply", "-o", dir_ / "out.ply",
                               "--degenerate-quality", "-1"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(dir_.List().size(), 2u) << "only bad.ply and seeds.ply";
}

// ---- step 5b: folded flaps ----

// The 4 x 4 grid of unit cells in z = 0, each cell (a, b, d), (a, d, c) with a its lower left corner.
TriangleMesh GridSheet() {
  TriangleMesh m;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) m.vertices.emplace_back(i, j, 0);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const int a = j * 5 + i, b = a + 1, c = a + 5, d = c + 1;
      m.faces.push_back({a, b, d});
      m.faces.push_back({a, d, c});
    }
  return m;
}

size_t EdgesWithFaces(const std::vector<Tri>& faces, size_t at_least) {
  const EdgeFaces inc = BuildEdgeFaces(faces);
  return static_cast<size_t>(
      std::count_if(inc.faces.begin(), inc.faces.end(), [&](const auto& f) { return f.size() >= at_least; }));
}

TEST(ThinMeshFolds, AFaceWithAFreeEdgeFoldedOverAnotherAtABranchingEdgeGoes) {
  TriangleMesh m = GridSheet();
  const std::vector<Tri> sheet = m.faces;
  // The flap: on the diagonal (1,1)-(2,2) of the sheet, its third vertex (3,2) on the side of (2,1), i.e.
  // folded over the face (1,1), (2,1), (2,2); its edge (1,1)-(3,2) is free, (2,2)-(3,2) a third face.
  const int a = 6, d = 12, x = 13;
  m.faces.push_back({a, d, x});
  ASSERT_EQ(EdgesWithFaces(m.faces, 3), 2u);
  EXPECT_EQ(RemoveFoldedFlaps(m.vertices, m.faces, 25.0), 1u);
  EXPECT_EQ(m.faces, sheet);  // the sheet as it was, in its order
  EXPECT_EQ(EdgesWithFaces(m.faces, 3), 0u);
  // Unfolded (its third vertex lifted to 45 degrees over the sheet: outside the overlap angle), it stays.
  TriangleMesh lifted = GridSheet();
  lifted.vertices.emplace_back(2.5, 1.5, 0.5 * std::sqrt(2.0) * 1.0);  // 45 degrees up from the diagonal
  lifted.faces.push_back({a, d, static_cast<int>(lifted.vertices.size()) - 1});
  EXPECT_EQ(RemoveFoldedFlaps(lifted.vertices, lifted.faces, 25.0), 0u);
}

TEST(ThinMeshFolds, BranchingSheetsAndFoldsWithoutAFreeEdgeStay) {
  // Three half-planes on one spine, 120 degrees apart, each with free outer edges: a branching curve.
  TriangleMesh book;
  book.vertices = {Vec3(0, 0, 0), Vec3(0, 0, 1)};
  for (int k = 0; k < 3; ++k) {
    const Vec3 out(std::cos(2 * M_PI * k / 3), std::sin(2 * M_PI * k / 3), 0);
    const int o = static_cast<int>(book.vertices.size());
    book.vertices.push_back(out);
    book.vertices.push_back(out + Vec3(0, 0, 1));
    book.faces.push_back({0, o, o + 1});
    book.faces.push_back({0, o + 1, 1});
  }
  EXPECT_EQ(RemoveFoldedFlaps(book.vertices, book.faces, 25.0), 0u);
  EXPECT_EQ(book.faces.size(), 6u);
  // A second layer without a free edge (a face repeated over the sheet's own vertices) is not a flap.
  TriangleMesh doubled = GridSheet();
  doubled.faces.push_back({6, 12, 7});
  doubled.faces.push_back({6, 12, 11});
  EXPECT_EQ(RemoveFoldedFlaps(doubled.vertices, doubled.faces, 25.0), 0u);
}

}  // namespace
}  // namespace voroudf

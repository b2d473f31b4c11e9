// The synthetic non-manifold benchmark construction on a box made in code.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.h"
#include "common/mesh_topology.h"
#include "pipelines/tools/synthetic_nonmanifold.h"

namespace voroudf {
namespace {

// Surface of [0,2]x[0,1]x[0,1], each face split into 2x2 quads (so the cut crosses several triangles).
TriangleMesh Box() {
  TriangleMesh m;
  const Vec3 size(2, 1, 1);
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const int base = static_cast<int>(m.vertices.size());
      for (int i = 0; i <= 2; ++i)
        for (int j = 0; j <= 2; ++j) {
          Vec3 p;
          p[axis] = side * size[axis];
          p[u] = i * size[u] / 2;
          p[v] = j * size[v] / 2;
          m.vertices.push_back(p);
        }
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          const int a = base + 3 * i + j, b = a + 3, c = a + 4, d = a + 1;
          m.faces.push_back({a, b, c});
          m.faces.push_back({a, c, d});
        }
    }
  return WeldVertices(m, 1e-9);  // the six faces share their border vertices
}

TEST(SyntheticNonManifold, CrossingsBecomeFourFacedEdgesOnTheTwoCutPlanes) {
  const TriangleMesh box = Box();
  ASSERT_EQ(ComputeTopology(box).euler, 2);
  OverlapOptions options;
  const TriangleMesh merged = MakeOverlapNonManifold(box, options);
  const EdgeFaces ef = BuildEdgeFaces(merged.faces);
  const Vec3 n = options.plane_normal.normalized();
  const Vec3 centre(1, 0.5, 0.5);
  const double band = options.overlap_rel * std::sqrt(6.0);
  int nonmanifold = 0, on_caps = 0;
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const size_t valence = ef.faces[e].size();
    EXPECT_TRUE(valence == 2 || valence == 4) << valence;  // closed parts glued along curves
    if (valence != 4) continue;
    ++nonmanifold;
    for (int v : ef.edges[e]) {
      // The parts can only cross where both exist: in the overlap band between the cut plane (h = 0,
      // the negative part's cap) and its shifted copy (h = -band, the positive part's cap).
      const double h = n.dot(merged.vertices[v] - centre);
      EXPECT_TRUE(h > -band - 1e-9 && h < 1e-9) << h;
      on_caps += std::abs(h) < 1e-9 || std::abs(h + band) < 1e-9;
    }
  }
  EXPECT_GE(nonmanifold, 8);
  EXPECT_GT(on_caps, 0);  // each cap crosses the other part's walls
  EXPECT_EQ(ComputeTopology(merged).boundary_edges, 0u);
}

TEST(SyntheticNonManifold, RefusesOpenMeshes) {
  TriangleMesh open = Box();
  open.faces.pop_back();
  EXPECT_THROW(MakeOverlapNonManifold(open, OverlapOptions{}), InputError);
}

}  // namespace
}  // namespace voroudf

#pragma once
// Combinatorics of indexed triangle sets that may be non-manifold: edge-to-face incidence, valences,
// boundary and non-manifold edges and vertices, components, Euler characteristic, welding. Written by
// hand because OpenMesh's halfedge structure cannot hold an edge with three or more faces (DESIGN.md).
#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/types.h"

namespace voroudf {

using Edge = std::array<int, 2>;  ///< vertex indices, smaller first

inline Edge MakeEdge(int a, int b) { return a < b ? Edge{a, b} : Edge{b, a}; }
inline uint64_t EdgeKey(const Edge& e) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(e[0])) << 32) | static_cast<uint32_t>(e[1]);
}

/// The vertex of face t that is neither a nor b; -1 if there is none (a face that repeats a vertex).
inline int ThirdVertex(const Tri& t, int a, int b) {
  for (int v : t)
    if (v != a && v != b) return v;
  return -1;
}

/// The vertex triple in increasing order: the key of "the same three vertices" in any orientation.
inline Tri SortedTri(Tri t) {
  if (t[0] > t[1]) std::swap(t[0], t[1]);
  if (t[1] > t[2]) std::swap(t[1], t[2]);
  if (t[0] > t[1]) std::swap(t[0], t[1]);
  return t;
}

/// A hash of a vertex triple (as stored: callers that mean "the same three vertices" sort them first).
struct TriHash {
  size_t operator()(const Tri& t) const {
    uint64_t h = static_cast<uint32_t>(t[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(t[1]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(t[2]);
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

/// Every undirected edge of the mesh with the faces that contain it, in a deterministic order
/// (edges sorted by (v0, v1); faces in increasing index).
struct EdgeFaces {
  std::vector<Edge> edges;
  std::vector<std::vector<int>> faces;  ///< per edge
  std::unordered_map<uint64_t, int> index;  ///< EdgeKey -> position in `edges`

  /// Position of edge (a, b), or -1.
  int Find(int a, int b) const;
};

/// Builds the edge-face incidence. Degenerate faces (repeated vertex) contribute their distinct edges.
EdgeFaces BuildEdgeFaces(const std::vector<Tri>& faces);

struct TopologyStats {
  size_t num_vertices = 0;          ///< referenced by at least one face
  size_t num_edges = 0;
  size_t num_faces = 0;
  size_t boundary_edges = 0;        ///< valence 1
  size_t nonmanifold_edges = 0;     ///< valence >= 3
  size_t nonmanifold_vertices = 0;  ///< on a non-manifold edge, or whose faces form several fans
  size_t components = 0;            ///< connected through shared vertices
  long long euler = 0;              ///< V - E + F over referenced vertices
};

/// Counts over the mesh as given (no welding). \pre face indices are valid
TopologyStats ComputeTopology(const TriangleMesh& mesh);

/// Component id per face, faces connected when they share an edge; ids in order of first face.
std::vector<int> EdgeConnectedComponents(const std::vector<Tri>& faces, int* num_components);

/// Feature edges of a welded mesh: edges with two faces whose dihedral angle departs from flat by more
/// than `min_angle_deg` (the angle between the faces' normals, with the normals oriented consistently
/// across the edge when the faces are), and every non-manifold edge (3+ faces: a branching curve).
/// In BuildEdgeFaces order. The second form takes the mesh's incidence, when the caller has it.
std::vector<Edge> FeatureEdges(const TriangleMesh& mesh, double min_angle_deg);
std::vector<Edge> FeatureEdges(const TriangleMesh& mesh, const EdgeFaces& ef, double min_angle_deg);

/// (b − a) × (c − a) for face t = (a, b, c) of `vertices`: its normal by its orientation, twice its area long.
Vec3 AreaNormal(const std::vector<Vec3>& vertices, const Tri& t);

/// Merges vertices closer than `tolerance` (grid hashing; the smallest index is kept), remaps faces,
/// drops faces that became degenerate and vertices no face references.
TriangleMesh WeldVertices(const TriangleMesh& mesh, double tolerance);

/// The same mesh in an order that depends on its geometry alone: vertices sorted by (x, y, z), each face
/// rotated to start at its smallest vertex index (orientation kept), faces sorted. For generators whose
/// libraries emit elements in an order that follows memory addresses (CGAL's corefinement), so that the
/// same geometry always gives the same bytes.
TriangleMesh CanonicalOrder(const TriangleMesh& mesh);

/// Drops vertices no face references, renumbering the rest in order.
TriangleMesh RemoveUnreferencedVertices(const TriangleMesh& mesh);

/// Triangle quality of Frey & Borouchaki (paper, supplementary): (6/sqrt 3) * area / (half-perimeter *
/// longest edge); 1 for an equilateral triangle, 0 for a degenerate one.
double TriangleQuality(const Vec3& a, const Vec3& b, const Vec3& c);

/// Mean over all faces of TriangleQuality (the paper's TQ): 1 for an equilateral triangle, 0 for a
/// degenerate one (which still counts in the mean). 0 for a mesh without faces.
double MeanTriangleQuality(const TriangleMesh& mesh);

}  // namespace voroudf

#pragma once
// Exact closest point on a triangle set: a bounding volume hierarchy tuned for many point queries.
//
// Why not CGAL's AABB_tree: it is the reference this is tested and benchmarked against (tests/bench/
// bench_udf.cpp), but its generic kernel and traversal run several times slower than the pipeline's
// budget (>= 1 M queries per second per core near the surface). This BVH keeps what makes the query fast:
// binned-SAH splits, at most kMaxLeafSize triangles per leaf stored contiguously with their Ericson
// coefficients and plane precomputed, 64-byte nodes holding both children's boxes in one flat array, and a
// nearest-child-first traversal that prunes boxes (and triangles, by their plane) by squared distance.
#include <cstdint>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// Closest point of a triangle (a, b, c) to p by Ericson's Voronoi-region method (Real-Time Collision
/// Detection, 2005, Sec. 5.1.5), made robust for degenerate triangles: a triangle whose edges are
/// (numerically) collinear or of zero length is treated as the union of its three edges, and no
/// division is ever by zero. Returns the closest point; this is the reference the BVH's inlined version
/// is tested against.
Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

class TriangleBvh {
 public:
  static constexpr int kMaxLeafSize = 4;

  struct Hit {
    double sq_distance = 0.0;  ///< squared distance from the query to `point`
    Vec3 point;                ///< the closest point on the triangle set
    int face = -1;             ///< index of its triangle in the faces given to the constructor
    int slot = -1;             ///< its place in the BVH: pass it as the hint of a nearby query
  };

  /// Builds the hierarchy over every face (degenerate ones included; faces are not welded or deduplicated:
  /// the field is defined by the triangles alone, so duplicates and soups are harmless).
  /// \pre faces is non-empty and every index is a valid vertex; vertices are finite.
  TriangleBvh(const std::vector<Vec3>& vertices, const std::vector<Tri>& faces);

  /// The closest point to p over all triangles. Ties (the medial axis) go to the triangle with the
  /// smallest slot: the answer is the minimum of (squared distance, slot), whatever the hint.
  /// \param hint the slot of a previous nearby query's hit (or -1): testing that triangle first gives a
  ///        tight bound at once, which prunes most of the traversal for spatially coherent queries. Every
  ///        triangle within kTieSlack of the running bound is still examined, so the hint changes the
  ///        cost, never the result.
  /// Thread-safe (const, no shared mutable state).
  Hit Closest(const Vec3& p, int hint = -1) const;

  /// Unit normal of face `face` (original index); for a degenerate face a deterministic unit vector
  /// orthogonal to its longest edge (or +z if all three corners coincide).
  Vec3 FaceNormal(int face) const;

  size_t num_nodes() const { return nodes_.size(); }
  size_t num_degenerate() const { return num_degenerate_; }
  int depth() const { return depth_; }

 private:
  // An inner node holds the boxes of its two children, so that choosing the nearer child reads one cache
  // line. Child c is a leaf of count[c] > 0 triangles starting at slot child[c] of tris_, or (count 0) the
  // inner node nodes_[child[c]]. Float bounds, rounded outwards, keep a node at 64 bytes.
  struct alignas(64) Node {
    float lo[3][2];  // [axis][child]: both children's bounds along an axis side by side (SIMD loads)
    float hi[3][2];
    int32_t child[2];
    int32_t count[2];
  };
  struct ChildRef {
    int32_t index;
    int32_t count;
    Eigen::AlignedBox3d box;
  };
  // Triangle data in leaf order: a, b - a, c - a and the dot products Ericson's method reuses.
  struct PackedTri {
    double a[3], ab[3], ac[3];
    double d00, d01, d11, inv_det;  // inv_det = 1/(d00 d11 - d01^2); 0 marks a degenerate triangle
    double n[3];                    // unit normal (zero if degenerate): (ap.n)^2 bounds the distance from below
  };

  ChildRef Build(std::vector<int>& order, int begin, int end, const std::vector<Vec3>& centroid,
                 const std::vector<Eigen::AlignedBox3d>& box, int depth);
  void SetChild(int node, int c, const ChildRef& ref);

  std::vector<Node> nodes_;
  std::vector<PackedTri> tris_;
  std::vector<int> face_of_;   // leaf-order slot -> original face index
  std::vector<Vec3> normal_;   // per original face
  size_t num_degenerate_ = 0;
  double tie_slack_ = 0.0;  // lengths this much above the best are still examined (rounding of bounds)
  int depth_ = 0;
};

}  // namespace voroudf

#pragma once
// The non-manifold curves of a reference's surface that its connectivity does not show (docs/evaluate.md,
// "Non-manifold curves of the reference"). A UDF is the distance to the union of the triangles; where two
// parts of a mesh cross, or touch along a line without sharing its vertices (parts modelled separately and
// placed against each other), the union branches there although no edge of the mesh has 3 faces. The mesh
// a UDF mesher makes of it has branching edges there, rightly.
#include <vector>

#include "common/mesh_topology.h"
#include "common/types.h"

namespace voroudf {

/// Segments where the union of `mesh`'s triangles is non-manifold away from its edges of 3+ faces: pieces of
/// the intersection of two non-coplanar triangles along which 3 or more half-sheets of the union meet.
/// The half-sheets at a piece are counted at its midpoint m over every triangle within `tolerance` of m whose
/// plane contains the piece's line: the directions across the line, in its plane, that point into it from m
/// (2 where m is inside it, 1 where m is on its edge); directions within `min_angle_deg` of each other count once (the coincident walls of two touching
/// parts; two sheets crossing at a smaller angle, such as two nearly coincident faceted surfaces, are one sheet to a
/// UDF mesher, as a crease below the feature angle is no feature). So two parts crossing give 4, a part
/// whose face ends on another's gives 3 (both non-manifold), and two faces meeting at an edge with
/// unshared vertices give 2 (a seam or crease: not reported). Pieces on an
/// edge of the mesh are not reported (its edges of 3+ faces are NonManifoldEdges' business).
///
/// Candidate pairs from CGAL's box intersection over the triangles' bounding boxes; each pair whose planes
/// cross (at more than 1 degree) meets along its planes' line clipped to both triangles.
/// \param mesh           welded (WeldVertices), in the normalised frame
/// \param tolerance      distance below which a point lies on a triangle (the weld tolerance)
/// \param min_angle_deg  sheets closer in angle than this are one (evaluate's --feature-angle)
/// \returns the segments as vertices + edges, in a deterministic order (independent of threads)
struct CurveSegments {
  std::vector<Vec3> vertices;
  std::vector<Edge> edges;
};
CurveSegments CrossingCurves(const TriangleMesh& mesh, double tolerance, double min_angle_deg);

/// Whether the union of `mesh`'s triangles branches across each line through points[i] along directions[i]:
/// its cross-section by the plane through the point normal to the line, within the disc of radius `radius`,
/// has a connected piece that leaves the disc at 3 or more points. Pieces closer than `join` are one (parts
/// that touch or coincide), and so are exits closer than `join` (coincident faces of two parts). The
/// cross-section of a manifold surface is a set of curves, each piece of which leaves the disc twice or
/// not at all; a rim inside the disc leaves once. So 3+ exits mean a wall on a plate, a face leaving another
/// tangentially (where the coincident faces of two nested parts part), parts crossing (4) or touching:
/// the branching that CrossingCurves, which looks for lines where two triangles cross at an angle, cannot
/// see. Two sheets closer than the radius but apart are two pieces of 2 exits each. Candidate triangles
/// from CGAL's box intersection.
/// \pre points and directions (non-zero) of the same size; radius > join > 0
std::vector<char> BranchesAcross(const TriangleMesh& mesh, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& directions, double radius, double join);

/// For each point, the distinct exits from the disc (as in BranchesAcross, same `radius` and `join`) of the
/// cross-section's piece that passes within `join` of the point; 0 if none does. Across an open boundary
/// (a rim) of the union the piece through a point on it leaves the disc once; across an unwelded seam (two
/// faces ending on the same line, or one ending within `join` of another) it leaves twice, because the union
/// goes on there. A piece that turns back inside the disc (a strip narrower than the radius) leaves 0 times.
/// \pre points and directions (non-zero) of the same size; radius > join > 0
std::vector<size_t> ExitsThrough(const TriangleMesh& mesh, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& directions, double radius, double join);

}  // namespace voroudf

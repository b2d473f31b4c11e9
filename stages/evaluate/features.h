#pragma once
// evaluate's feature recall (docs/evaluate.md, "Features"): how much of the reference's sharp edges, corners
// and open boundary the mesh traces with its own edges and vertices.
#include <cstddef>
#include <vector>

#include "common/mesh_topology.h"
#include "common/monitor.h"
#include "common/types.h"

namespace voroudf {

/// The median length of the mesh's edges (each edge once); 0 without edges.
double MedianEdgeLength(const TriangleMesh& mesh);

/// Edges with exactly one face, in BuildEdgeFaces order.
std::vector<Edge> BoundaryEdges(const TriangleMesh& mesh);

/// Vertices where 3 or more of `edges` meet.
std::vector<int> Corners(const std::vector<Edge>& edges);

/// Samples of `ref`'s boundary edges (SampleEdges, `samples` of them) that lie on a rim of the union of its
/// triangles, the open boundary a UDF has: those whose cross-section piece leaves a disc of 2 x `tolerance`
/// at most once (ExitsThrough, pieces within `tolerance` joined). Samples on an unwelded seam, where another
/// face of the reference ends on or within `tolerance` of the same line, are not: the UDF's zero set goes on
/// there, and a mesh that closes it is right. \param rim_length receives the boundary edges' length times
/// the share of samples kept. All samples if `tolerance` is 0.
std::vector<Vec3> RimSamples(const TriangleMesh& ref, double tolerance, size_t samples, double* rim_length);

struct FeatureMetrics {
  double tolerance = 0;            ///< 0.1 x the mesh's median edge length: "on" a mesh edge or vertex
  double feature_length = 0;       ///< total length of the reference's feature edges
  double recall = 1;               ///< share of that length within `tolerance` of a mesh edge (1 if none)
  double feature_mean_x1e3 = 0;    ///< mean distance of the reference's feature samples to the mesh's feature edges, x1e3
  double feature_max_x1e3 = 0;     ///< their maximum / reference diagonal, x1e3
  size_t corners = 0;              ///< reference corners (3+ feature edges meet)
  size_t corners_matched = 0;      ///< of those, with a mesh vertex within `tolerance`
  double boundary_length = 0;      ///< length of the reference's rims: its boundary edges where its union ends
  double boundary_recall = 1;      ///< share of it within `tolerance` of a mesh boundary edge (1 if none)
  double boundary_max_x1e3 = 0;    ///< largest distance of a reference boundary sample to the mesh's boundary edges / diagonal, x1e3
  std::vector<Vec3> missed;        ///< the reference's feature samples farther than `tolerance` from every mesh edge
};

/// \pre both meshes welded, in the reference's frame; `diagonal` the reference's bbox diagonal there
FeatureMetrics FeatureRecall(const TriangleMesh& mesh, const TriangleMesh& ref, double feature_angle_deg,
                             size_t samples, double diagonal, Monitor& monitor);

}  // namespace voroudf

#pragma once
// How well a mesh of a built-in shape keeps the shape's non-manifold curves (the robustness sweep,
// pipelines/nonmanifold-sweep.sh, and the chain tests).
#include <cstddef>

#include "common/shapes.h"
#include "common/types.h"

namespace voroudf {

struct BranchingCheck {
  size_t nonmanifold_edges = 0;  ///< edges with 3+ faces
  size_t off_curve = 0;          ///< of those, the ones with an end farther than `tol` from the curves, or the midpoint farther than max(tol, 5 % of the edge)
  double max_offset = 0;         ///< the largest such distance over all non-manifold edges
  double longest_gap = 0;        ///< longest stretch of the curves farther than `tol` from every non-manifold edge
  size_t boundary_edges = 0;
  long long euler = 0, expected_euler = 0;
  double mean_edge = 0;          ///< mean edge length of the mesh (the spacing the gap is judged by)
  bool pass = false;             ///< no edge off the curves, no gap over `max_gap`, the expected chi
};

/// \param max_gap  longest uncovered stretch allowed; <= 0: 3 x the mesh's mean edge length
BranchingCheck CheckBranchingCurves(const TriangleMesh& mesh, const ShapeTopology& truth, double tol, double max_gap);

}  // namespace voroudf

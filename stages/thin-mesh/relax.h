#pragma once
// thin-mesh's last step (docs/thin-mesh.md, step 7): tangential relaxation of the thin mesh's vertices.
// Not in the paper, whose mesh vertices are the optimised seeds themselves: the seeds are spread by
// repulsion, which leaves their spacing uneven by about 15 % (optimize-seeds' spacing CV), and the triangles
// follow that unevenness. A few Laplacian steps in each vertex's tangent plane, taken back onto the zero set,
// even the triangles out without moving the surface (Botsch et al., Polygon Mesh Processing, 2010, Sec. 6.5:
// the tangential smoothing of isotropic remeshing).
#include <cstddef>

#include "common/monitor.h"
#include "common/types.h"
#include "common/udf.h"

namespace voroudf {

struct RelaxOptions {
  int iterations = 3;              ///< --relax-iters: Laplacian steps (0: off)
  double step = 0.5;               ///< --relax-step: the share of the way to the ring's centroid taken per step
  double feature_angle_deg = 30.0; ///< vertices on an edge whose faces' normals differ by more stay (evaluate's)
  double max_turn_deg = 30.0;      ///< a move that turns one of its vertex's faces by more than this is undone

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

struct RelaxStats {
  size_t movable = 0;  ///< vertices the relaxation may move
  size_t moves = 0;    ///< moves kept, over all steps
  size_t undone = 0;   ///< moves undone: not projected, off to another sheet, or turning a face
};

/// Moves every vertex of `mesh` that lies inside a smooth manifold patch toward the centroid of its
/// neighbours, within its tangent plane, then back onto the zero set of `udf`; `options.iterations` times,
/// all vertices at once from the previous positions (so the result does not depend on the order or the
/// threads).
///
/// Which vertices move: those whose faces form one closed fan, none of whose edges is a boundary,
/// non-manifold or feature edge (FeatureEdges at `feature_angle_deg`). So rims, branching curves, sharp
/// edges and corners stay where the seeds put them, and the connectivity is not touched: topology, boundary
/// and non-manifold edges are those of the input.
///
/// A move is undone when the projection does not converge, when the projected point lies farther from the
/// tangent-plane target than the target from the vertex (it reached another sheet), or when it turns one of
/// the vertex's faces by more than `max_turn_deg` (those faces' moved vertices are all undone, until no face
/// turns so far). Invariant: every vertex stays on the zero set (projected, or not moved).
/// \param mesh  faces oriented consistently within each manifold component; vertices on the zero set
RelaxStats RelaxTangentially(const Udf& udf, TriangleMesh& mesh, const RelaxOptions& options, Monitor& monitor);

}  // namespace voroudf

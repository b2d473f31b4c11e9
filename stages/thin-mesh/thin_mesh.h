#pragma once
// Stage 4 (DESIGN.md; paper Sec. 3.4, "Mesh Thinning", Fig. 8): collapses the flat volumes of the thick dual
// mesh by removing face pairs from closed tetrahedra, then removes small components, keeping the edges that
// are shared by 3+ faces where the surface really branches.
#include <cstddef>
#include <string>

#include "common/monitor.h"
#include "common/types.h"
#include "common/udf.h"
#include "formats/mesh_io.h"

namespace voroudf {

struct ThinMeshOptions {
  /// Components with fewer faces than this are removed (--min-component-faces; paper: 10).
  size_t min_component_faces = 10;
  /// A face is degenerate when it repeats a vertex or its triangle quality (6/sqrt3 area / (half-perimeter x
  /// longest edge), 1 for equilateral) is below this (--degenerate-quality). Three seeds on one straight
  /// sharp edge give such slivers (quality ~1e-6), as do coincident seeds (0).
  double degenerate_quality = 1e-3;
  /// Step 4 (--fold-flatness, degrees; 0: off): the faces around a non-manifold edge are re-triangulated (2-D
  /// Delaunay in their best-fit plane) when all are within this angle of that plane, i.e. the edge is a fold
  /// of a sheet rather than a branching of the surface, and the result has fewer non-manifold edges and no
  /// more boundary edges.
  double fold_flatness_deg = 25.0;
  /// --thinning: "paper" runs only the paper's steps (drop degenerate and duplicate faces, tetrahedra,
  /// small components); "repair" (prototype) also the repairs listed in `repairs`.
  std::string thinning = "repair";
  /// --repairs (prototype): which of split (step 0b), folds (4), holes (5), rims (6) run with "repair".
  std::string repairs = "split,folds,holes,rims";

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// What ThinMesh did, for logs and tests.
struct ThinMeshStats {
  size_t duplicate_faces = 0;       ///< faces over the same vertex set as an earlier face, dropped
  size_t degenerate_faces = 0;      ///< dropped
  size_t faces_split = 0;           ///< faces over a vertex lying on their edge, split in two there
  size_t tetrahedra = 0;            ///< closed tetrahedra found (over all rounds)
  size_t tetrahedra_thinned = 0;    ///< of those, the ones a face pair was removed from
  size_t tetrahedra_left = 0;       ///< closed tetrahedra at the end (no pair on a manifold edge)
  size_t components_removed = 0;    ///< small components removed
  size_t component_faces_removed = 0;
  size_t small_components_left = 0; ///< small components whose removal would have opened a hole
  size_t folds_retriangulated = 0;   ///< step 4: patches around flat non-manifold edges replaced
  size_t cracks_split = 0;           ///< step 5: faces split over a vertex on their boundary edge (T-junctions)
  size_t holes_closed = 0;           ///< step 5: triangular holes and notches given their face
  size_t rim_folds_opened = 0;       ///< step 6: patches around folds at open rims replaced
  int rounds = 0;                   ///< rounds of (tetrahedra, components) until nothing changed
};

/// Thins a thick dual mesh (paper Sec. 3.4). Written by hand: no installed library handles triangle sets
/// with edges of any valence (OpenMesh refuses them, DESIGN.md).
///
///  0. Drops degenerate faces; a face (a, b, s) whose edge ab has a vertex m on it (known from a degenerate
///     face (a, m, b)) is split into (a, m, s) and (m, b, s); then drops duplicate faces (same vertex set; the
///     first is kept).
///  1. Closed tetrahedra: 4 vertices whose 4 triangles are all present, processed in increasing order of
///     their sorted vertex quadruple. From each (whose faces are all still present) the pair of faces that
///     share an edge of valence exactly 2 (a manifold edge, so removing the pair opens no hole elsewhere)
///     and whose centroids have the largest sum of UDF values is removed (Fig. 8); a tetrahedron with no
///     such pair is left. Repeated until a pass removes nothing.
///  2. Small components: maximal sets of faces connected across manifold edges (valence 2), i.e. a
///     component ends at boundary and non-manifold edges. A component with < min_component_faces faces is
///     removed when that leaves every one of its non-manifold border edges with 2+ faces (no new hole);
///     largest mean centroid UDF first (Fig. 8's rule), repeated until none can go. So isolated small pieces, fins and the sides of residual
///     polyhedra ("non-manifold polyhedral artifacts", Sec. 3.4) go, while a surface is never cut open.
///  3. Steps 1–2 repeat until neither changes the mesh.
///  4. Flat folds (two faces on the same side of an edge, overlapping): for each non-manifold or folded edge,
///     then each cluster of vertices joined by such edges, the faces touching it (or only those within
///     fold_flatness_deg of the fold's plane when that star is not flat) are replaced by the 2-D Delaunay
///     triangles of their vertices projected on their best-fit plane (inside the projected patch), or else
///     by a greedy triangulation keeping the edges shared with the faces around, or by ear clipping of the
///     patch's outline, when all patch faces are within fold_flatness_deg of that
///     plane, the edges shared with faces outside the patch stay, and the result has fewer non-manifold +
///     folded edges, no more non-manifold and no more boundary edges. Branching edges (sheets meeting at an
///     angle) are not flat and stay.
///  5. A boundary edge (a, b) with one face (a, b, s) and a vertex m joined to a and b that lies on the
///     segment a-b (quality of (a, m, b) below 0.1): the face is split into (a, m, s) and (m, b, s) unless
///     either is degenerate, exists, or lies over a face of its edge on m (a T-junction: the other sheets
///     split a-b at m). Then, where a vertex b has boundary edges to a and c and a-c is an edge (a triangular hole, or a notch at a
///     branching curve), the face (a, b, c) is added unless it is degenerate or lies over a face of one of
///     its edges (a junction lost by the dual or by steps 1–4).
///  6. Step 4 again, where a folded edge between two boundary vertices may become a boundary edge (a fold at
///     an open rim). Unreferenced vertices are dropped (order kept).
///
/// \param udf    the field, for the centroid values
/// \param thick  vertices + faces with valid indices (the caller validates them)
/// \param stats  optional counts
/// Deterministic (faces keep their input order, the faces made by steps 4–6 last), independent of the thread count.
TriangleMesh ThinMesh(const Udf& udf, const TriangleMesh& thick, const ThinMeshOptions& options, Monitor& monitor,
                      ThinMeshStats* stats = nullptr);

/// The edges shared by 3+ faces, as line segments over the vertices they use (for thin-mesh --nm-edges).
EdgeSet NonManifoldEdges(const TriangleMesh& mesh);

}  // namespace voroudf

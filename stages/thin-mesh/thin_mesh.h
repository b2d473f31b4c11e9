#pragma once
// Stage 4 (DESIGN.md; paper Sec. 3.4, "Mesh Thinning", Fig. 8): removes face pairs from the closed
// tetrahedra the dual still has, then small components, then closes the junction gaps the dual left,
// keeping the edges that are shared by 3+ faces where the surface really branches.
#include <cstddef>
#include <string>

#include "common/monitor.h"
#include "common/types.h"
#include "common/udf.h"
#include "formats/mesh_io.h"
#include "stages/thin-mesh/feature_chords.h"
#include "stages/thin-mesh/relax.h"

namespace voroudf {

struct ThinMeshOptions {
  /// Components with fewer faces than this are removed (--min-component-faces; paper: 10).
  size_t min_component_faces = 10;
  /// A face is degenerate when it repeats a vertex or its triangle quality (6/sqrt3 area / (half-perimeter x
  /// longest edge), 1 for equilateral) is below this (--degenerate-quality): coincident seeds, or three
  /// seeds on one straight sharp edge.
  double degenerate_quality = 1e-3;
  /// --thinning: "paper", the paper's two steps only (tetrahedra, small components); "close-holes" (the
  /// default), then the junction gaps the dual left are closed (close_holes.h).
  std::string thinning = "close-holes";
  /// --overlap-angle (degrees): a face added by closing a gap must not lie within this angle of a face on
  /// one of its edges, seen from the edge (at an open rim, that is the face already there).
  double overlap_angle_deg = 25.0;
  /// --layer-angle (degrees; not with --thinning paper): step 2 removes a small component that has no free
  /// edge only if each of its faces on a border edge lies within this angle of a face that stays on that
  /// edge (a second layer: a bubble's cap, a fold); 180 removes every small component, as the paper does.
  double layer_angle_deg = 60.0;
  /// --rim-flaps (not with --thinning paper): step 6 removes the faces that hang from a free edge across a
  /// non-manifold edge where every edge they leave with one face lies on a rim (no surface beyond it).
  bool rim_flaps = true;
  /// --fold-flaps (not with --thinning paper): step 5b removes the faces that hang from a free edge folded
  /// over another face of a non-manifold edge (within the overlap angle), then closes the holes again.
  bool fold_flaps = true;
  /// --shell-rings (not with --thinning paper; 0: off): step 3b opens the closed shells that steps 1-3 leave
  /// and whose faces lie within this many edges of one of their faces, at a face off the surface.
  int shell_rings = 1;
  /// Step 7, tangential relaxation (relax.h; --relax-iters, --relax-step, --relax-feature-angle).
  RelaxOptions relax;
  /// Step 7, sharp-edge chords split onto their feature first (feature_chords.h; --split-feature-chords).
  ChordSplitOptions chords;

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// What ThinMesh did, for logs and tests.
struct ThinMeshStats {
  size_t duplicate_faces = 0;       ///< faces over the same vertex set as an earlier face, dropped
  size_t degenerate_faces = 0;      ///< dropped
  size_t tetrahedra = 0;            ///< closed tetrahedra found (first round)
  size_t tetrahedra_thinned = 0;    ///< of those, the ones a face pair was removed from
  size_t tetrahedra_left = 0;       ///< closed tetrahedra at the end (no pair on a manifold edge)
  size_t shells_opened = 0;         ///< step 3b: closed shells opened, one face removed from each
  size_t components_removed = 0;    ///< small components removed
  size_t component_faces_removed = 0;
  size_t small_components_left = 0; ///< small components whose removal would have opened a hole
  size_t cracks_split = 0;          ///< step 4: faces split over a vertex on their boundary edge (T-junctions)
  size_t holes_closed = 0;          ///< step 4: triangular holes and notches given their face
  size_t tetrahedra_closed_thinned = 0;  ///< step 5: tetrahedra that step 4's faces closed, thinned
  size_t flap_faces_removed = 0;    ///< step 5: faces of dangling flaps removed
  size_t folded_flaps_removed = 0;  ///< step 5b: folded flaps removed
  size_t holes_closed_after_folds = 0;  ///< step 5b: triangular holes closed after them
  size_t rim_flaps_removed = 0;     ///< step 6: flaps at a rim removed
  int rounds = 0;                   ///< rounds of (tetrahedra, components) until nothing changed
  RelaxStats relax;                 ///< step 7
  ChordSplitStats chords;           ///< step 7, the chords
};

/// Thins a dual mesh (paper Sec. 3.4). Written by hand: no installed library handles triangle sets with
/// edges of any valence (OpenMesh refuses them, DESIGN.md).
///
///  0. Drops degenerate faces, then duplicate faces (same vertex set; the first is kept).
///  1. Closed tetrahedra: 4 vertices whose 4 triangles are all present. From each the pair of faces that
///     share an edge of valence exactly 2 (a manifold edge, so removing the pair opens no hole elsewhere)
///     and whose centroids have the largest sum of UDF values is removed (Fig. 8), a pair that leaves no
///     other edge of the tetrahedron with one face first; a tetrahedron with no such pair is left.
///     Repeated until a pass removes nothing.
///  2. Small components: maximal sets of faces connected across manifold edges (valence 2), i.e. a
///     component ends at boundary and non-manifold edges. A component with < min_component_faces faces is
///     removed when that leaves every one of its non-manifold border edges with 2+ faces (no new hole) and,
///     unless thinning is "paper", when it has a free edge or is a layer (layer_angle_deg);
///     largest mean centroid UDF first (Fig. 8's rule), repeated until none can go.
///  3. Steps 1-2 repeat until neither changes the mesh.
///  3b. Unless thinning is "paper" or shell_rings is 0: the closed shells left (tetrahedra whose edges all
///     carry a third face, bubbles of more faces) within shell_rings edges of one of their faces are opened
///     at a face off the surface (centroid UDF above 0.1 x its longest edge), the largest centroid UDF
///     first: each removal lowers b2 by one and leaves b0 and b1 as they were. Shells whose faces all lie
///     on the surface (cavities) stay.
///  4. Unless thinning is "paper": SplitFacesOverCracks, then CloseTriangularHoles (close_holes.h).
///  5. Then, if step 4 changed anything: the closed tetrahedra (step 1's rule), and a small component (as in
///     step 2) that has a free edge is removed when that leaves no border edge with a single face and keeps
///     the Euler characteristic (a dangling flap, collapsed from its free edge).
///  5b. Unless thinning is "paper" or fold_flaps is off: RemoveFoldedFlaps (rim_flaps.h), a face with a free
///     edge lying over another face of a non-manifold edge within the overlap angle, a collapse each; then,
///     if any went, CloseTriangularHoles again.
///  6. Unless thinning is "paper" or rim_flaps is off: a face with a free edge and a non-manifold edge is
///     removed when every edge it leaves with one face lies on a rim: the UDF shows no surface beyond that
///     edge. Where a branching curve ends at the rims of its sheets, the regions of a rim seed of one sheet
///     and a seed of another meet at the curve's end, and the dual joins them by a face across the curve.
///  Manifold components are then oriented consistently, unreferenced vertices dropped (order kept).
///  7. SplitFeatureChords (feature_chords.h), if options.chords.enabled: a sharp edge that cuts across a
///     curved feature is split at the feature's point between its ends; the topology stays. Then
///     RelaxTangentially (relax.h), unless options.relax.iterations is 0: the vertices inside smooth manifold
///     patches are evened out along the surface; the connectivity stays.
///
/// \param udf    the field, for the centroid values
/// \param thick  vertices + faces with valid indices (the caller validates them)
/// \param stats  optional counts
/// Deterministic (faces keep their input order, the faces made by step 4 last), independent of the thread count.
TriangleMesh ThinMesh(const Udf& udf, const TriangleMesh& thick, const ThinMeshOptions& options, Monitor& monitor,
                      ThinMeshStats* stats = nullptr);

/// The edges shared by 3+ faces, as line segments over the vertices they use (for thin-mesh --nm-edges).
EdgeSet NonManifoldEdges(const TriangleMesh& mesh);

}  // namespace voroudf

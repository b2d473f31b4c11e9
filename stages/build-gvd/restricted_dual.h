#pragma once
// The dual of the geodesic Voronoi diagram as a subcomplex of the seeds' 3-D Delaunay triangulation
// (docs/build-gvd.md, "The dual"): one construction with a stated invariant in place of the thick dual and
// its repair passes.
#include <cstddef>
#include <vector>

#include "common/types.h"

namespace voroudf {

struct RestrictedDualStats {
  size_t delaunay_faces = 0;      ///< finite facets of the seeds' 3-D Delaunay triangulation
  size_t witnessed = 0;           ///< witnessed triples given
  size_t witnessed_delaunay = 0;  ///< of those, Delaunay facets (kept)
  size_t flat_cells_resolved = 0; ///< flat tetrahedra whose kept faces folded, replaced by their 2-D Delaunay faces
  size_t faces_added = 0;         ///< faces those replacements added that no sample witnessed
  size_t faces_dropped = 0;       ///< witnessed faces those replacements dropped
};

/// The faces of the dual: the witnessed triples (seed triples whose geodesic Voronoi regions meet, from
/// the labelled samples) that are facets of the 3-D Delaunay triangulation of `seeds`.
///
/// Invariant: the result is a subcomplex of Del(seeds), so no two of its triangles cross or overlap
/// except in a shared edge or vertex, and no triangle appears twice. The one overlap a subcomplex still
/// allows is inside a flat tetrahedron (four seeds on one sheet, nearly on a circle: all four of its
/// faces are witnessed where four regions meet at one point); there the faces of its two triangulations
/// fold over each other. A Delaunay tetrahedron whose dihedral angle at an edge is below
/// `flat_dihedral_deg` with at least three kept faces is such a degenerate junction, and its kept faces
/// are replaced by the 2-D Delaunay triangulation of its four seeds in their best-fit plane (two faces, or
/// three around a seed inside the others' triangle): the triangulation the restricted Voronoi diagram of
/// a plane gives.
///
/// \param seeds      seed positions (coincident seeds: the later ones get no face)
/// \param witnessed  sorted triples of seed indices, each vertex triple once, smallest index first
std::vector<Tri> RestrictedDual(const std::vector<Vec3>& seeds, const std::vector<Tri>& witnessed,
                                double flat_dihedral_deg, RestrictedDualStats* stats);

}  // namespace voroudf

#pragma once
// thin-mesh's flaps: faces that hang from a free edge at a branching edge. Step 6 (docs/thin-mesh.md, "Flaps
// at a rim"): the face the dual puts across the end of a branching curve where it meets the rims of its
// sheets. Step 5b ("Folded flaps"): a face folded over another where a junction's triangles overlap.
#include <cstddef>
#include <vector>

#include "common/types.h"
#include "common/udf.h"

namespace voroudf {

/// Removes, in face order on the live edge counts, every face that
///  - lies off the surface: its centroid's UDF is above 0.1 x its longest edge (a face of a sheet, even a
///    curved one at the seed spacing, has a few hundredths at most; a face from one sheet to another across
///    a branching curve about a third);
///  - has a free edge (one face) and an edge with 3 or more faces;
///  - leaves no edge with one face but on a rim: the UDF probed around the edge's midpoint, at half the
///    height of the face that stays on it, every 15 degrees from straight beyond the edge to 30 degrees short
///    of that face, stays above 0.3 x that radius (a crease's or a branching curve's other face lies within
///    7.5 degrees of a probe: at most 0.13 x).
/// Invariant: an edge is left with one face only where the surface ends.
///
/// \param udf       the field (centroids and probes)
/// \param vertices  the mesh's vertices
/// \param faces     its faces, with valid indices; the removed ones are erased (order otherwise kept)
/// \returns the number of faces removed
size_t RemoveRimFlaps(const Udf& udf, const std::vector<Vec3>& vertices, std::vector<Tri>& faces);

/// Removes, in face order on the live edge counts, every *folded flap*: a face that has a free edge (one
/// face) and, on an edge with 3 or more faces, lies over another face of that edge: their third vertices,
/// seen from the edge, within `overlap_angle_deg` of each other. The dual leaves one where a junction's
/// triangles overlap and a triangle next to them is missing: the overlap is the branching edge, the missing
/// one the free edge. Removing a face with a free edge is a collapse: chi, the components and the loops stay,
/// and the hole it bordered, now one face larger, is left to CloseTriangularHoles.
/// Invariant: no face with a free edge lies folded over another face at a branching edge.
/// \returns the number of faces removed
size_t RemoveFoldedFlaps(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double overlap_angle_deg);

}  // namespace voroudf

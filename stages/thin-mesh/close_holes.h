#pragma once
// thin-mesh's last step (docs/thin-mesh.md, step 4): closing the gaps a junction leaves when the dual missed
// its face. The one repair the locally Delaunay dual still needs, measured on the non-manifold sweep
// (docs/reports/design-notes.md, thin-mesh).
#include <cstddef>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// Cracks (T-junctions): a boundary edge (a, b) whose one face is (a, b, s), with a vertex m that is joined
/// to a and to b by edges and lies on the segment a-b (the triangle (a, m, b) a sliver, quality below
/// `max_sliver_quality`): one sheet's face spans the edge that the other sheets split at m (on sphere-disc,
/// a curve seed whose region the disc's dense samples missed). The face is split into (a, m, s) and
/// (m, b, s), unless either is degenerate (quality below `min_quality`), exists, or would lie over a face
/// of its edge on m (third vertices within acos(min_cos) of each other seen from the edge). Up to four
/// rounds. Returns the faces split; new faces are appended, split ones removed (order otherwise kept).
size_t SplitFacesOverCracks(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double min_quality,
                            double min_cos, double max_sliver_quality);

/// Triangular holes and notches: adds the face (a, b, c) wherever b has boundary edges (edges with one
/// face) to a and to c and the third side a-c is an edge too, either a boundary edge (a hole of one
/// triangle) or one with faces (a notch next to a branching curve: a sheet's face missing there), unless
/// the triangle is degenerate or would lie over a face of one of its edges (at an open rim, three
/// consecutive rim vertices: the face already there). Then, with the same tests, the face (a, b, m) for a
/// boundary edge (a, b) not closed so whose ends are both joined to m by branching edges (3+ faces): a
/// sheet's face missing between the free edge and the curve. Returns the number of faces added (appended).
size_t CloseTriangularHoles(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double min_quality,
                            double min_cos);

}  // namespace voroudf

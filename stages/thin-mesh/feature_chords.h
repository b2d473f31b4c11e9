#pragma once
// thin-mesh step 7's first part (docs/thin-mesh.md, off by default): sharp-edge chords split onto their feature. Consecutive curve seeds
// of a curved sharp edge (a hole's rim, a fillet's end) are joined by a straight mesh edge, which cuts across
// the feature by its sagitta; where that is more than a small share of the edge, the edge is split at the
// feature's point between them. Not in the paper. The feature point is where the tangent planes of the two
// sheets meet in the edge's bisecting plane, as optimize-seeds' L1 step finds a curve seed (paper Sec. 3.2),
// here from one UDF query on each side.
#include <cstddef>

#include "common/monitor.h"
#include "common/types.h"
#include "common/udf.h"

namespace voroudf {

struct ChordSplitOptions {
  bool enabled = false;             ///< --split-feature-chords (off: it trades triangle quality and vertices for CD)
  double sagitta_rel = 0.1;         ///< split when the feature lies farther than this x the edge's length from it
};

struct ChordSplitStats {
  size_t sharp = 0;   ///< sharp manifold edges
  size_t chords = 0;  ///< of those, farther than sagitta_rel from their feature
  size_t split = 0;   ///< split onto the feature
};

/// Splits every sharp manifold edge (a, b) that cuts across its feature: where the two sheets' tangent planes
/// (from the UDF at m + |ab|/4 toward each face's third vertex, m the midpoint; more than 20 degrees apart)
/// meet the plane through m normal to ab, at p with |p - m| > sagitta_rel x |ab| (and at most |ab| / 2), and
/// p lies on the zero set (d(p) <= |p - m| / 4), the edge is split at p: each of its two faces becomes two.
/// On a straight sharp edge p is m. Edges are judged on the input and split once each (a face with two
/// chords: only its first, in edge order).
/// Invariant: an edge split on a manifold edge adds one vertex, three edges and two faces, so the Euler
/// characteristic, the boundary and the non-manifold edges are the input's; face orientation is kept.
/// \param mesh  vertices on the zero set of `udf`
/// \param feature_angle_deg  an edge is sharp when its faces' normals differ by more (the relaxation's angle,
///        so that the split points are vertices the relaxation keeps in place)
ChordSplitStats SplitFeatureChords(const Udf& udf, TriangleMesh& mesh, const ChordSplitOptions& options,
                                   double feature_angle_deg, Monitor& monitor);

}  // namespace voroudf

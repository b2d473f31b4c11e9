#pragma once
// The synthetic non-manifold benchmark shapes of the paper (Sec. 4.1, "Comparisons on Non-Manifold
// Models"): a CAD mesh cut by a plane, one part shifted so that the two overlap in a narrow band, merged.
#include <string>

#include "common/types.h"

namespace voroudf {

struct OverlapOptions {
  Vec3 plane_normal = Vec3(0.48, 0.64, 0.6);  ///< cut plane normal (normalised; deliberately not axis-aligned)
  double plane_offset_rel = 0.0;  ///< plane position along the normal from the bbox centre, × bbox diagonal
  double overlap_rel = 0.02;      ///< shift of the positive part towards the negative one, × bbox diagonal

  void Check() const;
};

/// Cuts the closed triangle mesh `mesh` with the plane (bbox centre + offset·diag·n, normal n) into two
/// closed parts (CGAL::Polygon_mesh_processing::clip with clip_volume), translates the positive part by
/// −overlap·diag·n so that both overlap in a band, corefines them in exact arithmetic (EPECK) so that their
/// surfaces meet on shared vertices along every crossing curve, and merges them into one indexed face set.
/// The crossing curves become edges with four faces: the ground-truth non-manifold edges.
/// \pre `mesh` is a closed, non-self-intersecting triangle mesh (InputError otherwise)
/// \throws InputError if the mesh is open or self-intersecting or the plane misses it
/// \param name  used in error messages (the file the mesh came from)
TriangleMesh MakeOverlapNonManifold(const TriangleMesh& mesh, const OverlapOptions& options,
                                    const std::string& name = "mesh");

}  // namespace voroudf

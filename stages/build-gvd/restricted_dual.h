#pragma once
// The dual of the geodesic Voronoi diagram, one triangulation per junction instead of every triple a
// junction's samples see (docs/build-gvd.md, "The dual").
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/types.h"

namespace voroudf {

struct RestrictedDualStats {
  size_t witnessed = 0;     ///< witnessed triples given
  size_t kept = 0;          ///< of those, locally Delaunay (kept)
  size_t degenerate = 0;    ///< of those, collinear seeds (no circumsphere): dropped
};

/// The locally Delaunay witnessed triples. A witnessed triple (i, j, k) — three seeds whose geodesic
/// Voronoi regions meet, from the labelled samples — is dropped when a seed v that is a geodesic neighbour
/// of all three (it shares a witnessed triple with each) lies strictly inside its circumcircle in the
/// chart of the four: the plane normal to their mean surface normal, used only when the four normals
/// agree within `chart_angle_deg` (sign-blind). Then the four regions meet at one junction of a sheet,
/// and the triangle is not a face of that junction's Delaunay triangulation.
///
/// Why: where n >= 4 regions meet at nearly one point the samples witness all C(n, 3) triples, which stack
/// into closed tetrahedra and folds (the thick dual). Among the seeds of one junction on a sheet, the
/// triples that survive are the Delaunay triangulation of those seeds in their tangent plane — the dual a
/// plane's Voronoi diagram has (Delaunay 1934; on surfaces, the restricted Delaunay triangulation,
/// Edelsbrunner & Shah 1997): a disc of n - 2 triangles, never a tetrahedron. The test of a triangle and a
/// fourth seed uses the same plane as the test of any other triangle of those four, so the two
/// triangulations of a quadrilateral never both fail or both pass. Only common geodesic neighbours are
/// tested, so seeds across a thin gap (the other side of a plate, whose regions never meet these) never
/// block; and only seeds with the triangle on one chart, so a crease's other face never blocks.
/// Four seeds exactly on one circle do not block each other: both triangulations stay, thin-mesh chooses.
///
/// \param seeds      seed positions
/// \param normals    a unit surface normal (UDF gradient) per seed, either orientation; zero: no chart
/// \param on_sheet   per seed, whether it lies on a sheet (rank 1 or unknown): only those normals count
/// \param witnessed  triples of seed indices, each vertex triple once, indices sorted
/// \returns the kept triples in the order given (collinear triples are dropped)
std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                                        const std::vector<uint8_t>& on_sheet, const std::vector<Tri>& witnessed,
                                        double chart_angle_deg, RestrictedDualStats* stats);

}  // namespace voroudf

#pragma once
// The dual of the geodesic Voronoi diagram, one triangulation per junction instead of every triple a
// junction's samples see (docs/build-gvd.md, "The dual").
#include <cstddef>
#include <vector>

#include "common/types.h"

namespace voroudf {

struct RestrictedDualStats {
  size_t witnessed = 0;     ///< witnessed triples given
  size_t kept = 0;          ///< of those, locally Delaunay (kept)
  size_t degenerate = 0;    ///< of those, collinear seeds (no circumsphere): dropped
};

/// The locally Delaunay witnessed triples. A witnessed triple (i, j, k) — three seeds whose geodesic
/// Voronoi regions meet, from the labelled samples — is dropped when a seed that is a geodesic neighbour
/// of all three (it shares a witnessed triple with each) lies within `flat` x R of the triangle's plane and
/// strictly inside its circumcircle (R its radius): then the four regions meet at one junction, and the
/// triangle is not a face of that junction's Delaunay triangulation.
///
/// Why: where n >= 4 regions meet at nearly one point the samples witness all C(n, 3) triples, which stack
/// into closed tetrahedra and folds (the thick dual). Among the seeds of one junction on a sheet, nearly
/// coplanar, the triples that survive are the Delaunay triangulation of those seeds in their plane — the
/// dual the Voronoi diagram of a plane has: a disc of n - 2 triangles, never a tetrahedron (Delaunay 1934;
/// on surfaces, the restricted Delaunay triangulation, Edelsbrunner & Shah 1997). Only the common
/// geodesic neighbours are tested, so seeds across a thin gap (the other side of a plate, whose regions
/// never meet these) never block; and only nearly coplanar ones, so a crease's other face never blocks.
/// Seeds exactly on the circle (a perfectly cocircular junction) do not block either: both triangulations
/// of such a junction stay, and thin-mesh chooses.
///
/// \param seeds      seed positions
/// \param witnessed  triples of seed indices, each vertex triple once, indices sorted
/// \param flat       how far from a triangle's plane, relative to its circumradius, a seed still counts
/// \returns the kept triples in the order given
std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Tri>& witnessed, double flat,
                                        RestrictedDualStats* stats);

}  // namespace voroudf

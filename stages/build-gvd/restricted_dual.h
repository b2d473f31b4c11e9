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
  size_t kept = 0;          ///< triples returned: the locally Delaunay ones and the hole guard's replacements
  size_t degenerate = 0;    ///< of those, collinear seeds (no circumsphere): dropped
  size_t kept_against_holes = 0;  ///< blocked triples kept: removing them would open a hole (hole guard)
  size_t replaced = 0;      ///< blocked triples that would open a hole and jump a feature seed: flipped
  size_t gaps_closed = 0;   ///< holes whose outline is one junction's four seeds, filled (CloseJunctionGaps)
  size_t added = 0;         ///< triangles the flips and fills added (not witnessed)
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
/// Hole guard: a blocked triple is removed only where that opens no hole — where it lies on a closed shell of
/// the triples left (FaceComplex::OnLocalTwoCycle, one ring: its Delaunay replacements were witnessed, and
/// b2 falls) or has an edge no other triple covers (a collapse); passes repeat until none goes. Where it
/// would open a hole (its replacements were never witnessed: near a branching curve the dense samples see
/// fewer of a junction's regions) it stays — unless the seed that blocks it is a feature seed beyond an edge
/// of two feature seeds (the triangle jumps it along a chain): then the Delaunay flip through that seed, in
/// their chart, takes its place. **Invariant:** the filter lowers b2 and never raises b1 over the witnessed
/// triples, except through the flips, which cover the same part of the chart.
///
/// Junction holes: where the samples saw a junction of four regions only in part, the hole left has the four
/// seeds as its outline — a blocked triple, its blocker beyond one of its edges, and nothing in the
/// quadrilateral but what the samples saw of it. The missing triangles of the four seeds' Delaunay
/// triangulation in their chart fill it (the blocked triple, if still there, gives way to them). Each edge of
/// the outline must carry a triple outside the quadrilateral (one, or several at a link of two curve seeds),
/// no other triple may lie in it, and two of the four at least must be sheet seeds. **Invariant:** a fill
/// closes exactly one hole (b1 falls by one) and adds no fold or branching edge on a sheet.
///
/// \param seeds      seed positions
/// \param normals    a unit surface normal (UDF gradient) per seed, either orientation; zero: no chart
/// \param on_sheet   per seed, whether it lies on a sheet (rank 1 or unknown): only those normals count
/// \param witnessed  triples of seed indices, each vertex triple once, indices sorted
/// \returns the kept triples, sorted (collinear triples are dropped)
std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                                        const std::vector<uint8_t>& on_sheet, const std::vector<Tri>& witnessed,
                                        double chart_angle_deg, RestrictedDualStats* stats);

struct ChainLinkStats {
  size_t links = 0;    ///< chain links found between curve seeds
  size_t jumps = 0;    ///< jumps over a curve seed whose triples were dropped
  size_t dropped = 0;  ///< triples dropped in all
  size_t added = 0;      ///< triples the splits of jumps and the spanned junctions added (not witnessed)
  size_t junctions = 0;  ///< junctions spanned by their link instead of by sheet seeds across it
};

/// The triples that follow the feature chains instead of jumping along or across them. A *chain link* is a
/// pair of curve seeds (c, c') (rank 2 or 3: on a crease, a rim, a branching curve or a corner) that are
/// geodesic neighbours (they share a triple) and consecutive: no third curve seed that is a geodesic
/// neighbour of both lies strictly inside the sphere with diameter cc' (the Gabriel rule among the curve
/// seeds; Gabriel & Sokal 1969). Three rules, in this order:
///  - **jumps**: where x and y are both linked to a curve seed c, more than 135 degrees apart at c, and are no
///    link themselves, the triples on xy jump c along the chain. Each (x, y, z) is split at c into (x, c, z)
///    and (c, y, z) (z = c: the sliver along the chain, replaced by nothing). Where z is a sheet seed, the
///    halves the samples did not witness are added (near a crossing a sheet's half of a junction goes
///    unseen); where z is a curve seed (a corner where chains meet: no sheet's triangle) both must be
///    present. All of a jump's triples together, or none.
///  - **crossings**: where the four triples of a link cc' and two sheet seeds a, b are all present — a closed
///    tetrahedron, two ways of spanning one junction — a and b lie on two sides of the link (their directions
///    from it, across it, more than 60 degrees apart) and ab carries 4 or more triples, the two triples on
///    ab, (c, a, b) and (c', a, b), are dropped and the two on the link stay. Where sheets cross at a gap of
///    the chain, the triples on ab cut across the curve; no chart decides there (the four seeds span two
///    planes), and thin-mesh's pair rule needs an edge of exactly two triples (an edge of two, across a
///    crease, is left to it).
///  - **junctions spanned by their link**: two curve seeds c, c' at most 1.5 mean dual edges apart, with no
///    curve seed that is a neighbour of both inside the sphere with diameter cc', make triples with pairs of
///    sheet seeds S (at least one pair with both; a pair with one of them only closed by a triple among S),
///    each pair on two sides of cc' (more than 60 degrees), and some (c, c', s) is missing: a sheet seed's
///    region reached the curve between c and c' (a diagonal ab across the chain with (c, a, b) and
///    (c', a, b); where three sheets meet at a gap, a double pyramid on a triple of S). Those triples and the
///    ones among S become (c, c', s) for every s in S: the link, one triangle per sheet.
///
/// Invariant: a triple is dropped only where the triples that replace it are present or added (a jump's
/// halves cover its triangle but for the sliver along the chain, a junction's the link's triangles), and a change that would leave any edge
/// with one triple where it had more is not made: no new boundary edge appears, so no hole opens. Jumps and
/// links are taken in seed order on the live triples (deterministic).
///
/// \param seeds     seed positions
/// \param is_curve  per seed, whether it lies on a feature curve or a corner (rank 2 or 3)
/// \param triples   triples of seed indices, each vertex triple once, indices sorted
/// \returns the kept and added triples, sorted
std::vector<Tri> KeepChainLinks(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& is_curve,
                                const std::vector<Tri>& triples, ChainLinkStats* stats);

}  // namespace voroudf

#pragma once
// The optimizer's per-seed state and the operations on feature seeds that step 7 (feature-seed thinning)
// and step 8 (feature chains) of docs/optimize-seeds.md make: which seeds crowd a feature seed, the links
// of the feature curves, where a chain's trial seeds start and whether one stays, and dropping seeds from
// the state. Used by optimizer.cpp and optimize_seeds.cpp; tests reach SeedsBesideFeatures through optimize_seeds.h.

#include <cstddef>
#include <utility>
#include <vector>

#include "common/types.h"
#include "stages/optimize-seeds/l1_tangent.h"
#include "stages/optimize-seeds/optimize_seeds.h"
#include "stages/optimize-seeds/repulsion.h"
#include "stages/optimize-seeds/seed_index.h"
#include "stages/optimize-seeds/voronoi_cells.h"

namespace voroudf {

/// The state carried through Alg. 1: positions on the zero set with their field, ranks and move spaces.
struct SeedState {
  std::vector<Vec3> position;
  std::vector<double> udf;
  std::vector<Vec3> normal;
  std::vector<TangentRank> rank;
  std::vector<MoveSpace> space;
};

/// The direction a curve seed may move in (rank 2: its move space is a line); zero for the others.
std::vector<Vec3> Tangents(const SeedState& s);

/// The mean distance of x from the tangent planes of seed i's cell samples, |n·(p − x) − d| (the terms of
/// the L1 energy, paper Eq. energy_l1); +inf for a cell without one. Decides between crowded feature seeds.
double TangentMisfit(const CellSamples& cells, size_t i, const Vec3& x);

/// The links of the feature curves: every curve seed (rank 2, with a tangent) and the nearest feature seed
/// ahead of it and behind it along its tangent (and along the other's, when it has one), within `radius`.
/// chords: each such pair once, sorted. ends: a curve seed with no such seed on one side (the chain ends
/// there, or has a gap longer than the radius), with the unit direction of that side.
struct FeatureLinks {
  std::vector<std::pair<int, int>> chords;
  std::vector<std::pair<int, Vec3>> ends;
};

/// Seeds on two curves (OnTwoCurves with `two_curves`) are never linked.
FeatureLinks FindFeatureLinks(const SeedState& s, const std::vector<Vec3>& tangent, double radius,
                              const TwoCurves& two_curves);

/// Removes the seeds marked in `drop` from every array of the state, keeping the others' order.
void EraseSeeds(SeedState& s, const std::vector<char>& drop);

/// Drops the seeds below index `first` that are not on a feature (rank < 2) and lie within `clearance` of a
/// seed from `first` on (seeds just added onto a feature curve), as the feature-seed thinning keeps sheet
/// seeds clear of curve seeds.
void DropSheetSeedsNear(SeedState& s, size_t first, double clearance);

/// Keeps the seed count after seeds were added on the feature chains: drops up to `count` sheet seeds (rank
/// 1) whose 6 nearest seeds are sheet seeds too, the most crowded first (smallest nearest-neighbour
/// distance, then index), never two that are among each other's 6 nearest, so that no hole wider than
/// about a spacing opens and no feature's neighbourhood thins. Returns the count dropped.
size_t DropCrowdedSheetSeeds(SeedState& s, size_t count);

/// Feature-seed thinning (SeedsBesideFeatures) judged at `where` (the seeds' positions or their step
/// targets), at the state's ranks; the marked seeds leave the state and, if given, `carried` (a per-seed
/// array alongside it). `where` may be s.position or *carried: it is read before either changes. Returns the
/// count dropped.
size_t ThinCrowded(SeedState& s, const std::vector<Vec3>& where, const std::vector<double>& misfit, double limit,
                   const TwoCurves& two_curves, std::vector<Vec3>* carried = nullptr);

/// A trial seed of RefineFeatureChains: from a chord (a, b) or from one spacing beyond a chain's end at a.
struct ChainTrial {
  int a = -1, b = -1;  // a chord's ends, or (a, -1): a chain end at seed a
  Vec3 start = Vec3::Zero(), direction = Vec3::Zero();
};

/// The trials of one round of RefineFeatureChains over the links with a seed from `fresh` on: the midpoints
/// of the chords that are gaps (longer than max_gap) or, with bend_tol > 0, of every chord of at least 2.5
/// clearances; and one spacing beyond every chain end (with max_gap > 0).
std::vector<ChainTrial> ChainTrials(const SeedState& s, const FeatureLinks& links, size_t fresh, double bend_tol,
                                    double max_gap, double clearance, double spacing);

/// Whether a trial that landed at `landed`, in a cell of rank `rank` with curve tangent t_new, found the
/// feature it was sent to: for a chord, on a curve along it between 1/4 and 3/4 of it, at most a quarter
/// chord from its start and, unless the chord is a gap, more than bend_tol from it; for an end, 0.5–1.6
/// spacings ahead on a curve running that way or on a corner. Returns the radius within which no feature
/// seed may lie (0.2 chords, 0.5 spacings), or -1 where the trial missed.
double LandedOnItsFeature(const SeedState& s, const ChainTrial& c, const Vec3& landed, int rank, const Vec3& t_new,
                          double bend_tol, double max_gap, double spacing);

/// Whether a landed trial seed is crowded: a feature seed of the n before the round (`index`), or a seed
/// added in this round (from n on: two ends facing each other), nearer than crowd_radius (at least the
/// clearance, so that the feature-seed thinning keeps every seed added); or, for a curve seed (rank 2), a
/// corner within a spacing: a cell that near sees the corner's planes, so the seed would be ranked 3 at the
/// next analysis and stepped onto the corner, crowding it, and the thinning may then keep the one beside the
/// corner (open corners of crossing-planes and three-discs: a non-manifold edge 0.004–0.01 off the curve,
/// and 0.3–0.5 off it at a rim's corner).
/// A curve seed of another curve (OnTwoCurves with `tangent`, the tangents of the n seeds, and `t_new`, the
/// landed seed's) does not crowd it.
bool Crowded(const SeedState& s, size_t n, const SeedIndex& index, const Vec3& landed, int rank, double crowd_radius,
             double spacing, const Vec3& t_new, const std::vector<Vec3>& tangent, const TwoCurves& two_curves);

}  // namespace voroudf

#pragma once
// optimize-seeds' state across the rounds of Alg. 1 (docs/optimize-seeds.md): the Voronoi cells and their
// samples, the paper's L1 tangent step, the feature chains, the repulsion kernel's width and neighbours, and
// the projection back onto the surface. OptimizeSeeds (optimize_seeds.cpp) runs the rounds with it.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "common/monitor.h"
#include "common/projection.h"
#include "common/udf.h"
#include "stages/optimize-seeds/feature_seeds.h"
#include "stages/optimize-seeds/fitted_normals.h"
#include "stages/optimize-seeds/l1_tangent.h"
#include "stages/optimize-seeds/optimize_seeds.h"
#include "stages/optimize-seeds/repulsion.h"
#include "stages/optimize-seeds/sample_pool.h"
#include "stages/optimize-seeds/voronoi_cells.h"

namespace voroudf {

/// FindFeatureLinks' search radius, in mean spacings: chords longer than this are not seen as chords.
constexpr double kFeatureLinkRadius = 2.5;

class Optimizer {
 public:
  Optimizer(const Udf& udf, const OptimizeSeedsOptions& options, Monitor& monitor)
      : udf_(udf), options_(options), monitor_(monitor), diagonal_(udf.Domain().Diagonal()) {
    cell_options_.samples_per_cell = options.samples_per_cell;
    cell_options_.radius_knn = options.cell_knn;
    cell_options_.radius_factor = options.cell_radius_factor;
    cell_options_.early_samples = options.early_samples;
    cell_options_.early_rank_threshold = 0.5 * options.rank_threshold;
    projection_ = RelativeProjection(diagonal_, options.proj_tol_rel, options.proj_floor_rel, options.proj_max_iters);
    projection_.twin_factor = options.proj_twin_factor;
  }

  // Projects `moved` onto the zero set; a seed whose projection fails goes back to `previous` (which is on
  // the surface). So does a seed that lands nearer to another seed than min(min_separation, the distance to
  // its nearest neighbour before the move) (both seeds, if both moved): projection is not injective
  // (everything beyond a cube corner lands on the corner; L1 steps of neighbours meet on a feature at their
  // common cell face), and seeds that meet would make σ, the minimum pairwise distance, shrink for every
  // seed, iteration after iteration. Returns the largest displacement from `previous`.
  double Project(SeedState& s, const std::vector<Vec3>& previous, std::vector<Vec3> moved, double min_separation);

  // Cells, samples, rank and null space of every seed at the current positions. early: the repulsion
  // rounds, which only need ranks and null spaces, let cells that clearly see one plane stop at
  // --early-samples; the L1 steps and the final ranks take every cell whole. The cells returned stay valid
  // until the next call (they are the cache itself unless the sample planes were changed).
  const CellSamples& Analyze(SeedState& s, bool early = false);

  // Between repulsion rounds without new cells (--repulsion-cells first): ranks stay, a seed that moves in a
  // plane (a sheet seed) takes the tangent plane of its own gradient where Project left it, which is the
  // surface's there; a curve seed keeps its line, a corner stays fixed.
  void FollowTangentPlanes(SeedState& s) const;

  // The plane orthogonal to a seed's own gradient as a move space (dim 2), or dim 0 where the gradient
  // gives no plane.
  MoveSpace OwnTangentPlane(const Vec3& normal) const;

  // Paper Eq. (energy_l1_regularizer) for every seed, inside its cell. Returns the new (unprojected) positions.
  // features_only: only seeds whose cells have rank ≥ 2 (sharp edges, corners, rims) move.
  // misfit_at_target (optional): per seed, TangentMisfit at its new position, from the solver's terms (+inf
  // for a seed that did not move).
  // movers (optional): only the seeds marked there move.
  std::vector<Vec3> L1Step(const SeedState& s, const CellSamples& cells, bool features_only = false,
                           std::vector<double>* misfit_at_target = nullptr, const std::vector<char>* movers = nullptr);

  // Feature chains (not in the paper; docs/optimize-seeds.md, "Feature chains"). build-gvd joins
  // consecutive seeds of a feature curve by a mesh edge, the chord, so the mesh traces the curve only where
  // its chain of seeds is dense and on it. Each round finds the chain links (FindFeatureLinks) and moves a
  // trial seed onto the curve where a link asks for one: from the midpoint of a chord longer than
  // `max_gap` (a gap in the chain) or, with `bend_tol` > 0, of any chord (its midpoint may lie off a bent
  // curve by about h²/8R); and from one spacing beyond a chain's end along its tangent (the chain may stop
  // short of where the feature goes on). The move is projection, then the L1 step in the trial's own cell
  // among all seeds, which is what puts any seed onto a feature. A trial seed stays when it lands on a
  // feature and is not crowded by one: for a chord, on a curve (rank 2, tangent along the chord) between 1/4
  // and 3/4 of it, off it by at most a quarter chord (a bend, not a jump to another feature) and, unless the
  // chord is a gap, by more than `bend_tol`; for an end, 0.5–1.6 spacings ahead on a curve running that way,
  // or on a corner (rank 3); and only while there are fewer than `max_count` seeds (trials in a fixed order).
  // Invariant after a round that adds nothing, unless `max_count` stopped it: every chord of at least 2.5
  // clearances is at most `max_gap` long and has its midpoint within `bend_tol` of its curve, and one
  // spacing beyond every chain end there is no further curve for the L1 step to find. Sheet seeds nearer
  // than `clearance` to an added seed are dropped, as the feature-seed thinning does. Returns the count added.
  size_t RefineFeatureChains(SeedState& s, double bend_tol, double max_gap, double clearance, int rounds,
                             size_t max_count);

  // Alg. 1 line 4: σ = the minimum pairwise seed distance — over pairs that repulsion can change, i.e. with
  // at least one seed that may move (rank < 3). Two fixed seeds (a corner and a seed beside it whose cell
  // also sees three planes) would otherwise pin σ, and with it every seed's repulsion, at their distance.
  // Capped at sigma_max_spacing × the mean nearest-neighbour distance: once the seeds are nearly even the
  // minimum distance approaches the spacing itself, and a kernel that wide acts as a pressure that drives
  // seeds against the features and open rims (docs/optimize-seeds.md, "Kernel width"). And at least
  // sigma_min_spacing × that distance: on CAD shapes the minimum is a crowded pair at a sharp edge, far below
  // the spacing, and a kernel that narrow leaves the sheets uneven (fandisk 2.5k: spacing CV 0.29, mean
  // triangle quality 0.64; with the floor 0.18 and 0.80).
  double KernelWidth(const SeedState& s) const;

  // Thins the seeds at their current positions and ranks (feature_clearance × the mean spacing). A seed's
  // misfit, which decides between two crowded feature seeds, is the mean distance of its position from the
  // tangent planes of its cell's samples: zero on the corner itself. Returns the count dropped.
  size_t DropCrowded(SeedState& s, const CellSamples& cells) const;

  // Mean and coefficient of variation of the nearest-neighbour distances (the spacing's evenness).
  std::pair<double, double> SpacingStats(const std::vector<Vec3>& positions) const;

  // Same summation order as SpacingStats, so the value is bit-identical to its mean.
  double MeanSpacing(const std::vector<Vec3>& positions) const { return SpacingStats(positions).first; }
  // OnTwoCurves' thresholds at `spacing`: the option's separation; the bisector test widened to twice the
  // field's measured gradient error, which the tangents carry (exact fields measure under 2.5°: unchanged).
  TwoCurves TwoCurveTest(double spacing) const {
    return {options_.curve_separation * spacing, std::max(kTwoCurvesBisectorDeg, 2.0 * gradient_error_ * 180.0 / M_PI)};
  }

  NeighbourLists RepulsionNeighbours(const std::vector<Vec3>& positions, double radius) const;

  // Takes the cells' samples from one point set for the rest of the run (--cell-samples pool).
  void UsePool(double bucket_size);
  const SamplePool* pool() const { return pool_.get(); }

  double diagonal() const { return diagonal_; }
  size_t last_short_cells() const { return last_short_cells_; }
  double last_acceptance() const { return last_acceptance_; }
  double normal_spread() const { return normal_spread_; }
  const ProjectionOptions& projection() const { return projection_; }
  /// Every later projection takes zero sheets closer than this for one (Prepare measures it); where the field
  /// shows twins (`centre`), the sample planes are centred between them (CenterTwinPlanes).
  void SetTwinWithin(double within, bool centre) {
    projection_.twin_within = within;
    centre_twin_planes_ = centre && within > 0.0;
  }
  /// --sample-planes auto fits only where the gradients are off by more than this explains (ValueErrorTilt).
  void SetValueErrorTilt(double radians) { value_tilt_ = radians; }

 private:
  const Udf& udf_;
  const OptimizeSeedsOptions& options_;
  Monitor& monitor_;
  double diagonal_;
  CellSamplingOptions cell_options_;
  std::unique_ptr<SamplePool> pool_;
  ProjectionOptions projection_;
  uint64_t round_ = 0;  // sampling rounds so far: the random stream of every round differs
  CellSamples cached_cells_;             // the last round's cells, reused where nothing nearby moved
  CellSamples planed_cells_;             // the same with fitted or centred sample planes (noisy fields only)
  CellSamplingBuffers cell_buffers_;     // the cells' working memory, kept from round to round
  std::vector<Vec3> cached_positions_;
  size_t last_short_cells_ = 0;
  double last_acceptance_ = 0.0;
  // SeesTwoPlanes' bounds, fixed by the options: the angle range (radians) and each plane's share.
  double crease_angle_ = options_.crease_angle_deg * M_PI / 180.0;
  double crease_max_angle_ = BlindCreaseAngle(options_.rank_threshold);
  double crease_share_ = SecondPlaneShare(options_.rank_threshold);
  double normal_spread_ = 0.0;  ///< the last Analyze's UnexplainedNormalSpread (0 with --rank-noise off)
  // --sample-planes: 1 fit, 0 gradient, -1 auto (undecided until the first cells are measured).
  int fit_planes_ = options_.sample_planes == "fit" ? 1 : options_.sample_planes == "auto" ? -1 : 0;
  double gradient_error_ = 0.0;  ///< radians, the last measured median (FitSamplePlanes)
  double value_tilt_ = 0.0;      ///< radians (SetValueErrorTilt)
  bool centre_twin_planes_ = false;  ///< SetTwinWithin
};

}  // namespace voroudf

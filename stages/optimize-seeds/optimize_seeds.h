#pragma once
// Stage 2 (DESIGN.md; paper Sec. 3.1–3.2, Alg. 1): moves seeds onto the surface's sharp and non-manifold
// features with the constrained L1 tangent step, and spreads them evenly with feature-aware repulsion.
#include <cstdint>
#include <functional>
#include <string>

#include "common/monitor.h"
#include "common/projection.h"
#include "common/udf.h"
#include "formats/seeds_io.h"

namespace voroudf {

struct OptimizeSeedsOptions {
  uint64_t seed = 0;              ///< RNG seed for the cell samples (--seed)
  int samples_per_cell = 100;     ///< M, samples per Voronoi cell (paper: 100) (--samples-per-cell)
  /// In the repulsion rounds, a sheet seed's cell (neighbours sheet seeds too) whose first this many samples
  /// show one tangent plane clearly (rank 1 at half the rank threshold) keeps only those; 0: every cell
  /// gets M (--early-samples). Not in the paper, see docs/optimize-seeds.md ("Early samples").
  int early_samples = 0;
  /// --cell-samples: "pool" (default), each cell's M samples are its M lowest-mark points of one random
  /// point set fixed for the run (sample_pool.h), so that a cell that moved little keeps most samples and
  /// their UDF values; "fresh", M new rejection draws per cell and round (the paper). Both are uniform in
  /// the cell. Not in the paper, see docs/optimize-seeds.md ("Sample pool").
  std::string cell_samples = "pool";
  /// --pool-layers: the pool is split into this many independent point sets, which the sampling rounds
  /// take in turn, so that consecutive rounds see independent samples of a cell (1: every round the same).
  /// Each layer costs about M UDF queries per seed (docs/optimize-seeds.md, "Sample pool").
  int pool_layers = 2;
  /// --repulsion-cells: "every", every repulsion round draws the cells again for the ranks and move spaces
  /// (the paper's loop); "first", only the first round of an outer iteration does, and the later rounds keep
  /// those ranks, a sheet seed moving in the tangent plane of its own gradient. Not in the paper, see
  /// docs/optimize-seeds.md ("Cells in the repulsion rounds").
  std::string repulsion_cells = "every";
  double gamma = 10.0;            ///< γ, proximity weight, lengths relative to the domain diagonal (paper: 10) (--gamma)
  double delta = 1e-3;            ///< δ, inner loop stops when the gradient changes by less than this, relatively (paper: 1e-3) (--delta)
  int max_outer_iters = 3;        ///< cap on Alg. 1's outer loop (--max-outer-iters; see docs for why 3)
  int max_inner_iters = 5;        ///< cap on Alg. 1's inner loop (--max-inner-iters); 5 with sample-seeds' spread start
  /// L-BFGS iterations per inner round (--lbfgs-max-iters). Few: the round's energy on fixed tangent planes has
  /// no minimum, so a longer run only ends at the --max-step limit for every seed (docs: "Repulsion rounds")
  int lbfgs_max_iters = 3;
  double rank_threshold = 0.4;    ///< τ: rank(A) = #{singular values > τ·s_1} (--rank-threshold)
  /// A rank-1 cell whose normals show two planes turned by at least this many degrees, each seen by the share
  /// of samples τ asks of a second plane at 90°, is rank 2 (SeesTwoPlanes; --crease-angle-deg; 0: the paper's test alone)
  double crease_angle_deg = 30.0;
  /// --rank-noise: the rank test counts s_k > sqrt(τ² + ν²)·s_1, ν the median s_3/s_1 over the cells (the normal
  /// spread no surface explains: gradient errors), so that a noisy sheet is not a crease; off (default): the
  /// paper's test. Off by default: on feature-dense parts the median s_3/s_1 is geometry, not noise (docs).
  bool rank_noise = false;
  /// --curved-sheets: a rank-2 cell whose samples' normal lines meet on one axis is one sheet curved within
  /// the cell (a tube or a rod narrower than it; NormalsMeetOnOneAxis), rank 1. For parts thinner than a
  /// spacing, with sample-seeds --thin-boost; off by default: over the shared data it measures no better.
  bool curved_sheets = false;
  /// --sample-planes: gradient: each cell sample's tangent plane is its gradient's (the paper); fit: fitted to
  /// the foot points of the cell's samples (FitSamplePlanes; fields with gradient errors); auto: fit when the
  /// first cells' gradients are off those planes by more than sample_planes_auto_deg and by more than the
  /// field's value errors explain (FitPaysOff).
  std::string sample_planes = "auto";
  double sample_planes_auto_deg = 8.0;
  int cell_knn = 6;               ///< the cell's bounding ball has radius cell_radius_factor × distance to the k-th nearest seed (--cell-knn)
  double cell_radius_factor = 0.5;///< (--cell-radius-factor)
  double sigma_max_spacing = 0.5; ///< σ ≤ this × mean nearest-neighbour distance; 0: no cap (--sigma-max-spacing)
  double sigma_min_spacing = 0.5; ///< σ ≥ this × mean nearest-neighbour distance; 0: the paper's rule alone (--sigma-min-spacing)
  /// Seeds crowding a feature seed are dropped (SeedsBesideFeatures with limit this × the mean nearest-
  /// neighbour distance): feature seeds are thinned to this spacing, sheet seeds kept this far from them
  /// (--feature-clearance; 0: none). Not in the paper.
  double feature_clearance = 0.4;
  /// Curve seeds this × the mean nearest-neighbour distance or more apart across their tangents lie on two
  /// curves when their chord leaves the tangents' bisector (OnTwoCurves): the two rims of a plate's edge face,
  /// a chamfer's two edges. Then neither crowds the other out and they are not linked into one chain
  /// (--curve-separation; 0: any curve seed crowds another within the clearance). Not in the paper.
  double curve_separation = 0.45;
  /// L1 steps of the feature seeds (rank ≥ 2) alone after the outer loop, each after fresh cells and ranks
  /// (--feature-steps). Not in the paper's Alg. 1, see docs/optimize-seeds.md.
  int feature_steps = 3;
  /// Where a feature curve bends away from the chord between two consecutive feature seeds by more than
  /// this × the mean spacing, a seed is added on the curve between them (--feature-chord-tol; 0: never).
  /// Not in the paper, see docs/optimize-seeds.md ("Feature chains").
  double feature_chord_tol = 0.0;
  /// Where two consecutive seeds of a feature chain lie farther apart than this × the mean spacing, a seed
  /// is added on the curve between them, and a chain's end is extended one spacing along its curve while
  /// the L1 step finds the curve there (--feature-gap-max; 0: never; 1–2.5, the chain search radius).
  /// Not in the paper, see docs/optimize-seeds.md ("Feature chains").
  double feature_gap_max = 1.5;
  double max_step = 0.5;          ///< trust region: a repulsion round moves a seed at most this many σ (--max-step)
  double repulsion_cutoff = 3.0;  ///< neighbours interact within this many σ (kernel 1.1e-2 at 3σ) (--repulsion-cutoff)
  /// --l1-curve-step: how the L1 step moves a curve seed (rank 2). "free": in every direction (the paper);
  /// "across" (default): only across its curve unless its cell sees a third plane (StepAcrossCurve); "auto":
  /// across on a field with a floor (value errors: the projection measured a twin width), free on an exact
  /// field. Not in the paper, see docs/optimize-seeds.md ("Curve seeds step across their curve").
  std::string l1_curve_step = "across";
  double l1_tol_rel = 1e-6;       ///< L1 step solved to this position accuracy, relative to the diagonal (--l1-tol-rel)
  int l1_max_steps = 200;         ///< iterations of the L1 step's interior-point method before it gives up (--l1-max-steps)
  double move_tol = 1e-3;         ///< an inner loop moving no seed farther than move_tol·σ "makes no update" (--move-tol)
  double outer_tol = 0.02;        ///< outer loop ends when σ does not grow and the spacing CV drops by less than this, relatively (--outer-tol)
  double proj_tol_rel = 1e-5;     ///< projection tolerance on d, relative to the diagonal (as sample-seeds) (--proj-tol-rel)
  int proj_max_iters = 50;        ///< projection steps before a move is undone (--proj-max-iters)
  double proj_floor_rel = 1e-2;   ///< a kink's bottom with d below this x diagonal is on the zero set (as sample-seeds) (--proj-floor-rel)
  double proj_twin_factor = kProjTwinFactor;  ///< zero sheets closer than this x the measured floor are one surface (as sample-seeds) (--proj-twin-factor)

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// Summary of one outer iteration, passed to the trace callback and logged.
struct OuterIterationReport {
  int iteration = 0;               ///< 1-based
  double sigma = 0.0;              ///< kernel width (world units)
  double energy = 0.0;             ///< repulsion energy at the end of the inner loop
  int inner_rounds = 0;
  double max_inner_move = 0.0;     ///< largest seed displacement in the inner loop (world units)
  double mean_abs_udf = 0.0;
  double spacing_cv = 0.0;         ///< coefficient of variation of the nearest-neighbour distances
  size_t rank_count[4] = {0, 0, 0, 0};
  double seconds = 0.0;
};

/// The bisector test of OnTwoCurves on exact tangents, degrees.
constexpr double kTwoCurvesBisectorDeg = 15.0;

/// The two-curve test's thresholds (OnTwoCurves). The default never finds two curves.
struct TwoCurves {
  double min_separation = 0.0;                 ///< world units; 0: off
  double bisector_deg = kTwoCurvesBisectorDeg;  ///< more off the tangents' bisector than this: two curves
};

/// Marks the seeds that crowd a feature seed: feature seeds (rank ≥ 2) are thinned greedily, corners (rank 3)
/// before curves (rank 2), so that no two lie nearer than `limit`; then every sheet seed (rank < 2) nearer
/// than `limit` to a kept feature seed is marked. Within a rank, seeds with a lower misfit are kept first.
/// Why (not in the paper): optimize-seeds gathers every seed whose cell sees two sheets onto the curve, so
/// the curve seeds end up 2–5 times denser than the sheets and unevenly spaced (crossing-planes, 1k seeds:
/// gaps 0.2–1.1 sheet spacings); their thin geodesic regions are narrower than build-gvd's neighbourhoods
/// resolve, and the dual folds beside the curve. A sheet seed beside a curve has a region that reaches the
/// curve between the curve's seeds, with the same result; two seeds at one corner give a sliver and hold
/// each other off the corner (docs/optimize-seeds.md, "Feature clearance").
/// \param position  seed positions
/// \param rank      per seed, 0–3 (values above 3 count as 3)
/// \param limit     clearance distance (world units)
/// \param misfit    optional, per seed: lower is preferred among equal ranks; empty: input order
/// \param tangent   optional, per seed: the unit curve direction of a curve seed, zero for others. Given, a
///                  sheet seed is also marked when it lies within `limit` of the segment between two kept
///                  feature seeds (within 3 × `limit` of it) that runs along their tangents (|cos| ≥ 0.9):
///                  between two curve seeds, it is as near the curve as beside one.
/// \param two_curves  with `tangent`: a curve seed is kept beside a kept curve seed of another curve
///                  (OnTwoCurves).
/// \return          per seed, 1 if it should be dropped
std::vector<char> SeedsBesideFeatures(const std::vector<Vec3>& position, const std::vector<uint8_t>& rank, double limit,
                                      const std::vector<double>& misfit = {}, const std::vector<Vec3>& tangent = {},
                                      const TwoCurves& two_curves = {});

/// Whether curve seeds at a and b, with unit tangents t_a and t_b, lie on two curves rather than on one: the
/// chord ab runs more than `test.bisector_deg` off the bisector of the two tangents (on one smooth curve a
/// chord bisects its ends' tangents; a circular arc's does exactly), and each lies at least
/// `test.min_separation` (world units) from the other's tangent line. Why the separation: parallel curves closer
/// than about half a spacing bound a strip that build-gvd's samples do not resolve, and both chains there
/// give a dual with holes (docs/optimize-seeds.md, "Two curves side by side"); such curves stay one chain.
/// Where the field's gradients are off by θ the
/// tangents are too, and the bisector by up to θ: the caller widens `bisector_deg` to 2θ. False where a
/// tangent is zero or min_separation <= 0.
bool OnTwoCurves(const Vec3& a, const Vec3& t_a, const Vec3& b, const Vec3& t_b, const TwoCurves& test);

/// Paper Alg. 1 lines 2–16 (Sec. 3.1 Eqs. energy_l1 / energy_l1_regularizer, Sec. 3.2 Eqs. particle /
/// particle_proj). Input seeds are first projected onto the zero set (seeds that do not converge and exact
/// duplicates are dropped, with a warning). Then, per outer iteration: (1) the constrained L1 tangent step
/// of every seed inside its Voronoi cell (l1_tangent.h), then projection; (2) σ = the minimum distance
/// between seeds, over pairs with at least one movable (rank < 3) seed, kept within [sigma_min_spacing,
/// sigma_max_spacing] × the mean nearest-neighbour distance; (3) inner rounds of: cells and samples recomputed (voronoi_cells.h),
/// rank and null space V₀ of every seed's tangent-plane matrix, Gaussian repulsion over neighbours within
/// repulsion_cutoff·σ minimised with L-BFGS in the null spaces (repulsion.h, trust region max_step·σ),
/// projection — until the projected gradient's norm changes by less than δ relatively, or
/// max_inner_iters. A move whose projection fails, or that lands a seed nearer to another than
/// min(floor, its previous nearest distance), is undone. The outer loop ends when an inner loop moves no
/// seed farther than move_tol·σ, or after max_outer_iters. Then feature_steps L1 steps of the feature seeds
/// alone put seeds that slid along a curved feature back onto it; before each move, seeds whose targets
/// crowd a feature seed's are dropped (SeedsBesideFeatures, by the misfit at the target). Then the
/// ranks are recomputed at the final positions and crowding seeds dropped again. With feature_gap_max or
/// feature_chord_tol, before outer iterations 2, 3, … (dropping as many crowded sheet seeds) and at the
/// end, seeds are added on the feature chains where two consecutive seeds lie more than
/// feature_gap_max spacings apart, beyond a chain's ends while the L1 step finds its curve there, and
/// (feature_chord_tol) where a chord leaves its curve.
/// \param udf           the field (thread-safe batched queries); lengths are relative to its domain diagonal
/// \param input         seeds (only positions are used); at least 2 distinct ones
/// \param options       see OptimizeSeedsOptions; checked first (UsageError)
/// \param monitor       logs one line per outer iteration and a progress task per outer iteration
/// \param on_iteration  optional: sees the seeds after every outer iteration (for --trace)
/// \return seeds on the zero set (d < proj_tol_rel·diagonal) with UDF value, gradient and rank, in input
///         order (fewer than the input when seeds were dropped). Deterministic for given inputs and options, also across thread counts (fixed-order
///         reductions, per-seed random streams). Throws InputError for fewer than 2 distinct seeds,
///         NumericalError if fewer than 2 seeds reach the surface.
SeedCloud OptimizeSeeds(const Udf& udf, const SeedCloud& input, const OptimizeSeedsOptions& options, Monitor& monitor,
                        const std::function<void(const OuterIterationReport&, const SeedCloud&)>& on_iteration = {});

}  // namespace voroudf

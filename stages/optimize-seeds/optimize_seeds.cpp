#include "stages/optimize-seeds/optimize_seeds.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>

#include "common/errors.h"
#include "common/projection.h"
#include "stages/optimize-seeds/feature_seeds.h"
#include "stages/optimize-seeds/l1_tangent.h"
#include "stages/optimize-seeds/repulsion.h"
#include "stages/optimize-seeds/seed_index.h"
#include "stages/optimize-seeds/voronoi_cells.h"

namespace voroudf {
namespace {
// FindFeatureLinks' search radius, in mean spacings: chords longer than this are not seen as chords.
constexpr double kFeatureLinkRadius = 2.5;
}  // namespace

void OptimizeSeedsOptions::Check() const {
  if (samples_per_cell < 3 || samples_per_cell > 100000) throw UsageError("--samples-per-cell must be in [3, 100000]");
  if (early_samples != 0 && (early_samples < 3 || early_samples > samples_per_cell))
    throw UsageError("--early-samples must be 0 or in [3, --samples-per-cell]");
  if (!(gamma > 0.0) || !std::isfinite(gamma)) throw UsageError("--gamma must be positive");
  if (!(delta > 0.0 && delta < 1.0)) throw UsageError("--delta must be in (0, 1)");
  if (max_outer_iters < 0) throw UsageError("--max-outer-iters must be at least 0");
  if (max_inner_iters < 1) throw UsageError("--max-inner-iters must be at least 1");
  if (lbfgs_max_iters < 1) throw UsageError("--lbfgs-max-iters must be at least 1");
  if (!(rank_threshold > 0.0 && rank_threshold < 1.0)) throw UsageError("--rank-threshold must be in (0, 1)");
  if (!(crease_angle_deg >= 0.0 && crease_angle_deg * M_PI / 180.0 < BlindCreaseAngle(rank_threshold))) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%.1f", BlindCreaseAngle(rank_threshold) * 180.0 / M_PI);
    throw UsageError(std::string("--crease-angle-deg must be in [0, ") + limit +
                     "): from 2 atan(--rank-threshold) degrees on, the rank test sees a crease itself");
  }
  if (cell_knn < 1 || cell_knn > 64) throw UsageError("--cell-knn must be in [1, 64]");
  if (!(cell_radius_factor > 0.0 && cell_radius_factor <= 10.0)) throw UsageError("--cell-radius-factor must be in (0, 10]");
  if (!(max_step >= 0.0 && max_step <= 100.0)) throw UsageError("--max-step must be in [0, 100]");
  if (cell_samples != "pool" && cell_samples != "fresh") throw UsageError("--cell-samples must be pool or fresh");
  if (repulsion_cells != "every" && repulsion_cells != "first") throw UsageError("--repulsion-cells must be every or first");
  if (l1_curve_step != "auto" && l1_curve_step != "free" && l1_curve_step != "across")
    throw UsageError("--l1-curve-step must be auto, free or across");
  if (!(pool_layers >= 1 && pool_layers <= 64)) throw UsageError("--pool-layers must be in [1, 64]");
  if (!(sigma_max_spacing >= 0.0 && sigma_max_spacing <= 10.0)) throw UsageError("--sigma-max-spacing must be in [0, 10]");
  if (!(sigma_min_spacing >= 0.0 && sigma_min_spacing <= 10.0)) throw UsageError("--sigma-min-spacing must be in [0, 10]");
  if (!(feature_clearance >= 0.0 && feature_clearance <= 1.0)) throw UsageError("--feature-clearance must be in [0, 1]");
  if (feature_steps < 0) throw UsageError("--feature-steps must be at least 0");
  if (!(feature_chord_tol >= 0.0 && feature_chord_tol <= 1.0)) throw UsageError("--feature-chord-tol must be in [0, 1]");
  if (!(feature_gap_max == 0.0 || (feature_gap_max >= 1.0 && feature_gap_max <= kFeatureLinkRadius)))
    throw UsageError("--feature-gap-max must be 0 or in [1, 2.5] (no chain link is sought beyond 2.5 spacings)");
  if (sigma_max_spacing > 0.0 && sigma_min_spacing > sigma_max_spacing)
    throw UsageError("--sigma-min-spacing must not exceed --sigma-max-spacing");
  if (!(repulsion_cutoff >= 1.0 && repulsion_cutoff <= 10.0)) throw UsageError("--repulsion-cutoff must be in [1, 10]");
  if (!(l1_tol_rel > 0.0 && l1_tol_rel < 0.1)) throw UsageError("--l1-tol-rel must be in (0, 0.1)");
  if (l1_max_steps < 1) throw UsageError("--l1-max-steps must be at least 1");
  if (!(move_tol >= 0.0 && move_tol < 1.0)) throw UsageError("--move-tol must be in [0, 1)");
  if (!(outer_tol >= 0.0 && outer_tol < 1.0)) throw UsageError("--outer-tol must be in [0, 1)");
  CheckRelativeProjection(proj_tol_rel, proj_floor_rel, proj_max_iters, proj_twin_factor);
}

namespace {

std::string Format(const char* format, double a = 0, double b = 0, double c = 0, double d = 0, double e = 0) {
  char line[256];
  std::snprintf(line, sizeof line, format, a, b, c, d, e);
  return line;
}


// Rounds of RefineFeatureChains: each halves the chords it refines, so their misfit falls by 4 per round,
// and takes a chain's end one spacing farther along its feature.
constexpr int kFeatureChainRounds = 6;
// ... before each outer iteration after the first, which moves the seeds anyway.
constexpr int kFeatureChainRoundsInLoop = 2;
// Feature steps after the --feature-steps ones, taken while a feature seed's step would still move it more
// than kFeatureSettledMove mean spacings (a seed ranked as a feature only after its neighbours stepped).
constexpr int kFeatureExtraSteps = 2;
constexpr double kFeatureSettledMove = 0.05;
// After the last chain fill only the seeds this many mean spacings from an added seed take the feature
// steps again: farther ones have cells the added seeds do not reach (a cell is about a spacing across).
constexpr double kSettleReach = 2.0;
// SeesTwoPlanes' contrast: between a uniform spread's 3.46 (one curved sheet) and the > 9 of two planes.
constexpr double kCreaseContrast = 6.0;
// A chain fill leaves at most this share more seeds than the input count (or the count before the fill, if
// more), so --count stays the output size within a few percent: the fills before outer iterations give
// back crowded sheet seeds, and where there are too few (most seeds ranked as features: feature-dense
// parts, or gradient errors of 30° that make the rank test take sheets for curves) the last added go; the
// last fill, which gives back none, stops there.
constexpr double kChainCountSlack = 0.02;

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
  double Project(SeedState& s, const std::vector<Vec3>& previous, std::vector<Vec3> moved, double min_separation) {
    const size_t n = moved.size();
    ProjectionResult r = ProjectToZeroSet(udf_, moved, projection_, Monitor::Null());
    std::vector<char> accept(r.converged);
    const size_t failed = n - r.num_converged;
    std::vector<double> floor(n, min_separation);
    {
      const SeedIndex before(previous);
#pragma omp parallel
      {
        std::vector<int> knn;
#pragma omp for schedule(static)
        for (long li = 0; li < static_cast<long>(n); ++li) {
          const size_t i = static_cast<size_t>(li);
          before.Nearest(previous[i], 2, knn);
          for (int j : knn)
            if (static_cast<size_t>(j) != i) floor[i] = std::min(floor[i], (previous[static_cast<size_t>(j)] - previous[i]).norm());
          floor[i] = std::max(floor[i], 1e-9 * diagonal_);
        }
      }
    }
    size_t separated = 0;
    for (int pass = 0; pass < 64; ++pass) {
      std::vector<Vec3> trial(n);
      for (size_t i = 0; i < n; ++i) trial[i] = accept[i] ? moved[i] : previous[i];
      const SeedIndex index(trial);
      std::vector<char> reject(n, 0);
#pragma omp parallel
      {
        std::vector<int> found;
#pragma omp for schedule(static)
        for (long li = 0; li < static_cast<long>(n); ++li) {
          const size_t i = static_cast<size_t>(li);
          if (!accept[i] || moved[i] == previous[i]) continue;
          index.WithinRadius(trial[i], floor[i] * (1.0 + 1e-5) + 1e-12, found);
          for (int j : found)
            if (static_cast<size_t>(j) != i && (trial[static_cast<size_t>(j)] - trial[i]).norm() < floor[i]) reject[i] = 1;
        }
      }
      const size_t rejected = static_cast<size_t>(std::count(reject.begin(), reject.end(), 1));
      if (rejected == 0) break;
      separated += rejected;
      for (size_t i = 0; i < n; ++i)
        if (reject[i]) accept[i] = 0;
    }
    double largest = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (accept[i]) {
        s.position[i] = moved[i];
        s.udf[i] = r.distance[i];
        s.normal[i] = r.gradient[i];
        largest = std::max(largest, (moved[i] - previous[i]).norm());
      } else {
        s.position[i] = previous[i];
      }
    }
    if (failed > 0) monitor_.Debug(std::to_string(failed) + " moves undone: projection did not converge");
    if (separated > 0) monitor_.Debug(std::to_string(separated) + " moves undone: they ended too near another seed");
    return largest;
  }

  // Cells, samples, rank and null space of every seed at the current positions. early: the repulsion
  // rounds, which only need ranks and null spaces, let cells that clearly see one plane stop at
  // --early-samples; the L1 steps and the final ranks take every cell whole.
  CellSamples Analyze(SeedState& s, bool early = false) {
    const SeedIndex index(s.position);
    CellSamplingOptions cell_options = cell_options_;
    if (!early) cell_options.early_samples = 0;
    // Only sheet seeds whose neighbours (last round's cells) are all sheet seeds may stop early: beside a
    // feature a second sheet can cover a small part of a cell, which the first samples may miss.
    std::vector<char> allowed;
    if (early && cell_options.early_samples > 0) {
      const size_t n = s.position.size();
      allowed.assign(n, 0);
      if (cached_cells_.radius.size() == n) {
        for (size_t i = 0; i < n; ++i) {
          bool sheet = s.rank[i].rank == 1;
          for (size_t k = cached_cells_.neighbour_offset[i]; k < cached_cells_.neighbour_offset[i + 1] && sheet; ++k)
            sheet = s.rank[static_cast<size_t>(cached_cells_.neighbour[k])].rank == 1;
          allowed[i] = sheet;
        }
      }
      cell_options.early_allowed = &allowed;
    }
    // Seeds dropped since the last call shift the later ones' indices: the cache follows them by position.
    if (!cached_positions_.empty() && cached_positions_.size() != s.position.size())
      CarryCells(s.position, cell_options, cached_cells_, cached_positions_);
    CellSamples cells = SampleVoronoiCells(udf_, s.position, index, cell_options, options_.seed, round_++,
                                           cached_positions_.empty() ? nullptr : &cached_cells_, &cached_positions_);
    const long n = static_cast<long>(s.position.size());
    std::vector<TangentRank> ranks(static_cast<size_t>(n));
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) {
      const size_t begin = cells.sample_offset[i], end = cells.sample_offset[i + 1];
      ranks[static_cast<size_t>(i)] =
          ComputeTangentRank(cells.gradient.data() + begin, end - begin, options_.rank_threshold);
    }
    // Gradient errors spread every cell's normals alike; the rank test counts only what the surface adds.
    normal_spread_ = options_.rank_noise ? UnexplainedNormalSpread(ranks) : 0.0;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i) {
      TangentRank& r = ranks[static_cast<size_t>(i)];
      RecountRank(r, options_.rank_threshold, normal_spread_);
      if (r.rank == 1 && crease_angle_ > 0.0 &&
          SeesTwoPlanes(cells.gradient.data() + cells.sample_offset[i],
                        cells.sample_offset[i + 1] - cells.sample_offset[i], r, crease_angle_, crease_max_angle_,
                        crease_share_, kCreaseContrast))
        r.rank = 2;
      MoveSpace& space = s.space[i];
      if (r.rank == 0) {
        // No usable sample (an empty cell within the budget): move in the tangent plane of the seed's own
        // gradient, as on a sheet, and report rank 0 ("unknown").
        space = OwnTangentPlane(s.normal[i]);
      } else {
        space.dim = 3 - r.rank;
        space.basis.setZero();
        for (int d = 0; d < space.dim; ++d) space.basis.col(d) = r.v.col(r.rank + d);
      }
      s.rank[i] = r;
    }
    cached_cells_ = cells;
    cached_positions_ = s.position;
    last_short_cells_ = cells.short_cells;
    if (cells.draws) last_acceptance_ = static_cast<double>(cells.drawn_samples) / static_cast<double>(cells.draws);
    monitor_.Debug("cells: " + std::to_string(cells.redrawn) + " of " + std::to_string(n) + " redrawn, " +
                   std::to_string(cells.early_cells) + " of them with their early samples only, " +
                   std::to_string(cells.reused) + " samples' UDF values reused");
    return cells;
  }

  // Between repulsion rounds without new cells (--repulsion-cells first): ranks stay, a seed that moves in a
  // plane (a sheet seed) takes the tangent plane of its own gradient where Project left it, which is the
  // surface's there; a curve seed keeps its line, a corner stays fixed.
  void FollowTangentPlanes(SeedState& s) const {
    for (size_t i = 0; i < s.position.size(); ++i) {
      if (s.space[i].dim != 2 || s.normal[i].squaredNorm() < 0.25) continue;
      const MoveSpace own = OwnTangentPlane(s.normal[i]);
      if (own.dim == 2) s.space[i].basis = own.basis;
    }
  }

  // The plane orthogonal to a seed's own gradient as a move space (dim 2), or dim 0 where the gradient
  // gives no plane.
  MoveSpace OwnTangentPlane(const Vec3& normal) const {
    const TangentRank own = ComputeTangentRank(&normal, 1, options_.rank_threshold);
    MoveSpace space;
    space.dim = own.rank == 1 ? 2 : 0;
    space.basis.leftCols<2>() = own.v.rightCols<2>();
    return space;
  }

  // Paper Eq. (energy_l1_regularizer) for every seed, inside its cell. Returns the new (unprojected) positions.
  // features_only: only seeds whose cells have rank ≥ 2 (sharp edges, corners, rims) move.
  // misfit_at_target (optional): per seed, TangentMisfit at its new position, from the solver's terms (+inf
  // for a seed that did not move).
  // movers (optional): only the seeds marked there move.
  std::vector<Vec3> L1Step(const SeedState& s, const CellSamples& cells, bool features_only = false,
                           std::vector<double>* misfit_at_target = nullptr, const std::vector<char>* movers = nullptr) {
    const long n = static_cast<long>(s.position.size());
    if (misfit_at_target) misfit_at_target->assign(static_cast<size_t>(n), INFINITY);
    L1TangentOptions solver;
    // Lengths relative to the diagonal: ‖y − y*‖ ≤ sqrt(gap/γ) ≤ l1_tol_rel.
    solver.gap_tolerance = options_.gamma * options_.l1_tol_rel * options_.l1_tol_rel;
    solver.max_newton_steps = options_.l1_max_steps;
    std::vector<Vec3> moved(s.position);
    std::vector<int> sweeps(static_cast<size_t>(n), 0);
    std::vector<char> converged(static_cast<size_t>(n), 1);
    const bool across_curves =
        options_.l1_curve_step == "across" || (options_.l1_curve_step == "auto" && projection_.twin_within > 0.0);
#pragma omp parallel
    {
      L1TangentProblem problem;
      problem.gamma = options_.gamma;
#pragma omp for schedule(dynamic, 32)
      for (long i = 0; i < n; ++i) {
        if ((features_only && s.rank[i].rank < 2) || (movers && !(*movers)[static_cast<size_t>(i)])) continue;
        const Vec3& x0 = s.position[i];
        // Lengths relative to the domain diagonal (DESIGN.md), so γ means the same for any scale of the
        // shape; the paper's shapes are normalised to about unit size, where its γ = 10 was chosen.
        const double scale = diagonal_;
        const double inv_l = 1.0 / scale;
        problem.Clear();
        for (size_t m = cells.sample_offset[i]; m < cells.sample_offset[i + 1]; ++m) {
          const Vec3& g = cells.gradient[m];
          if (g.squaredNorm() < 0.25) continue;  // a source that cannot tell: no tangent plane
          const Vec3 a = g.normalized();
          problem.AddTerm(a, (a.dot(cells.point[m] - x0) - cells.distance[m]) * inv_l);
        }
        if (problem.a.empty()) continue;
        for (size_t k = cells.neighbour_offset[i]; k < cells.neighbour_offset[i + 1]; ++k) {
          const Vec3 e = s.position[static_cast<size_t>(cells.neighbour[k])] - x0;
          const double len = e.norm();
          problem.c.push_back(e / len);
          problem.h.push_back(0.5 * len * inv_l);  // the bisector plane of x_i and x_j
        }
        // The cell is also bounded by the cube circumscribing its sampling ball: the tangent planes are only
        // trusted where they were sampled (docs/optimize-seeds.md, "Bounding the cells").
        for (int axis = 0; axis < 3; ++axis) {
          for (double sign : {1.0, -1.0}) {
            problem.c.push_back(sign * Vec3::Unit(axis));
            problem.h.push_back(cells.radius[i] * inv_l);
          }
        }
        const L1TangentSolution solution = SolveL1Tangent(problem, solver);
        const size_t first = cells.sample_offset[i], count = cells.sample_offset[i + 1] - first;
        const Vec3 y = across_curves ? StepAcrossCurve(solution.y, s.rank[i], &cells.gradient[first], count) : solution.y;
        moved[i] = x0 + scale * y;
        if (misfit_at_target) {
          // TangentMisfit at the target, from the solver's (merged, weighted) terms.
          double sum = 0.0, weight = 0.0;
          for (size_t k = 0; k < problem.a.size(); ++k) {
            const double w = problem.w.empty() ? 1.0 : problem.w[k];
            sum += w * std::abs(problem.a[k].dot(y) - problem.b[k]);
            weight += w;
          }
          (*misfit_at_target)[i] = scale * sum / weight;
        }
        sweeps[i] = solution.sweeps;
        converged[i] = solution.converged;
      }
    }
    const size_t failed = std::count(converged.begin(), converged.end(), 0);
    const double mean_sweeps = std::accumulate(sweeps.begin(), sweeps.end(), 0.0) / static_cast<double>(n);
    monitor_.Debug(Format("L1 step: %.1f Newton steps per seed on average", mean_sweeps));
    if (failed > 0)
      monitor_.Debug(std::to_string(failed) + " L1 steps hit --l1-max-steps before the gap certificate "
                     "(their best feasible point is used)");
    return moved;
  }

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
                             size_t max_count) {
    const size_t n0 = s.position.size();
    size_t added = 0, last_added = 0;
    const double spacing = MeanSpacing(s.position);
    for (int round = 0; round < rounds; ++round) {
      Analyze(s);
      const size_t n = s.position.size();
      const std::vector<Vec3> tangent = Tangents(s);
      const FeatureLinks links = FindFeatureLinks(s, tangent, kFeatureLinkRadius * spacing);
      // After the first round only links with a seed added in the last round can have changed.
      const size_t fresh = round > 0 ? n - last_added : 0;
      const std::vector<ChainTrial> trials = ChainTrials(s, links, fresh, bend_tol, max_gap, clearance, spacing);
      last_added = 0;
      if (trials.empty()) break;
      std::vector<Vec3> trial_points(trials.size());
      for (size_t k = 0; k < trials.size(); ++k) trial_points[k] = trials[k].start;
      const ProjectionResult projected = ProjectToZeroSet(udf_, trial_points, projection_, Monitor::Null());
      SeedState trial = s;
      std::vector<size_t> trial_of;
      for (size_t k = 0; k < trials.size(); ++k) {
        if (!projected.converged[k]) continue;
        trial.position.push_back(trial_points[k]);
        trial.udf.push_back(projected.distance[k]);
        trial.normal.push_back(projected.gradient[k]);
        trial_of.push_back(k);
      }
      trial.rank.resize(trial.position.size());
      trial.space.resize(trial.position.size());
      const CellSamples cells = Analyze(trial);
      std::vector<char> movers(trial.position.size(), 0);
      std::fill(movers.begin() + static_cast<long>(n), movers.end(), 1);
      std::vector<Vec3> target = L1Step(trial, cells, false, nullptr, &movers);
      std::vector<Vec3> landed(target.begin() + static_cast<long>(n), target.end());
      const ProjectionResult r = ProjectToZeroSet(udf_, landed, projection_, Monitor::Null());
      // Where each trial landed, its cell: the rank and the tangent that decide whether it stays.
      for (size_t t = 0; t < landed.size(); ++t) trial.position[n + t] = landed[t];
      Analyze(trial);
      const SeedIndex index(s.position);
      for (size_t t = 0; t < landed.size(); ++t) {
        const ChainTrial& c = trials[trial_of[t]];
        const int rank = trial.rank[n + t].rank;
        if (!r.converged[t] || rank < 2) continue;
        const Vec3 t_new = rank == 2 ? Vec3(trial.space[n + t].basis.col(0)) : Vec3::Zero();
        const double crowd_radius = LandedOnItsFeature(s, c, landed[t], rank, t_new, bend_tol, max_gap, spacing);
        if (crowd_radius < 0.0 || Crowded(s, n, index, landed[t], rank, std::max(crowd_radius, clearance), spacing) ||
            s.position.size() >= max_count)
          continue;
        s.position.push_back(landed[t]);
        s.udf.push_back(r.distance[t]);
        s.normal.push_back(r.gradient[t]);
        ++last_added;
      }
      s.rank.resize(s.position.size());
      s.space.resize(s.position.size());
      added += last_added;
      if (last_added == 0) break;
    }
    if (added > 0 && clearance > 0.0) DropSheetSeedsNear(s, n0, clearance);
    return added;
  }

  // Alg. 1 line 4: σ = the minimum pairwise seed distance — over pairs that repulsion can change, i.e. with
  // at least one seed that may move (rank < 3). Two fixed seeds (a corner and a seed beside it whose cell
  // also sees three planes) would otherwise pin σ, and with it every seed's repulsion, at their distance.
  // Capped at sigma_max_spacing × the mean nearest-neighbour distance: once the seeds are nearly even the
  // minimum distance approaches the spacing itself, and a kernel that wide acts as a pressure that drives
  // seeds against the features and open rims (docs/optimize-seeds.md, "Kernel width"). And at least
  // sigma_min_spacing × that distance: on CAD shapes the minimum is a crowded pair at a sharp edge, far below
  // the spacing, and a kernel that narrow leaves the sheets uneven (fandisk 2.5k: spacing CV 0.29, mean
  // triangle quality 0.64; with the floor 0.18 and 0.80).
  double KernelWidth(const SeedState& s) const {
    const SeedIndex index(s.position);
    const long n = static_cast<long>(s.position.size());
    std::vector<double> nearest(static_cast<size_t>(n), INFINITY);
#pragma omp parallel
    {
      std::vector<int> knn;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        index.Nearest(s.position[i], 2, knn);
        for (int j : knn)
          if (j != i) nearest[i] = std::min(nearest[i], (s.position[static_cast<size_t>(j)] - s.position[i]).norm());
      }
    }
    double minimum = INFINITY, sum = 0.0;
    for (long i = 0; i < n; ++i) {
      sum += nearest[i];
      if (s.space[i].dim > 0) minimum = std::min(minimum, nearest[i]);
    }
    if (options_.sigma_max_spacing > 0.0) minimum = std::min(minimum, options_.sigma_max_spacing * sum / static_cast<double>(n));
    if (std::isfinite(minimum)) minimum = std::max(minimum, options_.sigma_min_spacing * sum / static_cast<double>(n));
    return minimum;
  }

  // Thins the seeds at their current positions and ranks (feature_clearance × the mean spacing). A seed's
  // misfit, which decides between two crowded feature seeds, is the mean distance of its position from the
  // tangent planes of its cell's samples: zero on the corner itself. Returns the count dropped.
  size_t DropCrowded(SeedState& s, const CellSamples& cells) const {
    std::vector<double> misfit(s.position.size());
    for (size_t i = 0; i < misfit.size(); ++i) misfit[i] = TangentMisfit(cells, i, s.position[i]);
    return ThinCrowded(s, s.position, misfit, options_.feature_clearance * MeanSpacing(s.position));
  }

  // Mean and coefficient of variation of the nearest-neighbour distances (the spacing's evenness).
  std::pair<double, double> SpacingStats(const std::vector<Vec3>& positions) const {
    const SeedIndex index(positions);
    const long n = static_cast<long>(positions.size());
    std::vector<double> nearest(static_cast<size_t>(n), 0.0);
#pragma omp parallel
    {
      std::vector<int> knn;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        index.Nearest(positions[i], 2, knn);
        for (int j : knn)
          if (j != i) nearest[i] = (positions[static_cast<size_t>(j)] - positions[i]).norm();
      }
    }
    double sum = 0.0, sum_sq = 0.0;
    for (double d : nearest) sum += d;
    const double mean = sum / static_cast<double>(n);
    for (double d : nearest) sum_sq += (d - mean) * (d - mean);
    return {mean, mean > 0.0 ? std::sqrt(sum_sq / static_cast<double>(n)) / mean : 0.0};
  }

  // Same summation order as SpacingStats, so the value is bit-identical to its mean.
  double MeanSpacing(const std::vector<Vec3>& positions) const { return SpacingStats(positions).first; }

  NeighbourLists RepulsionNeighbours(const std::vector<Vec3>& positions, double radius) const {
    const SeedIndex index(positions);
    const long n = static_cast<long>(positions.size());
    std::vector<std::vector<std::pair<int, int>>> per_seed(static_cast<size_t>(n));
#pragma omp parallel
    {
      std::vector<int> found;
#pragma omp for schedule(dynamic, 64)
      for (long i = 0; i < n; ++i) {
        index.WithinRadius(positions[i], radius, found);
        for (int j : found)
          if (j > i) per_seed[i].emplace_back(static_cast<int>(i), j);
      }
    }
    std::vector<std::pair<int, int>> pairs;
    for (auto& p : per_seed) pairs.insert(pairs.end(), p.begin(), p.end());
    return NeighbourLists::FromPairs(static_cast<size_t>(n), std::move(pairs));
  }

  // Takes the cells' samples from one point set for the rest of the run (--cell-samples pool).
  void UsePool(double bucket_size) {
    pool_ = std::make_unique<SamplePool>(options_.seed, bucket_size, options_.pool_layers);
    cell_options_.pool = pool_.get();
  }
  const SamplePool* pool() const { return pool_.get(); }

  double diagonal() const { return diagonal_; }
  size_t last_short_cells() const { return last_short_cells_; }
  double last_acceptance() const { return last_acceptance_; }
  double normal_spread() const { return normal_spread_; }
  const ProjectionOptions& projection() const { return projection_; }
  /// Every later projection takes zero sheets closer than this for one (Prepare measures it).
  void SetTwinWithin(double within) { projection_.twin_within = within; }

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
  std::vector<Vec3> cached_positions_;
  size_t last_short_cells_ = 0;
  double last_acceptance_ = 0.0;
  // SeesTwoPlanes' bounds, fixed by the options: the angle range (radians) and each plane's share.
  double crease_angle_ = options_.crease_angle_deg * M_PI / 180.0;
  double crease_max_angle_ = BlindCreaseAngle(options_.rank_threshold);
  double crease_share_ = SecondPlaneShare(options_.rank_threshold);
  double normal_spread_ = 0.0;  ///< the last Analyze's UnexplainedNormalSpread (0 with --rank-noise off)
};

SeedCloud ToCloud(const SeedState& s) {
  SeedCloud cloud;
  cloud.Resize(s.position.size());
  for (size_t i = 0; i < s.position.size(); ++i) {
    cloud.position[i] = s.position[i];
    cloud.normal[i] = s.normal[i];
    cloud.udf[i] = s.udf[i];
    cloud.rank[i] = static_cast<uint8_t>(s.rank[i].rank);
  }
  return cloud;
}

void CountRanks(const SeedState& s, OuterIterationReport& report) {
  double sum = 0.0;
  for (size_t i = 0; i < s.position.size(); ++i) {
    ++report.rank_count[std::clamp(s.rank[i].rank, 0, 3)];
    sum += std::abs(s.udf[i]);
  }
  report.mean_abs_udf = sum / static_cast<double>(s.position.size());
}

// Input seeds on the zero set, in input order, without exact duplicates (their repulsion has no direction);
// *twin_within: the twin separation their projection measured (common/projection.h).
SeedState Prepare(const Udf& udf, const SeedCloud& input, const ProjectionOptions& projection, Monitor& monitor,
                  double* twin_within) {
  if (input.size() < 2)
    throw InputError("input seeds", "has " + std::to_string(input.size()) + " seed(s); optimize-seeds needs at least 2");
  std::vector<size_t> order(input.size());
  std::iota(order.begin(), order.end(), 0);
  auto less = [&](size_t a, size_t b) {
    const Vec3 &p = input.position[a], &q = input.position[b];
    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<char> keep(input.size(), 1);
  for (size_t k = 1; k < order.size(); ++k)
    if (input.position[order[k]] == input.position[order[k - 1]]) keep[order[k]] = 0;
  std::vector<Vec3> points;
  for (size_t i = 0; i < input.size(); ++i)
    if (keep[i]) points.push_back(input.position[i]);
  if (points.size() < input.size())
    monitor.Warn(std::to_string(input.size() - points.size()) + " duplicate seeds dropped");
  if (points.size() < 2) throw InputError("input seeds", "fewer than 2 distinct seeds");

  ProjectionResult r = ProjectToZeroSet(udf, points, projection, monitor);
  SeedState s;
  *twin_within = r.twin_within;
  if (r.twin_within > 0.0)
    monitor.Info(TwinSheetsSummary(r, udf.Domain().Diagonal(), "seeds"));
  for (size_t i = 0; i < points.size(); ++i) {
    if (!r.converged[i]) continue;
    s.position.push_back(points[i]);
    s.udf.push_back(r.distance[i]);
    s.normal.push_back(r.gradient[i]);
  }
  if (s.position.size() < points.size())
    monitor.Warn(std::to_string(points.size() - s.position.size()) + " seeds dropped: projection onto the zero set did not converge");
  if (s.position.size() < 2) throw NumericalError("fewer than 2 seeds reached the surface of " + udf.Describe());
  s.rank.resize(s.position.size());
  s.space.resize(s.position.size());
  return s;
}

// Step 8 (docs/optimize-seeds.md, "Feature chains"): seeds added on the feature chains and the sheet seeds
// beside them dropped; keep_count: as many more crowded sheet seeds dropped as keep the count. No fill leaves
// more than max(before, (1 + kChainCountSlack) x n) seeds, n the input count.
struct ChainFill {
  size_t added = 0, dropped = 0;
};
ChainFill FillChains(Optimizer& opt, SeedState& s, const OptimizeSeedsOptions& options, size_t n, int rounds,
                     bool keep_count) {
  ChainFill fill;
  const double spacing = opt.MeanSpacing(s.position);
  const size_t before = s.position.size();
  const size_t most = std::max(before, static_cast<size_t>((1.0 + kChainCountSlack) * static_cast<double>(n)));
  fill.added = opt.RefineFeatureChains(s, options.feature_chord_tol * spacing, options.feature_gap_max * spacing,
                                       options.feature_clearance * spacing, rounds,
                                       keep_count ? std::numeric_limits<size_t>::max() : most);
  if (fill.added == 0) return fill;
  if (keep_count && s.position.size() > before) DropCrowdedSheetSeeds(s, s.position.size() - before);
  if (s.position.size() > most) {
    // Too few sheet seeds to give back (most seeds ranked as features): the last seeds added go again.
    // Dropped seeds keep their order, so the seeds added are still the last ones.
    std::vector<char> drop(s.position.size(), 0);
    std::fill(drop.begin() + static_cast<long>(most), drop.end(), 1);
    fill.added -= s.position.size() - most;
    EraseSeeds(s, drop);
  }
  fill.dropped = before + fill.added - s.position.size();
  opt.Analyze(s);
  return fill;
}

// One outer iteration (Alg. 1 lines 3-15): the chains filled first (not in the first iteration), the L1
// tangent step, then repulsion rounds until the delta rule or the cap. Fills report's sigma, energy,
// inner_rounds and max_inner_move.
void OuterIteration(Optimizer& opt, SeedState& s, const OptimizeSeedsOptions& options, const RepulsionOptions& repulsion,
                    int outer, bool chains, size_t n, OuterIterationReport& report, Monitor& monitor) {
  using Clock = std::chrono::steady_clock;
  Task task(monitor, "outer iteration " + std::to_string(outer), static_cast<uint64_t>(options.max_inner_iters + 1));
  // The chains filled before every outer iteration but the first, keeping the count: this iteration's L1
  // step and repulsion then spread the seeds around the added ones and over the dropped ones' holes.
  if (chains && outer > 1) {
    const ChainFill fill = FillChains(opt, s, options, n, kFeatureChainRoundsInLoop, true);
    monitor.Debug(std::to_string(fill.added) + " seeds added on feature chains, " + std::to_string(fill.dropped) +
                  " sheet seeds dropped");
  }
  // Alg. 1 line 3: the L1 tangent step, then back onto the zero set.
  const auto l1_t0 = Clock::now();
  const CellSamples cells = opt.Analyze(s);
  const auto l1_t1 = Clock::now();
  const std::vector<Vec3> before = s.position;
  std::vector<Vec3> stepped = opt.L1Step(s, cells);
  const auto l1_t2 = Clock::now();
  const double l1_move = opt.Project(s, before, std::move(stepped), 0.25 * opt.MeanSpacing(s.position));
  monitor.Debug(Format("  L1 times: cells %.3f s, solve %.3f s, projection %.3f s",
                       std::chrono::duration<double>(l1_t1 - l1_t0).count(),
                       std::chrono::duration<double>(l1_t2 - l1_t1).count(),
                       std::chrono::duration<double>(Clock::now() - l1_t2).count()));
  task.Advance();
  // Lines 4–15: the kernel width, then repulsion rounds. σ is computed right after the first round's
  // cells, so that the movable/fixed split it depends on is the one the round uses.
  double previous_gradient = -1.0;
  for (int inner = 1; inner <= options.max_inner_iters; ++inner) {
    const auto t0 = Clock::now();
    if (inner == 1 || options.repulsion_cells == "every") {
      opt.Analyze(s, true);
    } else {
      opt.FollowTangentPlanes(s);
    }
    if (inner == 1) {
      report.sigma = opt.KernelWidth(s);
      if (!std::isfinite(report.sigma)) break;  // every seed is fixed: nothing to repel
    }
    const auto t1 = Clock::now();
    const NeighbourLists neighbours = opt.RepulsionNeighbours(s.position, options.repulsion_cutoff * report.sigma);
    const RepulsionResult r = MinimizeRepulsion(s.position, s.space, neighbours, report.sigma, repulsion);
    const auto t2 = Clock::now();
    const std::vector<Vec3> previous = s.position;
    report.max_inner_move = std::max(report.max_inner_move, opt.Project(s, previous, r.positions, 0.5 * report.sigma));
    const auto t3 = Clock::now();
    monitor.Debug(Format("  times: cells %.3f s, repulsion %.3f s, projection %.3f s",
                         std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count(),
                         std::chrono::duration<double>(t3 - t2).count()));
    report.energy = RepulsionEnergy(s.position, neighbours, report.sigma, nullptr);
    report.inner_rounds = inner;
    task.Advance();
    monitor.Debug(Format("  inner %.0f: energy %.6g -> %.6g, projected gradient %.4g, %.0f L-BFGS iterations",
                         inner, r.initial_energy, report.energy, r.initial_gradient_norm, r.iterations));
    const double g = r.initial_gradient_norm;
    // δ rule (Alg. 1 line 15): the gradient's relative decrease from the previous round is below δ. On
    // the cells' random samples the gradient settles at a noise floor rather than at a fixed value, so
    // a round that does not lower it (a signed, not an absolute change) also ends the loop.
    const bool settled = previous_gradient >= 0.0 && previous_gradient - g <= options.delta * previous_gradient;
    previous_gradient = g;
    if (g == 0.0 || settled) break;
  }
  task.Advance(static_cast<uint64_t>(options.max_inner_iters - report.inner_rounds));
  monitor.Debug(Format("L1 step moved seeds up to %.3g (relative)", l1_move / opt.diagonal()));
}

// Last L1 steps: repulsion moves a seed on a curved feature (a circle) along its tangent, and projection
// brings it back to the surface but not exactly onto the feature. Only seeds whose cells see a feature
// (rank ≥ 2) take them: a sheet seed beside an edge would otherwise be pulled onto the edge next to the
// seeds already there, undoing the last repulsion's spacing (fandisk 3k: spacing CV 0.26 -> 0.31 with
// every seed, see docs). More than one: a seed whose cell sees the second sheet only after the first step
// (rank 1 -> 2) gets onto the curve in the next (crossing-planes and sphere-disc, 25 runs: seeds left
// 0.003–0.007 off the curve with one step, none with three).
// Step 7 as a function of the state: run again after step 8 (below).
// A sheet seed beside a curve may see the second sheet only once its neighbours have stepped (rank 1 -> 2
// at a later analysis) and would end ranked as a feature but off it (sphere-disc, 200 seeds: 0.35
// spacings off the equator): the steps go on, kFeatureExtraSteps at most, while some feature seed's step
// would move it more than kFeatureSettledMove spacings.
// With `around` (the seeds added by step 8), only the seeds within kSettleReach spacings of one of them
// step: the others' cells are as the first settling left them.
size_t SettleFeatures(Optimizer& opt, SeedState& s, const OptimizeSeedsOptions& options, bool chains,
                      const std::vector<Vec3>* around) {
  size_t crowded = 0;
  const int steps = options.max_outer_iters > 0 ? options.feature_steps : 0;
  const int most = steps > 0 ? steps + (chains ? kFeatureExtraSteps : 0) : 0;
  std::unique_ptr<SeedIndex> around_index;
  if (around && !around->empty()) around_index = std::make_unique<SeedIndex>(*around);
  std::vector<char> movers;
  std::vector<int> near;
  for (int step = 0;; ++step) {
    const CellSamples cells = opt.Analyze(s);
    std::vector<double> misfit;
    std::vector<Vec3> targets;
    bool move = step < most;
    if (move && around_index) {
      const double reach = kSettleReach * opt.MeanSpacing(s.position);
      movers.assign(s.position.size(), 0);
      for (size_t i = 0; i < s.position.size(); ++i) {
        around_index->WithinRadius(s.position[i], reach, near);
        movers[i] = !near.empty();
      }
    }
    if (move) targets = opt.L1Step(s, cells, true, &misfit, around_index ? &movers : nullptr);
    if (move && step >= steps) {
      const double settled = kFeatureSettledMove * opt.MeanSpacing(s.position);
      move = false;
      for (size_t i = 0; i < targets.size() && !move; ++i) move = (targets[i] - s.position[i]).norm() > settled;
    }
    if (!move) {
      // The ranks at the final positions; then the seeds crowding a higher-ranked feature seed there.
      if (options.feature_clearance > 0.0) crowded += opt.DropCrowded(s, cells);
      return crowded;
    }
    // Seeds whose steps meet are thinned before the move (the better fitting target stays): otherwise two
    // corner seeds both step onto one corner, Project undoes both moves as too near, and neither reaches it.
    if (options.feature_clearance > 0.0) {
      crowded += ThinCrowded(s, targets, misfit, options.feature_clearance * opt.MeanSpacing(s.position), &targets);
    }
    const std::vector<Vec3> before = s.position;
    opt.Project(s, before, std::move(targets), 0.25 * opt.MeanSpacing(s.position));
  }
}

}  // namespace

SeedCloud OptimizeSeeds(const Udf& udf, const SeedCloud& input, const OptimizeSeedsOptions& options, Monitor& monitor,
                        const std::function<void(const OuterIterationReport&, const SeedCloud&)>& on_iteration) {
  options.Check();
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  Optimizer opt(udf, options, monitor);
  double twin_within = 0.0;
  SeedState s = Prepare(udf, input, opt.projection(), monitor, &twin_within);
  opt.SetTwinWithin(twin_within);
  const size_t n = s.position.size();
  const auto [spacing_in, cv_in] = opt.SpacingStats(s.position);
  // Buckets of 1.5 spacings: a cell's ball (radius ~0.8 spacing) meets 8-27, whose points are scanned in one
  // stream each; smaller buckets cover the ball more tightly but cost more per bucket than they save.
  if (options.cell_samples == "pool") opt.UsePool(1.5 * spacing_in);
  monitor.Info(std::to_string(n) + " seeds on the surface; domain diagonal " + Format("%.6g", opt.diagonal()) +
               Format("; spacing CV %.3f", cv_in));

  RepulsionOptions repulsion;
  repulsion.max_iterations = options.lbfgs_max_iters;
  repulsion.max_step = options.max_step;
  const bool chains = (options.feature_chord_tol > 0.0 || options.feature_gap_max > 0.0) && options.max_outer_iters > 0;
  double previous_sigma = 0.0, previous_cv = cv_in;
  for (int outer = 1; outer <= options.max_outer_iters; ++outer) {
    const auto outer_start = Clock::now();
    OuterIterationReport report;
    report.iteration = outer;
    OuterIteration(opt, s, options, repulsion, outer, chains, n, report, monitor);
    CountRanks(s, report);
    report.spacing_cv = opt.SpacingStats(s.position).second;
    report.seconds = std::chrono::duration<double>(Clock::now() - outer_start).count();
    monitor.Info(Format("outer %.0f: sigma %.4g (rel), energy %.6g, mean |udf| %.3g (rel), %.0f inner rounds, ",
                        outer, report.sigma / opt.diagonal(), report.energy, report.mean_abs_udf / opt.diagonal(),
                        report.inner_rounds) +
                 "ranks 0/1/2/3: " + std::to_string(report.rank_count[0]) + "/" + std::to_string(report.rank_count[1]) +
                 "/" + std::to_string(report.rank_count[2]) + "/" + std::to_string(report.rank_count[3]) +
                 Format(", spacing CV %.3f, cell acceptance %.2f, normal spread %.3f, %.2f s", report.spacing_cv,
                        opt.last_acceptance(), opt.normal_spread(), report.seconds));
    if (on_iteration) on_iteration(report, ToCloud(s));
    if (report.max_inner_move <= options.move_tol * report.sigma) {
      monitor.Info("converged: the inner loop made no update");
      break;
    }
    // "No update" in the spacing: σ did not grow (the spreading is not still opening up) and the spacing CV
    // dropped by less than outer_tol relatively.
    if (outer > 1 && report.sigma <= previous_sigma * (1.0 + options.outer_tol) &&
        report.spacing_cv >= previous_cv * (1.0 - options.outer_tol)) {
      monitor.Info(Format("converged: the spacing no longer improves (CV %.3f -> %.3f)", previous_cv, report.spacing_cv));
      break;
    }
    previous_sigma = report.sigma;
    previous_cv = report.spacing_cv;
  }
  size_t crowded = SettleFeatures(opt, s, options, chains, nullptr);
  const auto [spacing_out, cv_out] = opt.SpacingStats(s.position);
  if (crowded > 0)
    monitor.Info(std::to_string(crowded) + Format(" seeds dropped by the feature-seed thinning (nearer than %.2f x the "
                                                  "mean spacing to a kept curve or corner seed)", options.feature_clearance));
  // The chains filled once more at the final positions, so that the invariant holds for the output. The
  // added seeds change their neighbours' cells: a sheet seed beside a crossing may see the second sheet
  // only now (rank 1 -> 2), so step 7 runs again and every seed ranked as a feature ends on its feature.
  if (chains) {
    const ChainFill fill = FillChains(opt, s, options, n, kFeatureChainRounds, false);
    if (fill.added > 0) {
      const std::vector<Vec3> added(s.position.end() - static_cast<long>(fill.added), s.position.end());
      const size_t settled = SettleFeatures(opt, s, options, chains, &added);
      monitor.Info(std::to_string(fill.added) + " seeds added on feature chains (" +
                   (options.feature_gap_max > 0.0 ? (options.feature_chord_tol > 0.0 ? "gaps, ends, bends" : "gaps, ends")
                                                  : "bends") +
                   "); " + std::to_string(fill.dropped) + " sheet seeds beside them dropped, " +
                   std::to_string(settled) + " by the feature-seed thinning after the last feature steps");
    }
  }
  if (const SamplePool* pool = opt.pool())
    monitor.Info("sample pool: " + std::to_string(pool->points()) + " points in " + std::to_string(pool->buckets()) +
                 " cubes, " + std::to_string(pool->evaluated()) + " with UDF values, " +
                 Format("%.0f MB", static_cast<double>(pool->bytes()) / 1e6));
  OuterIterationReport final_report;
  CountRanks(s, final_report);
  monitor.Info(Format("done in %.2f s; mean |udf| %.3g (rel); spacing CV %.3f -> %.3f; ",
                      std::chrono::duration<double>(Clock::now() - start).count(), final_report.mean_abs_udf / opt.diagonal(),
                      cv_in, cv_out) +
               "ranks 0/1/2/3: " + std::to_string(final_report.rank_count[0]) + "/" +
               std::to_string(final_report.rank_count[1]) + "/" + std::to_string(final_report.rank_count[2]) + "/" +
               std::to_string(final_report.rank_count[3]));
  return ToCloud(s);
}

}  // namespace voroudf

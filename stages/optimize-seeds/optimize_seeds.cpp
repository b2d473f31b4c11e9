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
#include "stages/optimize-seeds/optimizer.h"
#include "stages/optimize-seeds/repulsion.h"
#include "stages/optimize-seeds/seed_index.h"
#include "stages/optimize-seeds/voronoi_cells.h"

namespace voroudf {

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
  if (sample_planes != "gradient" && sample_planes != "fit" && sample_planes != "auto")
    throw UsageError("--sample-planes must be gradient, fit or auto");
  if (!(pool_layers >= 1 && pool_layers <= 64)) throw UsageError("--pool-layers must be in [1, 64]");
  if (!(sigma_max_spacing >= 0.0 && sigma_max_spacing <= 10.0)) throw UsageError("--sigma-max-spacing must be in [0, 10]");
  if (!(sigma_min_spacing >= 0.0 && sigma_min_spacing <= 10.0)) throw UsageError("--sigma-min-spacing must be in [0, 10]");
  if (!(feature_clearance >= 0.0 && feature_clearance <= 1.0)) throw UsageError("--feature-clearance must be in [0, 1]");
  if (!(curve_separation >= 0.0 && curve_separation <= 2.0)) throw UsageError("--curve-separation must be in [0, 2]");
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
// A chain fill leaves at most this share more seeds than the input count (or the count before the fill, if
// more), so --count stays the output size within a few percent: the fills before outer iterations give
// back crowded sheet seeds, and where there are too few (most seeds ranked as features: feature-dense
// parts, or gradient errors of 30° that make the rank test take sheets for curves) the last added go; the
// last fill, which gives back none, stops there.
constexpr double kChainCountSlack = 0.02;

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
// *twin_within: the twin separation their projection measured (common/projection.h), *twins_seen: whether it
// moved at least kTwinMinFloorShare of them to a ridge between twin sheets; *value_tilt: how far
// the field's value errors tilt its zero set, from the seeds that stopped at a floor or ridge (ValueErrorTilt).
SeedState Prepare(const Udf& udf, const SeedCloud& input, const ProjectionOptions& projection, Monitor& monitor,
                  double* twin_within, bool* twins_seen, double* value_tilt) {
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
  *twins_seen = static_cast<double>(r.num_merged) >= kTwinMinFloorShare * static_cast<double>(r.num_converged);
  if (r.twin_within > 0.0)
    monitor.Info(TwinSheetsSummary(r, udf.Domain().Diagonal(), "seeds"));
  std::vector<Vec3> at_floor;
  std::vector<double> floor;
  for (size_t i = 0; i < points.size(); ++i)
    if (r.converged[i] && r.distance[i] >= projection.tolerance) at_floor.push_back(points[i]), floor.push_back(r.distance[i]);
  *value_tilt = ValueErrorTilt(at_floor, floor);
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
  const CellSamples& cells = opt.Analyze(s);
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
    monitor.Debug(Format("  inner %d: energy %.6g -> %.6g, projected gradient %.4g, %d L-BFGS iterations",
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
    const CellSamples& cells = opt.Analyze(s);
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
      const double spacing = opt.MeanSpacing(s.position);
      crowded += ThinCrowded(s, targets, misfit, options.feature_clearance * spacing, opt.TwoCurveTest(spacing),
                             &targets);
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
  double twin_within = 0.0, value_tilt = 0.0;
  bool twins_seen = false;
  SeedState s = Prepare(udf, input, opt.projection(), monitor, &twin_within, &twins_seen, &value_tilt);
  opt.SetTwinWithin(twin_within, twins_seen);
  opt.SetValueErrorTilt(value_tilt);
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
    monitor.Info(Format("outer %d: sigma %.4g (rel), energy %.6g, mean |udf| %.3g (rel), %d inner rounds, ",
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

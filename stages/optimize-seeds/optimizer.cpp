#include "stages/optimize-seeds/optimizer.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "stages/optimize-seeds/seed_index.h"

namespace voroudf {
namespace {
// SeesTwoPlanes' contrast: between a uniform spread's 3.46 (one curved sheet) and the > 9 of two planes.
constexpr double kCreaseContrast = 6.0;
// NormalsMeetOnOneAxis' residual: a tube's normal lines meet its axis exactly with exact gradients; a
// crease's face samples miss any common point by a good part of the spread.
constexpr double kCurvedSheetResidual = 0.2;
}  // namespace

double Optimizer::Project(SeedState& s, const std::vector<Vec3>& previous, std::vector<Vec3> moved, double min_separation) {
  const size_t n = moved.size();
  std::vector<Vec3> targets;  // kept for the rule below only
  if (centre_twin_planes_) targets = moved;
  ProjectionResult r = ProjectToZeroSet(udf_, moved, projection_, Monitor::Null());
  // Where the field shows twins, a curve or corner seed's target is where the centred planes cross: the edge as
  // both sides of the field see it. Projecting it puts it on a twin sheet |e| out (the cylinder round the edge),
  // from where the twin merge along a gradient that an error tilts may not come back. So such a seed whose
  // target reads at most the largest error the floors show (0.4 x the twin separation: between the twins)
  // stays at its target.
  if (centre_twin_planes_) {
    std::vector<size_t> idx;
    std::vector<Vec3> at;
    for (size_t i = 0; i < n && i < s.rank.size(); ++i)
      if (s.rank[i].rank >= 2 && r.converged[i]) idx.push_back(i), at.push_back(targets[i]);
    std::vector<double> d;
    std::vector<Vec3> g;
    if (!at.empty()) udf_.Evaluate(at, d, g);
    for (size_t k = 0; k < idx.size(); ++k)
      if (d[k] <= 0.4 * projection_.twin_within) {
        moved[idx[k]] = at[k];
        r.distance[idx[k]] = d[k];
        r.gradient[idx[k]] = g[k];
      }
  }
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

const CellSamples& Optimizer::Analyze(SeedState& s, bool early) {
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
    CarryCells(s.position, cell_options, cached_cells_, cached_positions_, &cell_buffers_.spare);
  CellSamples next = SampleVoronoiCells(udf_, s.position, index, cell_options, options_.seed, round_++,
                                        cached_positions_.empty() ? nullptr : &cached_cells_, &cached_positions_,
                                        &cell_buffers_);
  cell_buffers_.spare = std::move(cached_cells_);
  cached_cells_ = std::move(next);
  cached_positions_ = s.position;
  // The cache keeps the field's own values and gradients (a kept cell is fitted afresh): sample planes are
  // changed on a copy. Without them the cache is the result, and megabytes are not copied on one thread.
  const bool planes_change = fit_planes_ != 0 || centre_twin_planes_;
  if (planes_change) planed_cells_ = cached_cells_;
  CellSamples& cells = planes_change ? planed_cells_ : cached_cells_;
  if (fit_planes_ != 0) {
    SamplePlanes planes = FitSamplePlanes(cells, SamplePlaneFit{});
    gradient_error_ = planes.median_angle;
    if (fit_planes_ < 0) {
      fit_planes_ = FitPaysOff(gradient_error_, value_tilt_, options_.sample_planes_auto_deg * M_PI / 180.0) ? 1 : 0;
      monitor_.Info(Format("gradients %.1f deg off the planes of their foot points (median), value errors tilt "
                           "the zero set %.1f deg: %s", gradient_error_ * 180.0 / M_PI, value_tilt_ * 180.0 / M_PI,
                           fit_planes_ ? "sample planes fitted" : "sample planes from the gradients"));
    }
    if (fit_planes_ > 0) UseSamplePlanes(cells, planes);
    monitor_.Debug(Format("sample planes: gradients %.2f deg off (median)", gradient_error_ * 180.0 / M_PI));
  }
  if (centre_twin_planes_)
    CenterTwinPlanes(cells, projection_.twin_within, projection_.tolerance, fit_planes_ > 0);
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
    else if (r.rank == 2 && options_.curved_sheets && NormalsMeetOnOneAxis(cells.point.data() + cells.sample_offset[i],
                                                 cells.distance.data() + cells.sample_offset[i],
                                                 cells.gradient.data() + cells.sample_offset[i],
                                                 cells.sample_offset[i + 1] - cells.sample_offset[i], r,
                                                 kCurvedSheetResidual))
      r.rank = 1;
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
  last_short_cells_ = cells.short_cells;
  if (cells.draws) last_acceptance_ = static_cast<double>(cells.drawn_samples) / static_cast<double>(cells.draws);
  monitor_.Debug("cells: " + std::to_string(cells.redrawn) + " of " + std::to_string(n) + " redrawn, " +
                 std::to_string(cells.early_cells) + " of them with their early samples only, " +
                 std::to_string(cells.reused) + " samples' UDF values reused");
  return cells;
}

void Optimizer::FollowTangentPlanes(SeedState& s) const {
  for (size_t i = 0; i < s.position.size(); ++i) {
    if (s.space[i].dim != 2 || s.normal[i].squaredNorm() < 0.25) continue;
    const MoveSpace own = OwnTangentPlane(s.normal[i]);
    if (own.dim == 2) s.space[i].basis = own.basis;
  }
}

MoveSpace Optimizer::OwnTangentPlane(const Vec3& normal) const {
  const TangentRank own = ComputeTangentRank(&normal, 1, options_.rank_threshold);
  MoveSpace space;
  space.dim = own.rank == 1 ? 2 : 0;
  space.basis.leftCols<2>() = own.v.rightCols<2>();
  return space;
}

std::vector<Vec3> Optimizer::L1Step(const SeedState& s, const CellSamples& cells, bool features_only,
                         std::vector<double>* misfit_at_target, const std::vector<char>* movers) {
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
  monitor_.Debug(Format("L1 step: %.1f interior-point iterations per seed on average", mean_sweeps));
  if (failed > 0)
    monitor_.Debug(std::to_string(failed) + " L1 steps hit --l1-max-steps before the gap certificate "
                   "(their best feasible point is used)");
  return moved;
}

size_t Optimizer::RefineFeatureChains(SeedState& s, double bend_tol, double max_gap, double clearance, int rounds,
                           size_t max_count) {
  const size_t n0 = s.position.size();
  size_t added = 0, last_added = 0;
  const double spacing = MeanSpacing(s.position);
  for (int round = 0; round < rounds; ++round) {
    Analyze(s);
    const size_t n = s.position.size();
    const std::vector<Vec3> tangent = Tangents(s);
    const TwoCurves two_curves = TwoCurveTest(spacing);
    const FeatureLinks links = FindFeatureLinks(s, tangent, kFeatureLinkRadius * spacing, two_curves);
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
    const CellSamples& cells = Analyze(trial);
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
      if (crowd_radius < 0.0 ||
          Crowded(s, n, index, landed[t], rank, std::max(crowd_radius, clearance), spacing, t_new, tangent,
                  two_curves) ||
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

double Optimizer::KernelWidth(const SeedState& s) const {
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

size_t Optimizer::DropCrowded(SeedState& s, const CellSamples& cells) const {
  std::vector<double> misfit(s.position.size());
  for (size_t i = 0; i < misfit.size(); ++i) misfit[i] = TangentMisfit(cells, i, s.position[i]);
  const double spacing = MeanSpacing(s.position);
  return ThinCrowded(s, s.position, misfit, options_.feature_clearance * spacing, TwoCurveTest(spacing));
}

std::pair<double, double> Optimizer::SpacingStats(const std::vector<Vec3>& positions) const {
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

NeighbourLists Optimizer::RepulsionNeighbours(const std::vector<Vec3>& positions, double radius) const {
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

void Optimizer::UsePool(double bucket_size) {
  pool_ = std::make_unique<SamplePool>(options_.seed, bucket_size, options_.pool_layers);
  cell_options_.pool = pool_.get();
}

}  // namespace voroudf

#include "common/projection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "common/errors.h"

namespace voroudf {

ProjectionOptions RelativeProjection(double diagonal, double tol_rel, double floor_rel, int max_iterations) {
  ProjectionOptions options;
  options.tolerance = tol_rel * diagonal;
  options.floor_tolerance = floor_rel * diagonal;
  options.max_iterations = max_iterations;
  return options;
}

void CheckRelativeProjection(double tol_rel, double floor_rel, int max_iterations, double twin_factor) {
  if (!(tol_rel > 0.0 && tol_rel < 0.1)) throw UsageError("--proj-tol-rel must be in (0, 0.1)");
  if (!(floor_rel >= 0.0 && floor_rel < 0.1)) throw UsageError("--proj-floor-rel must be in [0, 0.1)");
  if (max_iterations < 1) throw UsageError("--proj-max-iters must be at least 1");
  if (!(twin_factor >= 0.0 && twin_factor <= 10.0)) throw UsageError("--proj-twin-factor must be in [0, 10]");
}

double EstimateTwinWithin(const ProjectionResult& result, double tolerance, double factor) {
  if (!(factor > 0.0)) return 0.0;
  std::vector<double> floors;
  for (size_t i = 0; i < result.converged.size(); ++i)
    if (result.converged[i] && result.distance[i] >= tolerance) floors.push_back(result.distance[i]);
  if (floors.size() < 16 || static_cast<double>(floors.size()) < kTwinMinFloorShare * static_cast<double>(result.num_converged))
    return 0.0;
  const size_t q = static_cast<size_t>(0.99 * static_cast<double>(floors.size() - 1));
  std::nth_element(floors.begin(), floors.begin() + static_cast<long>(q), floors.end());
  return factor * floors[q];
}

namespace {

// Probes at three distances: a tilted gradient reads a probe short by r (1 - cos tilt), so a probe at r
// tells twins apart only beyond 0.13 r; the near ones find the close twins, the far one the rest.
constexpr std::array<double, 3> kScales = {0.25, 0.5, 1.0};

// A kink before the near probe (MergeTwinSheets' second rule): the field there no longer rises at 1 and its
// gradient along the line, slope, is at most 0.3 (past a sheet it reads about +1) and at least -0.75 (a fall
// at about 1 is a ridge between two sheets, the twin rule's to take or leave: where it fails, as between the
// two faces of a wall thinner than `within`, this rule must not take it either); with a_p = 1 for now, the kink
// is where the rise from the point meets the line through the probe at that slope. Returns its distance, or -1.
double KinkBeforeProbe(double f, double slope, double r, double tolerance) {
  if (!(f < std::cos(M_PI / 6.0) * r && slope <= 0.3 && slope >= -0.75)) return -1.0;
  const double s = (f - slope * r) / (1.0 - slope);
  return s > 8.0 * tolerance && s < r ? s : -1.0;
}

// MergeTwinSheets' second rule, for the probed points (`probed`, unit gradients `dir`, probe values pd, pg) that
// found no twin (`best` empty): where a side's near probe shows a kink before it (KinkBeforeProbe), one more
// value halfway to the kink measures the rise a_p (within [0.5, 1.5], and a_p - slope >= 0.7: a kink, not a
// bend), and the point goes to the kink, nearer side first, appended to moved / target.
void KinksWithoutTwins(const Udf& udf, const std::vector<Vec3>& points, const std::vector<size_t>& probed,
                       const std::vector<Vec3>& dir, const std::vector<double>& pd, const std::vector<Vec3>& pg,
                       const std::vector<size_t>& best, double tolerance, double within, std::vector<size_t>& moved,
                       std::vector<Vec3>& target, std::vector<double>& top) {
  struct Kink { size_t k; Vec3 v; double s, slope, reach; };  // reach: the probe's line at 0, f - slope r
  std::vector<Kink> kinks;
  std::vector<Vec3> halfway;
  // The near probe only: kinks farther out (the middle probe's) merged the faces of thin walls at value error
  // 3e-3 (TD 34 -> 56 on six CAD shapes) for 4 % of CD at 1e-3.
  const double r = kScales[0] * within;
  for (size_t k = 0; k < probed.size(); ++k) {
    if (best[k] != SIZE_MAX) continue;
    for (int side = 0; side < 2; ++side) {
      const Vec3 v = side == 0 ? dir[k] : Vec3(-dir[k]);
      const size_t j = kScales.size() * k * 2 + static_cast<size_t>(side);
      const double slope = pg[j].dot(v), s = KinkBeforeProbe(pd[j], slope, r, tolerance);
      if (s < 0.0) continue;
      kinks.push_back({k, v, s, slope, pd[j] - slope * r});
      halfway.push_back(points[probed[k]] + 0.5 * s * v);
    }
  }
  if (kinks.empty()) return;
  std::vector<double> d;
  std::vector<Vec3> g;
  udf.Evaluate(halfway, d, g);
  std::vector<size_t> chosen(probed.size(), SIZE_MAX);
  std::vector<double> at(kinks.size(), -1.0), rise(kinks.size(), 0.0);
  for (size_t c = 0; c < kinks.size(); ++c) {
    const Kink& kink = kinks[c];
    rise[c] = d[c] / (0.5 * kink.s);  // a_p
    if (!(rise[c] >= 0.5 && rise[c] <= 1.5 && rise[c] - kink.slope >= 0.7)) continue;
    at[c] = kink.reach / (rise[c] - kink.slope);  // where the rise meets the probe's line
    if (!(at[c] > 8.0 * tolerance && at[c] < r)) continue;
    size_t& b = chosen[kink.k];
    if (b == SIZE_MAX || at[c] < at[b]) b = c;
  }
  for (size_t k = 0; k < probed.size(); ++k)
    if (chosen[k] != SIZE_MAX) {
      const size_t c = chosen[k];
      moved.push_back(probed[k]);
      target.push_back(points[probed[k]] + at[c] * kinks[c].v);
      top.push_back(rise[c] * at[c]);
    }
}

}  // namespace

void MergeTwinSheets(const Udf& udf, std::vector<Vec3>& points, ProjectionResult& result, double tolerance,
                     double within) {
  std::vector<size_t> probed;
  std::vector<Vec3> probes, dir;
  for (size_t i = 0; i < points.size(); ++i) {
    // Points at a floor too: a step that ends just past a zero sheet (the error varies along it) converges at
    // that V's bottom. A real floor (e > 0) reads within + e on both sides and stays.
    if (!result.converged[i] || result.gradient[i].squaredNorm() < 0.25) continue;
    const Vec3 u = result.gradient[i].normalized();
    probed.push_back(i);
    dir.push_back(u);
    for (double scale : kScales) {
      probes.push_back(points[i] + scale * within * u);
      probes.push_back(points[i] - scale * within * u);
    }
  }
  if (probed.empty()) return;
  std::vector<double> pd, d;
  std::vector<Vec3> pg, g;
  udf.Evaluate(probes, pd, pg);
  // A probe counts when it read less than within cos 30° with its gradient within 60° of its own direction (near
  // an edge the line crosses the twin sheet obliquely).
  // Every such probe is a candidate, not just the nearest: where the error varies along the normal the field
  // rises slower than 1 on one side, and a probe there passes the test although no twin lies beyond it; its
  // projection comes back to the point itself. So each candidate's twin is found and checked, and the nearest
  // one that checks out wins.
  const double passed = std::cos(M_PI / 6.0), onward = std::cos(M_PI / 3.0);
  std::vector<size_t> owner;  // per candidate: index into probed
  std::vector<Vec3> twin_at;  // per candidate: its probe, then the twin it projects to
  for (size_t k = 0; k < probed.size(); ++k)
    for (size_t scale = 0; scale < kScales.size(); ++scale)
      for (int side = 0; side < 2; ++side) {
        const size_t j = (kScales.size() * k + scale) * 2 + static_cast<size_t>(side);
        const double r = kScales[scale] * within;
        const Vec3 v = side == 0 ? dir[k] : Vec3(-dir[k]);
        if (!std::isfinite(pd[j]) || !(pd[j] < passed * r) || pg[j].dot(v) < onward * pg[j].norm()) continue;
        owner.push_back(k);
        twin_at.push_back(probes[j]);
      }
  // The twin itself, from that probe: where its own error puts it, not where the probe's error said.
  ProjectionOptions to_twin;
  to_twin.tolerance = tolerance;
  to_twin.max_iterations = 8;
  const ProjectionResult twin = ProjectToZeroSet(udf, twin_at, to_twin, Monitor::Null());
  std::vector<double> separation(owner.size(), -1.0);  // -1: no twin
  std::vector<size_t> quarter_at(owner.size(), SIZE_MAX);  // per candidate with a twin: its quarter points
  std::vector<Vec3> quarters;
  for (size_t c = 0; c < owner.size(); ++c) {
    const Vec3& p = points[probed[owner[c]]];
    const double t = (twin_at[c] - p).norm();
    // Closer than 8 tolerances may be the point's own sheet: a converged point lies within a tolerance over the
    // field's slope of it, on either side, and the slopes below are not measurable there.
    if (!(twin.converged[c] && t < within && t > 8.0 * tolerance)) continue;
    separation[c] = t;
    quarter_at[c] = quarters.size();
    quarters.push_back(p + 0.25 * (twin_at[c] - p));
    quarters.push_back(p + 0.75 * (twin_at[c] - p));
  }
  // Between the sheets |d + e| = |e| - d rises from each sheet to a kink on the surface (d = 0), at slopes
  // 1 -+ the error's own slope along the line. The quarter points measure both slopes a_p, a_t; where both are
  // within [0.5, 1.5] it is a ridge, and its top, where the two lines meet, is at s = a_t t / (a_p + a_t) from
  // the point: the surface itself for an error linear along the line (the midpoint is off by e's slope x t/2).
  if (!quarters.empty()) udf.Evaluate(quarters, d, g);
  std::vector<Vec3> ridge(owner.size());
  std::vector<size_t> best(probed.size(), SIZE_MAX);
  for (size_t c = 0; c < owner.size(); ++c) {
    const double t = separation[c];
    if (!(t > 0.0)) continue;
    const double a_p = d[quarter_at[c]] / (0.25 * t), a_t = d[quarter_at[c] + 1] / (0.25 * t);
    if (!(a_p >= 0.5 && a_p <= 1.5 && a_t >= 0.5 && a_t <= 1.5)) continue;  // not a ridge
    const Vec3& p = points[probed[owner[c]]];
    ridge[c] = p + (a_t / (a_p + a_t)) * (twin_at[c] - p);
    size_t& b = best[owner[c]];
    if (b == SIZE_MAX || t < separation[b]) b = c;
  }
  std::vector<size_t> moved;
  std::vector<Vec3> target;
  std::vector<double> top;  // the value a kink's top should read (NaN: a twin's ridge)
  for (size_t k = 0; k < probed.size(); ++k)
    if (best[k] != SIZE_MAX) moved.push_back(probed[k]), target.push_back(ridge[best[k]]), top.push_back(NAN);
  KinksWithoutTwins(udf, points, probed, dir, pd, pg, best, tolerance, within, moved, target, top);
  if (moved.empty()) return;
  udf.Evaluate(target, d, g);
  for (size_t k = 0; k < moved.size(); ++k) {
    // A kink's top reads what the rise predicts; a level stretch (the field clipped) reads less: no kink.
    if (std::isfinite(top[k]) && !(d[k] >= 0.75 * top[k] && d[k] <= 1.25 * top[k])) continue;
    points[moved[k]] = target[k];
    result.distance[moved[k]] = d[k];
    result.gradient[moved[k]] = g[k];
    ++result.num_merged;
  }
}

std::string TwinSheetsSummary(const ProjectionResult& result, double diagonal, const std::string& what) {
  char line[200];
  std::snprintf(line, sizeof line, "the field has a floor: zero sheets within %.3g (%.3g x diagonal) taken for one, %zu ",
                result.twin_within, result.twin_within / diagonal, result.num_merged);
  return line + what + " moved to the ridge between them";
}

ProjectionResult ProjectToZeroSet(const Udf& udf, std::vector<Vec3>& points, const ProjectionOptions& options,
                                  Monitor& monitor) {
  const size_t n = points.size();
  ProjectionResult result;
  result.converged.assign(n, 0);
  result.distance.assign(n, INFINITY);
  result.gradient.assign(n, Vec3::Zero());
  const Box domain = udf.Domain();
  const double escape = domain.Diagonal();

  std::vector<size_t> active(n);
  for (size_t i = 0; i < n; ++i) active[i] = i;
  // Per point: the gradient its last ordinary step followed (zero before the first), and whether the last
  // move went to a kink's bottom.
  std::vector<Vec3> stepped_along(n, Vec3::Zero());
  std::vector<double> step_length(n, 0.0);  // of the last ordinary step
  std::vector<char> at_kink(n, 0);
  std::vector<Vec3> batch;
  std::vector<double> d;
  std::vector<Vec3> g;
  // Iteration 0 only evaluates; iterations 1..max_iterations each take one step.
  // Every point's step is its own: the loops run on every thread (on one, they were a tenth of build-gvd's
  // serial time), and which points go on is kept in order.
  std::vector<char> moving;
  for (int iter = 0; iter <= options.max_iterations && !active.empty(); ++iter) {
    batch.resize(active.size());
#pragma omp parallel for schedule(static)
    for (long k = 0; k < static_cast<long>(active.size()); ++k) batch[static_cast<size_t>(k)] = points[active[static_cast<size_t>(k)]];
    udf.Evaluate(batch, d, g);
    moving.assign(active.size(), 0);
    size_t at_floor_count = 0;
#pragma omp parallel for schedule(static) reduction(+ : at_floor_count)
    for (long lk = 0; lk < static_cast<long>(active.size()); ++lk) {
      const size_t k = static_cast<size_t>(lk), i = active[k];
      result.distance[i] = d[k];
      result.gradient[i] = g[k];
      // A kink's bottom found from a step much longer than its value is refined by one more bracket: the
      // bottom lies where both sides' values meet, and the field's error varies along a long step.
      const bool at_floor = at_kink[i] && d[k] < options.floor_tolerance &&
                            (step_length[i] <= 4.0 * d[k] || g[k].squaredNorm() < 0.25);
      if (d[k] < options.tolerance || at_floor) {
        result.converged[i] = 1;
        at_floor_count += d[k] >= options.tolerance;
        continue;
      }
      if (iter == options.max_iterations || !std::isfinite(d[k]) || g[k].squaredNorm() < 0.25) continue;
      if (!at_kink[i] && options.floor_tolerance > 0 && g[k].dot(stepped_along[i]) < 0) {
        points[i] += 0.5 * d[k] * stepped_along[i];  // back to the kink's bottom (see the header)
        at_kink[i] = 1;
      } else {
        points[i] -= d[k] * g[k];
        stepped_along[i] = g[k];
        step_length[i] = d[k] * g[k].norm();
        at_kink[i] = 0;
      }
      moving[k] = domain.Contains(points[i], escape);
    }
    result.num_at_floor += at_floor_count;
    std::vector<size_t> still;
    for (size_t k = 0; k < active.size(); ++k)
      if (moving[k]) still.push_back(active[k]);
    active.swap(still);
    monitor.Debug("projection step " + std::to_string(iter) + ": " + std::to_string(active.size()) + " points moving");
  }
  for (char c : result.converged) result.num_converged += c ? 1 : 0;
  result.twin_within = options.twin_within > 0.0 ? options.twin_within
                                                 : EstimateTwinWithin(result, options.tolerance, options.twin_factor);
  if (result.twin_within > 0.0) {
    MergeTwinSheets(udf, points, result, options.tolerance, result.twin_within);
    monitor.Debug("twin sheets within " + std::to_string(result.twin_within) + ": " +
                  std::to_string(result.num_merged) + " points moved to the ridge between them");
  }
  return result;
}

}  // namespace voroudf

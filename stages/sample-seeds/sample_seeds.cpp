#include "stages/sample-seeds/sample_seeds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "common/errors.h"
#include "common/knn.h"
#include "common/projection.h"
#include "common/rng.h"
#include "common/udf_spec.h"
#include "stages/sample-seeds/thin_sizing.h"

namespace voroudf {

void SampleSeedsOptions::Check() const {
  if (count == 0) throw UsageError("--count must be at least 1");
  if (count > 100000000) throw UsageError("--count must be at most 1e8");
  CheckRelativeProjection(proj_tol_rel, proj_floor_rel, proj_max_iters, proj_twin_factor);
  if (!(band_rel >= 0.0)) throw UsageError("--band-rel must be >= 0");
  if (!(dedup_rel >= 0.0 && dedup_rel < 0.1)) throw UsageError("--dedup-rel must be in [0, 0.1)");
  if (!(thin_boost >= 1.0 && thin_boost <= 64.0)) throw UsageError("--thin-boost must be in [1, 64]");
  if (spread_pool < 1 || spread_pool > 64) throw UsageError("--spread-pool must be in [1, 64]");
}

namespace {

Vec3 Candidate(const Box& box, uint64_t seed, uint64_t index) {
  Rng rng(seed, index);
  Vec3 p;
  for (int k = 0; k < 3; ++k) p[k] = rng.Uniform(box.min[k], box.max[k]);
  return p;
}

// The first `count` candidates (in index order) within the band. Candidates are evaluated in batches so
// that every source, external processes included, sees large requests.
std::vector<Vec3> DrawInBand(const Udf& udf, const Box& box, const SampleSeedsOptions& options, Monitor& monitor) {
  std::vector<Vec3> points;
  if (options.band_rel <= 0.0) {
    points.resize(options.count);
    for (size_t i = 0; i < options.count; ++i) points[i] = Candidate(box, options.seed, i);
    return points;
  }
  const double band = options.band_rel * box.Diagonal();
  // Give up after this many candidates: the band holds essentially none of the box.
  const uint64_t max_candidates = std::max<uint64_t>(100000000, 1000 * options.count);
  uint64_t next = 0;
  std::vector<Vec3> batch;
  std::vector<double> d;
  std::vector<Vec3> g;
  Task task(monitor, "drawing in the band", options.count);
  // The points kept are the first `count` in candidate order whatever the batches, so the batch sizes set
  // only how many candidates beyond the last kept one are asked: a first batch of kPilot measures the band's
  // share of the box, and each later one asks for what is still wanted at that rate, plus a fifth.
  constexpr double kPilot = 65536.0, kMinBatch = 4096.0;
  while (points.size() < options.count && next < max_candidates) {
    size_t n = static_cast<size_t>(kPilot);
    if (next > 0) {
      const double rate = std::max(1e-4, static_cast<double>(points.size()) / static_cast<double>(next));
      const double want = static_cast<double>(options.count - points.size());
      n = static_cast<size_t>(std::clamp(1.2 * want / rate, kMinBatch, 1e7));
    }
    batch.resize(n);
    for (size_t k = 0; k < n; ++k) batch[k] = Candidate(box, options.seed, next + k);
    udf.Evaluate(batch, d, g);
    for (size_t k = 0; k < n && points.size() < options.count; ++k) {
      if (d[k] < band) {
        points.push_back(batch[k]);
        task.Advance(1);
      }
    }
    next += n;
  }
  char line[160];
  std::snprintf(line, sizeof line, "%zu of %llu candidates fell within d < %.3g (band %g x diagonal)",
                points.size(), static_cast<unsigned long long>(next), band, options.band_rel);
  monitor.Info(line);
  if (points.empty()) throw NumericalError("no point of the domain box lies within the band d < " + std::to_string(band) +
                                           " of the surface of " + udf.Describe() + "; try a larger --band-rel");
  return points;
}

// Indices (into `points`, in order) of the points with no earlier kept point closer than `radius`.
std::vector<size_t> KeepDistinct(const std::vector<Vec3>& points, const std::vector<size_t>& candidates, double radius) {
  if (radius <= 0.0) return candidates;
  auto cell = [&](const Vec3& p, int k) { return static_cast<long long>(std::floor(p[k] / radius)); };
  auto key = [](long long x, long long y, long long z) {
    return static_cast<uint64_t>(x) * 73856093ull ^ static_cast<uint64_t>(y) * 19349663ull ^
           static_cast<uint64_t>(z) * 83492791ull;
  };
  std::unordered_map<uint64_t, std::vector<size_t>> grid;
  std::vector<size_t> kept;
  for (size_t i : candidates) {
    const Vec3& p = points[i];
    const long long cx = cell(p, 0), cy = cell(p, 1), cz = cell(p, 2);
    bool near = false;
    for (long long dx = -1; dx <= 1 && !near; ++dx)
      for (long long dy = -1; dy <= 1 && !near; ++dy)
        for (long long dz = -1; dz <= 1 && !near; ++dz) {
          const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (size_t j : it->second)
            if ((points[j] - p).squaredNorm() < radius * radius) near = true;
        }
    if (near) continue;
    grid[key(cx, cy, cz)].push_back(i);
    kept.push_back(i);
  }
  return kept;
}

// Twice the median nearest-neighbour distance: about sqrt(area / count) for uniform points.
double SpacingOf(const std::vector<Vec3>& p) {
  int k_found = 0;
  const std::vector<int> nearest = KNearestAmong(p, 1, &k_found, Monitor::Null(), "nearest seeds");
  std::vector<double> nn;
  for (size_t k = 0; k < p.size(); ++k)
    if (nearest[k] >= 0) nn.push_back((p[static_cast<size_t>(nearest[k])] - p[k]).norm());
  std::nth_element(nn.begin(), nn.begin() + static_cast<std::ptrdiff_t>(nn.size() / 2), nn.end());
  return 2.0 * nn[nn.size() / 2];
}

// Chooses `count` of the projected draws `converged`: with --thin-boost the relative spacing s = 1/√w of
// ThinSeedWeights (thin_sizing.h) at each draw, then with --spread-pool the count farthest apart in the metric
// d / s (even where the part is thick, about w times denser where it is thin), without it count at random
// with chances ∝ w. In pool order.
std::vector<size_t> ChooseSeeds(const Udf& udf, const SampleSeedsOptions& options, const std::vector<size_t>& converged,
                                const std::vector<Vec3>& points, const std::vector<Vec3>& normal, Monitor& monitor) {
  std::vector<Vec3> p(converged.size()), n(converged.size());
  for (size_t k = 0; k < converged.size(); ++k) p[k] = points[converged[k]], n[k] = normal[converged[k]];
  std::vector<double> weight, spacing;
  char line[300];
  if (options.thin_boost > 1.0) {
    // The spacing of `count` uniform seeds, from the pool's.
    const double h = SpacingOf(p) * std::sqrt(static_cast<double>(p.size()) / static_cast<double>(options.count));
    weight = ThinSeedWeights(ProbeThickness(udf, p, n, h), h, options.thin_boost);
    for (double w : weight) spacing.push_back(1.0 / std::sqrt(w));
    const size_t thin = static_cast<size_t>(std::count_if(weight.begin(), weight.end(), [](double w) { return w > 1.0; }));
    std::snprintf(line, sizeof line,
                  "thin parts: %zu of %zu pool points lie where the part is thinner than 2h (h = %.3g, the spacing of "
                  "count uniform seeds)", thin, p.size(), h);
    monitor.Info(line);
  }
  std::vector<size_t> chosen;
  if (options.spread_pool > 1) {
    double radius = 0.0;
    chosen = FarthestPointSubset(p, options.count, &radius, spacing.empty() ? nullptr : &spacing);
    std::snprintf(line, sizeof line, "spread: %zu of %zu projected draws chosen farthest apart%s; every draw within %.3g of one",
                  chosen.size(), p.size(), spacing.empty() ? "" : " (distances / the thin parts' spacing)", radius);
    monitor.Info(line);
  } else {
    chosen = ChooseWeighted(weight, options.count, options.seed);
  }
  if (!weight.empty()) {
    size_t thin_chosen = 0;
    for (size_t k : chosen) thin_chosen += weight[k] > 1.0;
    std::snprintf(line, sizeof line, "thin parts: %zu of the %zu seeds chosen there", thin_chosen, chosen.size());
    monitor.Info(line);
  }
  std::vector<size_t> keep(chosen.size());
  for (size_t k = 0; k < chosen.size(); ++k) keep[k] = converged[chosen[k]];
  return keep;
}

}  // namespace

SeedCloud SampleSeeds(const Udf& udf, const SampleSeedsOptions& options, Monitor& monitor) {
  options.Check();
  const Box box = udf.Domain();
  monitor.Info("domain box " + FormatBox(box) + ", diagonal " + std::to_string(box.Diagonal()));
  SampleSeedsOptions draw_options = options;
  // A pool to choose from (ChooseSeeds): ceil(B) times denser for thin parts, spread_pool times for the spread.
  draw_options.count = static_cast<size_t>(std::ceil(options.thin_boost)) * static_cast<size_t>(options.spread_pool) * options.count;
  std::vector<Vec3> points = DrawInBand(udf, box, draw_options, monitor);
  ProjectionOptions proj =
      RelativeProjection(box.Diagonal(), options.proj_tol_rel, options.proj_floor_rel, options.proj_max_iters);
  proj.twin_factor = options.proj_twin_factor;
  const ProjectionResult r = ProjectToZeroSet(udf, points, proj, monitor);

  std::vector<size_t> converged;
  for (size_t i = 0; i < points.size(); ++i)
    if (r.converged[i]) converged.push_back(i);
  if ((options.thin_boost > 1.0 || options.spread_pool > 1) && converged.size() > 1)
    converged = ChooseSeeds(udf, options, converged, points, r.gradient, monitor);
  const std::vector<size_t> kept = KeepDistinct(points, converged, options.dedup_rel * box.Diagonal());

  SeedCloud seeds;
  seeds.Resize(kept.size());
  for (size_t k = 0; k < kept.size(); ++k) {
    seeds.position[k] = points[kept[k]];
    seeds.normal[k] = r.gradient[kept[k]];
    seeds.udf[k] = r.distance[kept[k]];
  }
  const size_t dropped = points.size() - r.num_converged;
  char line[300];
  std::snprintf(line, sizeof line,
                "%zu of %zu seeds projected to d < %.3g (%zu of them at a kink's bottom with d < %.3g); %zu dropped "
                "(not converged in %d steps)",
                r.num_converged, points.size(), proj.tolerance, r.num_at_floor, proj.floor_tolerance, dropped,
                proj.max_iterations);
  if (dropped > 0) monitor.Warn(line);
  else monitor.Info(line);
  if (kept.size() < converged.size()) {
    std::snprintf(line, sizeof line, "%zu seeds dropped as duplicates (within %.3g of an earlier seed)",
                  converged.size() - kept.size(), options.dedup_rel * box.Diagonal());
    monitor.Info(line);
  }
  if (r.num_converged == 0) throw NumericalError("no seed reached the surface of " + udf.Describe());
  return seeds;
}

}  // namespace voroudf

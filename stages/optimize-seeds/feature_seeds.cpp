#include "stages/optimize-seeds/feature_seeds.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "stages/optimize-seeds/optimize_seeds.h"
#include "stages/optimize-seeds/seed_index.h"

namespace voroudf {

bool OnTwoCurves(const Vec3& a, const Vec3& t_a, const Vec3& b, const Vec3& t_b, const TwoCurves& test) {
  if (!(test.min_separation > 0.0) || t_a.squaredNorm() == 0.0 || t_b.squaredNorm() == 0.0) return false;
  const Vec3 ab = b - a;
  if ((ab - ab.dot(t_a) * t_a).norm() < test.min_separation || (ab - ab.dot(t_b) * t_b).norm() < test.min_separation)
    return false;
  const Vec3 bisector = (t_a + (t_a.dot(t_b) < 0.0 ? Vec3(-t_b) : t_b)).normalized();
  return std::abs(bisector.dot(ab.normalized())) < std::cos(test.bisector_deg * M_PI / 180.0);
}

std::vector<Vec3> Tangents(const SeedState& s) {
  std::vector<Vec3> tangent(s.position.size(), Vec3::Zero());
  for (size_t i = 0; i < tangent.size(); ++i)
    if (s.rank[i].rank == 2 && s.space[i].dim == 1) tangent[i] = s.space[i].basis.col(0);
  return tangent;
}

double TangentMisfit(const CellSamples& cells, size_t i, const Vec3& x) {
  double sum = 0.0;
  size_t count = 0;
  for (size_t m = cells.sample_offset[i]; m < cells.sample_offset[i + 1]; ++m) {
    const Vec3& g = cells.gradient[m];
    if (g.squaredNorm() < 0.25) continue;  // as in L1Step: no tangent plane
    sum += std::abs(g.normalized().dot(cells.point[m] - x) - cells.distance[m]);
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : INFINITY;
}

FeatureLinks FindFeatureLinks(const SeedState& s, const std::vector<Vec3>& tangent, double radius,
                              const TwoCurves& two_curves) {
  const size_t n = s.position.size();
  FeatureLinks links;
  const SeedIndex index(s.position);
  std::vector<int> found;
  for (size_t i = 0; i < n; ++i) {
    if (s.rank[i].rank != 2 || tangent[i].isZero()) continue;
    index.WithinRadius(s.position[i], radius, found);
    int best[2] = {-1, -1};
    for (int j : found) {  // nearest first
      const size_t uj = static_cast<size_t>(j);
      if (uj == i || s.rank[uj].rank < 2) continue;
      const Vec3 e = s.position[uj] - s.position[i];
      const double along = e.dot(tangent[i]);
      if (std::abs(along) < 0.8 * e.norm()) continue;
      if (!tangent[uj].isZero() && std::abs(e.dot(tangent[uj])) < 0.8 * e.norm()) continue;
      if (OnTwoCurves(s.position[i], tangent[i], s.position[uj], tangent[uj], two_curves)) continue;
      int& side = best[along > 0.0 ? 0 : 1];
      if (side < 0) side = j;
    }
    for (int k = 0; k < 2; ++k) {
      const int j = best[k];
      if (j >= 0) {
        links.chords.emplace_back(std::min<int>(static_cast<int>(i), j), std::max<int>(static_cast<int>(i), j));
      } else {
        links.ends.emplace_back(static_cast<int>(i), k == 0 ? tangent[i] : Vec3(-tangent[i]));
      }
    }
  }
  std::sort(links.chords.begin(), links.chords.end());
  links.chords.erase(std::unique(links.chords.begin(), links.chords.end()), links.chords.end());
  return links;
}

void EraseSeeds(SeedState& s, const std::vector<char>& drop) {
  size_t k = 0;
  for (size_t i = 0; i < s.position.size(); ++i) {
    if (drop[i]) continue;
    s.position[k] = s.position[i];
    s.udf[k] = s.udf[i];
    s.normal[k] = s.normal[i];
    s.rank[k] = s.rank[i];
    s.space[k] = s.space[i];
    ++k;
  }
  s.position.resize(k);
  s.udf.resize(k);
  s.normal.resize(k);
  s.rank.resize(k);
  s.space.resize(k);
}

void DropSheetSeedsNear(SeedState& s, size_t first, double clearance) {
  const SeedIndex index(s.position);
  std::vector<char> drop(s.position.size(), 0);
  std::vector<int> near;
  for (size_t i = first; i < s.position.size(); ++i) {
    index.WithinRadius(s.position[i], clearance, near);
    for (int j : near)
      if (static_cast<size_t>(j) < first && s.rank[static_cast<size_t>(j)].rank < 2) drop[static_cast<size_t>(j)] = 1;
  }
  EraseSeeds(s, drop);
}

size_t DropCrowdedSheetSeeds(SeedState& s, size_t count) {
  constexpr int kNeighbours = 6;
  const size_t n = s.position.size();
  const SeedIndex index(s.position);
  std::vector<std::vector<int>> near(n);
  std::vector<double> nearest(n, INFINITY);
  std::vector<size_t> candidates;
  for (size_t i = 0; i < n; ++i) {
    if (s.rank[i].rank != 1) continue;
    index.Nearest(s.position[i], kNeighbours + 1, near[i]);
    bool sheet = near[i].size() > 1;
    for (int j : near[i]) sheet = sheet && s.rank[static_cast<size_t>(j)].rank == 1;
    if (!sheet) continue;
    for (int j : near[i])
      if (static_cast<size_t>(j) != i) nearest[i] = std::min(nearest[i], (s.position[static_cast<size_t>(j)] - s.position[i]).norm());
    candidates.push_back(i);
  }
  std::sort(candidates.begin(), candidates.end(),
            [&](size_t a, size_t b) { return nearest[a] != nearest[b] ? nearest[a] < nearest[b] : a < b; });
  std::vector<char> drop(n, 0), blocked(n, 0);
  size_t dropped = 0;
  for (size_t i : candidates) {
    if (dropped == count) break;
    if (blocked[i]) continue;
    drop[i] = 1;
    ++dropped;
    for (int j : near[i]) blocked[static_cast<size_t>(j)] = 1;
  }
  EraseSeeds(s, drop);
  return dropped;
}

size_t ThinCrowded(SeedState& s, const std::vector<Vec3>& where, const std::vector<double>& misfit, double limit,
                   const TwoCurves& two_curves, std::vector<Vec3>* carried) {
  std::vector<uint8_t> ranks(s.rank.size());
  for (size_t i = 0; i < ranks.size(); ++i) ranks[i] = static_cast<uint8_t>(s.rank[i].rank);
  const std::vector<char> drop = SeedsBesideFeatures(where, ranks, limit, misfit, Tangents(s), two_curves);
  const size_t dropped = static_cast<size_t>(std::count(drop.begin(), drop.end(), 1));
  if (dropped == 0) return 0;
  EraseSeeds(s, drop);
  if (carried) {
    size_t k = 0;
    for (size_t i = 0; i < drop.size(); ++i)
      if (!drop[i]) (*carried)[k++] = (*carried)[i];
    carried->resize(k);
  }
  return dropped;
}

std::vector<char> SeedsBesideFeatures(const std::vector<Vec3>& position, const std::vector<uint8_t>& rank, double limit,
                                      const std::vector<double>& misfit, const std::vector<Vec3>& tangent,
                                      const TwoCurves& two_curves) {
  if (!misfit.empty() && misfit.size() != position.size()) throw std::invalid_argument("SeedsBesideFeatures: misfit size");
  if (!tangent.empty() && tangent.size() != position.size()) throw std::invalid_argument("SeedsBesideFeatures: tangent size");
  const size_t n = position.size();
  std::vector<char> drop(n, 0);
  std::vector<Vec3> feature;
  std::vector<size_t> feature_id;
  for (size_t i = 0; i < n; ++i)
    if (rank[i] >= 2) {
      feature.push_back(position[i]);
      feature_id.push_back(i);
    }
  if (feature.empty()) return drop;
  // Greedy thinning: corners first, then curve seeds, then the sheets; within a rank by misfit (or input
  // order). A seed is dropped when a feature seed kept before it lies within the limit: so a sheet seed gives
  // way to a curve or corner seed, a curve seed to a corner or another curve seed, a corner to a corner.
  auto clamped = [&](size_t i) { return std::min<int>(rank[i], 3); };
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (clamped(a) != clamped(b)) return clamped(a) > clamped(b);
    return !misfit.empty() && misfit[a] < misfit[b];
  });
  const SeedIndex index(feature);
  std::vector<char> kept(n, 0);
  std::vector<int> found;
  // A sheet seed between two curve seeds is also near the curve: the segment between two kept feature
  // seeds stands for the curve when it runs along the curve tangent of its ends (of those that have one,
  // at least one). The tangent test keeps a segment from cutting across a face between two edges' seeds.
  auto along_curve = [&](size_t a, size_t b) {
    const Vec3 e = (position[b] - position[a]).normalized();
    int with_tangent = 0;
    for (size_t end : {a, b}) {
      if (tangent[end].squaredNorm() == 0.0) continue;
      if (std::abs(tangent[end].dot(e)) < 0.9) return false;
      ++with_tangent;
    }
    return with_tangent > 0;
  };
  auto segment_distance = [&](const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    return (p - (a + t * ab)).norm();
  };
  std::vector<size_t> near;
  for (size_t i : order) {
    index.WithinRadius(position[i], limit, found);
    for (int f : found) {
      const size_t j = feature_id[static_cast<size_t>(f)];
      if (kept[j] && !(clamped(i) == 2 && clamped(j) == 2 && !tangent.empty() &&
                       OnTwoCurves(position[i], tangent[i], position[j], tangent[j], two_curves)))
        drop[i] = 1;
    }
    if (!drop[i] && clamped(i) < 2 && !tangent.empty()) {
      index.WithinRadius(position[i], 3.0 * limit, found);
      near.clear();
      for (int f : found)
        if (kept[feature_id[static_cast<size_t>(f)]]) near.push_back(feature_id[static_cast<size_t>(f)]);
      for (size_t a = 0; a < near.size() && !drop[i]; ++a)
        for (size_t b = a + 1; b < near.size() && !drop[i]; ++b)
          if (along_curve(near[a], near[b]) && segment_distance(position[i], position[near[a]], position[near[b]]) < limit)
            drop[i] = 1;
    }
    kept[i] = !drop[i];
  }
  return drop;
}

namespace {
// Where a gap between a corner and a curve seed is split, in spacings from the corner: beyond the one
// spacing within which no curve seed is added, with room for the L1 step's move onto the curve.
constexpr double kCornerGapSplit = 1.05;
}  // namespace

std::vector<ChainTrial> ChainTrials(const SeedState& s, const FeatureLinks& links, size_t fresh, double bend_tol,
                                    double max_gap, double clearance, double spacing) {
  std::vector<ChainTrial> trials;
  for (const auto& [a, b] : links.chords) {
    if (static_cast<size_t>(b) < fresh) continue;
    const Vec3 &pa = s.position[static_cast<size_t>(a)], &pb = s.position[static_cast<size_t>(b)];
    const double h = (pb - pa).norm();
    const bool gap = max_gap > 0.0 && h > max_gap;
    if (h < 2.5 * clearance || (bend_tol <= 0.0 && !gap)) continue;
    // A gap between a corner and a curve seed is split kCornerGapSplit spacings from the corner (its
    // midpoint when that is farther), so that the added seed clears the corner rule of Crowded and both
    // pieces of a gap up to 2 spacings are at most 1.5 spacings long.
    Vec3 start = 0.5 * (pa + pb);
    const bool a_corner = s.rank[static_cast<size_t>(a)].rank == 3, b_corner = s.rank[static_cast<size_t>(b)].rank == 3;
    if (gap && a_corner != b_corner) {
      const Vec3 &corner = a_corner ? pa : pb, &other = a_corner ? pb : pa;
      const double from_corner = std::min(std::max(0.5 * h, kCornerGapSplit * spacing), 0.7 * h);
      start = corner + (from_corner / h) * (other - corner);
    }
    trials.push_back({a, b, start, Vec3::Zero()});
  }
  if (max_gap > 0.0)
    for (const auto& [a, direction] : links.ends)
      if (static_cast<size_t>(a) >= fresh)
        trials.push_back({a, -1, s.position[static_cast<size_t>(a)] + spacing * direction, direction});
  return trials;
}

double LandedOnItsFeature(const SeedState& s, const ChainTrial& c, const Vec3& landed, int rank, const Vec3& t_new,
                          double bend_tol, double max_gap, double spacing) {
  const Vec3& pa = s.position[static_cast<size_t>(c.a)];
  if (c.b >= 0) {
    const Vec3& pb = s.position[static_cast<size_t>(c.b)];
    const double h = (pb - pa).norm(), u = (landed - pa).dot(pb - pa) / (h * h);
    const double off = (landed - c.start).norm();
    const bool gap = max_gap > 0.0 && h > max_gap;
    if (rank != 2 || u < 0.25 || u > 0.75 || off > 0.25 * h || (!gap && off <= bend_tol) ||
        std::abs(t_new.dot(pb - pa)) < 0.8 * h)
      return -1.0;
    return 0.2 * h;
  }
  const Vec3 e = landed - pa;
  const double ahead = e.dot(c.direction);
  if (ahead < 0.5 * spacing || ahead > 1.6 * spacing || ahead < 0.8 * e.norm()) return -1.0;
  if (rank == 2 && std::abs(t_new.dot(e)) < 0.8 * e.norm()) return -1.0;
  return 0.5 * spacing;
}

bool Crowded(const SeedState& s, size_t n, const SeedIndex& index, const Vec3& landed, int rank, double crowd_radius,
             double spacing, const Vec3& t_new, const std::vector<Vec3>& tangent, const TwoCurves& two_curves) {
  std::vector<int> near;
  index.WithinRadius(landed, std::max(crowd_radius, spacing), near);
  for (int j : near) {
    const int rank_j = s.rank[static_cast<size_t>(j)].rank;
    const double d = (s.position[static_cast<size_t>(j)] - landed).norm();
    if (rank_j >= 2 && d < crowd_radius &&
        !(rank == 2 && rank_j == 2 &&
          OnTwoCurves(landed, t_new, s.position[static_cast<size_t>(j)], tangent[static_cast<size_t>(j)], two_curves)))
      return true;
    if (rank_j == 3 && rank == 2) return true;
  }
  for (size_t k = n; k < s.position.size(); ++k)
    if ((s.position[k] - landed).norm() < crowd_radius) return true;
  return false;
}

}  // namespace voroudf

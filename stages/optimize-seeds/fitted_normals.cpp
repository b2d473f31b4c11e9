#include "stages/optimize-seeds/fitted_normals.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "stages/optimize-seeds/seed_index.h"

namespace voroudf {
namespace {

// A cell's samples [begin, end): their foot points p - d g, unit gradients, and whether they have a plane.
struct Feet {
  std::vector<Vec3> foot, unit;
  std::vector<char> usable;
  Feet(const CellSamples& cells, size_t begin, size_t end) : foot(end - begin), unit(end - begin), usable(end - begin) {
    for (size_t a = 0; a < end - begin; ++a) {
      const Vec3& g = cells.gradient[begin + a];
      usable[a] = g.squaredNorm() >= 0.25 && std::isfinite(cells.distance[begin + a]);
      unit[a] = usable[a] ? Vec3(g.normalized()) : Vec3::Zero();
      foot[a] = cells.point[begin + a] - cells.distance[begin + a] * g;
    }
  }
};

// Fits the planes of one cell's samples [begin, end) into normal/offset (unchanged where too few agree);
// appends each fitted sample's angle to its gradient. Brute force over the cell's ≤ M samples: M² distance
// tests per cell are cheaper than building a tree for 100 points.
void FitCell(const CellSamples& cells, size_t begin, size_t end, const SamplePlaneFit& fit,
             std::vector<Vec3>& normal, std::vector<double>& distance, std::vector<char>& fitted,
             std::vector<double>& angles) {
  const size_t m = end - begin;
  const Feet feet(cells, begin, end);
  const std::vector<Vec3>& foot = feet.foot;
  const std::vector<Vec3>& unit = feet.unit;
  const std::vector<char>& usable = feet.usable;
  const double agree = std::cos(fit.agree_deg * M_PI / 180.0);
  const size_t k_max = static_cast<size_t>(fit.neighbours);
  std::vector<double> best_d(k_max);
  std::vector<size_t> best_i(k_max);
  std::vector<Vec3> fit_point(k_max);
  // Planes are fitted at every `stride`-th sample (the anchors; the samples are in random order) and each
  // sample takes the plane of the nearest anchor that agrees with it: a fit per sample costs M² per cell.
  const size_t stride = static_cast<size_t>(fit.anchor_stride);
  std::vector<size_t> anchor;
  std::vector<Vec3> anchor_normal, anchor_centre;
  std::vector<double> anchor_spread;  // √λ₁: how far the fit's foot points spread along its plane
  for (size_t a = 0; a < m; a += stride) {
    if (!usable[a]) continue;
    // The k nearest agreeing foot points, kept unsorted with the farthest of them known.
    size_t count = 0, worst = 0;
    for (size_t b = 0; b < m; ++b) {
      if (!usable[b] || unit[a].dot(unit[b]) < agree) continue;
      const double d2 = (foot[b] - foot[a]).squaredNorm();
      if (count < k_max) {
        best_d[count] = d2, best_i[count] = b;
        if (d2 > best_d[worst]) worst = count;
        ++count;
      } else if (d2 < best_d[worst]) {
        best_d[worst] = d2, best_i[worst] = b;
        for (size_t q = 0; q < k_max; ++q)
          if (best_d[q] > best_d[worst]) worst = q;
      }
    }
    if (count < static_cast<size_t>(fit.min_neighbours)) continue;
    // The plane of the foot points, then of the points p − d n̂ along that plane's normal: a foot point
    // along a gradient turned by θ lies d (1 − cos θ) off the surface on its sample's side, which offsets the
    // first plane by the mean of that (half the cell's error at 15°); the second puts each point on the
    // surface wherever n̂ is the surface's normal, whatever the gradient.
    Vec3 c, n, lambda;
    bool plane = true;
    for (int pass = 0; pass < 2 && plane; ++pass) {
      for (size_t q = 0; q < count; ++q) {
        const size_t b = best_i[q];
        fit_point[q] = pass == 0 ? foot[b] : Vec3(cells.point[begin + b] - cells.distance[begin + b] * n);
      }
      c = Vec3::Zero();
      for (size_t q = 0; q < count; ++q) c += fit_point[q];
      c /= static_cast<double>(count);
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (size_t q = 0; q < count; ++q) {
        const Vec3 v = fit_point[q] - c;
        cov += v * v.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
      eig.computeDirect(cov);  // closed form for 3 x 3; eigenvalues ascending
      // Points that do not lie on one plane (two sheets closer than the neighbourhood, a corner) give no
      // plane: the samples near them keep their gradients'.
      lambda = eig.eigenvalues().cwiseMax(0.0);
      plane = lambda[0] <= fit.max_thickness * fit.max_thickness * lambda[1];
      n = eig.eigenvectors().col(0);
      if (n.dot(unit[a]) < 0.0) n = -n;
    }
    if (!plane) continue;
    anchor.push_back(a);
    anchor_normal.push_back(n);
    anchor_spread.push_back(std::sqrt(lambda[1] / static_cast<double>(count)));
    anchor_centre.push_back(c);
  }
  for (size_t a = 0; a < m; ++a) {
    if (!usable[a]) continue;
    size_t best = SIZE_MAX;
    double best_d2 = INFINITY;
    for (size_t q = 0; q < anchor.size(); ++q) {
      if (unit[a].dot(unit[anchor[q]]) < agree) continue;
      // A plane the sample's own foot point is not on (the other of two close sheets) is not its plane.
      if (std::abs(anchor_normal[q].dot(foot[a] - anchor_centre[q])) > fit.max_thickness * anchor_spread[q]) continue;
      const double d2 = (foot[anchor[q]] - foot[a]).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = q;
    }
    if (best == SIZE_MAX) {
      angles.push_back(0.0);  // keeps its gradient's plane
      continue;
    }
    Vec3 n = anchor_normal[best];
    if (n.dot(unit[a]) < 0.0) n = -n;
    normal[begin + a] = n;
    distance[begin + a] = n.dot(cells.point[begin + a] - anchor_centre[best]);
    fitted[begin + a] = 1;
    angles.push_back(std::acos(std::clamp(n.dot(unit[a]), -1.0, 1.0)));
  }
}

double Median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

SamplePlanes FitSamplePlanes(const CellSamples& cells, const SamplePlaneFit& fit) {
  const long n = static_cast<long>(cells.sample_offset.size()) - 1;
  SamplePlanes planes;
  planes.normal = cells.gradient;
  planes.distance = cells.distance;
  planes.fitted.assign(cells.point.size(), 0);
  std::vector<std::vector<double>> angles(static_cast<size_t>(std::max(n, 0L)));
#pragma omp parallel for schedule(dynamic, 16)
  for (long i = 0; i < n; ++i)
    FitCell(cells, cells.sample_offset[static_cast<size_t>(i)], cells.sample_offset[static_cast<size_t>(i) + 1], fit,
            planes.normal, planes.distance, planes.fitted, angles[static_cast<size_t>(i)]);
  std::vector<double> all;
  for (const auto& a : angles) all.insert(all.end(), a.begin(), a.end());
  planes.median_angle = Median(all);
  return planes;
}

void CenterTwinPlanes(CellSamples& cells, double within, double tolerance, bool mid_planes) {
  const long n = static_cast<long>(cells.sample_offset.size()) - 1;
  const double other_side = -std::cos(50.0 * M_PI / 180.0);
  std::vector<double> centred = cells.distance;
  std::vector<Vec3> centred_normal;
  if (mid_planes) centred_normal = cells.gradient;
#pragma omp parallel for schedule(dynamic, 16)
  for (long i = 0; i < n; ++i) {
    const size_t begin = cells.sample_offset[static_cast<size_t>(i)], end = cells.sample_offset[static_cast<size_t>(i) + 1];
    const size_t m = end - begin;
    const Feet feet(cells, begin, end);
    const std::vector<Vec3>& foot = feet.foot;
    const std::vector<Vec3>& unit = feet.unit;
    const std::vector<char>& usable = feet.usable;
    // Brute force over the cell's <= M samples, as in FitCell.
    for (size_t a = 0; a < m; ++a) {
      if (!usable[a]) continue;
      size_t best = SIZE_MAX;
      double best_d2 = INFINITY;
      for (size_t b = 0; b < m; ++b) {
        if (!usable[b] || unit[a].dot(unit[b]) > other_side) continue;
        // A sample between the twins points at the same sheet as the other side's samples there (gap 0).
        const Vec3 delta = foot[a] - foot[b];
        const double along = unit[a].dot(delta);
        if (std::abs(along) <= 8.0 * tolerance) continue;
        const double lateral2 = delta.squaredNorm() - along * along;
        if (lateral2 < best_d2) best_d2 = lateral2, best = b;
      }
      if (best == SIZE_MAX) continue;
      const double gap = unit[a].dot(foot[a] - foot[best]);
      if (std::abs(gap) >= within) continue;
      if (!mid_planes) {
        centred[begin + a] += 0.5 * gap;
        continue;
      }
      // The mid-plane of the two: the mean of their signed distances (with opposite normals exactly
      // value += gap / 2).
      const Vec3 mid = 0.5 * (unit[a] - unit[best]);
      const Vec3& p = cells.point[begin + a];
      const double height = 0.5 * (unit[a].dot(p - foot[a]) - unit[best].dot(p - foot[best]));
      const double norm = mid.norm();
      centred_normal[begin + a] = mid / norm;
      centred[begin + a] = height / norm;
    }
  }
  cells.distance.swap(centred);
  if (mid_planes) cells.gradient.swap(centred_normal);
}

void UseSamplePlanes(CellSamples& cells, SamplePlanes& planes) {
  cells.gradient.swap(planes.normal);
  cells.distance.swap(planes.distance);
}

double ValueErrorTilt(const std::vector<Vec3>& points, const std::vector<double>& floor) {
  if (points.size() < 16) return 0.0;
  const SeedIndex index(points);
  std::vector<double> slope;
  std::vector<int> near;
  for (size_t i = 0; i < points.size(); ++i) {
    index.Nearest(points[i], 2, near);
    for (int j : near) {
      const double dx = (points[static_cast<size_t>(j)] - points[i]).norm();
      if (static_cast<size_t>(j) == i || !(dx > 0.0)) continue;
      slope.push_back(std::abs(floor[static_cast<size_t>(j)] - floor[i]) / dx);
      break;
    }
  }
  return std::atan(Median(slope) / std::cos(M_PI / 4.0));
}

}  // namespace voroudf

#include "stages/build-gvd/restricted_dual.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>

namespace voroudf {
namespace {

// Whether p lies strictly inside the circumcircle of (a, b, c), all four projected onto the plane normal to
// `chart` (their mean surface normal). The plane is that of the four points, not of the triangle, so that
// the test is the same for every triangle of the four: of a quadrilateral's two triangulations exactly one
// passes (unless the four are cocircular within `cocircular`, relative: then neither blocks).
bool InCircumcircle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, const Vec3& chart, double cocircular) {
  const Vec3 u = chart.unitOrthogonal(), v = chart.cross(u).normalized();
  auto flat = [&](const Vec3& q) { return Eigen::Vector2d((q - p).dot(u), (q - p).dot(v)); };
  const Eigen::Vector2d A = flat(a), B = flat(b), C = flat(c);  // p at the origin
  const double orient = (B - A).x() * (C - A).y() - (B - A).y() * (C - A).x();
  const double det = A.squaredNorm() * (B.x() * C.y() - B.y() * C.x()) - B.squaredNorm() * (A.x() * C.y() - A.y() * C.x()) +
                     C.squaredNorm() * (A.x() * B.y() - A.y() * B.x());
  const double scale = std::max({A.squaredNorm(), B.squaredNorm(), C.squaredNorm()});
  return det * (orient > 0 ? 1 : -1) > cocircular * scale * std::abs(orient);
}

// The chart of four seeds, the plane their junction is triangulated in: the best-fit plane of the four,
// when they are nearly coplanar (its thickness at most `max_flatness` x its extent) and every one of them
// on a sheet has its surface normal within the angle of `min_cos` of the plane's normal (sign-blind: a
// UDF's gradient has no orientation). Zero otherwise: across a crease or where two sheets cross, the four
// lie on no common plane of the surface. Seeds on a sharp edge, corner or branching curve have no normal
// of their own (their gradient is one of their sheets') and no say in it.
Vec3 ChartNormal(const std::array<int, 4>& id, const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                 const std::vector<uint8_t>& on_sheet, double min_cos, double max_flatness) {
  Vec3 centre = Vec3::Zero();
  for (int s : id) centre += seeds[static_cast<size_t>(s)] / 4;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int s : id) cov += (seeds[static_cast<size_t>(s)] - centre) * (seeds[static_cast<size_t>(s)] - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (!(eig.eigenvalues()(0) <= max_flatness * max_flatness * eig.eigenvalues()(2))) return Vec3::Zero();
  const Vec3 plane = eig.eigenvectors().col(0);
  for (int s : id)
    if (on_sheet[static_cast<size_t>(s)] && !(std::abs(plane.dot(normals[static_cast<size_t>(s)])) >= min_cos))
      return Vec3::Zero();
  return plane;
}

}  // namespace

std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                                        const std::vector<uint8_t>& on_sheet, const std::vector<Tri>& witnessed,
                                        double chart_angle_deg, RestrictedDualStats* stats_out) {
  RestrictedDualStats stats;
  stats.witnessed = witnessed.size();
  // Geodesic neighbours: the seeds each seed shares a witnessed triple with.
  std::vector<std::vector<int>> neighbours(seeds.size());
  for (const Tri& t : witnessed)
    for (int k = 0; k < 3; ++k)
      for (int m = 0; m < 3; ++m)
        if (m != k) neighbours[static_cast<size_t>(t[k])].push_back(t[m]);
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  constexpr double kCocircular = 1e-9;
  constexpr double kMaxFlatness = 0.25;
  const double min_cos = std::cos(chart_angle_deg * M_PI / 180.0);
  std::vector<Tri> kept;
  std::vector<int> common, both;
  for (const Tri& t : witnessed) {
    const Vec3 &a = seeds[static_cast<size_t>(t[0])], &b = seeds[static_cast<size_t>(t[1])], &c = seeds[static_cast<size_t>(t[2])];
    const Vec3 normal = (b - a).cross(c - a);
    if (!(normal.squaredNorm() > 1e-24 * (b - a).squaredNorm() * (c - a).squaredNorm())) {
      ++stats.degenerate;  // collinear: no circle, no triangle
      continue;
    }
    // The neighbours of all three seeds: those that could make a fourth corner of this junction.
    const auto& n0 = neighbours[static_cast<size_t>(t[0])];
    const auto& n1 = neighbours[static_cast<size_t>(t[1])];
    const auto& n2 = neighbours[static_cast<size_t>(t[2])];
    both.clear();
    std::set_intersection(n0.begin(), n0.end(), n1.begin(), n1.end(), std::back_inserter(both));
    common.clear();
    std::set_intersection(both.begin(), both.end(), n2.begin(), n2.end(), std::back_inserter(common));
    bool blocked = false;
    for (int v : common) {
      if (v == t[0] || v == t[1] || v == t[2]) continue;
      const Vec3 chart = ChartNormal({t[0], t[1], t[2], v}, seeds, normals, on_sheet, min_cos, kMaxFlatness);
      if (chart.isZero()) continue;
      if (InCircumcircle(a, b, c, seeds[static_cast<size_t>(v)], chart, kCocircular)) {
        blocked = true;
        break;
      }
    }
    if (!blocked) kept.push_back(t);
  }
  stats.kept = kept.size();
  if (stats_out) *stats_out = stats;
  return kept;
}

}  // namespace voroudf

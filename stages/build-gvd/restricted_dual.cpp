#include "stages/build-gvd/restricted_dual.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace voroudf {
namespace {

// Whether p lies strictly inside the circumcircle of (a, b, c), all four projected onto their best-fit
// plane. The plane is that of the four points, not of the triangle, so that the test is the same for
// every triangle of the four: of a quadrilateral's two triangulations, exactly one passes (unless the
// four are cocircular within `cocircular`, relative: then neither blocks).
bool InCircumcircle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, double cocircular) {
  const Vec3 centre = (a + b + c + p) / 4;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3* q : {&a, &b, &c, &p}) cov += (*q - centre) * (*q - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Vec3 u = eig.eigenvectors().col(2), v = eig.eigenvectors().col(1);
  auto flat = [&](const Vec3& q) { return Eigen::Vector2d((q - centre).dot(u), (q - centre).dot(v)); };
  const Eigen::Vector2d A = flat(a), B = flat(b), C = flat(c), P = flat(p);
  const double orient = (B - A).x() * (C - A).y() - (B - A).y() * (C - A).x();
  const Eigen::Vector2d ap = A - P, bp = B - P, cp = C - P;
  const double det = ap.squaredNorm() * (bp.x() * cp.y() - bp.y() * cp.x()) -
                     bp.squaredNorm() * (ap.x() * cp.y() - ap.y() * cp.x()) +
                     cp.squaredNorm() * (ap.x() * bp.y() - ap.y() * bp.x());
  // det / orient has the units of length^2 x area; compare with the scale of the four points.
  const double scale = std::max({ap.squaredNorm(), bp.squaredNorm(), cp.squaredNorm()});
  return det * (orient > 0 ? 1 : -1) > cocircular * scale * std::abs(orient);
}

// Whether the triangle (a, b, c) is Delaunay against `others`: none of them that lies within
// `flat` x R of its plane (R its circumradius) falls strictly inside its circumcircle. Neighbours
// farther from the plane (across a crease, on a curved sheet's far side) have no say: there the plane is
// no chart of the surface.
bool LocallyDelaunay(const Vec3& a, const Vec3& b, const Vec3& c, const std::vector<const Vec3*>& others, double flat,
                     bool* degenerate) {
  const Vec3 ab = b - a, ac = c - a, normal = ab.cross(ac);
  const double n2 = normal.squaredNorm();
  *degenerate = !(n2 > 1e-24 * ab.squaredNorm() * ac.squaredNorm());
  if (*degenerate) return false;
  const Vec3 o = a + (ac.squaredNorm() * normal.cross(ab) + ab.squaredNorm() * ac.cross(normal)) / (2 * n2);
  const Vec3 n = normal / std::sqrt(n2);
  const double r2 = (o - a).squaredNorm();
  constexpr double kCocircular = 1e-9;
  for (const Vec3* p : others) {
    const double off = n.dot(*p - o);
    if (off * off > flat * flat * r2) continue;
    if (InCircumcircle(a, b, c, *p, kCocircular)) return false;
  }
  return true;
}

}  // namespace

std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Tri>& witnessed, double flat,
                                        RestrictedDualStats* stats_out) {
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
  std::vector<Tri> kept;
  std::vector<int> common, both;
  std::vector<const Vec3*> others;
  for (const Tri& t : witnessed) {
    // The neighbours of all three seeds: those that could make a fourth corner of this junction.
    const auto& n0 = neighbours[static_cast<size_t>(t[0])];
    const auto& n1 = neighbours[static_cast<size_t>(t[1])];
    const auto& n2 = neighbours[static_cast<size_t>(t[2])];
    both.clear();
    std::set_intersection(n0.begin(), n0.end(), n1.begin(), n1.end(), std::back_inserter(both));
    common.clear();
    std::set_intersection(both.begin(), both.end(), n2.begin(), n2.end(), std::back_inserter(common));
    others.clear();
    for (int v : common)
      if (v != t[0] && v != t[1] && v != t[2]) others.push_back(&seeds[static_cast<size_t>(v)]);
    bool degenerate = false;
    if (LocallyDelaunay(seeds[static_cast<size_t>(t[0])], seeds[static_cast<size_t>(t[1])],
                        seeds[static_cast<size_t>(t[2])], others, flat, &degenerate)) {
      kept.push_back(t);
    }
    stats.degenerate += degenerate ? 1 : 0;
  }
  stats.kept = kept.size();
  if (stats_out) *stats_out = stats;
  return kept;
}

}  // namespace voroudf

#include "stages/build-gvd/restricted_dual.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "common/mesh_topology.h"

namespace voroudf {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
using Tds = CGAL::Triangulation_data_structure_3<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_3<Kernel, Tds>;

Tri Sorted(int a, int b, int c) {
  Tri t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

uint64_t TriKey(const Tri& t) {
  return (static_cast<uint64_t>(t[0]) * 2654435761u) ^ (static_cast<uint64_t>(t[1]) << 21) ^
         (static_cast<uint64_t>(t[2]) << 42);
}

struct TriHash {
  size_t operator()(const Tri& t) const { return static_cast<size_t>(TriKey(t)); }
};
using TriSet = std::unordered_set<Tri, TriHash>;

// The smallest dihedral angle of tetrahedron (p0..p3), in degrees: near 0 for a flat one (sliver).
double MinDihedralDeg(const std::array<Vec3, 4>& p) {
  double smallest = 180.0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      int o[2], k = 0;
      for (int m = 0; m < 4; ++m)
        if (m != a && m != b) o[k++] = m;
      const Vec3 e = (p[b] - p[a]).normalized();
      Vec3 u = p[o[0]] - p[a], v = p[o[1]] - p[a];
      u -= u.dot(e) * e;
      v -= v.dot(e) * e;
      if (u.norm() == 0 || v.norm() == 0) return 0.0;
      const double cosine = std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0);
      smallest = std::min(smallest, std::acos(cosine) * 180.0 / M_PI);
    }
  return smallest;
}

// Orientation and in-circle in the plane (doubles; the points are seed positions projected on a plane).
double Orient2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}
bool InCircle(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  // d inside the circle through a, b, c (counter-clockwise).
  const Eigen::Vector2d ad = a - d, bd = b - d, cd = c - d;
  const double det = ad.squaredNorm() * (bd.x() * cd.y() - bd.y() * cd.x()) -
                     bd.squaredNorm() * (ad.x() * cd.y() - ad.y() * cd.x()) +
                     cd.squaredNorm() * (ad.x() * bd.y() - ad.y() * bd.x());
  return det > 0;
}

// The 2-D Delaunay triangulation of four seeds in their best-fit plane, as seed triples.
std::vector<Tri> PlanarDelaunay(const std::array<int, 4>& id, const std::array<Vec3, 4>& p) {
  Vec3 centre = Vec3::Zero();
  for (const Vec3& q : p) centre += q / 4;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& q : p) cov += (q - centre) * (q - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Vec3 u = eig.eigenvectors().col(2), v = eig.eigenvectors().col(1);
  std::array<Eigen::Vector2d, 4> q;
  for (int k = 0; k < 4; ++k) q[k] = Eigen::Vector2d((p[k] - centre).dot(u), (p[k] - centre).dot(v));
  // One point inside the triangle of the other three: the three triangles around it.
  for (int in = 0; in < 4; ++in) {
    int o[3], k = 0;
    for (int m = 0; m < 4; ++m)
      if (m != in) o[k++] = m;
    const double s0 = Orient2(q[o[0]], q[o[1]], q[in]), s1 = Orient2(q[o[1]], q[o[2]], q[in]),
                 s2 = Orient2(q[o[2]], q[o[0]], q[in]);
    if ((s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0))
      return {Sorted(id[in], id[o[0]], id[o[1]]), Sorted(id[in], id[o[1]], id[o[2]]), Sorted(id[in], id[o[2]], id[o[0]])};
  }
  // A convex quadrilateral: find its cyclic order, then the diagonal whose triangles have empty circles.
  int order[4] = {0, 1, 2, 3};
  const Eigen::Vector2d mid = (q[0] + q[1] + q[2] + q[3]) / 4;
  std::sort(order, order + 4, [&](int a, int b) {
    return std::atan2(q[a].y() - mid.y(), q[a].x() - mid.x()) < std::atan2(q[b].y() - mid.y(), q[b].x() - mid.x());
  });
  const int a = order[0], b = order[1], c = order[2], d = order[3];  // counter-clockwise
  // Diagonal a-c unless d lies inside the circle of (a, b, c); ties to the smaller seed pair (deterministic).
  const bool use_ac = !InCircle(q[a], q[b], q[c], q[d]);
  if (use_ac) return {Sorted(id[a], id[b], id[c]), Sorted(id[a], id[c], id[d])};
  return {Sorted(id[a], id[b], id[d]), Sorted(id[b], id[c], id[d])};
}

}  // namespace

std::vector<Tri> RestrictedDual(const std::vector<Vec3>& seeds, const std::vector<Tri>& witnessed,
                                double flat_dihedral_deg, RestrictedDualStats* stats_out) {
  RestrictedDualStats stats;
  stats.witnessed = witnessed.size();
  std::vector<std::pair<Kernel::Point_3, int>> points;
  points.reserve(seeds.size());
  for (size_t i = 0; i < seeds.size(); ++i)
    points.emplace_back(Kernel::Point_3(seeds[i].x(), seeds[i].y(), seeds[i].z()), static_cast<int>(i));
  const Delaunay dt(points.begin(), points.end());

  const TriSet witnessed_set(witnessed.begin(), witnessed.end());
  TriSet kept;
  for (auto f = dt.finite_facets_begin(); f != dt.finite_facets_end(); ++f) {
    ++stats.delaunay_faces;
    int v[3], k = 0;
    for (int m = 0; m < 4; ++m)
      if (m != f->second) v[k++] = f->first->vertex(m)->info();
    const Tri t = Sorted(v[0], v[1], v[2]);
    if (witnessed_set.count(t)) kept.insert(t);
  }
  stats.witnessed_delaunay = kept.size();

  // Flat tetrahedra with folding kept faces: their 2-D Delaunay faces instead. Decided on the faces kept
  // before any replacement, in the order of the cells' sorted seed quadruples (deterministic).
  std::vector<std::pair<std::array<int, 4>, std::vector<Tri>>> replacements;
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    std::array<int, 4> id;
    std::array<Vec3, 4> p;
    for (int m = 0; m < 4; ++m) {
      id[m] = c->vertex(m)->info();
      p[m] = seeds[static_cast<size_t>(id[m])];
    }
    int kept_faces = 0;
    for (int m = 0; m < 4; ++m) {
      int v[3], k = 0;
      for (int o = 0; o < 4; ++o)
        if (o != m) v[k++] = id[o];
      kept_faces += kept.count(Sorted(v[0], v[1], v[2])) ? 1 : 0;
    }
    if (kept_faces < 3 || MinDihedralDeg(p) >= flat_dihedral_deg) continue;
    std::array<int, 4> sorted_id = id;
    std::sort(sorted_id.begin(), sorted_id.end());
    replacements.emplace_back(sorted_id, PlanarDelaunay(id, p));
  }
  std::sort(replacements.begin(), replacements.end());
  for (const auto& [cell, faces] : replacements) {
    ++stats.flat_cells_resolved;
    const int* s = cell.data();
    const Tri all[4] = {Sorted(s[1], s[2], s[3]), Sorted(s[0], s[2], s[3]), Sorted(s[0], s[1], s[3]), Sorted(s[0], s[1], s[2])};
    for (const Tri& t : all) {
      const bool wanted = std::find(faces.begin(), faces.end(), t) != faces.end();
      if (wanted && kept.insert(t).second) ++stats.faces_added;
      if (!wanted && kept.erase(t)) ++stats.faces_dropped;
    }
  }
  std::vector<Tri> out(kept.begin(), kept.end());
  std::sort(out.begin(), out.end());
  if (stats_out) *stats_out = stats;
  return out;
}

}  // namespace voroudf

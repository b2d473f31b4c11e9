#include "pipelines/tools/synthetic_nonmanifold.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/clip.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/transform.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <map>

#include "common/errors.h"
#include "common/mesh_topology.h"

namespace voroudf {
namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

Mesh ToCgal(const TriangleMesh& m) {
  std::vector<Point> points;
  points.reserve(m.vertices.size());
  for (const Vec3& v : m.vertices) points.emplace_back(v.x(), v.y(), v.z());
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(m.faces.size());
  for (const Tri& t : m.faces) polygons.push_back({size_t(t[0]), size_t(t[1]), size_t(t[2])});
  PMP::orient_polygon_soup(points, polygons);
  Mesh out;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, out);
  return out;
}

// Appends a CGAL mesh to `out`, sharing vertices with identical exact coordinates (converted to double, equal
// exact points give equal doubles): this is where the two corefined parts are glued along their crossings.
void Append(const Mesh& m, std::map<std::array<double, 3>, int>& index, TriangleMesh& out) {
  std::vector<int> id(m.number_of_vertices() + m.number_of_removed_vertices(), -1);
  for (auto v : m.vertices()) {
    const Point& p = m.point(v);
    const std::array<double, 3> key{CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
    const auto [it, inserted] = index.emplace(key, static_cast<int>(out.vertices.size()));
    if (inserted) out.vertices.emplace_back(key[0], key[1], key[2]);
    id[v.idx()] = it->second;
  }
  for (auto f : m.faces()) {
    Tri t;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) t[k++] = id[v.idx()];
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) out.faces.push_back(t);
  }
}

}  // namespace

void OverlapOptions::Check() const {
  if (!(plane_normal.norm() > 0)) throw UsageError("--normal must be a non-zero vector");
  if (!(overlap_rel > 0 && overlap_rel < 0.5)) throw UsageError("--overlap-rel must be in (0, 0.5)");
  if (!(std::abs(plane_offset_rel) < 0.5)) throw UsageError("--offset-rel must be in (-0.5, 0.5)");
}

TriangleMesh MakeOverlapNonManifold(const TriangleMesh& input, const OverlapOptions& options,
                                    const std::string& name) {
  options.Check();
  const TriangleMesh mesh = WeldVertices(input, 0.0);
  Mesh base = ToCgal(mesh);
  if (!CGAL::is_closed(base)) throw InputError(name, "is not closed: the overlap construction needs a solid");
  if (PMP::does_self_intersect(base)) throw InputError(name, "intersects itself");

  Box box{Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY)};
  for (const Vec3& v : mesh.vertices) {
    box.min = box.min.cwiseMin(v);
    box.max = box.max.cwiseMax(v);
  }
  const Vec3 n = options.plane_normal.normalized();
  const double diag = box.Diagonal();
  const Vec3 origin = box.Center() + options.plane_offset_rel * diag * n;
  const Kernel::Plane_3 plane(Point(origin.x(), origin.y(), origin.z()), Kernel::Vector_3(n.x(), n.y(), n.z()));

  Mesh negative = base, positive = base;
  PMP::clip(negative, plane, CGAL::parameters::clip_volume(true));
  PMP::clip(positive, plane.opposite(), CGAL::parameters::clip_volume(true));
  if (negative.number_of_faces() == 0 || positive.number_of_faces() == 0)
    throw InputError(name, "the cut plane does not cross the mesh");
  const Vec3 shift = -options.overlap_rel * diag * n;
  PMP::transform(Kernel::Aff_transformation_3(CGAL::TRANSLATION, Kernel::Vector_3(shift.x(), shift.y(), shift.z())),
                 positive);
  PMP::corefine(negative, positive);

  TriangleMesh out;
  std::map<std::array<double, 3>, int> index;
  Append(negative, index, out);
  Append(positive, index, out);
  return CanonicalOrder(out);
}

}  // namespace voroudf

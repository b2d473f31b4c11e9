#include "stages/evaluate/features.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "stages/evaluate/crossings.h"
#include "stages/evaluate/evaluate.h"

namespace voroudf {
namespace {

std::vector<Edge> AllEdges(const TriangleMesh& m) { return BuildEdgeFaces(m.faces).edges; }

// Share of the samples of `edges` (by length) within `tol` of `targets`, and their mean and largest distance.
struct Coverage {
  double share = 1, mean = 0, max = 0, length = 0;
  std::vector<Vec3> missed;  ///< the samples farther than the tolerance
};
Coverage CoverPoints(const std::vector<Vec3>& points, double length, const TriangleMesh& to,
                    const std::vector<Edge>& targets, double tol, Monitor& monitor) {
  Coverage c;
  c.length = length;
  if (points.empty()) return c;
  if (targets.empty()) {
    c.share = 0;
    c.mean = c.max = std::numeric_limits<double>::infinity();
    c.missed = points;
    return c;
  }
  const std::vector<double> d = DistancesToSegments(points, to.vertices, targets, monitor);
  size_t within = 0;
  double sum = 0;
  for (size_t k = 0; k < d.size(); ++k) {
    const double x = d[k];
    if (x > tol) c.missed.push_back(points[k]);
    within += x <= tol ? 1 : 0;
    sum += x;
    c.max = std::max(c.max, x);
  }
  c.share = static_cast<double>(within) / static_cast<double>(d.size());
  c.mean = sum / static_cast<double>(d.size());
  return c;
}
Coverage Cover(const TriangleMesh& from, const std::vector<Edge>& edges, const TriangleMesh& to,
               const std::vector<Edge>& targets, double tol, size_t samples, Monitor& monitor) {
  double length = 0;
  const std::vector<Vec3> points = SampleEdges(from, edges, samples, &length);
  return CoverPoints(points, length, to, targets, tol, monitor);
}

}  // namespace

// The samples of the reference's boundary edges where its union ends (RimSamples in features.h).
std::vector<Vec3> RimSamples(const TriangleMesh& ref, double tolerance, size_t samples, double* rim_length) {
  std::vector<Vec3> along;
  double length = 0;
  const std::vector<Vec3> points = SampleEdges(ref, BoundaryEdges(ref), samples, &length, &along);
  *rim_length = length;
  if (points.empty() || !(tolerance > 0)) return points;
  const std::vector<size_t> exits = ExitsThrough(ref, points, along, 2 * tolerance, tolerance);
  std::vector<Vec3> rim;
  for (size_t k = 0; k < points.size(); ++k)
    if (exits[k] <= 1) rim.push_back(points[k]);
  *rim_length = length * static_cast<double>(rim.size()) / static_cast<double>(points.size());
  return rim;
}

double MedianEdgeLength(const TriangleMesh& m) {
  const EdgeFaces ef = BuildEdgeFaces(m.faces);
  std::vector<double> len;
  len.reserve(ef.edges.size());
  for (const Edge& e : ef.edges)
    len.push_back((m.vertices[static_cast<size_t>(e[1])] - m.vertices[static_cast<size_t>(e[0])]).norm());
  if (len.empty()) return 0.0;
  std::nth_element(len.begin(), len.begin() + static_cast<long>(len.size() / 2), len.end());
  return len[len.size() / 2];
}

std::vector<Edge> BoundaryEdges(const TriangleMesh& mesh) {
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  std::vector<Edge> out;
  for (size_t e = 0; e < ef.edges.size(); ++e)
    if (ef.faces[e].size() == 1) out.push_back(ef.edges[e]);
  return out;
}

std::vector<int> Corners(const std::vector<Edge>& edges) {
  std::map<int, int> degree;
  for (const Edge& e : edges) ++degree[e[0]], ++degree[e[1]];
  std::vector<int> out;
  for (const auto& [v, d] : degree)
    if (d >= 3) out.push_back(v);
  return out;
}

FeatureMetrics FeatureRecall(const TriangleMesh& mesh, const TriangleMesh& ref, double feature_angle_deg,
                             size_t samples, double diagonal, Monitor& monitor) {
  FeatureMetrics f;
  f.tolerance = 0.1 * MedianEdgeLength(mesh);
  const std::vector<Edge> ref_features = FeatureEdges(ref, feature_angle_deg);
  const std::vector<Edge> mesh_features = FeatureEdges(mesh, feature_angle_deg);
  const Coverage on_edges = Cover(ref, ref_features, mesh, AllEdges(mesh), f.tolerance, samples, monitor);
  f.feature_length = on_edges.length;
  f.recall = on_edges.share;
  f.missed = on_edges.missed;
  const Coverage on_features = Cover(ref, ref_features, mesh, mesh_features, f.tolerance, samples, monitor);
  f.feature_mean_x1e3 = on_features.mean * 1e3;
  f.feature_max_x1e3 = on_features.max / diagonal * 1e3;
  const std::vector<int> corners = Corners(ref_features);
  f.corners = corners.size();
  if (!corners.empty()) {
    std::vector<Vec3> at;
    for (int v : corners) at.push_back(ref.vertices[static_cast<size_t>(v)]);
    const std::vector<Edge> points = [&] {
      std::vector<Edge> p;
      for (size_t v = 0; v < mesh.vertices.size(); ++v) p.push_back({static_cast<int>(v), static_cast<int>(v)});
      return p;
    }();
    for (double d : DistancesToSegments(at, mesh.vertices, points, monitor)) f.corners_matched += d <= f.tolerance ? 1 : 0;
  }
  double rim_length = 0;
  const std::vector<Vec3> rim_points = RimSamples(ref, f.tolerance, samples, &rim_length);
  const Coverage rim = CoverPoints(rim_points, rim_length, mesh, BoundaryEdges(mesh), f.tolerance, monitor);
  f.boundary_length = rim.length;
  f.boundary_recall = rim.share;
  f.boundary_max_x1e3 = rim.max / diagonal * 1e3;
  return f;
}

}  // namespace voroudf

#include "pipelines/tools/curve_check.h"

#include <algorithm>
#include <array>
#include <limits>
#include <vector>

#include "common/mesh_topology.h"

namespace voroudf {
namespace {

double SegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

double CurveDistance(const Vec3& p, const std::vector<std::vector<Vec3>>& curves) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& line : curves)
    for (size_t i = 0; i + 1 < line.size(); ++i) best = std::min(best, SegmentDistance(p, line[i], line[i + 1]));
  return best;
}

}  // namespace

BranchingCheck CheckBranchingCurves(const TriangleMesh& mesh, const ShapeTopology& truth, double tol, double max_gap) {
  BranchingCheck c;
  const TopologyStats topo = ComputeTopology(mesh);
  c.boundary_edges = topo.boundary_edges;
  c.euler = topo.euler;
  c.expected_euler = truth.euler;
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  std::vector<std::array<Vec3, 2>> nm;
  double total_length = 0;
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const Vec3& a = mesh.vertices[static_cast<size_t>(ef.edges[e][0])];
    const Vec3& b = mesh.vertices[static_cast<size_t>(ef.edges[e][1])];
    total_length += (b - a).norm();
    if (ef.faces[e].size() < 3) continue;
    nm.push_back({a, b});
    // On the curve: both ends within tol, and the midpoint within tol or 5 % of the edge's length (the
    // sagitta of a chord of a curved curve: 1.6 % for an edge of 0.065 on sphere-disc's circle of 0.5).
    const double ends = std::max(CurveDistance(a, truth.branching_curves), CurveDistance(b, truth.branching_curves));
    const double mid = CurveDistance(0.5 * (a + b), truth.branching_curves);
    c.max_offset = std::max(c.max_offset, std::max(ends, mid));
    c.off_curve += ends > tol || mid > std::max(tol, 0.05 * (b - a).norm()) ? 1 : 0;
  }
  c.nonmanifold_edges = nm.size();
  c.mean_edge = ef.edges.empty() ? 0.0 : total_length / static_cast<double>(ef.edges.size());
  if (max_gap <= 0) max_gap = 3 * c.mean_edge;
  for (const auto& line : truth.branching_curves) {
    double gap = 0;
    for (size_t i = 0; i < line.size(); ++i) {
      bool covered = false;
      for (const auto& s : nm)
        if (SegmentDistance(line[i], s[0], s[1]) <= tol) {
          covered = true;
          break;
        }
      if (covered) {
        gap = 0;
      } else if (i > 0) {
        gap += (line[i] - line[i - 1]).norm();
      }
      c.longest_gap = std::max(c.longest_gap, gap);
    }
  }
  c.pass = c.off_curve == 0 && c.longest_gap <= max_gap && c.euler == c.expected_euler &&
           (!truth.branching_curves.empty() ? !nm.empty() : nm.empty());
  return c;
}

}  // namespace voroudf

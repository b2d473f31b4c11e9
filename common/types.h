#pragma once
// Basic geometric types shared by every library of voroudf.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <vector>

namespace voroudf {

using Vec3 = Eigen::Vector3d;
using Tri = std::array<int, 3>;

/// Axis-aligned box; the domain of a UDF. All relative lengths in voroudf are fractions of its diagonal.
struct Box {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();

  Vec3 Extent() const { return max - min; }
  Vec3 Center() const { return 0.5 * (min + max); }
  double Diagonal() const { return Extent().norm(); }
  bool Contains(const Vec3& p, double slack = 0.0) const {
    return (p.array() >= min.array() - slack).all() && (p.array() <= max.array() + slack).all();
  }
  /// Grows the box by `margin` on every side.
  Box Inflated(double margin) const { return {min.array() - margin, max.array() + margin}; }
};

/// The unit direction from the line through `a` with unit direction `axis` towards `x`, perpendicular to the
/// line: where faces or seeds around an edge lie, compared by angle (thin-mesh's layer and fold tests,
/// build-gvd's sides of a chain link).
inline Vec3 AcrossLine(const Vec3& a, const Vec3& axis, const Vec3& x) {
  Vec3 d = x - a;
  d -= d.dot(axis) * axis;
  return d.normalized();
}

/// An indexed triangle set. Edges may be shared by any number of faces (non-manifold meshes are first-class).
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Tri> faces;
};

}  // namespace voroudf

#pragma once
// Built-in analytic UDFs (`--udf shape:NAME`): exact distances and gradients to simple surfaces with
// sharp edges, corners, open boundaries and non-manifold curves, for demos and tests.
#include <memory>
#include <string>
#include <vector>

#include "common/udf.h"

namespace voroudf {

/// A surface piece with an exact closest-point query.
class Primitive {
 public:
  virtual ~Primitive() = default;
  /// Closest point of the piece to `p`; `normal` receives a unit surface normal at that point.
  /// Where the closest point is not unique (medial axis) one is chosen deterministically.
  virtual Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const = 0;
};

std::unique_ptr<Primitive> MakeSphere(const Vec3& center, double radius);
/// The half of a sphere on the +axis side of the plane through its centre (an open surface).
std::unique_ptr<Primitive> MakeHemisphere(const Vec3& center, double radius, const Vec3& axis);
/// Flat disc, open boundary circle.
std::unique_ptr<Primitive> MakeDisc(const Vec3& center, const Vec3& normal, double radius);
/// Rectangle spanned by unit vectors u, v (orthogonal) with half sizes hu, hv.
std::unique_ptr<Primitive> MakeRectangle(const Vec3& center, const Vec3& u, const Vec3& v, double hu, double hv);
/// Surface of the axis-aligned cube [-h, h]^3 (12 sharp edges, 8 corners).
std::unique_ptr<Primitive> MakeCubeSurface(double half_size);
/// Torus around the z axis (major radius R, minor radius r).
std::unique_ptr<Primitive> MakeTorus(double major_radius, double minor_radius);

/// UDF of a union of primitives: the minimum of their distances, the gradient of the nearest one
/// (the first in order on ties). Exact wherever the primitives' closest points are.
class AnalyticUdf : public Udf {
 public:
  AnalyticUdf(std::string name, std::string description, Box domain, std::vector<std::unique_ptr<Primitive>> parts);
  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  Box Domain() const override { return domain_; }
  std::string Describe() const override;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::string description_;
  Box domain_;
  std::vector<std::unique_ptr<Primitive>> parts_;
};

/// Names accepted by MakeShape, with a one-line description each (for --help and errors).
std::vector<std::pair<std::string, std::string>> ShapeCatalog();

/// Builds the named shape; throws InputError listing the known names for an unknown one.
std::unique_ptr<AnalyticUdf> MakeShape(const std::string& name);

/// The triangle mesh of a polyhedral built-in shape (cube, feature-prism), exactly its surface: its sharp
/// edges and corners are the shape's, so it serves as the reference for evaluating a mesh of the shape.
/// Throws InputError for a shape that is not a polyhedron.
TriangleMesh ShapeMesh(const std::string& name);

/// What is known in closed form of a built-in shape's topology, for tests and the robustness sweep.
struct ShapeTopology {
  long long euler = 0;  ///< Euler characteristic of the surface
  /// Its non-manifold curves (where 3+ sheets meet) as polylines with points every 1e-3 or closer; empty
  /// for a shape without one.
  std::vector<std::vector<Vec3>> branching_curves;
};
/// \pre `name` is in ShapeCatalog()
ShapeTopology KnownTopology(const std::string& name);

}  // namespace voroudf

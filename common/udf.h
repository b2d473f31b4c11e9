#pragma once
// The unsigned distance field interface every stage reads through (DESIGN.md, "UDF sources").
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// An unsigned distance field d: R^3 -> [0, inf) with a unit gradient, on a domain box.
///
/// Gradient conventions (every source keeps them; docs/udf-sources.md):
///  - off the surface the gradient is the unit vector pointing away from the closest surface point,
///    so that x - d(x) * n(x) is that closest point;
///  - where d = 0 (on the surface, where the UDF has a kink) it is a unit normal of the surface there,
///    of either orientation (every use in voroudf is sign-blind: |n.(p-x) - d|, x - 0 * n);
///  - on the medial axis (several closest points) it is the direction to one of them, chosen
///    deterministically.
///  - a source that cannot tell (a flat region of a sampled grid) returns the zero vector.
class Udf {
 public:
  virtual ~Udf() = default;

  /// Distance and gradient at `count` points. Thread-safe: may run concurrently from many threads.
  virtual void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const = 0;

  /// Evaluates a whole batch using all threads (in-process sources split it into chunks; an external
  /// process source sends it as large requests instead).
  virtual void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const;

  /// The field's own domain (mesh bbox plus margin, grid box, shape box).
  virtual Box Domain() const = 0;

  /// One line for logs and provenance, e.g. "shape:cube (surface of [-0.5,0.5]^3)".
  virtual std::string Describe() const = 0;

  // Conveniences over Evaluate.
  void Evaluate(const std::vector<Vec3>& points, std::vector<double>& distance, std::vector<Vec3>& gradient) const;
  double Distance(const Vec3& p) const;
  double Distance(const Vec3& p, Vec3* gradient) const;
};

}  // namespace voroudf

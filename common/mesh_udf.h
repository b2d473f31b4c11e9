#pragma once
// `--udf path.{obj,off,ply,stl}`: the exact unsigned distance to a triangle mesh (DESIGN.md, UDF sources),
// as the paper's benchmarks use for ground-truth meshes.
#include <memory>
#include <string>

#include "common/triangle_bvh.h"
#include "common/udf.h"

namespace voroudf {

struct MeshUdfOptions {
  /// --udf-normalize: move the mesh's bbox centre to the origin and scale its largest bbox extent to 1
  /// before anything else, so a mesh in any units gives the same result; every output is then in that frame.
  bool normalize = false;
  /// Domain box = mesh bbox grown by margin_rel * (largest bbox extent) on every side; 0.1 matches the
  /// built-in shapes (unit extent in [-0.6, 0.6]^3).
  double margin_rel = 0.1;
};

/// d(x) = min over the triangles of the distance to the triangle; the field is defined by the triangles
/// alone (connectivity is ignored), so open, non-manifold, multi-component meshes and STL soups with
/// duplicate or degenerate faces all work.
///
/// Gradient: (x - c)/|x - c| with c the closest point. Where d <= 1e-12 * max(largest bbox extent,
/// largest |coordinate|) (on the
/// surface, where the UDF has a kink) it is the unit normal of the closest triangle, oriented towards x
/// when that side can be told (n.(x - c) >= 0), else as stored; a degenerate triangle's normal is a
/// deterministic unit vector orthogonal to its longest edge. On the medial axis: the direction to the
/// closest point of the tied triangle that comes first in the BVH's leaf order — the same whatever the
/// batch, its order or the thread count (tested). A non-finite query gets a NaN distance and a zero gradient.
///
/// Thread-safe; EvaluateChunk costs one BVH query per point (see tests/bench/bench_udf.cpp).
class MeshUdf : public Udf {
 public:
  /// \param mesh  the triangles (vertices must be finite; faces index valid vertices)
  /// \param name  how Describe() names the source (usually the file path)
  /// Throws InputError if the mesh has no faces or all its vertices coincide.
  MeshUdf(TriangleMesh mesh, std::string name, const MeshUdfOptions& options = {});

  /// Reads the file with ReadMesh (formats/mesh_io.h: .ply .obj .off .stl, STL corners welded).
  /// Throws InputError for an unreadable, malformed or empty mesh.
  static std::unique_ptr<MeshUdf> Open(const std::string& path, const MeshUdfOptions& options = {});

  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  /// Large batches are evaluated in Morton (Z-curve) order of the points, so that consecutive queries
  /// touch the same BVH nodes and triangles (cache locality); results are written back in input order and
  /// do not depend on the order (the traversal depends only on the query point).
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  using Udf::Evaluate;
  Box Domain() const override { return domain_; }
  std::string Describe() const override;

  /// The mesh in the frame of the field (after --udf-normalize if it was asked for).
  const TriangleMesh& mesh() const { return mesh_; }
  const TriangleBvh& bvh() const { return *bvh_; }

 private:
  TriangleMesh mesh_;
  std::string name_;
  MeshUdfOptions options_;
  Box bbox_, domain_;
  Vec3 original_center_ = Vec3::Zero();
  double scale_ = 1.0;  // normalised = (original - original_center_) * scale_
  double on_surface_sq_ = 0.0;
  std::unique_ptr<TriangleBvh> bvh_;
};

}  // namespace voroudf

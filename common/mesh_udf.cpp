#include "common/mesh_udf.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>
#include <limits>
#include <sstream>

#include "common/morton.h"
#include "common/errors.h"
#include "common/udf_spec.h"
#include "formats/mesh_io.h"

namespace voroudf {

MeshUdf::MeshUdf(TriangleMesh mesh, std::string name, const MeshUdfOptions& options)
    : mesh_(std::move(mesh)), name_(std::move(name)), options_(options) {
  if (mesh_.faces.empty()) throw InputError(name_, "the mesh has no triangles (a mesh UDF needs at least one face)");
  Eigen::AlignedBox3d bb;
  for (const Tri& t : mesh_.faces)
    for (int k = 0; k < 3; ++k) bb.extend(mesh_.vertices[t[k]]);  // unreferenced vertices do not count
  double extent = bb.sizes().maxCoeff();
  if (!(extent > 0.0) || !std::isfinite(extent))
    throw InputError(name_, "all the mesh's vertices coincide (zero extent): no surface to measure distances to");
  if (options_.normalize) {
    original_center_ = bb.center();
    scale_ = 1.0 / extent;
    for (Vec3& v : mesh_.vertices) v = (v - original_center_) * scale_;
    bb = Eigen::AlignedBox3d((bb.min() - original_center_) * scale_, (bb.max() - original_center_) * scale_);
    extent = 1.0;
  }
  bbox_ = {bb.min(), bb.max()};
  domain_ = bbox_.Inflated(options_.margin_rel * extent);
  // Rounding in x - c grows with the coordinates' magnitude, not only the extent (a 1 m part placed at
  // 1 km): below this the direction x - c is noise.
  const double magnitude = std::max(bbox_.min.cwiseAbs().maxCoeff(), bbox_.max.cwiseAbs().maxCoeff());
  const double on_surface = 1e-12 * std::max(extent, magnitude);
  on_surface_sq_ = on_surface * on_surface;
  bvh_ = std::make_unique<TriangleBvh>(mesh_.vertices, mesh_.faces);
}

std::unique_ptr<MeshUdf> MeshUdf::Open(const std::string& path, const MeshUdfOptions& options) {
  return std::make_unique<MeshUdf>(ReadMesh(path), path, options);
}

void MeshUdf::EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  int hint = -1;  // consecutive points of a batch are often close (Morton order): start from the last hit
  for (size_t i = 0; i < count; ++i) {
    const TriangleBvh::Hit hit = bvh_->Closest(points[i], hint);
    hint = hit.slot;
    if (hit.face < 0) {  // non-finite query: every comparison failed
      distance[i] = std::numeric_limits<double>::quiet_NaN();
      gradient[i] = Vec3::Zero();
      continue;
    }
    const Vec3 diff = points[i] - hit.point;
    if (hit.sq_distance <= on_surface_sq_) {
      // On the surface (x - c)/|x - c| is noise or 0/0: the triangle's normal, on x's side where measurable.
      const Vec3 n = bvh_->FaceNormal(hit.face);
      gradient[i] = n.dot(diff) < 0.0 ? Vec3(-n) : n;
      distance[i] = diff.norm();
    } else {
      // d = |x - c| (not sqrt of the squared distance) so that x - d n = c to the last bit.
      const double d = diff.norm();
      distance[i] = d;
      gradient[i] = diff / d;
    }
  }
}

void MeshUdf::Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  constexpr size_t kSortAbove = 4096;  // below this a batch fits the caches anyway
  if (count < kSortAbove) {
    Udf::Evaluate(points, count, distance, gradient);
    return;
  }
  const std::vector<size_t> order = MortonOrder(points, count, domain_);
  constexpr size_t kChunk = 256;
  const long chunks = static_cast<long>((count + kChunk - 1) / kChunk);
#pragma omp parallel for schedule(dynamic, 4)
  for (long c = 0; c < chunks; ++c) {
    const size_t begin = static_cast<size_t>(c) * kChunk, end = std::min(count, begin + kChunk);
    Vec3 p[kChunk], g[kChunk];
    double d[kChunk];
    for (size_t i = begin; i < end; ++i) p[i - begin] = points[order[i]];
    EvaluateChunk(p, end - begin, d, g);
    for (size_t i = begin; i < end; ++i) distance[order[i]] = d[i - begin], gradient[order[i]] = g[i - begin];
  }
}

std::string MeshUdf::Describe() const {
  std::ostringstream out;
  out << name_ << " (mesh: " << mesh_.vertices.size() << " vertices, " << mesh_.faces.size() << " triangles";
  if (bvh_->num_degenerate() > 0) out << ", " << bvh_->num_degenerate() << " degenerate";
  out << "; bbox " << FormatBox(bbox_);
  if (options_.normalize) {
    // Full precision: users map results back with x = c + x' / scale.
    std::ostringstream map;
    map.precision(17);
    map << " after --udf-normalize x' = (x - [" << original_center_.x() << "," << original_center_.y() << ","
        << original_center_.z() << "]) * " << scale_;
    out << map.str();
  }
  out << "; domain " << FormatBox(domain_) << " = bbox + " << options_.margin_rel << " * max extent)";
  return out.str();
}

}  // namespace voroudf

#include "common/udf_spec.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <vector>

#include "common/errors.h"
#include "common/exec_udf.h"
#include "common/grid_udf.h"
#include "common/mesh_udf.h"
#include "common/noisy_udf.h"
#include "common/shapes.h"

namespace voroudf {
namespace {

bool StartsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

std::string LowerExtension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

class NormalizedUdf : public Udf {
 public:
  NormalizedUdf(std::unique_ptr<Udf> inner, const Box& frame)
      : inner_(std::move(inner)), center_(frame.Center()), scale_(1.0 / frame.Extent().maxCoeff()) {
    const Box d = inner_->Domain();
    domain_ = {(d.min - center_) * scale_, (d.max - center_) * scale_};
  }
  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    std::vector<Vec3> original(count);
    for (size_t i = 0; i < count; ++i) original[i] = center_ + points[i] / scale_;
    inner_->EvaluateChunk(original.data(), count, distance, gradient);
    for (size_t i = 0; i < count; ++i) distance[i] *= scale_;
  }
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    std::vector<Vec3> original(count);
    for (size_t i = 0; i < count; ++i) original[i] = center_ + points[i] / scale_;
    inner_->Evaluate(original.data(), count, distance, gradient);
    for (size_t i = 0; i < count; ++i) distance[i] *= scale_;
  }
  using Udf::Evaluate;
  Box Domain() const override { return domain_; }
  std::string Describe() const override {
    std::ostringstream out;
    out.precision(17);  // users map results back with x = c + x' / scale
    out << inner_->Describe() << "; --udf-normalize: x' = (x - [" << center_.x() << "," << center_.y() << ","
        << center_.z() << "]) * " << scale_ << ", domain " << FormatBox(domain_);
    return out.str();
  }

 private:
  std::unique_ptr<Udf> inner_;
  Vec3 center_;
  double scale_;
  Box domain_;
};

// "noisy:OPTIONS:INNER" -> {OPTIONS, INNER}: the options end at the first ':' after the prefix, the rest is
// the inner SPEC (which may itself contain ':'). False if there is no such ':'.
bool SplitNoisySpec(const std::string& spec, std::string* options, std::string* inner) {
  const auto colon = spec.find(':', 6);
  if (!StartsWith(spec, "noisy:") || colon == std::string::npos) return false;
  *options = spec.substr(6, colon - 6);
  *inner = spec.substr(colon + 1);
  return true;
}

}  // namespace

std::string FormatBox(const Box& box) {
  std::ostringstream out;
  out << "[" << box.min.x() << "," << box.min.y() << "," << box.min.z() << "]-[" << box.max.x() << ","
      << box.max.y() << "," << box.max.z() << "]";
  return out.str();
}

std::unique_ptr<Udf> NormalizeUdf(std::unique_ptr<Udf> inner, const Box& frame) {
  return std::make_unique<NormalizedUdf>(std::move(inner), frame);
}

std::string BaseUdfSpec(const std::string& spec) {
  std::string base = spec, options, inner;
  while (SplitNoisySpec(base, &options, &inner)) base = inner;
  return base;
}

UdfSourceKind ClassifyUdfSpec(const std::string& spec) {
  if (StartsWith(spec, "shape:")) return UdfSourceKind::kShape;
  if (StartsWith(spec, "exec:")) return UdfSourceKind::kExec;
  if (StartsWith(spec, "unix:")) return UdfSourceKind::kUnix;
  if (StartsWith(spec, "noisy:")) return UdfSourceKind::kNoisy;
  const std::string ext = LowerExtension(spec);
  if (ext == "obj" || ext == "off" || ext == "ply" || ext == "stl") return UdfSourceKind::kMesh;
  if (ext == "npy") return UdfSourceKind::kGrid;
  throw InputError("--udf '" + spec +
                   "': expected shape:NAME, a mesh (.obj .off .ply .stl), a grid (.npy), exec:COMMAND, unix:SOCKET or noisy:OPTIONS:SPEC");
}

std::unique_ptr<Udf> OpenUdf(const std::string& spec, const UdfSourceOptions& options) {
  // Sources whose only box is their domain are normalised by it.
  auto by_domain = [&](std::unique_ptr<Udf> udf) {
    if (!options.normalize) return udf;
    const Box frame = udf->Domain();
    return NormalizeUdf(std::move(udf), frame);
  };
  ExecUdfOptions exec_options;
  exec_options.timeout_s = options.exec_timeout_s;
  switch (ClassifyUdfSpec(spec)) {
    case UdfSourceKind::kShape:
      return MakeShape(spec.substr(6));
    case UdfSourceKind::kMesh: {
      MeshUdfOptions mesh_options;
      mesh_options.normalize = options.normalize;  // by the mesh's own bbox, not the inflated domain
      return MeshUdf::Open(spec, mesh_options);
    }
    case UdfSourceKind::kGrid:
      return by_domain(GridUdf::Open(spec, options.grid_box));
    case UdfSourceKind::kExec:
      return by_domain(std::make_unique<ExecUdf>(spec.substr(5), exec_options));
    case UdfSourceKind::kUnix:
      return by_domain(std::make_unique<ExecUdf>(ExecUdf::UnixSocket{spec.substr(5)}, exec_options));
    case UdfSourceKind::kNoisy: {
      std::string noise_options, inner;
      if (!SplitNoisySpec(spec, &noise_options, &inner))
        throw UsageError("--udf '" + spec + "': expected noisy:OPTIONS:SPEC, e.g. noisy:value=1e-3,grad=15:shape:cube");
      const UdfNoise noise = ParseUdfNoise(noise_options);
      return MakeNoisyUdf(OpenUdf(inner, options), noise);
    }
  }
  throw InputError(spec, "unknown kind of UDF source");
}

}  // namespace voroudf

#include "formats/labels_io.h"

#include "common/errors.h"
#include "common/input_file.h"
#include "formats/kinds.h"
#include "formats/ply.h"

namespace voroudf {

LabeledSamples ReadLabels(const std::string& path) { return LabelsFromPly(ply::Read(path), InputName(path)); }

LabeledSamples LabelsFromPly(const ply::File& file, const std::string& path) {
  CheckDeclaredKind(file, path, "labels", kLabelsFormatVersion);
  const ply::Element& v = RequireElement(file, path, "vertex", "labels");
  const auto& x = RequireScalar(v, path, "x");
  const auto& y = RequireScalar(v, path, "y");
  const auto& z = RequireScalar(v, path, "z");
  const auto& label = RequireScalar(v, path, "label");
  const auto* dist = OptionalScalar(v, path, "dist");
  LabeledSamples s;
  s.position.resize(v.count);
  s.label.resize(v.count);
  s.dist.assign(v.count, 0.0);
  for (size_t i = 0; i < v.count; ++i) {
    s.position[i] = Vec3(x[i], y[i], z[i]);
    if (label[i] < -1 || label[i] != static_cast<int>(label[i]))
      throw InputError(path, "element 'vertex' item " + std::to_string(i) + ": label must be an integer >= -1");
    s.label[i] = static_cast<int>(label[i]);
    if (dist) s.dist[i] = (*dist)[i];
  }
  if (const ply::Element* e = file.Find("edge")) {
    const auto& a = RequireScalar(*e, path, "vertex1");
    const auto& b = RequireScalar(*e, path, "vertex2");
    s.edges.resize(e->count);
    for (size_t i = 0; i < e->count; ++i) {
      if (a[i] < 0 || b[i] < 0 || a[i] >= static_cast<double>(v.count) || b[i] >= static_cast<double>(v.count))
        throw InputError(path, "element 'edge' item " + std::to_string(i) + ": vertex index out of range [0, " +
                                   std::to_string(v.count) + ")");
      s.edges[i] = {static_cast<int>(a[i]), static_cast<int>(b[i])};
    }
  }
  return s;
}

void WriteLabels(const std::string& path, const LabeledSamples& s, const Provenance& provenance, bool ascii) {
  ply::File file;
  file.encoding = ascii ? ply::Encoding::kAscii : ply::Encoding::kBinaryLittleEndian;
  file.comments = ProvenanceComments("labels", kLabelsFormatVersion, provenance);
  ply::Element v = MakeVertexElement(s.position);
  v.properties.push_back(MakeScalar("label", ply::Type::kInt32, std::vector<double>(s.label.begin(), s.label.end())));
  // An unreached sample (label -1) has no geodesic distance: written as -1, so every value is finite.
  std::vector<double> dist = s.dist;
  for (size_t i = 0; i < dist.size() && i < s.label.size(); ++i)
    if (s.label[i] < 0) dist[i] = -1.0;
  v.properties.push_back(MakeScalar("dist", ply::Type::kFloat32, std::move(dist)));
  file.elements.push_back(std::move(v));
  if (!s.edges.empty()) file.elements.push_back(MakeEdgeElement(s.edges));
  ply::Write(path, file);
}

}  // namespace voroudf

#include "formats/kinds.h"

#include <cmath>
#include <sstream>

#include "common/errors.h"

namespace voroudf {

DeclaredKind FindDeclaredKind(const ply::File& file) {
  for (const auto& c : file.comments) {
    std::istringstream in(c);
    std::string tag, kind, version;
    if (!(in >> tag >> kind >> version) || tag != "voroudf") continue;
    DeclaredKind d;
    d.kind = kind;
    try {
      d.version = std::stoi(version);
    } catch (const std::exception&) {
      d.version = -1;
    }
    return d;
  }
  return {};
}

void CheckDeclaredKind(const ply::File& file, const std::string& path, const std::string& kind, int known_version) {
  const DeclaredKind d = FindDeclaredKind(file);
  if (d.kind.empty()) return;  // a file from another tool: judged by its elements alone
  if (d.kind != kind) throw InputError(path, "is a voroudf " + d.kind + " file, expected a " + kind + " file");
  if (d.version < 1) throw InputError(path, "bad voroudf " + kind + " format version in header comment");
  if (d.version > known_version) {
    throw InputError(path, "voroudf " + kind + " format version " + std::to_string(d.version) +
                               " is newer than this program reads (up to " + std::to_string(known_version) +
                               "); update voroudf");
  }
}

std::vector<std::string> ProvenanceComments(const std::string& kind, int version, const Provenance& provenance) {
  std::vector<std::string> c{"voroudf " + kind + " " + std::to_string(version)};
  if (!provenance.stage.empty()) c.push_back("stage " + provenance.stage);
  if (!provenance.udf.empty()) c.push_back("udf " + provenance.udf);
  if (!provenance.options.empty()) c.push_back("options " + provenance.options);
  return c;
}

const ply::Element& RequireElement(const ply::File& file, const std::string& path, const std::string& element,
                                   const std::string& kind) {
  const ply::Element* e = file.Find(element);
  if (!e) throw InputError(path, "no '" + element + "' element (expected a " + kind + " file)");
  return *e;
}

const std::vector<double>* OptionalScalar(const ply::Element& element, const std::string& path,
                                          const std::string& name) {
  const ply::Property* p = element.Find(name);
  if (!p) return nullptr;
  if (p->is_list) throw InputError(path, "element '" + element.name + "' property '" + name + "' is a list, expected a scalar");
  for (size_t i = 0; i < p->values.size(); ++i) {
    if (!std::isfinite(p->values[i])) {
      throw InputError(path, "element '" + element.name + "' item " + std::to_string(i) + " property '" + name +
                                 "' is not finite");
    }
  }
  return &p->values;
}

const std::vector<double>& RequireScalar(const ply::Element& element, const std::string& path, const std::string& name) {
  const auto* v = OptionalScalar(element, path, name);
  if (!v) throw InputError(path, "element '" + element.name + "' has no property '" + name + "'");
  return *v;
}

const ply::Property* FindList(const ply::Element& element, const std::vector<std::string>& names) {
  for (const auto& n : names) {
    const ply::Property* p = element.Find(n);
    if (p && p->is_list) return p;
  }
  return nullptr;
}

ply::Element MakeVertexElement(const std::vector<Vec3>& positions) {
  ply::Element v;
  v.name = "vertex";
  v.count = positions.size();
  const char* names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> col(v.count);
    for (size_t i = 0; i < v.count; ++i) col[i] = positions[i][k];
    v.properties.push_back(MakeScalar(names[k], ply::Type::kFloat32, std::move(col)));
  }
  return v;
}

ply::Element MakeEdgeElement(const std::vector<std::array<int, 2>>& edges) {
  ply::Element e;
  e.name = "edge";
  e.count = edges.size();
  std::vector<double> a(e.count), b(e.count);
  for (size_t i = 0; i < e.count; ++i) {
    a[i] = edges[i][0];
    b[i] = edges[i][1];
  }
  e.properties.push_back(MakeScalar("vertex1", ply::Type::kInt32, std::move(a)));
  e.properties.push_back(MakeScalar("vertex2", ply::Type::kInt32, std::move(b)));
  return e;
}

ply::Property MakeScalar(const std::string& name, ply::Type type, std::vector<double> values) {
  ply::Property p;
  p.name = name;
  p.type = type;
  p.values = std::move(values);
  return p;
}

}  // namespace voroudf

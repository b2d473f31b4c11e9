#include "common/udf_spec.h"

#include <algorithm>
#include <cctype>

#include "common/errors.h"
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

}  // namespace

UdfSourceKind ClassifyUdfSpec(const std::string& spec) {
  if (StartsWith(spec, "shape:")) return UdfSourceKind::kShape;
  if (StartsWith(spec, "exec:")) return UdfSourceKind::kExec;
  const std::string ext = LowerExtension(spec);
  if (ext == "obj" || ext == "off" || ext == "ply" || ext == "stl") return UdfSourceKind::kMesh;
  if (ext == "npy") return UdfSourceKind::kGrid;
  throw InputError("--udf '" + spec +
                   "': expected shape:NAME, a mesh (.obj .off .ply .stl), a grid (.npy) or exec:COMMAND");
}

std::unique_ptr<Udf> OpenUdf(const std::string& spec, const UdfSourceOptions& /*options*/) {
  switch (ClassifyUdfSpec(spec)) {
    case UdfSourceKind::kShape:
      return MakeShape(spec.substr(6));
    case UdfSourceKind::kMesh:
    case UdfSourceKind::kGrid:
    case UdfSourceKind::kExec:
      break;
  }
  throw InputError(spec, "this kind of UDF source is not implemented yet (only shape:NAME is)");
}

}  // namespace voroudf

#pragma once
// `--udf SPEC`: the one parser every stage uses to open a UDF source.
#include <memory>
#include <string>

#include "common/udf.h"

namespace voroudf {

/// What kind of source a SPEC names (by prefix or file extension).
enum class UdfSourceKind { kShape, kMesh, kGrid, kExec };

/// Options that apply to some sources (set from the common CLI flags).
struct UdfSourceOptions {
  std::string grid_box;          ///< --udf-box "xmin,ymin,zmin,xmax,ymax,zmax" for .npy grids
  double exec_timeout_s = 60.0;  ///< --udf-timeout: longest wait for an external process's answer
};

/// Classifies a SPEC; throws InputError (exit 3) for one that names no known kind of source.
UdfSourceKind ClassifyUdfSpec(const std::string& spec);

/// Opens the source named by `spec`: "shape:NAME", "path.{obj,off,ply,stl}", "path.npy", "exec:COMMAND".
/// Throws InputError (exit 3) when the source cannot be opened or is malformed.
std::unique_ptr<Udf> OpenUdf(const std::string& spec, const UdfSourceOptions& options = {});

}  // namespace voroudf

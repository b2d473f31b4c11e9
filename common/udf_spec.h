#pragma once
// `--udf SPEC`: the one parser every stage uses to open a UDF source (docs/udf-sources.md).
#include <memory>
#include <string>

#include "common/udf.h"

namespace voroudf {

/// What kind of source a SPEC names (by prefix or file extension).
enum class UdfSourceKind { kShape, kMesh, kGrid, kExec, kUnix, kNoisy };

/// Options that apply to some sources (set from the common CLI flags).
struct UdfSourceOptions {
  std::string grid_box;          ///< --udf-box "xmin,ymin,zmin,xmax,ymax,zmax" for .npy grids
  double exec_timeout_s = 60.0;  ///< --udf-timeout: longest wait for an external process's answer
  /// --udf-normalize: work in a frame where the source's box is centred on the origin with largest extent 1
  /// (for a mesh the mesh's bbox, for a grid or exec: source the domain box; shapes are already unit-sized
  /// and are left as they are). Every output is then in that frame.
  bool normalize = false;
};

/// Classifies a SPEC; throws InputError (exit 3) for one that names no known kind of source.
UdfSourceKind ClassifyUdfSpec(const std::string& spec);

/// The SPEC without its noisy:OPTIONS: wrappers (the source the field comes from).
std::string BaseUdfSpec(const std::string& spec);

/// Opens the source named by `spec`: "shape:NAME", "path.{obj,off,ply,stl}", "path.npy", "exec:COMMAND",
/// "unix:SOCKET", "noisy:OPTIONS:SPEC" (common/noisy_udf.h).
/// Throws InputError (exit 3) when the source cannot be opened or is malformed, UsageError (exit 2) for a
/// malformed --udf-box.
std::unique_ptr<Udf> OpenUdf(const std::string& spec, const UdfSourceOptions& options = {});

/// "[x0,y0,z0]-[x1,y1,z1]" for logs.
std::string FormatBox(const Box& box);

/// Wraps `inner` so that it is seen in the frame x' = (x - c) * s with c the centre of `frame` and
/// s = 1 / (largest extent of `frame`): d'(x') = s * d(c + x'/s), same unit gradient, domain mapped alike.
/// Batches are forwarded whole (an exec: source keeps its large requests).
std::unique_ptr<Udf> NormalizeUdf(std::unique_ptr<Udf> inner, const Box& frame);

}  // namespace voroudf

#pragma once
// Labelled samples of the geodesic Voronoi diagram (docs/formats.md): PLY `vertex` with float x y z,
// int label (seed index, -1 unreached), float dist (geodesic), and optionally an `edge` element with
// int vertex1 vertex2 (the pruned kNN graph).
#include <array>
#include <string>
#include <vector>

#include "common/provenance.h"
#include "common/types.h"
#include "formats/ply.h"

namespace voroudf {

struct LabeledSamples {
  std::vector<Vec3> position;
  std::vector<int> label;
  std::vector<double> dist;
  std::vector<std::array<int, 2>> edges;  ///< optional graph

  size_t size() const { return position.size(); }
};

/// Reads a labels file. Throws InputError (exit 3) for anything malformed.
LabeledSamples ReadLabels(const std::string& path);
/// The same from a PLY file already parsed; `name` names it in messages.
LabeledSamples LabelsFromPly(const ply::File& file, const std::string& name);
void WriteLabels(const std::string& path, const LabeledSamples& samples, const Provenance& provenance,
                 bool ascii = false);

}  // namespace voroudf

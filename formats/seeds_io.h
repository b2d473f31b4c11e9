#pragma once
// Seeds files (docs/formats.md): PLY `vertex` with float x y z, nx ny nz (UDF gradient), udf, uchar rank.
#include <cstdint>
#include <string>
#include <vector>

#include "common/provenance.h"
#include "common/types.h"
#include "formats/ply.h"

namespace voroudf {

/// Rank of a seed's tangent-plane matrix: what kind of surface point it sits on.
enum SeedRank : uint8_t { kRankUnknown = 0, kRankSheet = 1, kRankEdge = 2, kRankCorner = 3 };

struct SeedCloud {
  std::vector<Vec3> position;
  std::vector<Vec3> normal;     ///< UDF gradient at the seed (zero if the file had none)
  std::vector<double> udf;      ///< UDF value at the seed (0 if the file had none)
  std::vector<uint8_t> rank;    ///< SeedRank
  bool has_field = true;        ///< false when read from a file without nx ny nz udf

  size_t size() const { return position.size(); }
  void Resize(size_t n);
};

/// Reads a seeds file. x y z are required; nx ny nz, udf and rank are optional so that point clouds
/// written by other tools can be used. Throws InputError (exit 3) for anything malformed.
SeedCloud ReadSeeds(const std::string& path);
/// The same from a PLY file already parsed; `name` names it in messages.
SeedCloud SeedsFromPly(const ply::File& file, const std::string& name);

/// Writes atomically, binary little-endian unless `ascii`.
void WriteSeeds(const std::string& path, const SeedCloud& seeds, const Provenance& provenance, bool ascii = false);

}  // namespace voroudf

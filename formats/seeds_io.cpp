#include "formats/seeds_io.h"

#include "common/errors.h"
#include "common/input_file.h"
#include "formats/kinds.h"
#include "formats/ply.h"

namespace voroudf {

void SeedCloud::Resize(size_t n) {
  position.resize(n, Vec3::Zero());
  normal.resize(n, Vec3::Zero());
  udf.resize(n, 0.0);
  rank.resize(n, kRankUnknown);
}

SeedCloud ReadSeeds(const std::string& path) { return SeedsFromPly(ply::Read(path), InputName(path)); }

SeedCloud SeedsFromPly(const ply::File& file, const std::string& path) {
  CheckDeclaredKind(file, path, "seeds", kSeedsFormatVersion);
  if (FindDeclaredKind(file).kind.empty()) {
    const ply::Element* faces = file.Find("face");
    if (faces && faces->count > 0) throw InputError(path, "has a 'face' element: this is a mesh, not a seeds file");
  }
  const ply::Element& v = RequireElement(file, path, "vertex", "seeds");
  const auto& x = RequireScalar(v, path, "x");
  const auto& y = RequireScalar(v, path, "y");
  const auto& z = RequireScalar(v, path, "z");
  const auto* nx = OptionalScalar(v, path, "nx");
  const auto* ny = OptionalScalar(v, path, "ny");
  const auto* nz = OptionalScalar(v, path, "nz");
  const auto* udf = OptionalScalar(v, path, "udf");
  const auto* rank = OptionalScalar(v, path, "rank");
  if ((nx || ny || nz) && !(nx && ny && nz)) throw InputError(path, "element 'vertex' has only some of nx ny nz");

  SeedCloud seeds;
  seeds.Resize(v.count);
  seeds.has_field = nx && udf;
  for (size_t i = 0; i < v.count; ++i) {
    seeds.position[i] = Vec3(x[i], y[i], z[i]);
    if (nx) seeds.normal[i] = Vec3((*nx)[i], (*ny)[i], (*nz)[i]);
    if (udf) seeds.udf[i] = (*udf)[i];
    if (rank) {
      const double r = (*rank)[i];
      if (r < 0 || r > 3 || r != static_cast<int>(r))
        throw InputError(path, "element 'vertex' item " + std::to_string(i) + ": rank must be 0..3");
      seeds.rank[i] = static_cast<uint8_t>(r);
    }
  }
  return seeds;
}

void WriteSeeds(const std::string& path, const SeedCloud& seeds, const Provenance& provenance, bool ascii) {
  const size_t n = seeds.size();
  std::vector<double> c[5];
  for (auto& col : c) col.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) c[k][i] = seeds.normal[i][k];
    c[3][i] = seeds.udf[i];
    c[4][i] = seeds.rank[i];
  }
  ply::File file;
  file.encoding = ascii ? ply::Encoding::kAscii : ply::Encoding::kBinaryLittleEndian;
  file.comments = ProvenanceComments("seeds", kSeedsFormatVersion, provenance);
  ply::Element v = MakeVertexElement(seeds.position);
  const char* names[4] = {"nx", "ny", "nz", "udf"};
  for (int k = 0; k < 4; ++k) v.properties.push_back(MakeScalar(names[k], ply::Type::kFloat32, std::move(c[k])));
  v.properties.push_back(MakeScalar("rank", ply::Type::kUInt8, std::move(c[4])));
  file.elements.push_back(std::move(v));
  ply::Write(path, file);
}

}  // namespace voroudf

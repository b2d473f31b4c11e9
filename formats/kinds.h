#pragma once
// The voroudf file kinds and their versions, and the checks every reader of them shares.
// A voroudf file says what it is in a header comment: `comment voroudf <kind> <version>`.
#include <array>
#include <string>
#include <vector>

#include "common/provenance.h"
#include "common/types.h"
#include "formats/ply.h"

namespace voroudf {

/// Current version of each voroudf file kind. A reader refuses a newer version than it knows.
inline constexpr int kSeedsFormatVersion = 1;
inline constexpr int kLabelsFormatVersion = 1;
inline constexpr int kMeshFormatVersion = 1;
inline constexpr int kEdgesFormatVersion = 1;

/// Which voroudf kind a file declares ("" if it has no voroudf comment, as files from other tools).
struct DeclaredKind {
  std::string kind;
  int version = 0;
};
DeclaredKind FindDeclaredKind(const ply::File& file);

/// Refuses a file that declares another voroudf kind, or a newer version of this one.
void CheckDeclaredKind(const ply::File& file, const std::string& path, const std::string& kind, int known_version);

/// Header comments for a file of `kind`: the kind line, then stage, udf and options.
std::vector<std::string> ProvenanceComments(const std::string& kind, int version, const Provenance& provenance);

/// Required element; the message names the kind of file expected.
const ply::Element& RequireElement(const ply::File& file, const std::string& path, const std::string& element,
                                   const std::string& kind);
/// Required scalar property; finite values enforced.
const std::vector<double>& RequireScalar(const ply::Element& element, const std::string& path, const std::string& name);
/// Optional scalar property (nullptr if absent); finite values enforced when present.
const std::vector<double>* OptionalScalar(const ply::Element& element, const std::string& path,
                                          const std::string& name);
/// The first of `names` that exists as a list property (nullptr if none).
const ply::Property* FindList(const ply::Element& element, const std::vector<std::string>& names);

/// A `vertex` element with float x y z (further properties may be appended).
ply::Element MakeVertexElement(const std::vector<Vec3>& positions);
/// An `edge` element with int vertex1 vertex2.
ply::Element MakeEdgeElement(const std::vector<std::array<int, 2>>& edges);

/// A scalar property filled from values (ints or floats as `type`).
ply::Property MakeScalar(const std::string& name, ply::Type type, std::vector<double> values);

}  // namespace voroudf

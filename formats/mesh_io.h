#pragma once
// Meshes (docs/formats.md): PLY `vertex` float x y z + `face` list uchar int vertex_indices, kept as plain
// indexed face sets so that edges shared by 3+ faces survive. Reference meshes may also be OBJ, OFF or STL.
#include <array>
#include <string>
#include <vector>

#include "common/provenance.h"
#include "common/types.h"
#include "formats/ply.h"

namespace voroudf {

/// Reads a voroudf mesh or any PLY mesh (float or double coordinates, `vertex_indices` or `vertex_index`,
/// polygons split into triangle fans, extra properties ignored). Throws InputError.
TriangleMesh ReadMeshPly(const std::string& path);
/// The same from a PLY file already parsed; `name` names it in messages.
TriangleMesh MeshFromPly(const ply::File& file, const std::string& name);

/// Reads .ply, .obj, .off or .stl (chosen by extension, case-insensitive). STL vertices are welded
/// (bit-identical positions become one vertex). Throws InputError.
TriangleMesh ReadMesh(const std::string& path);
/// The same from a file's bytes in memory; `format` is "ply", "obj", "off" or "stl", `name` names the
/// file in messages. Throws InputError.
TriangleMesh ParseMesh(const std::string& bytes, const std::string& format, const std::string& name);

void WriteMeshPly(const std::string& path, const TriangleMesh& mesh, const Provenance& provenance, bool ascii = false);

/// A set of line segments (e.g. the non-manifold edges of a mesh) as PLY `vertex` + `edge` (vertex1 vertex2).
struct EdgeSet {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 2>> edges;
};
void WriteEdgesPly(const std::string& path, const EdgeSet& edges, const Provenance& provenance, bool ascii = false);

}  // namespace voroudf

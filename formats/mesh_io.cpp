#include "formats/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "common/errors.h"
#include "common/input_file.h"
#include "formats/kinds.h"
#include "formats/ply.h"

namespace voroudf {
namespace {

std::string LowerExtension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}


// Appends polygon `poly` as a triangle fan after checking its indices.
void AddPolygon(TriangleMesh& mesh, const std::vector<long long>& poly, size_t num_vertices, const std::string& path,
                const std::string& where) {
  if (poly.size() < 3) throw InputError(path, where + ": a face needs at least 3 vertices");
  for (long long i : poly) {
    if (i < 0 || i >= static_cast<long long>(num_vertices)) {
      throw InputError(path, where + ": vertex index " + std::to_string(i) + " out of range [0, " +
                                 std::to_string(num_vertices) + ")");
    }
  }
  for (size_t k = 1; k + 1 < poly.size(); ++k)
    mesh.faces.push_back({static_cast<int>(poly[0]), static_cast<int>(poly[k]), static_cast<int>(poly[k + 1])});
}

void CheckFiniteVertices(const TriangleMesh& mesh, const std::string& path) {
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite()) throw InputError(path, "vertex " + std::to_string(i) + " is not finite");
}

double ParseNumber(const std::string& token, const std::string& path, int line) {
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || end != token.c_str() + token.size())
    throw InputError(path, "line " + std::to_string(line) + ": '" + token + "' is not a number");
  return v;
}

TriangleMesh ParseObj(const std::string& bytes, const std::string& path) {
  std::istringstream in(bytes);
  TriangleMesh mesh;
  std::vector<std::vector<long long>> faces;
  std::vector<int> face_lines;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    if (key == "v") {
      std::string a, b, c;
      if (!(words >> a >> b >> c)) throw InputError(path, "line " + std::to_string(line_no) + ": 'v' needs x y z");
      mesh.vertices.emplace_back(ParseNumber(a, path, line_no), ParseNumber(b, path, line_no),
                                 ParseNumber(c, path, line_no));
    } else if (key == "f") {
      std::vector<long long> poly;
      std::string token;
      while (words >> token) {
        // "i", "i/t", "i//n", "i/t/n"; negative indices count back from the last vertex so far.
        const std::string first = token.substr(0, token.find('/'));
        char* end = nullptr;
        const long long idx = std::strtoll(first.c_str(), &end, 10);
        if (first.empty() || end != first.c_str() + first.size() || idx == 0)
          throw InputError(path, "line " + std::to_string(line_no) + ": bad face index '" + token + "'");
        poly.push_back(idx > 0 ? idx - 1 : static_cast<long long>(mesh.vertices.size()) + idx);
      }
      faces.push_back(std::move(poly));
      face_lines.push_back(line_no);
    }
  }
  for (size_t f = 0; f < faces.size(); ++f)
    AddPolygon(mesh, faces[f], mesh.vertices.size(), path, "line " + std::to_string(face_lines[f]));
  return mesh;
}

// An OFF index or count: an integer-valued number in [0, limit].
long long ParseIndex(const std::string& token, double limit, const std::string& path, int line, const char* what) {
  const double v = ParseNumber(token, path, line);
  if (!(v >= 0 && v <= limit) || v != std::floor(v))
    throw InputError(path, "line " + std::to_string(line) + ": " + what + " '" + token + "' is not an integer in [0, " +
                               std::to_string(static_cast<long long>(limit)) + "]");
  return static_cast<long long>(v);
}

TriangleMesh ParseOff(const std::string& bytes, const std::string& path) {
  std::istringstream in(bytes);
  std::string line;
  int line_no = 0;
  // Lines without comments and blanks, as token lists.
  auto next = [&](std::vector<std::string>* tokens) {
    while (std::getline(in, line)) {
      ++line_no;
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream w(line);
      tokens->clear();
      std::string t;
      while (w >> t) tokens->push_back(t);
      if (!tokens->empty()) return true;
    }
    return false;
  };
  std::vector<std::string> t;
  if (!next(&t)) throw InputError(path, "empty file");
  const std::string magic = t[0];
  if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0)
    throw InputError(path, "not an OFF file (first word is '" + magic + "')");
  if (std::find(t.begin(), t.end(), "BINARY") != t.end()) throw InputError(path, "binary OFF is not supported");
  t.erase(t.begin());
  if (t.empty() && !next(&t)) throw InputError(path, "missing vertex/face counts");
  if (t.size() < 2) throw InputError(path, "line " + std::to_string(line_no) + ": expected vertex and face counts");
  const long long nv = ParseIndex(t[0], 1e9, path, line_no, "vertex count");
  const long long nf = ParseIndex(t[1], 1e9, path, line_no, "face count");
  // A vertex line takes at least 6 bytes ("0 0 0\n") and a face line 8 ("3 0 1 2\n"): counts the file
  // cannot hold are refused before anything is reserved from them.
  if (6.0 * static_cast<double>(nv) + 8.0 * static_cast<double>(nf) > static_cast<double>(bytes.size()))
    throw InputError(path, "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                               " faces, more than its " + std::to_string(bytes.size()) + " bytes can hold (truncated?)");
  TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(nv));
  for (size_t i = 0; i < static_cast<size_t>(nv); ++i) {
    if (!next(&t)) throw InputError(path, "file ends after " + std::to_string(i) + " of " + std::to_string(static_cast<size_t>(nv)) + " vertices (truncated?)");
    if (t.size() < 3) throw InputError(path, "line " + std::to_string(line_no) + ": a vertex needs x y z");
    mesh.vertices.emplace_back(ParseNumber(t[0], path, line_no), ParseNumber(t[1], path, line_no),
                               ParseNumber(t[2], path, line_no));
  }
  for (size_t f = 0; f < static_cast<size_t>(nf); ++f) {
    if (!next(&t)) throw InputError(path, "file ends after " + std::to_string(f) + " of " + std::to_string(static_cast<size_t>(nf)) + " faces (truncated?)");
    const long long k = ParseIndex(t[0], 1e6, path, line_no, "face size");
    if (t.size() < static_cast<size_t>(k) + 1)
      throw InputError(path, "line " + std::to_string(line_no) + ": face has fewer indices than its count");
    std::vector<long long> poly;
    for (size_t j = 1; j <= static_cast<size_t>(k); ++j)
      poly.push_back(ParseIndex(t[j], static_cast<double>(mesh.vertices.size()), path, line_no, "vertex index"));
    AddPolygon(mesh, poly, mesh.vertices.size(), path, "line " + std::to_string(line_no));
  }
  return mesh;
}

// Welds bit-identical vertices (STL stores every triangle's corners separately).
struct VertexWelder {
  struct Hash {
    size_t operator()(const std::array<float, 3>& p) const {
      uint32_t b[3];
      std::memcpy(b, p.data(), sizeof b);
      return (static_cast<size_t>(b[0]) * 73856093u) ^ (static_cast<size_t>(b[1]) * 19349663u) ^
             (static_cast<size_t>(b[2]) * 83492791u);
    }
  };
  std::unordered_map<std::array<float, 3>, int, Hash> index;
  int Add(TriangleMesh& mesh, const std::array<float, 3>& p) {
    const auto [it, inserted] = index.emplace(p, static_cast<int>(mesh.vertices.size()));
    if (inserted) mesh.vertices.emplace_back(p[0], p[1], p[2]);
    return it->second;
  }
};

TriangleMesh ParseStl(const std::string& bytes, const std::string& path) {
  TriangleMesh mesh;
  VertexWelder welder;
  uint32_t n = 0;
  if (bytes.size() >= 84) std::memcpy(&n, bytes.data() + 80, 4);
  const bool binary = bytes.size() >= 84 && bytes.size() == 84 + 50ull * n;
  if (binary) {
    mesh.faces.reserve(n);
    for (uint32_t f = 0; f < n; ++f) {
      const char* rec = bytes.data() + 84 + 50ull * f;
      Tri tri;
      for (int k = 0; k < 3; ++k) {
        std::array<float, 3> p;
        std::memcpy(p.data(), rec + 12 + 12 * k, 12);
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
          throw InputError(path, "triangle " + std::to_string(f) + " has a non-finite vertex");
        tri[k] = welder.Add(mesh, p);
      }
      mesh.faces.push_back(tri);
    }
    return mesh;
  }
  if (bytes.compare(0, 5, "solid") != 0)
    throw InputError(path, "not an STL file (neither ASCII 'solid' nor a binary size of 84 + 50 * triangles bytes)");
  std::istringstream in(bytes);
  std::string line;
  std::vector<int> corners;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string word, a, b, c;
    if (!(words >> word) || word != "vertex") continue;
    if (!(words >> a >> b >> c)) throw InputError(path, "line " + std::to_string(line_no) + ": 'vertex' needs x y z");
    const std::array<float, 3> p{static_cast<float>(ParseNumber(a, path, line_no)),
                                 static_cast<float>(ParseNumber(b, path, line_no)),
                                 static_cast<float>(ParseNumber(c, path, line_no))};
    corners.push_back(welder.Add(mesh, p));
  }
  if (corners.size() % 3 != 0) throw InputError(path, "ASCII STL has a facet without 3 vertices (truncated?)");
  for (size_t i = 0; i < corners.size(); i += 3) mesh.faces.push_back({corners[i], corners[i + 1], corners[i + 2]});
  return mesh;
}

}  // namespace

TriangleMesh ReadMeshPly(const std::string& path) { return MeshFromPly(ply::Read(path), InputName(path)); }

TriangleMesh MeshFromPly(const ply::File& file, const std::string& path) {
  CheckDeclaredKind(file, path, "mesh", kMeshFormatVersion);
  const ply::Element& v = RequireElement(file, path, "vertex", "mesh");
  const auto& x = RequireScalar(v, path, "x");
  const auto& y = RequireScalar(v, path, "y");
  const auto& z = RequireScalar(v, path, "z");
  const ply::Element* f = file.Find("face");
  if (!f) throw InputError(path, "no 'face' element (expected a mesh file)");
  const ply::Property* idx = FindList(*f, {"vertex_indices", "vertex_index"});
  if (!idx) throw InputError(path, "element 'face' has no list property 'vertex_indices'");
  TriangleMesh mesh;
  mesh.vertices.resize(v.count);
  for (size_t i = 0; i < v.count; ++i) mesh.vertices[i] = Vec3(x[i], y[i], z[i]);
  mesh.faces.reserve(f->count);
  size_t cursor = 0;
  std::vector<long long> poly;
  for (size_t i = 0; i < f->count; ++i) {
    poly.clear();
    for (uint32_t k = 0; k < idx->list_sizes[i]; ++k) poly.push_back(static_cast<long long>(idx->values[cursor++]));
    AddPolygon(mesh, poly, v.count, path, "element 'face' item " + std::to_string(i));
  }
  return mesh;
}

TriangleMesh ReadMesh(const std::string& path) {
  if (path == "-") return ParseMesh(ReadInputBytes(path), "ply", InputName(path));  // a stream is a pipeline mesh
  const std::string ext = LowerExtension(path);
  if (ext == "ply") {
    TriangleMesh mesh = ReadMeshPly(path);
    CheckFiniteVertices(mesh, path);
    return mesh;
  }
  if (ext != "obj" && ext != "off" && ext != "stl")
    throw InputError(path, "unknown mesh file extension (expected .ply, .obj, .off or .stl)");
  return ParseMesh(ReadInputBytes(path), ext, path);
}

TriangleMesh ParseMesh(const std::string& bytes, const std::string& format, const std::string& name) {
  TriangleMesh mesh;
  if (format == "ply") mesh = MeshFromPly(ply::Parse(bytes, name), name);
  else if (format == "obj") mesh = ParseObj(bytes, name);
  else if (format == "off") mesh = ParseOff(bytes, name);
  else if (format == "stl") mesh = ParseStl(bytes, name);
  else throw InputError(name, "unknown mesh format '" + format + "'");
  CheckFiniteVertices(mesh, name);
  return mesh;
}

void WriteMeshPly(const std::string& path, const TriangleMesh& mesh, const Provenance& provenance, bool ascii) {
  ply::File file;
  file.encoding = ascii ? ply::Encoding::kAscii : ply::Encoding::kBinaryLittleEndian;
  file.comments = ProvenanceComments("mesh", kMeshFormatVersion, provenance);
  ply::Element f;
  f.name = "face";
  f.count = mesh.faces.size();
  ply::Property idx;
  idx.name = "vertex_indices";
  idx.is_list = true;
  idx.count_type = ply::Type::kUInt8;
  idx.type = ply::Type::kInt32;
  idx.list_sizes.assign(f.count, 3);
  idx.values.reserve(3 * f.count);
  for (const Tri& t : mesh.faces)
    for (int k : t) idx.values.push_back(k);
  f.properties.push_back(std::move(idx));
  file.elements.push_back(MakeVertexElement(mesh.vertices));
  file.elements.push_back(std::move(f));
  ply::Write(path, file);
}

void WriteEdgesPly(const std::string& path, const EdgeSet& edges, const Provenance& provenance, bool ascii) {
  ply::File file;
  file.encoding = ascii ? ply::Encoding::kAscii : ply::Encoding::kBinaryLittleEndian;
  file.comments = ProvenanceComments("edges", kEdgesFormatVersion, provenance);
  file.elements.push_back(MakeVertexElement(edges.vertices));
  file.elements.push_back(MakeEdgeElement(edges.edges));
  ply::Write(path, file);
}

}  // namespace voroudf

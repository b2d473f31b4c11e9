#pragma once
// A complete PLY reader and writer (ASCII, binary little- and big-endian; every scalar type; list
// properties), on which the seeds, labels and mesh formats are built. Written by hand because none of the
// design's libraries reads PLY correctly for us: PCL's writer handles float32 only and OpenMesh tears
// non-manifold meshes apart.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace voroudf::ply {

enum class Type : uint8_t { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };
enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

/// Name as written in headers ("float", "uchar", ...).
const char* TypeName(Type type);
/// Accepts both spellings ("float"/"float32", "uchar"/"uint8", ...); returns false for unknown names.
bool ParseType(const std::string& name, Type* type);

/// One property of an element, values held as double (exact for every PLY scalar type).
struct Property {
  std::string name;
  Type type = Type::kFloat32;
  bool is_list = false;
  Type count_type = Type::kUInt8;    ///< type of the list length (lists only)
  std::vector<double> values;        ///< scalars: one per item; lists: all items' entries concatenated
  std::vector<uint32_t> list_sizes;  ///< lists only: entries per item
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;

  const Property* Find(const std::string& property) const;
  Property* Find(const std::string& property);
};

struct File {
  Encoding encoding = Encoding::kBinaryLittleEndian;
  std::vector<std::string> comments;  ///< `comment` lines, without the keyword
  std::vector<Element> elements;

  const Element* Find(const std::string& element) const;
};

/// Reads and validates the structure of a PLY file: magic, format line, header syntax, counts, list sizes,
/// truncation. Throws InputError naming the file, the element and what was expected.
File Read(const std::string& path);
/// Same, from bytes already in memory; `name` is used in error messages.
File Parse(const std::string& bytes, const std::string& name);

/// Serialises a file. Scalars are stored as their declared type (floats printed with enough digits to
/// round-trip exactly in ASCII). Binary output is little- or big-endian as requested, whatever the host.
std::string Serialize(const File& file);

/// Serialize + atomic write (temporary file and rename). Throws OutputError.
void Write(const std::string& path, const File& file);

}  // namespace voroudf::ply

#include "formats/ply.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/atomic_file.h"
#include "common/input_file.h"
#include "common/errors.h"

namespace voroudf::ply {
namespace {

constexpr size_t kMaxHeaderBytes = 1 << 20;

size_t TypeSize(Type t) {
  switch (t) {
    case Type::kInt8: case Type::kUInt8: return 1;
    case Type::kInt16: case Type::kUInt16: return 2;
    case Type::kInt32: case Type::kUInt32: case Type::kFloat32: return 4;
    case Type::kFloat64: return 8;
  }
  return 0;
}

bool HostIsLittleEndian() {
  const uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

bool IsIntegral(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

double IntegralMin(Type t) {
  switch (t) {
    case Type::kInt8: return -128;
    case Type::kInt16: return -32768;
    case Type::kInt32: return -2147483648.0;
    default: return 0;
  }
}

double IntegralMax(Type t) {
  switch (t) {
    case Type::kInt8: return 127;
    case Type::kUInt8: return 255;
    case Type::kInt16: return 32767;
    case Type::kUInt16: return 65535;
    case Type::kInt32: return 2147483647.0;
    default: return 4294967295.0;
  }
}

// Reads one binary scalar at p (swapping bytes if the file's order differs from the host's).
double DecodeBinary(const unsigned char* p, Type t, bool swap) {
  unsigned char b[8];
  const size_t n = TypeSize(t);
  for (size_t i = 0; i < n; ++i) b[i] = swap ? p[n - 1 - i] : p[i];
  switch (t) {
    case Type::kInt8: { int8_t v; std::memcpy(&v, b, 1); return v; }
    case Type::kUInt8: return b[0];
    case Type::kInt16: { int16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::kUInt16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
    case Type::kInt32: { int32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::kUInt32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
    case Type::kFloat32: { float v; std::memcpy(&v, b, 4); return v; }
    case Type::kFloat64: { double v; std::memcpy(&v, b, 8); return v; }
  }
  return 0.0;
}

void EncodeBinary(double value, Type t, bool swap, std::string& out) {
  unsigned char b[8];
  switch (t) {
    case Type::kInt8: { const int8_t v = static_cast<int8_t>(value); std::memcpy(b, &v, 1); break; }
    case Type::kUInt8: { const uint8_t v = static_cast<uint8_t>(value); std::memcpy(b, &v, 1); break; }
    case Type::kInt16: { const int16_t v = static_cast<int16_t>(value); std::memcpy(b, &v, 2); break; }
    case Type::kUInt16: { const uint16_t v = static_cast<uint16_t>(value); std::memcpy(b, &v, 2); break; }
    case Type::kInt32: { const int32_t v = static_cast<int32_t>(value); std::memcpy(b, &v, 4); break; }
    case Type::kUInt32: { const uint32_t v = static_cast<uint32_t>(value); std::memcpy(b, &v, 4); break; }
    case Type::kFloat32: { const float v = static_cast<float>(value); std::memcpy(b, &v, 4); break; }
    case Type::kFloat64: std::memcpy(b, &value, 8); break;
  }
  const size_t n = TypeSize(t);
  for (size_t i = 0; i < n; ++i) out.push_back(static_cast<char>(swap ? b[n - 1 - i] : b[i]));
}

void EncodeAscii(double value, Type t, std::string& out) {
  char buf[40];
  int len;
  if (t == Type::kFloat32) {
    len = std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(static_cast<float>(value)));
  } else if (t == Type::kFloat64) {
    len = std::snprintf(buf, sizeof buf, "%.17g", value);
  } else {
    len = std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(value));
  }
  out.append(buf, static_cast<size_t>(len));
}

std::vector<std::string> SplitWords(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  std::string w;
  while (in >> w) words.push_back(w);
  return words;
}

// Cursor over the body, binary or ASCII, with error messages that say where the problem is.
class BodyReader {
 public:
  BodyReader(const std::string& bytes, size_t pos, const std::string& name, Encoding enc)
      : bytes_(bytes), pos_(pos), name_(name), enc_(enc),
        swap_((enc == Encoding::kBinaryLittleEndian) != HostIsLittleEndian()) {}

  double Next(Type t, const Element& e, size_t item, const std::string& prop) {
    if (enc_ == Encoding::kAscii) return NextAscii(t, e, item, prop);
    const size_t n = TypeSize(t);
    if (pos_ + n > bytes_.size()) Truncated(e, item);
    const double v = DecodeBinary(reinterpret_cast<const unsigned char*>(bytes_.data()) + pos_, t, swap_);
    pos_ += n;
    return v;
  }

  [[noreturn]] void Truncated(const Element& e, size_t item) const {
    throw InputError(name_, "element '" + e.name + "': file ends in item " + std::to_string(item) + " of " +
                                std::to_string(e.count) + " (truncated file?)");
  }

  /// Bytes left after the body: a binary file with fewer bytes than its header promises is truncated
  /// (checked before parsing so that a huge bogus count fails fast).
  size_t Remaining() const { return bytes_.size() - pos_; }

 private:
  double NextAscii(Type t, const Element& e, size_t item, const std::string& prop) {
    const char* s = bytes_.data();
    const size_t end = bytes_.size();
    while (pos_ < end && std::isspace(static_cast<unsigned char>(s[pos_]))) ++pos_;
    if (pos_ >= end) Truncated(e, item);
    size_t stop = pos_;
    while (stop < end && !std::isspace(static_cast<unsigned char>(s[stop]))) ++stop;
    const std::string token(s + pos_, stop - pos_);
    pos_ = stop;
    char* parse_end = nullptr;
    errno = 0;
    const double v = std::strtod(token.c_str(), &parse_end);
    if (parse_end == token.c_str() || parse_end != token.c_str() + token.size()) {  // also a NUL inside
      throw InputError(name_, "element '" + e.name + "' item " + std::to_string(item) + " property '" + prop +
                                  "': '" + token + "' is not a number");
    }
    if (IsIntegral(t) && std::isfinite(v) && v != std::floor(v)) {
      throw InputError(name_, "element '" + e.name + "' item " + std::to_string(item) + " property '" + prop +
                                  "': '" + token + "' is not an integer");
    }
    // A binary value always fits its type; an ASCII one must too, or writing it back would wrap it.
    if (IsIntegral(t) && !(v >= IntegralMin(t) && v <= IntegralMax(t))) {
      throw InputError(name_, "element '" + e.name + "' item " + std::to_string(item) + " property '" + prop +
                                  "': " + token + " does not fit a " + TypeName(t));
    }
    // A float32 property holds a float: "%.9g" text converts back to exactly the float that was written.
    return t == Type::kFloat32 ? static_cast<double>(static_cast<float>(v)) : v;
  }

  const std::string& bytes_;
  size_t pos_;
  const std::string& name_;
  Encoding enc_;
  bool swap_;
};

// A count that may exceed every integer type (a header can declare 10^19 items of 8 bytes).
std::string Whole(long double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0Lf", x);
  return buf;
}

// A comment is one header line: control characters (a newline in a --udf path, say) would end it and
// let the rest be read as header keywords, so they are written as \xNN.
std::string EscapeComment(const std::string& c) {
  std::string out;
  for (unsigned char ch : c) {
    if (ch >= 0x20 && ch != 0x7f) {
      out += static_cast<char>(ch);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", ch);
      out += buf;
    }
  }
  return out;
}

// Every value must survive its declared type: finite, and for float32 within its range (a double beyond
// FLT_MAX would be written as inf). NumericalError (exit 4): the numbers, not the input, went wrong.
void CheckRepresentable(const File& file, const std::string& path) {
  for (const auto& e : file.elements)
    for (const auto& p : e.properties) {
      if (IsIntegral(p.type)) continue;
      const double limit = p.type == Type::kFloat32 ? std::numeric_limits<float>::max() : std::numeric_limits<double>::max();
      for (size_t k = 0; k < p.values.size(); ++k)
        if (!(std::abs(p.values[k]) <= limit)) {
          char value[40];
          std::snprintf(value, sizeof value, "%g", p.values[k]);
          throw NumericalError(path + ": element '" + e.name + "' property '" + p.name + "' value " +
                               std::to_string(k) + " is " + value + ", not a finite " + TypeName(p.type) +
                               ": nothing written");
        }
    }
}

}  // namespace

const char* TypeName(Type type) {
  switch (type) {
    case Type::kInt8: return "char";
    case Type::kUInt8: return "uchar";
    case Type::kInt16: return "short";
    case Type::kUInt16: return "ushort";
    case Type::kInt32: return "int";
    case Type::kUInt32: return "uint";
    case Type::kFloat32: return "float";
    case Type::kFloat64: return "double";
  }
  return "?";
}

bool ParseType(const std::string& n, Type* t) {
  if (n == "char" || n == "int8") *t = Type::kInt8;
  else if (n == "uchar" || n == "uint8") *t = Type::kUInt8;
  else if (n == "short" || n == "int16") *t = Type::kInt16;
  else if (n == "ushort" || n == "uint16") *t = Type::kUInt16;
  else if (n == "int" || n == "int32") *t = Type::kInt32;
  else if (n == "uint" || n == "uint32") *t = Type::kUInt32;
  else if (n == "float" || n == "float32") *t = Type::kFloat32;
  else if (n == "double" || n == "float64") *t = Type::kFloat64;
  else return false;
  return true;
}

const Property* Element::Find(const std::string& property) const {
  for (const auto& p : properties)
    if (p.name == property) return &p;
  return nullptr;
}

Property* Element::Find(const std::string& property) {
  for (auto& p : properties)
    if (p.name == property) return &p;
  return nullptr;
}

const Element* File::Find(const std::string& element) const {
  for (const auto& e : elements)
    if (e.name == element) return &e;
  return nullptr;
}

File Read(const std::string& path) {
  const std::string name = path == "-" ? "stdin" : path;
  const std::string bytes = ReadInputBytes(path, [&](const std::string& head) {
    if (head.compare(0, 4, "ply\n") != 0 && head.compare(0, 5, "ply\r\n") != 0)
      throw InputError(name, "not a PLY file (first line is not 'ply')");
  });
  return Parse(bytes, name);
}

namespace {

// The header: elements and properties declared, encoding, comments. `pos` ends at the body's first byte.
File ParseHeader(const std::string& bytes, const std::string& name, size_t& pos) {
  File file;
  pos = 0;
  int line_no = 0;
  bool have_format = false;
  auto next_line = [&](std::string* line) {
    if (pos >= bytes.size() || pos > kMaxHeaderBytes) return false;
    size_t nl = bytes.find('\n', pos);
    if (nl == std::string::npos) nl = bytes.size();
    *line = bytes.substr(pos, nl - pos);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos = std::min(nl + 1, bytes.size());  // a last line without '\n' ends the bytes, never beyond them
    ++line_no;
    return true;
  };
  auto header_error = [&](const std::string& what) {
    throw InputError(name, "PLY header line " + std::to_string(line_no) + ": " + what);
  };

  std::string line;
  if (!next_line(&line) || line != "ply") throw InputError(name, "not a PLY file (first line is not 'ply')");
  if (bytes.find("end_header", pos) == std::string::npos)
    throw InputError(name, "PLY header has no 'end_header' (truncated or not a PLY file)");
  bool ended = false;
  while (next_line(&line)) {
    const auto words = SplitWords(line);
    if (words.empty()) continue;
    const std::string& key = words[0];
    if (key == "format") {
      if (words.size() != 3) header_error("expected 'format <encoding> 1.0'");
      if (words[1] == "ascii") file.encoding = Encoding::kAscii;
      else if (words[1] == "binary_little_endian") file.encoding = Encoding::kBinaryLittleEndian;
      else if (words[1] == "binary_big_endian") file.encoding = Encoding::kBinaryBigEndian;
      else header_error("unknown encoding '" + words[1] + "'");
      if (words[2] != "1.0" && words[2] != "1") header_error("unsupported PLY version '" + words[2] + "'");
      have_format = true;
    } else if (key == "comment") {
      const size_t text = line.find_first_not_of(" \t", line.find("comment") + 7);
      file.comments.push_back(text == std::string::npos ? std::string() : line.substr(text));
    } else if (key == "obj_info") {
      continue;
    } else if (key == "element") {
      if (words.size() != 3) header_error("expected 'element <name> <count>'");
      char* end = nullptr;
      errno = 0;
      const unsigned long long count = std::strtoull(words[2].c_str(), &end, 10);
      if (end != words[2].data() + words[2].size() || words[2][0] == '-' || errno == ERANGE)
        header_error("element '" + words[1] + "' has a bad count '" + words[2] + "'");
      Element e;
      e.name = words[1];
      e.count = static_cast<size_t>(count);
      file.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (file.elements.empty()) header_error("property before any element");
      Property p;
      if (words.size() == 5 && words[1] == "list") {
        p.is_list = true;
        if (!ParseType(words[2], &p.count_type) || !IsIntegral(p.count_type))
          header_error("bad list count type '" + words[2] + "'");
        if (!ParseType(words[3], &p.type)) header_error("unknown type '" + words[3] + "'");
        p.name = words[4];
      } else if (words.size() == 3) {
        if (!ParseType(words[1], &p.type)) header_error("unknown type '" + words[1] + "'");
        p.name = words[2];
      } else {
        header_error("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
      }
      file.elements.back().properties.push_back(std::move(p));
    } else if (key == "end_header") {
      if (words.size() != 1) header_error("'end_header' must be alone on its line");
      ended = true;
      break;
    } else {
      header_error("unknown keyword '" + key + "'");
    }
  }
  if (!ended) throw InputError(name, "PLY header has no 'end_header' (truncated or not a PLY file)");
  if (!have_format) throw InputError(name, "PLY header has no 'format' line");
  return file;
}

// Refuses a body too short for what the header declares, before anything is allocated from its counts.
void CheckBodyLength(const File& file, const BodyReader& body, const std::string& name) {
  // Nothing is reserved from a declared count the file cannot hold. An ASCII value takes at least two
  // bytes (a digit and a separator; the last may end the file), so an ASCII body of more values than half
  // its bytes is truncated whatever it says.
  if (file.encoding == Encoding::kAscii) {
    long double values = 0;
    for (const auto& e : file.elements)
      values += static_cast<long double>(e.properties.size()) * static_cast<long double>(e.count);
    if (values > static_cast<long double>(body.Remaining() + 1) / 2)
      throw InputError(name, "file is shorter than its header promises (" + Whole(values) + " values declared, " +
                                 std::to_string(body.Remaining()) + " bytes of ASCII data): truncated file?");
  }
  // A binary body of fixed-size items can be checked against the file size before anything is allocated.
  if (file.encoding != Encoding::kAscii) {
    long double need = 0;
    bool has_list = false;
    for (const auto& e : file.elements) {
      size_t item = 0;
      for (const auto& p : e.properties) {
        if (p.is_list) has_list = true;
        item += TypeSize(p.is_list ? p.count_type : p.type);
      }
      need += static_cast<long double>(item) * static_cast<long double>(e.count);
    }
    if (need > static_cast<long double>(body.Remaining())) {
      throw InputError(name, std::string("file is shorter than its header promises") +
                                 (has_list ? " (at least " : " (") + Whole(need) +
                                 " bytes of data, " + std::to_string(body.Remaining()) + " present): truncated file?");
    }
  }
}

void ReadBody(File& file, BodyReader& body, const std::string& name) {
  for (auto& e : file.elements) {
    // Items of no property take no bytes: nothing to read, however many the header declares (a loop over
    // 10^19 of them would never end).
    if (e.properties.empty()) continue;
    for (auto& p : e.properties) {
      if (!p.is_list) p.values.reserve(e.count);
      else p.list_sizes.reserve(e.count);
    }
    for (size_t item = 0; item < e.count; ++item) {
      for (auto& p : e.properties) {
        if (!p.is_list) {
          p.values.push_back(body.Next(p.type, e, item, p.name));
          continue;
        }
        const double n = body.Next(p.count_type, e, item, p.name);
        if (!(n >= 0 && n <= 1e6)) {
          throw InputError(name, "element '" + e.name + "' item " + std::to_string(item) + " property '" + p.name +
                                     "': bad list length " + std::to_string(n));
        }
        const auto len = static_cast<uint32_t>(n);
        p.list_sizes.push_back(len);
        for (uint32_t k = 0; k < len; ++k) p.values.push_back(body.Next(p.type, e, item, p.name));
      }
    }
  }
}

}  // namespace

File Parse(const std::string& bytes, const std::string& name) {
  size_t pos = 0;
  File file = ParseHeader(bytes, name, pos);
  BodyReader body(bytes, pos, name, file.encoding);
  CheckBodyLength(file, body, name);
  ReadBody(file, body, name);
  return file;
}

std::string Serialize(const File& file) {
  std::string out;
  out += "ply\nformat ";
  out += file.encoding == Encoding::kAscii ? "ascii" : file.encoding == Encoding::kBinaryLittleEndian
                                                           ? "binary_little_endian"
                                                           : "binary_big_endian";
  out += " 1.0\n";
  for (const auto& c : file.comments) out += "comment " + EscapeComment(c) + "\n";
  size_t body_bytes = 0;
  for (const auto& e : file.elements) {
    out += "element " + e.name + " " + std::to_string(e.count) + "\n";
    for (const auto& p : e.properties) {
      if (p.is_list) {
        out += std::string("property list ") + TypeName(p.count_type) + " " + TypeName(p.type) + " " + p.name + "\n";
        body_bytes += p.list_sizes.size() * TypeSize(p.count_type) + p.values.size() * TypeSize(p.type);
      } else {
        out += std::string("property ") + TypeName(p.type) + " " + p.name + "\n";
        body_bytes += p.values.size() * TypeSize(p.type);
      }
    }
  }
  out += "end_header\n";
  const bool ascii = file.encoding == Encoding::kAscii;
  const bool swap = (file.encoding == Encoding::kBinaryLittleEndian) != HostIsLittleEndian();
  out.reserve(out.size() + (ascii ? 4 * body_bytes : body_bytes));
  for (const auto& e : file.elements) {
    if (e.properties.empty()) continue;  // items of no property are no bytes (as the parser reads them)
    std::vector<size_t> cursor(e.properties.size(), 0);
    for (size_t item = 0; item < e.count; ++item) {
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        if (ascii && k > 0) out.push_back(' ');
        if (!p.is_list) {
          ascii ? EncodeAscii(p.values[item], p.type, out) : EncodeBinary(p.values[item], p.type, swap, out);
          continue;
        }
        const uint32_t len = p.list_sizes[item];
        ascii ? EncodeAscii(len, p.count_type, out) : EncodeBinary(len, p.count_type, swap, out);
        for (uint32_t j = 0; j < len; ++j) {
          const double v = p.values[cursor[k]++];
          if (ascii) {
            out.push_back(' ');
            EncodeAscii(v, p.type, out);
          } else {
            EncodeBinary(v, p.type, swap, out);
          }
        }
      }
      if (ascii) out.push_back('\n');
    }
  }
  return out;
}

void Write(const std::string& path, const File& file) {
  CheckRepresentable(file, path);
  WriteFileAtomically(path, Serialize(file));
}

}  // namespace voroudf::ply

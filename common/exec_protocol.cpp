#include "common/exec_protocol.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace voroudf::protocol {
namespace {

void PutU32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }
uint32_t GetU32(const char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

}  // namespace

std::string Printable(const char* data, size_t n) {
  std::string s;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(data[i]);
    if (c >= 32 && c < 127) {
      s += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      s += buf;
    }
  }
  return s;
}

Hello ParseHello(const char* head) {
  if (std::memcmp(head, "VUDF", 4) != 0)
    throw ProtocolError("not a voroudf UDF server: its output starts with '" + Printable(head, 4) +
                        "', expected the magic 'VUDF' (docs/exec-protocol.md)");
  const uint32_t version = GetU32(head + 4);
  if (version != kVersion)
    throw ProtocolError("the server speaks protocol version " + std::to_string(version) +
                        ", this program knows version " + std::to_string(kVersion));
  float box[6];
  std::memcpy(box, head + 8, sizeof box);
  for (float b : box)
    if (!std::isfinite(b)) throw ProtocolError("the handshake's domain box has a non-finite number");
  Hello hello;
  hello.domain = Box{Vec3(box[0], box[1], box[2]), Vec3(box[3], box[4], box[5])};
  if (!(hello.domain.min.array() < hello.domain.max.array()).all())
    throw ProtocolError("the handshake's domain box is empty (min >= max)");
  if (!std::isfinite(hello.domain.Diagonal()))
    throw ProtocolError("the handshake's domain box is too large (its diagonal overflows)");
  hello.name_length = GetU32(head + 32);
  if (hello.name_length > kMaxNameBytes)
    throw ProtocolError("the handshake's server name is " + std::to_string(hello.name_length) +
                        " bytes long (at most 4096)");
  return hello;
}

std::string EncodeRequest(const Vec3* points, size_t count) {
  std::string request;
  request.reserve(4 + 12 * count);
  PutU32(request, static_cast<uint32_t>(count));
  for (size_t i = 0; i < count; ++i) {
    const float xyz[3] = {static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                          static_cast<float>(points[i].z())};
    request.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  }
  return request;
}

void CheckAnswerCount(const char* bytes4, size_t count) {
  const uint32_t echoed = GetU32(bytes4);
  if (echoed != count)
    throw ProtocolError("answered " + std::to_string(echoed) + " values to a request of " + std::to_string(count) +
                        " points (wrong count or garbage)");
}

void DecodeAnswer(const char* body, size_t count, uint64_t first_index, double* distance, Vec3* gradient) {
  for (size_t i = 0; i < count; ++i) {
    float d, g[3];
    std::memcpy(&d, body + 4 * i, 4);
    std::memcpy(g, body + 4 * count + 12 * i, 12);
    const Vec3 gi(g[0], g[1], g[2]);
    if (!std::isfinite(d) || !gi.allFinite())
      throw ProtocolError("answered a non-finite distance or gradient for point " + std::to_string(first_index + i) +
                          " (garbage?)");
    // Learned fields dip slightly below zero; the UDF is max(d, 0).
    distance[i] = std::max(0.0, static_cast<double>(d));
    const double len = gi.norm();
    gradient[i] = len > 0.0 && std::isfinite(len) ? Vec3(gi / len) : Vec3::Zero();
  }
}

}  // namespace voroudf::protocol

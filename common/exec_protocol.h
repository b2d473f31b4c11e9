#pragma once
// The bytes of the UDF server protocol (docs/exec-protocol.md), apart from the transport: what the client
// sends and how it reads what a server answers. Pure functions over buffers, so that they can be fuzzed
// and shared by every transport (exec: pipes today).
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "common/types.h"

namespace voroudf::protocol {

constexpr uint32_t kVersion = 1;
constexpr uint32_t kMaxRequest = 1u << 20;  ///< points per request
constexpr size_t kHelloBytes = 36;          ///< "VUDF", version, 6 float32 box, name length
constexpr uint32_t kMaxNameBytes = 4096;

/// What a server did wrong, in words for the user (the transport adds who the server is).
class ProtocolError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Hello {
  Box domain;
  uint32_t name_length = 0;  ///< bytes of server name that follow the fixed part
};

/// Parses the fixed kHelloBytes of a handshake. Throws ProtocolError for a wrong magic or version, a
/// non-finite or empty box, a name longer than kMaxNameBytes.
Hello ParseHello(const char* bytes);

/// The server name as printable text (other bytes as \xNN).
std::string Printable(const char* data, size_t n);

/// A request: uint32 count, then count float32 (x, y, z). \pre count <= kMaxRequest
std::string EncodeRequest(const Vec3* points, size_t count);

/// Bytes of an answer to a request of `count` points, after its uint32 count.
inline size_t AnswerBodyBytes(size_t count) { return 16 * count; }

/// Checks the uint32 count that starts an answer. Throws ProtocolError unless it equals `count`.
void CheckAnswerCount(const char* bytes4, size_t count);

/// Decodes an answer body (count float32 distances, then count float32 (gx, gy, gz)): distances are
/// clamped at 0 (a learned field dips below), gradients normalised (zero stays zero). Throws
/// ProtocolError for a non-finite value, naming the point as `first_index` + its place.
void DecodeAnswer(const char* body, size_t count, uint64_t first_index, double* distance, Vec3* gradient);

}  // namespace voroudf::protocol

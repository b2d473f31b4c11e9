#include "tests/fuzz/harnesses.h"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/exec_protocol.h"
#include "common/grid_udf.h"
#include "formats/labels_io.h"
#include "formats/mesh_io.h"
#include "formats/ply.h"
#include "formats/seeds_io.h"

namespace voroudf::fuzz {
namespace {

// A property-level fingerprint of a parsed file, to compare a file with its round trip.
std::string Shape(const ply::File& f) {
  std::string s = std::to_string(static_cast<int>(f.encoding)) + ":" + std::to_string(f.comments.size());
  for (const auto& e : f.elements) {
    s += "|" + e.name + "#" + std::to_string(e.count);
    for (const auto& p : e.properties)
      s += "," + p.name + std::to_string(p.values.size()) + "/" + std::to_string(p.list_sizes.size());
  }
  return s;
}

template <typename F>
void ExpectErrorOrResult(F&& f) {
  try {
    f();
  } catch (const Error&) {
    // the one documented way to refuse input
  }
}

}  // namespace

void Ply(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  ply::File file;
  try {
    file = ply::Parse(bytes, "fuzz.ply");
  } catch (const Error&) {
    return;
  }
  ExpectErrorOrResult([&] { SeedsFromPly(file, "fuzz.ply"); });
  ExpectErrorOrResult([&] { LabelsFromPly(file, "fuzz.ply"); });
  ExpectErrorOrResult([&] { MeshFromPly(file, "fuzz.ply"); });
  // What was read can be written and read back the same. Non-finite values are refused by the writers
  // (ply::Write), not by Serialize, so they are skipped here.
  for (const auto& e : file.elements)
    for (const auto& p : e.properties)
      for (double v : p.values)
        if (!(v == v) || v - v != 0) return;
  const ply::File back = ply::Parse(ply::Serialize(file), "round trip");
  if (Shape(back) != Shape(file)) std::abort();
  for (size_t i = 0; i < file.elements.size(); ++i)
    for (size_t k = 0; k < file.elements[i].properties.size(); ++k)
      if (back.elements[i].properties[k].values != file.elements[i].properties[k].values) std::abort();
}

void MeshText(const uint8_t* data, size_t size) {
  if (size == 0) return;
  static const char* const kFormats[] = {"obj", "off", "stl", "ply"};
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  ExpectErrorOrResult([&] {
    const TriangleMesh mesh = ParseMesh(bytes, kFormats[data[0] % 4], "fuzz");
    for (const Tri& t : mesh.faces)
      for (int v : t)
        if (v < 0 || static_cast<size_t>(v) >= mesh.vertices.size()) std::abort();
  });
}

void Npy(const uint8_t* data, size_t size) {
  if (size == 0) return;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if (data[0] % 2 == 1) {
    ExpectErrorOrResult([&] { ParseBoxJson(bytes, "fuzz.json"); });
    return;
  }
  ExpectErrorOrResult([&] {
    const NpyArray a = ParseNpyFloat32(bytes, "fuzz.npy");
    if (a.shape.size() != 3) return;
    const GridUdf grid(a.data, {a.shape[0], a.shape[1], a.shape[2]}, Box{Vec3::Zero(), Vec3::Ones()}, {}, "fuzz");
    const Vec3 probes[3] = {Vec3(0.5, 0.5, 0.5), Vec3(-1, 2, 0.25), Vec3(0, 0, 0)};
    double d[3];
    Vec3 g[3];
    grid.EvaluateChunk(probes, 3, d, g);
    for (int i = 0; i < 3; ++i)
      if (!(d[i] >= 0) || !g[i].allFinite()) std::abort();
  });
}

void ExecProtocol(const uint8_t* data, size_t size) {
  const char* p = reinterpret_cast<const char*>(data);
  if (size < protocol::kHelloBytes) return;
  try {
    const protocol::Hello hello = protocol::ParseHello(p);
    if (!std::isfinite(hello.domain.Diagonal())) std::abort();
    size_t at = protocol::kHelloBytes + hello.name_length;
    if (at > size) return;
    protocol::Printable(p + protocol::kHelloBytes, hello.name_length);
    uint64_t answered = 0;
    while (at < size) {
      const size_t count = 1 + static_cast<unsigned char>(p[at++]) % 64;
      std::vector<Vec3> points(count, Vec3(0.25, -0.5, 1e30));
      if (protocol::EncodeRequest(points.data(), count).size() != 4 + 12 * count) std::abort();
      if (at + 4 + protocol::AnswerBodyBytes(count) > size) return;
      protocol::CheckAnswerCount(p + at, count);
      std::vector<double> d(count);
      std::vector<Vec3> g(count);
      protocol::DecodeAnswer(p + at + 4, count, answered, d.data(), g.data());
      for (size_t i = 0; i < count; ++i)
        if (!(d[i] >= 0) || !std::isfinite(d[i]) || !g[i].allFinite() || g[i].norm() > 1 + 1e-9) std::abort();
      answered += count;
      at += 4 + protocol::AnswerBodyBytes(count);
    }
  } catch (const protocol::ProtocolError&) {
  }
}

}  // namespace voroudf::fuzz

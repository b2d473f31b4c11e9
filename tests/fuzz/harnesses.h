#pragma once
// The fuzz harnesses' bodies (pipelines/fuzz.sh runs them under libFuzzer): each feeds arbitrary bytes to
// one reader the way a stage would and accepts exactly two outcomes, a result or a voroudf::Error. A crash,
// a sanitizer report, another exception or an allocation beyond the fuzzer's limit is a bug. The same
// functions run over the committed corpus and every past crash in test_fuzz_regressions, so a fixed
// crash stays fixed in the ordinary test suite.
#include <cstddef>
#include <cstdint>

namespace voroudf::fuzz {

/// PLY parser, then the seeds, labels and mesh readers on what it parsed; a parsed file must serialise
/// and parse back to the same structure.
void Ply(const uint8_t* data, size_t size);
/// OBJ, OFF and STL readers (the first byte picks one), and PLY meshes.
void MeshText(const uint8_t* data, size_t size);
/// The .npy reader (then a grid UDF over the array when it is a 3-D grid) or the JSON box sidecar (first byte).
void Npy(const uint8_t* data, size_t size);
/// The exec: protocol client: a handshake, then answers to requests of sizes taken from the bytes.
void ExecProtocol(const uint8_t* data, size_t size);

}  // namespace voroudf::fuzz

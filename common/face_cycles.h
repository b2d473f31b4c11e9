#pragma once
// Which faces of a triangle set lie on a small closed shell (a 2-cycle over GF(2)), as faces are removed
// one by one. The homotopy argument behind thin-mesh's step 3b and build-gvd's hole guard: removing a face
// of a 2-cycle lowers b2 by one and keeps b0 and b1; removing a face with a free edge is a collapse and keeps
// all three; any other removal opens a hole (b1 + 1). Written by hand: no installed library tracks
// homology under face removal, and the local tests are Gaussian eliminations over a few tens of faces.
#include <array>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// Whether the edge set `target` (a face's three edges) is, over GF(2), a sum of the edge sets `rows`.
bool InGf2Span(const std::array<int, 3>& target, const std::vector<std::array<int, 3>>& rows);

/// A triangle set (any edge valences) whose faces can be removed, with local homology tests.
class FaceComplex {
 public:
  /// All faces present. \pre no face repeats a vertex
  explicit FaceComplex(const std::vector<Tri>& faces);

  bool present(int f) const { return present_[static_cast<size_t>(f)] != 0; }
  void Remove(int f);
  /// Whether an edge of face f has no other present face.
  bool HasFreeEdge(int f) const;
  /// Whether present face f lies on a 2-cycle of present faces whose vertices are all within `rings` edges
  /// (over present faces) of f's vertices: f's edges are, over GF(2), the sum of those faces' edges.
  bool OnLocalTwoCycle(int f, int rings) const;

 private:
  std::vector<Tri> faces_;
  std::vector<char> present_;
  std::vector<int> valence_;
  std::vector<std::array<int, 3>> face_edges_;
  std::vector<std::vector<int>> vertex_faces_;
};

}  // namespace voroudf

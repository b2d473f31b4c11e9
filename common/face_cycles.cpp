#include "common/face_cycles.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "common/mesh_topology.h"

namespace voroudf {

// Gaussian elimination on bitsets over the edges that occur, each row reduced against an echelon basis keyed
// by its leading bit; the target is in the span iff it reduces to zero.
bool InGf2Span(const std::array<int, 3>& target, const std::vector<std::array<int, 3>>& rows) {
  std::unordered_map<int, int> column;
  for (int e : target) column.emplace(e, static_cast<int>(column.size()));
  for (const auto& r : rows)
    for (int e : r) column.emplace(e, static_cast<int>(column.size()));
  const size_t words = (column.size() + 63) / 64;
  auto bits = [&](const std::array<int, 3>& edges) {
    std::vector<uint64_t> row(words, 0);
    for (int e : edges) {
      const int c = column.at(e);
      row[static_cast<size_t>(c / 64)] ^= uint64_t{1} << (c % 64);
    }
    return row;
  };
  auto lead = [&](const std::vector<uint64_t>& row) {
    for (size_t w = words; w-- > 0;)
      if (row[w]) return static_cast<int>(w * 64 + 63) - __builtin_clzll(row[w]);
    return -1;
  };
  std::unordered_map<int, std::vector<uint64_t>> basis;
  auto reduce = [&](std::vector<uint64_t>& row) {  // to zero (returns -1) or to a new leading bit
    for (int l = lead(row); l >= 0; l = lead(row)) {
      const auto it = basis.find(l);
      if (it == basis.end()) return l;
      for (size_t w = 0; w < words; ++w) row[w] ^= it->second[w];
    }
    return -1;
  };
  for (const auto& r : rows) {
    std::vector<uint64_t> row = bits(r);
    const int l = reduce(row);
    if (l >= 0) basis.emplace(l, std::move(row));
  }
  std::vector<uint64_t> t = bits(target);
  return reduce(t) < 0;
}

FaceComplex::FaceComplex(const std::vector<Tri>& faces) : faces_(faces), present_(faces.size(), 1) {
  const EdgeFaces incidence = BuildEdgeFaces(faces_);
  valence_.resize(incidence.edges.size());
  for (size_t e = 0; e < valence_.size(); ++e) valence_[e] = static_cast<int>(incidence.faces[e].size());
  face_edges_.resize(faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) {
    const Tri& t = faces_[f];
    face_edges_[f] = {incidence.Find(t[0], t[1]), incidence.Find(t[1], t[2]), incidence.Find(t[2], t[0])};
    for (int v : t) {
      if (static_cast<size_t>(v) >= vertex_faces_.size()) vertex_faces_.resize(static_cast<size_t>(v) + 1);
      vertex_faces_[static_cast<size_t>(v)].push_back(static_cast<int>(f));
    }
  }
}

void FaceComplex::Remove(int f) {
  if (!present_[static_cast<size_t>(f)]) return;
  present_[static_cast<size_t>(f)] = 0;
  for (int e : face_edges_[static_cast<size_t>(f)]) --valence_[static_cast<size_t>(e)];
}

bool FaceComplex::HasFreeEdge(int f) const {
  for (int e : face_edges_[static_cast<size_t>(f)])
    if (valence_[static_cast<size_t>(e)] == 1) return true;
  return false;
}

bool FaceComplex::OnLocalTwoCycle(int f, int rings) const {
  for (int e : face_edges_[static_cast<size_t>(f)])
    if (valence_[static_cast<size_t>(e)] < 2) return false;  // a free edge is on no 2-cycle
  const Tri& tf = faces_[static_cast<size_t>(f)];
  std::unordered_set<int> near(tf.begin(), tf.end());
  std::vector<int> frontier(tf.begin(), tf.end());
  for (int r = 0; r < rings; ++r) {
    std::vector<int> next;
    for (int v : frontier)
      for (int g : vertex_faces_[static_cast<size_t>(v)])
        if (present_[static_cast<size_t>(g)])
          for (int w : faces_[static_cast<size_t>(g)])
            if (near.insert(w).second) next.push_back(w);
    frontier.swap(next);
  }
  std::vector<int> local;  // present faces other than f with every vertex near f
  for (int v : near)
    for (int g : vertex_faces_[static_cast<size_t>(v)]) {
      const Tri& t = faces_[static_cast<size_t>(g)];
      if (g != f && present_[static_cast<size_t>(g)] && near.count(t[0]) && near.count(t[1]) && near.count(t[2]))
        local.push_back(g);
    }
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());
  std::vector<std::array<int, 3>> rows;
  rows.reserve(local.size());
  for (int g : local) rows.push_back(face_edges_[static_cast<size_t>(g)]);
  return InGf2Span(face_edges_[static_cast<size_t>(f)], rows);
}

}  // namespace voroudf

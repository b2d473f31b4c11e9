#include "stages/thin-mesh/close_holes.h"

#include <algorithm>
#include <iterator>
#include <map>
#include <set>

#include "common/mesh_topology.h"

namespace voroudf {
namespace {

using EdgePair = std::pair<int, int>;
EdgePair KeyOf(int u, int v) { return {std::min(u, v), std::max(u, v)}; }

/// Whether a face of triangle quality `quality` counts as degenerate (below `min_quality`, or of zero area).
bool IsDegenerate(double quality, double min_quality) { return !(quality >= min_quality) || quality == 0.0; }

/// Whether the faces (u, v, x) and (u, v, z) lie on the same side of their edge u-v, nearly coplanar: the
/// perpendiculars from the edge to x and to z within acos(min_cos) of each other.
bool SameSideOfEdge(const std::vector<Vec3>& vertices, int u, int v, int x, int z, double min_cos) {
  const Vec3& pu = vertices[static_cast<size_t>(u)];
  const Vec3 axis = (vertices[static_cast<size_t>(v)] - pu).normalized();
  auto perp = [&](int w) {
    Vec3 d = vertices[static_cast<size_t>(w)] - pu;
    d -= d.dot(axis) * axis;
    return d.norm() > 0.0 ? Vec3(d.normalized()) : d;
  };
  return perp(x).dot(perp(z)) >= min_cos;
}

/// Drops the faces marked in `gone` (order kept) and appends `added`.
void ReplaceFaces(std::vector<Tri>& faces, const std::vector<char>& gone, const std::vector<Tri>& added) {
  std::vector<Tri> next;
  for (size_t f = 0; f < faces.size(); ++f)
    if (!gone[f]) next.push_back(faces[f]);
  next.insert(next.end(), added.begin(), added.end());
  faces.swap(next);
}

/// The faces around each edge of a face list, for the hole-closing steps: each edge's third vertices, and
/// each vertex's neighbours along boundary edges (edges with one face).
struct EdgeFans {
  std::map<EdgePair, std::vector<int>> third;
  std::map<int, std::vector<int>> open;  // sorted

  explicit EdgeFans(const std::vector<Tri>& faces) {
    for (const Tri& t : faces)
      for (int k = 0; k < 3; ++k) {
        const int u = t[static_cast<size_t>(k)], v = t[static_cast<size_t>((k + 1) % 3)];
        third[KeyOf(u, v)].push_back(t[static_cast<size_t>((k + 2) % 3)]);
      }
    for (const auto& [e, w] : third)
      if (w.size() == 1) {
        open[e.first].push_back(e.second);
        open[e.second].push_back(e.first);
      }
    for (auto& [v, nb] : open) std::sort(nb.begin(), nb.end());
  }
  bool HasEdge(int u, int v) const { return third.count(KeyOf(u, v)) > 0; }
  bool HasFace(int u, int v, int w) const {
    const auto it = third.find(KeyOf(u, v));
    return it != third.end() && std::find(it->second.begin(), it->second.end(), w) != it->second.end();
  }
  /// Whether a face (u, v, w) would lie over a face of edge u-v: third vertices within acos(min_cos) of
  /// each other seen from the edge.
  bool Over(const std::vector<Vec3>& vertices, int u, int v, int w, double min_cos) const {
    const auto it = third.find(KeyOf(u, v));
    if (it == third.end()) return false;
    for (int z : it->second)
      if (SameSideOfEdge(vertices, u, v, w, z, min_cos)) return true;
    return false;
  }
  /// A new face (u, v, w): not degenerate, not there already, over no face of its three edges.
  bool Fits(const std::vector<Vec3>& vertices, int u, int v, int w, double min_quality, double min_cos) const {
    const double q = TriangleQuality(vertices[static_cast<size_t>(u)], vertices[static_cast<size_t>(v)],
                                     vertices[static_cast<size_t>(w)]);
    return !IsDegenerate(q, min_quality) && !HasFace(u, v, w) && !Over(vertices, u, v, w, min_cos) &&
           !Over(vertices, v, w, u, min_cos) && !Over(vertices, w, u, v, min_cos);
  }
};

}  // namespace

// Adds the face (a, b, c) wherever b has boundary edges (edges with one face) to a and to c and the
/// third side a-c is an edge too, either a boundary edge (a triangular hole) or one with faces (a notch
/// next to a branching curve or a sheet), unless the triangle is degenerate or would lie over a face of
/// one of its edges (third vertices within acos(min_cos) of each other seen from the edge: at an open rim
/// that is the face already there). Returns the number added.
size_t CloseTriangularHoles(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double min_quality,
                            double min_cos) {
  const EdgeFans fans(faces);
  size_t added = 0;
  std::set<Tri> done;
  for (const auto& [b, nb] : fans.open)
    for (size_t i = 0; i < nb.size(); ++i)
      for (size_t j = i + 1; j < nb.size(); ++j) {
        const int a = nb[i], c = nb[j];
        if (!fans.HasEdge(a, c)) continue;
        const Tri t = SortedTri({a, b, c});
        if (!done.insert(t).second || !fans.Fits(vertices, a, b, c, min_quality, min_cos)) continue;
        faces.push_back(t);
        ++added;
      }
  // A sheet's face missing at a branching curve: a boundary edge (a, b) whose ends are both joined to a
  // vertex m by branching edges (3+ faces). The hole (a, b, m) is bounded by one free edge and two edges of
  // the curve, which the missing face leaves one sheet short; (a, b, m) closes it.
  std::map<int, std::vector<int>> branching;  // vertex -> its neighbours along branching edges, sorted
  for (const auto& [e, w] : fans.third)
    if (w.size() >= 3) {
      branching[e.first].push_back(e.second);
      branching[e.second].push_back(e.first);
    }
  for (auto& [v, nb] : branching) std::sort(nb.begin(), nb.end());
  std::set<EdgePair> closed;  // the free edges the faces above were given
  for (size_t f = faces.size() - added; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      closed.insert(KeyOf(faces[f][static_cast<size_t>(k)], faces[f][static_cast<size_t>((k + 1) % 3)]));
  for (const auto& [e, w] : fans.third) {
    if (w.size() != 1 || closed.count(e)) continue;
    const auto ia = branching.find(e.first), ib = branching.find(e.second);
    if (ia == branching.end() || ib == branching.end()) continue;
    std::vector<int> common;
    std::set_intersection(ia->second.begin(), ia->second.end(), ib->second.begin(), ib->second.end(),
                          std::back_inserter(common));
    for (int m : common) {
      const Tri t = SortedTri({e.first, e.second, m});
      if (!done.insert(t).second || !fans.Fits(vertices, e.first, e.second, m, min_quality, min_cos)) continue;
      faces.push_back(t);
      ++added;
      break;  // one face per free edge
    }
  }
  return added;
}

// Cracks: a boundary edge (a, b) whose one face is (a, b, s), with a vertex m that is joined to a
/// and to b by edges and lies on the segment a-b (the triangle (a, m, b) a sliver, quality below
/// `max_sliver_quality`), is a T-junction: one sheet's face spans the edge that the other sheets split at
/// m (on sphere-disc, a curve seed whose region the disc's dense samples missed). The face is split into
/// (a, m, s) and (m, b, s), unless either is degenerate, exists, or would lie over a face of its edge on
/// m (third vertices within acos(min_cos) of each other seen from the edge). Returns the faces split.
size_t SplitFacesOverCracks(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double min_quality,
                            double min_cos, double max_sliver_quality) {
  auto at = [&](int v) -> const Vec3& { return vertices[static_cast<size_t>(v)]; };
  size_t split = 0;
  for (int round = 0; round < 4; ++round) {
    const EdgeFans fans(faces);
    std::map<EdgePair, size_t> face_of;    // edge -> (the last of) its faces
    std::map<int, std::set<int>> joined;  // vertex -> its neighbours along edges
    for (size_t f = 0; f < faces.size(); ++f) {
      const Tri& t = faces[f];
      for (int k = 0; k < 3; ++k) {
        const int u = t[static_cast<size_t>(k)], v = t[static_cast<size_t>((k + 1) % 3)];
        face_of[KeyOf(u, v)] = f;
        joined[u].insert(v);
        joined[v].insert(u);
      }
    }
    std::set<Tri> existing;
    for (const Tri& t : faces) existing.insert(SortedTri(t));
    std::vector<char> used(faces.size(), 0);
    std::vector<Tri> added;
    for (const auto& [e, w] : fans.third) {
      if (w.size() != 1) continue;
      const auto [a, b] = e;
      const int s = w[0];
      const size_t f = face_of[e];
      if (used[f]) continue;
      int best = -1;
      double best_quality = max_sliver_quality;
      for (int m : joined[a]) {
        if (m == b || m == s || !joined[b].count(m)) continue;
        const double t = (at(m) - at(a)).dot(at(b) - at(a)) / (at(b) - at(a)).squaredNorm();
        const double q = TriangleQuality(at(a), at(m), at(b));
        if (t > 0.0 && t < 1.0 && q < best_quality) best = m, best_quality = q;
      }
      if (best < 0) continue;
      const Tri h1 = SortedTri({a, best, s}), h2 = SortedTri({best, b, s});
      if (IsDegenerate(TriangleQuality(at(a), at(best), at(s)), min_quality) ||
          IsDegenerate(TriangleQuality(at(best), at(b), at(s)), min_quality) || existing.count(h1) || existing.count(h2) ||
          fans.Over(vertices, a, best, s, min_cos) || fans.Over(vertices, best, b, s, min_cos))
        continue;
      used[f] = 1;
      added.push_back(h1);
      added.push_back(h2);
      existing.insert(h1);
      existing.insert(h2);
      ++split;
    }
    if (added.empty()) break;
    ReplaceFaces(faces, used, added);
  }
  return split;
}

}  // namespace voroudf

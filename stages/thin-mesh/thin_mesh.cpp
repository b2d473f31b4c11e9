#include "stages/thin-mesh/thin_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "common/errors.h"
#include "common/mesh_topology.h"

namespace voroudf {
namespace {

Tri Sorted(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

struct TriHash {
  size_t operator()(const Tri& t) const {
    uint64_t h = static_cast<uint32_t>(t[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(t[1]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<uint32_t>(t[2]);
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

int Find(std::vector<int>& parent, int x) {
  while (parent[static_cast<size_t>(x)] != x) {
    parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
    x = parent[static_cast<size_t>(x)];
  }
  return x;
}

/// The mutable state of the thinning: faces, which are still present, and the valence of every edge.
class Thinner {
 public:
  Thinner(std::vector<Tri> faces, std::vector<double> centroid_udf)
      : faces_(std::move(faces)), udf_(std::move(centroid_udf)), alive_(faces_.size(), 1) {
    incidence_ = BuildEdgeFaces(faces_);
    valence_.resize(incidence_.edges.size());
    for (size_t e = 0; e < valence_.size(); ++e) valence_[e] = static_cast<int>(incidence_.faces[e].size());
    face_edges_.resize(faces_.size());
    for (size_t f = 0; f < faces_.size(); ++f) {
      const Tri& t = faces_[f];
      face_edges_[f] = {incidence_.Find(t[0], t[1]), incidence_.Find(t[1], t[2]), incidence_.Find(t[2], t[0])};
      by_vertices_.emplace(Sorted(t), static_cast<int>(f));
    }
  }

  const std::vector<Tri>& faces() const { return faces_; }
  const std::vector<char>& alive() const { return alive_; }

  /// Closed tetrahedra among the present faces: for each, its 4 faces (abc, abd, acd, bcd with a<b<c<d),
  /// sorted by the vertex quadruple.
  std::vector<std::array<int, 4>> Tetrahedra() const {
    std::vector<std::pair<std::array<int, 4>, std::array<int, 4>>> found;
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!alive_[f]) continue;
      const Tri t = Sorted(faces_[f]);
      const int a = t[0], b = t[1], c = t[2];
      const int eab = incidence_.Find(a, b);
      for (int g : incidence_.faces[static_cast<size_t>(eab)]) {
        if (!alive_[static_cast<size_t>(g)] || g == static_cast<int>(f)) continue;
        const Tri u = faces_[static_cast<size_t>(g)];
        const int d = u[0] + u[1] + u[2] - a - b;  // the vertex of g that is not a or b
        if (d <= c) continue;  // each tetrahedron once: from its face without the largest vertex
        const int h1 = Present({a, c, d}), h2 = Present({b, c, d});
        if (h1 < 0 || h2 < 0) continue;
        found.push_back({{a, b, c, d}, {static_cast<int>(f), g, h1, h2}});
      }
    }
    std::sort(found.begin(), found.end());
    std::vector<std::array<int, 4>> tets;
    tets.reserve(found.size());
    for (const auto& p : found) tets.push_back(p.second);
    return tets;
  }

  struct Pair {
    int fa = -1, fb = -1;
    int holes = 5;       ///< edges the removal would leave with one face
    double score = -1;   ///< summed centroid UDF
    bool valid() const { return fa >= 0; }
    /// Fewer new holes first, then the higher UDF.
    bool Better(const Pair& o) const { return holes != o.holes ? holes < o.holes : score > o.score; }
  };

  /// Fig. 8: the pair of faces of `tet` that share a manifold edge and whose centroids have the largest
  /// summed UDF; invalid when a face is gone or no pair shares a manifold edge.
  Pair BestPair(const std::array<int, 4>& tet) const {
    Pair best;
    for (int f : tet)
      if (!alive_[static_cast<size_t>(f)]) return best;
    for (int p = 0; p < 4; ++p)
      for (int q = p + 1; q < 4; ++q) {
        const int fa = tet[static_cast<size_t>(p)], fb = tet[static_cast<size_t>(q)];
        const int e = SharedEdge(fa, fb);
        if (e < 0 || valence_[static_cast<size_t>(e)] != 2) continue;
        // Edges of the pair other than the shared one that would be left with one face: inside a surface a
        // tetrahedron's outer edges carry a face of the surface too, and the pair to remove is the one that
        // leaves none open. Only then (and for a lone tetrahedron, where every pair opens 4) the UDF decides.
        Pair c{fa, fb, 0, udf_[static_cast<size_t>(fa)] + udf_[static_cast<size_t>(fb)]};
        for (int f : {fa, fb})
          for (int o : face_edges_[static_cast<size_t>(f)])
            c.holes += (o != e && valence_[static_cast<size_t>(o)] == 2) ? 1 : 0;
        if (!best.valid() || c.Better(best)) best = c;
      }
    return best;
  }

  /// One pass over `tets`: the tetrahedra whose best pair is best go first (where several tetrahedra share
  /// faces, as where 5+ Voronoi regions nearly meet, the order decides what is left), each re-evaluated
  /// when its turn comes. Returns the number thinned.
  size_t ThinPass(const std::vector<std::array<int, 4>>& tets) {
    std::vector<std::pair<Pair, size_t>> order;
    for (size_t t = 0; t < tets.size(); ++t) order.push_back({BestPair(tets[t]), t});
    std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) {
      if (x.first.valid() != y.first.valid()) return x.first.valid();
      return x.first.valid() && x.first.Better(y.first);
    });
    size_t thinned = 0;
    for (const auto& entry : order) {
      const Pair p = BestPair(tets[entry.second]);
      if (!p.valid()) continue;
      Remove(p.fa);
      Remove(p.fb);
      ++thinned;
    }
    return thinned;
  }

  /// Components connected across manifold edges, as face lists (each in increasing face order): first those
  /// with fewer than `min_faces` faces by decreasing mean centroid UDF, then the others by size.
  std::vector<std::vector<int>> ManifoldComponents(size_t min_faces) const {
    std::vector<int> parent(faces_.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (size_t e = 0; e < valence_.size(); ++e) {
      if (valence_[e] != 2) continue;
      int first = -1;
      for (int f : incidence_.faces[e]) {
        if (!alive_[static_cast<size_t>(f)]) continue;
        if (first < 0) {
          first = f;
        } else {
          const int ra = Find(parent, first), rb = Find(parent, f);
          parent[static_cast<size_t>(std::max(ra, rb))] = std::min(ra, rb);
        }
      }
    }
    std::unordered_map<int, size_t> slot;
    std::vector<std::vector<int>> comps;
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!alive_[f]) continue;
      const int r = Find(parent, static_cast<int>(f));
      auto it = slot.find(r);
      if (it == slot.end()) {
        it = slot.emplace(r, comps.size()).first;
        comps.emplace_back();
      }
      comps[it->second].push_back(static_cast<int>(f));
    }
    // Farthest from the surface (largest mean centroid UDF) first, as in Fig. 8: removing one side of a
    // residual bubble makes the other side unsafe to remove, and the side to keep is the one on the surface.
    std::vector<double> mean(comps.size(), 0.0);
    for (size_t c = 0; c < comps.size(); ++c) {
      for (int f : comps[c]) mean[c] += udf_[static_cast<size_t>(f)];
      mean[c] /= static_cast<double>(comps[c].size());
    }
    std::vector<size_t> order(comps.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
      const bool small_x = comps[x].size() < min_faces, small_y = comps[y].size() < min_faces;
      if (small_x != small_y) return small_x;
      if (small_x && mean[x] != mean[y]) return mean[x] > mean[y];
      return comps[x].size() < comps[y].size();
    });
    std::vector<std::vector<int>> sorted(comps.size());
    for (size_t k = 0; k < order.size(); ++k) sorted[k] = std::move(comps[order[k]]);
    comps.swap(sorted);
    return comps;
  }

  /// Removes `comp` unless that would leave one of its border edges with a single face (a new hole).
  bool RemoveComponentIfSafe(const std::vector<int>& comp) {
    std::unordered_map<int, int> uses;  // edge -> faces of comp on it
    for (int f : comp) {
      if (!alive_[static_cast<size_t>(f)]) return false;
      for (int e : face_edges_[static_cast<size_t>(f)]) ++uses[e];
    }
    for (const auto& [e, c] : uses) {
      const int v = valence_[static_cast<size_t>(e)];
      if (c < v && v - c < 2) return false;
    }
    for (int f : comp) Remove(f);
    return true;
  }

  /// Orients the faces of every manifold component consistently (breadth first from its first face), so that
  /// viewers shade it smoothly. A non-orientable component keeps the first orientation each face receives.
  void OrientComponents() {
    std::vector<char> seen(faces_.size(), 0);
    std::vector<int> queue;
    for (size_t start = 0; start < faces_.size(); ++start) {
      if (!alive_[start] || seen[start]) continue;
      seen[start] = 1;
      queue.assign(1, static_cast<int>(start));
      for (size_t head = 0; head < queue.size(); ++head) {
        const Tri& t = faces_[static_cast<size_t>(queue[head])];
        for (int k = 0; k < 3; ++k) {
          const int u = t[static_cast<size_t>(k)], w = t[static_cast<size_t>((k + 1) % 3)];
          const int e = incidence_.Find(u, w);
          if (valence_[static_cast<size_t>(e)] != 2) continue;
          for (int g : incidence_.faces[static_cast<size_t>(e)]) {
            if (!alive_[static_cast<size_t>(g)] || seen[static_cast<size_t>(g)]) continue;
            Tri& s = faces_[static_cast<size_t>(g)];
            // A consistent neighbour runs the shared edge the other way (w -> u).
            for (int m = 0; m < 3; ++m)
              if (s[static_cast<size_t>(m)] == u && s[static_cast<size_t>((m + 1) % 3)] == w) {
                std::swap(s[0], s[1]);
                break;
              }
            seen[static_cast<size_t>(g)] = 1;
            queue.push_back(g);
          }
        }
      }
    }
  }

 private:
  int Present(const Tri& sorted) const {
    const auto it = by_vertices_.find(sorted);
    return it != by_vertices_.end() && alive_[static_cast<size_t>(it->second)] ? it->second : -1;
  }
  int SharedEdge(int fa, int fb) const {
    for (int e : face_edges_[static_cast<size_t>(fa)])
      for (int o : face_edges_[static_cast<size_t>(fb)])
        if (e == o) return e;
    return -1;
  }
  void Remove(int f) {
    alive_[static_cast<size_t>(f)] = 0;
    for (int e : face_edges_[static_cast<size_t>(f)]) --valence_[static_cast<size_t>(e)];
  }

  std::vector<Tri> faces_;
  std::vector<double> udf_;
  std::vector<char> alive_;
  EdgeFaces incidence_;
  std::vector<int> valence_;  ///< present faces per edge
  std::vector<std::array<int, 3>> face_edges_;
  std::unordered_map<Tri, int, TriHash> by_vertices_;
};

/// Twice the signed area of the 2-D triangle (o, x, y): positive when counter-clockwise.
double Cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& x, const Eigen::Vector2d& y) {
  return (x - o).x() * (y - o).y() - (x - o).y() * (y - o).x();
}

/// Whether the 2-D point c lies in one of the faces `patch` of `faces`, projected to the coordinates `q`.
bool InsidePatch(const std::vector<Tri>& faces, const std::vector<size_t>& patch,
                 const std::unordered_map<int, Eigen::Vector2d>& q, const Eigen::Vector2d& c) {
  for (size_t f : patch) {
    const Tri& t = faces[f];
    const double d0 = Cross2(q.at(t[0]), q.at(t[1]), c), d1 = Cross2(q.at(t[1]), q.at(t[2]), c),
                 d2 = Cross2(q.at(t[2]), q.at(t[0]), c);
    if ((d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0)) return true;
  }
  return false;
}

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

/// Ear clipping of the outline of `patch` (its edges used by one patch face, which must form one simple
/// cycle) in the 2-D coordinates `q`: best ear (triangle quality) first. Empty when that fails.
std::vector<Tri> EarClip(const std::vector<Vec3>& vertices, const std::vector<size_t>& patch, const std::vector<Tri>& faces,
                         const std::unordered_map<int, Eigen::Vector2d>& q, double min_quality) {
  std::map<std::pair<int, int>, int> uses;
  for (size_t f : patch)
    for (int k = 0; k < 3; ++k) {
      const int u = faces[f][static_cast<size_t>(k)], w = faces[f][static_cast<size_t>((k + 1) % 3)];
      ++uses[{std::min(u, w), std::max(u, w)}];
    }
  std::map<int, std::vector<int>> next;
  for (const auto& [e, c] : uses)
    if (c == 1) {
      next[e.first].push_back(e.second);
      next[e.second].push_back(e.first);
    }
  if (next.size() < 3) return {};
  for (const auto& [v, n] : next)
    if (n.size() != 2) return {};
  std::vector<int> poly{next.begin()->first};
  int prev = -1;
  for (;;) {
    const std::vector<int>& n = next[poly.back()];
    const int nx = n[0] != prev ? n[0] : n[1];
    prev = poly.back();
    if (nx == poly.front()) break;
    poly.push_back(nx);
    if (poly.size() > next.size()) return {};
  }
  if (poly.size() != next.size()) return {};
  auto at = [&](int v) { return q.at(v); };
  double area = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) area += Cross2(Eigen::Vector2d::Zero(), at(poly[i]), at(poly[(i + 1) % poly.size()]));
  if (area < 0.0) std::reverse(poly.begin(), poly.end());
  std::vector<Tri> out;
  while (poly.size() > 3) {
    size_t best = poly.size();
    double best_q = -1.0;
    for (size_t i = 0; i < poly.size(); ++i) {
      const int p0 = poly[(i + poly.size() - 1) % poly.size()], p1 = poly[i], p2 = poly[(i + 1) % poly.size()];
      if (!(Cross2(at(p0), at(p1), at(p2)) > 0.0)) continue;
      bool empty = true;
      for (int v : poly) {
        if (v == p0 || v == p1 || v == p2) continue;
        if (Cross2(at(p0), at(p1), at(v)) >= 0 && Cross2(at(p1), at(p2), at(v)) >= 0 && Cross2(at(p2), at(p0), at(v)) >= 0)
          empty = false;
      }
      if (!empty) continue;
      const double quality = TriangleQuality(vertices[static_cast<size_t>(p0)], vertices[static_cast<size_t>(p1)],
                                             vertices[static_cast<size_t>(p2)]);
      if (quality > best_q) {
        best_q = quality;
        best = i;
      }
    }
    if (best == poly.size() || IsDegenerate(best_q, min_quality)) return {};
    out.push_back(Sorted({poly[(best + poly.size() - 1) % poly.size()], poly[best], poly[(best + 1) % poly.size()]}));
    poly.erase(poly.begin() + static_cast<long>(best));
  }
  const double quality = TriangleQuality(vertices[static_cast<size_t>(poly[0])], vertices[static_cast<size_t>(poly[1])],
                                         vertices[static_cast<size_t>(poly[2])]);
  if (!(Cross2(at(poly[0]), at(poly[1]), at(poly[2])) > 0.0) || IsDegenerate(quality, min_quality)) return {};
  out.push_back(Sorted({poly[0], poly[1], poly[2]}));
  return out;
}

/// An edge as its sorted vertex pair, and the faces (sorted) around each edge.
using EdgeKey = std::pair<int, int>;
using EdgeFaceMap = std::map<EdgeKey, std::vector<Tri>>;

EdgeKey KeyOf(int u, int v) { return {std::min(u, v), std::max(u, v)}; }

/// A triangulation of the projected patch (2-D coordinates `q` of the patch vertices `pv`) that keeps the
/// patch's edges shared with faces outside it: those edges first, then every other vertex pair by increasing
/// length whose segment stays inside the projected patch and crosses no edge taken; the triangles are the
/// empty 3-cycles of the edges taken whose centroids lie inside the patch. A greedy triangulation, by hand:
/// at most 24 points, and CGAL's constrained Delaunay would want a simple polygon, which a fold's outline is
/// not. Empty if the shared edges cross or a triangle is degenerate.
std::vector<Tri> GreedyTriangulation(const std::vector<Vec3>& vertices, const std::vector<Tri>& faces,
                                     const std::vector<size_t>& patch, const std::vector<int>& pv,
                                     std::unordered_map<int, Eigen::Vector2d>& q,
                                     const EdgeFaceMap& edge_faces,
                                     double min_quality) {
  auto inside = [&](const Eigen::Vector2d& c) { return InsidePatch(faces, patch, q, c); };
  std::set<Tri> own;
  for (size_t f : patch) own.insert(Sorted(faces[f]));
  std::set<EdgeKey> shared;
  for (size_t f : patch)
    for (int k = 0; k < 3; ++k) {
      const auto e = KeyOf(faces[f][static_cast<size_t>(k)], faces[f][static_cast<size_t>((k + 1) % 3)]);
      for (const Tri& t : edge_faces.at(e))
        if (!own.count(t)) shared.insert(e);
    }
  std::vector<std::pair<int, int>> taken;
  auto blocked = [&](int a, int b) {
    const Eigen::Vector2d &A = q[a], &B = q[b];
    for (const auto& [c, d] : taken) {
      if (c == a || c == b || d == a || d == b) continue;
      const double d1 = Cross2(A, B, q[c]), d2 = Cross2(A, B, q[d]), d3 = Cross2(q[c], q[d], A), d4 = Cross2(q[c], q[d], B);
      if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    }
    const double len2 = (B - A).squaredNorm();
    for (int v : pv) {  // through another vertex
      if (v == a || v == b) continue;
      const double t = (q[v] - A).dot(B - A) / len2;
      if (t > 0 && t < 1 && std::abs(Cross2(A, B, q[v])) < 1e-9 * len2) return true;
    }
    return false;
  };
  for (const auto& e : shared) {
    if (blocked(e.first, e.second)) return {};
    taken.push_back(e);
  }
  std::vector<std::pair<double, std::pair<int, int>>> candidates;
  for (size_t i = 0; i < pv.size(); ++i)
    for (size_t j = i + 1; j < pv.size(); ++j) {
      const auto e = KeyOf(pv[i], pv[j]);
      if (shared.count(e)) continue;
      const Eigen::Vector2d &A = q[e.first], &B = q[e.second];
      if (inside(0.25 * A + 0.75 * B) && inside(0.5 * (A + B)) && inside(0.75 * A + 0.25 * B))
        candidates.push_back({(A - B).squaredNorm(), e});
    }
  std::sort(candidates.begin(), candidates.end());
  for (const auto& [len2, e] : candidates)
    if (!blocked(e.first, e.second)) taken.push_back(e);
  std::map<int, std::set<int>> adj;
  for (const auto& [a, b] : taken) {
    adj[a].insert(b);
    adj[b].insert(a);
  }
  std::vector<Tri> out;
  for (const auto& [a, na] : adj)
    for (int b : na) {
      if (b <= a) continue;
      for (int c : adj[b]) {
        if (c <= b || !na.count(c)) continue;
        const Eigen::Vector2d &A = q[a], &B = q[b], &C = q[c];
        bool empty = true;
        for (int v : pv) {
          if (v == a || v == b || v == c) continue;
          const double d0 = Cross2(A, B, q[v]), d1 = Cross2(B, C, q[v]), d2 = Cross2(C, A, q[v]);
          empty = empty && !((d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0));
        }
        if (!empty || !inside((A + B + C) / 3.0)) continue;
        const double quality = TriangleQuality(vertices[static_cast<size_t>(a)], vertices[static_cast<size_t>(b)],
                                               vertices[static_cast<size_t>(c)]);
        if (IsDegenerate(quality, min_quality)) return {};
        out.push_back({a, b, c});
      }
    }
  return out;
}

/// Drops the faces marked in `gone` (order kept) and appends `added`.
void ReplaceFaces(std::vector<Tri>& faces, const std::vector<char>& gone, const std::vector<Tri>& added) {
  std::vector<Tri> next;
  for (size_t f = 0; f < faces.size(); ++f)
    if (!gone[f]) next.push_back(faces[f]);
  next.insert(next.end(), added.begin(), added.end());
  faces.swap(next);
}

/// Step 4's fold: two faces of edge e on the same side of it, nearly coplanar (their third vertices'
/// perpendiculars from the edge within acos(min_cos)).
bool FoldedEdge(const std::vector<Vec3>& vertices, const EdgeKey& e, const std::vector<Tri>& fs, double min_cos) {
  auto third = [&](const Tri& f) { return f[0] + f[1] + f[2] - e.first - e.second; };
  for (size_t i = 0; i < fs.size(); ++i)
    for (size_t j = i + 1; j < fs.size(); ++j)
      if (SameSideOfEdge(vertices, e.first, e.second, third(fs[i]), third(fs[j]), min_cos)) return true;
  return false;
}

/// A set of vertices whose faces step 4 re-triangulates, with its first bad edge and whether it has a
/// non-manifold edge.
struct FoldCandidate {
  std::vector<int> centre;  // sorted
  EdgeKey edge;
  bool is_nm;
};

/// Step 4's candidates: every bad edge alone (its two vertices), then every cluster of 3+ vertices joined by
/// bad edges (a fold can be a whole cycle of folded edges) or by boundary edges between their vertices.
/// \param bad  the non-manifold (true) and folded manifold (false) edges, in edge order
std::vector<FoldCandidate> FoldCandidates(const std::vector<std::pair<EdgeKey, bool>>& bad, const EdgeFaceMap& edge_faces) {
  std::vector<FoldCandidate> candidates;
  for (const auto& [edge, is_nm] : bad) candidates.push_back({{edge.first, edge.second}, edge, is_nm});
  std::map<int, int> parent;
  std::function<int(int)> root = [&](int x) { return parent[x] == x ? x : parent[x] = root(parent[x]); };
  for (const auto& [edge, is_nm] : bad) {
    parent.emplace(edge.first, edge.first);
    parent.emplace(edge.second, edge.second);
  }
  for (const auto& [edge, is_nm] : bad) {
    const int ra = root(edge.first), rb = root(edge.second);
    parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  // A hole next to folds (a boundary edge between two of their vertices) is part of the same defect: the
  // faces missing there are those the folds doubled.
  for (const auto& [e, fs] : edge_faces) {
    if (fs.size() != 1 || !parent.count(e.first) || !parent.count(e.second)) continue;
    const int ra = root(e.first), rb = root(e.second);
    parent[std::max(ra, rb)] = std::min(ra, rb);
  }
  std::map<int, FoldCandidate> clusters;
  for (const auto& [edge, is_nm] : bad) {
    auto [it, fresh] = clusters.emplace(root(edge.first), FoldCandidate{{}, edge, false});
    it->second.is_nm = it->second.is_nm || is_nm;
    (void)fresh;
  }
  for (const auto& [v, r] : parent) clusters[root(v)].centre.push_back(v);
  for (auto& [r, c] : clusters)
    if (c.centre.size() >= 3) candidates.push_back(std::move(c));
  return candidates;
}

/// The 2-D Delaunay triangles of the patch vertices `pv` (coordinates `q`) whose centroids lie inside the
/// projected patch, degenerate ones left out. By hand: at most 24 points.
std::vector<Tri> DelaunayInPatch(const std::vector<Vec3>& vertices, const std::vector<Tri>& faces,
                                 const std::vector<size_t>& patch, const std::vector<int>& pv,
                                 std::unordered_map<int, Eigen::Vector2d>& q, double min_quality) {
  auto inside_patch = [&](const Eigen::Vector2d& c) { return InsidePatch(faces, patch, q, c); };
  std::vector<Tri> tris;
  for (size_t i = 0; i < pv.size(); ++i)
    for (size_t j = i + 1; j < pv.size(); ++j)
      for (size_t k = j + 1; k < pv.size(); ++k) {
        const Eigen::Vector2d &A = q[pv[i]], &B = q[pv[j]], &C = q[pv[k]];
        const double area2 = Cross2(A, B, C);
        if (std::abs(area2) < 1e-12 * ((B - A).squaredNorm() + (C - A).squaredNorm())) continue;
        bool empty = true;
        for (size_t m = 0; m < pv.size() && empty; ++m) {
          if (m == i || m == j || m == k) continue;
          const Eigen::Vector2d& D = q[pv[m]];
          const Eigen::Vector2d a2 = A - D, b2 = B - D, c2 = C - D;
          const double det = a2.squaredNorm() * (b2.x() * c2.y() - b2.y() * c2.x()) -
                             b2.squaredNorm() * (a2.x() * c2.y() - a2.y() * c2.x()) +
                             c2.squaredNorm() * (a2.x() * b2.y() - a2.y() * b2.x());
          if ((area2 > 0 ? det : -det) > 0) empty = false;
        }
        if (!empty || !inside_patch((A + B + C) / 3.0)) continue;
        const double quality = TriangleQuality(vertices[static_cast<size_t>(pv[i])], vertices[static_cast<size_t>(pv[j])],
                                               vertices[static_cast<size_t>(pv[k])]);
        if (!IsDegenerate(quality, min_quality)) tris.push_back({pv[i], pv[j], pv[k]});
      }
  return tris;
}

/// Step 4's acceptance of the triangles `cand` for `patch`: the edges they share with faces outside the patch
/// stay, no face is duplicated, and non-manifold plus folded edges drop, with no more non-manifold and no
/// more boundary edges (beyond the rim folds opened, with `open_rim_folds`).
bool FoldRepairAccepted(const std::vector<Vec3>& vertices, const std::vector<Tri>& faces,
                        const std::vector<size_t>& patch, const std::vector<Tri>& cand, const EdgeFaceMap& edge_faces,
                        const std::set<Tri>& existing, const std::vector<char>& on_rim, bool open_rim_folds,
                        double min_cos) {
  // The patch's edges before and after.
  EdgeFaceMap after;
  for (size_t f : patch)
    for (int k = 0; k < 3; ++k) {
      const EdgeKey e = KeyOf(faces[f][static_cast<size_t>(k)], faces[f][static_cast<size_t>((k + 1) % 3)]);
      after.emplace(e, edge_faces.at(e));
    }
  for (const Tri& t : cand)
    for (int k = 0; k < 3; ++k) {
      const EdgeKey e = KeyOf(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]);
      const auto it = edge_faces.find(e);
      after.emplace(e, it == edge_faces.end() ? std::vector<Tri>() : it->second);
    }
  int nm_before = 0, nm_after = 0, open_before = 0, open_after = 0, fold_before = 0, fold_after = 0, rim_opened = 0;
  bool kept_shared = true;
  for (auto& [e, fs] : after) {
    const bool was_open = fs.size() == 1, was_folded = fs.size() == 2 && FoldedEdge(vertices, e, fs, min_cos);
    nm_before += fs.size() >= 3;
    open_before += was_open;
    fold_before += was_folded;
    size_t own = 0;
    for (size_t f : patch) {
      const auto it = std::find(fs.begin(), fs.end(), Sorted(faces[f]));
      if (it != fs.end()) {
        fs.erase(it);
        ++own;
      }
    }
    const bool shared = own > 0 && !fs.empty();  // also used by faces outside the patch
    bool in_new = false;
    for (const Tri& t : cand)
      if ((t[0] == e.first || t[1] == e.first || t[2] == e.first) && (t[0] == e.second || t[1] == e.second || t[2] == e.second)) {
        fs.push_back(t);
        in_new = true;
      }
    // An edge the patch shares with other faces stays: a branching curve is never cut off.
    kept_shared = kept_shared && (!shared || in_new);
    nm_after += fs.size() >= 3;
    open_after += fs.size() == 1;
    fold_after += fs.size() == 2 && FoldedEdge(vertices, e, fs, min_cos);
    // A new boundary edge is a hole, unless allowed at an open rim: both faces were on one side of the
    // edge and both its vertices are on the boundary (the fold's other side is empty).
    rim_opened += open_rim_folds && fs.size() == 1 && was_folded && on_rim[static_cast<size_t>(e.first)] &&
                  on_rim[static_cast<size_t>(e.second)];
  }
  bool duplicate = false;
  for (const Tri& t : cand) {
    bool own = false;
    for (size_t f : patch) own = own || Sorted(faces[f]) == t;
    duplicate = duplicate || (!own && existing.count(t) > 0);
  }
  return kept_shared && !(duplicate || nm_after > nm_before || open_after > open_before + rim_opened || nm_after + fold_after >= nm_before + fold_before);
}

/// Step 4: re-triangulates flat folds. For each non-manifold edge (a, b), in edge order, the patch of faces
/// touching a or b is replaced by the 2-D Delaunay triangulation of its vertices projected on the patch's
/// best-fit plane, keeping the triangles inside the projected patch, when every patch face is within
/// acos(min_cos) of that plane (a fold on a sheet, not a branching of the surface) and the replacement
/// lowers the number of non-manifold edges without adding boundary edges. With `open_rim_folds`, a folded
/// edge between two vertices on the mesh boundary may become a boundary edge (a fold at an open rim, whose
/// other side is empty). Returns the patches replaced.
size_t RetriangulateFlatFolds(const std::vector<Vec3>& vertices, std::vector<Tri>& faces, double min_cos,
                              double min_quality, bool open_rim_folds) {
  auto normal = [&](const Tri& t) {
    const Vec3& p0 = vertices[static_cast<size_t>(t[0])];
    return Vec3((vertices[static_cast<size_t>(t[1])] - p0).cross(vertices[static_cast<size_t>(t[2])] - p0));
  };
  size_t replaced = 0;
  for (int round = 0; round < 8; ++round) {
    EdgeFaceMap edge_faces;
    for (const Tri& t : faces)
      for (int k = 0; k < 3; ++k) edge_faces[KeyOf(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)])].push_back(Sorted(t));
    std::vector<char> on_rim(vertices.size(), 0);  // vertices with a boundary edge
    for (const auto& [e, fs] : edge_faces)
      if (fs.size() == 1) on_rim[static_cast<size_t>(e.first)] = on_rim[static_cast<size_t>(e.second)] = 1;
    std::vector<std::pair<EdgeKey, bool>> bad;  // non-manifold edges (true) and folded manifold edges (false)
    for (const auto& [e, fs] : edge_faces)
      if (fs.size() >= 3 || (fs.size() == 2 && FoldedEdge(vertices, e, fs, min_cos))) bad.push_back({e, fs.size() >= 3});
    if (bad.empty()) break;
    std::vector<char> touched(vertices.size(), 0);
    std::vector<char> gone(faces.size(), 0);
    std::vector<Tri> added;
    std::set<Tri> existing;
    for (const Tri& t : faces) existing.insert(Sorted(t));
    size_t this_round = 0;
    const std::vector<FoldCandidate> candidates = FoldCandidates(bad, edge_faces);
    for (const FoldCandidate& item : candidates) {
      const bool is_nm = item.is_nm;
      // The plane of the fold: a face of the first same-side pair on the candidate's edge.
      Vec3 fold_normal = Vec3::Zero();
      {
        const std::vector<Tri>& fs = edge_faces[item.edge];
        for (size_t i = 0; i < fs.size() && fold_normal.isZero(); ++i)
          for (size_t j = i + 1; j < fs.size() && fold_normal.isZero(); ++j)
            if (FoldedEdge(vertices, item.edge, {fs[i], fs[j]}, min_cos)) fold_normal = normal(fs[i]).normalized();
      }
      std::vector<size_t> patch;
      std::vector<int> pv;
      Vec3 mean = Vec3::Zero();
      // The whole star of the candidate's vertices first (non-manifold candidates), then only its part within
      // the flatness angle of the fold's plane: a fold next to a sharp edge or a branching curve (the rules
      // below keep that part joined to the rest and the shared edges in place).
      bool found = false, fresh = true;
      for (int restricted = is_nm ? 0 : 1; restricted <= 1 && !found && fresh; ++restricted) {
        if (restricted && fold_normal.isZero()) break;
        patch.clear();
        pv.clear();
        for (size_t f = 0; f < faces.size(); ++f) {
          if (gone[f]) continue;
          const Tri& t = faces[f];
          bool near = false;
          for (int v : t) near = near || std::binary_search(item.centre.begin(), item.centre.end(), v);
          if (!near) continue;
          if (restricted && !(std::abs(normal(t).normalized().dot(fold_normal)) >= min_cos)) continue;
          patch.push_back(f);
        }
        if (patch.empty()) continue;
        for (size_t f : patch)
          for (int v : faces[f]) {
            pv.push_back(v);
            fresh = fresh && !touched[static_cast<size_t>(v)];
          }
        std::sort(pv.begin(), pv.end());
        pv.erase(std::unique(pv.begin(), pv.end()), pv.end());
        if (pv.size() > 24) continue;
        const Vec3 ref = normal(faces[patch[0]]).normalized();
        mean = Vec3::Zero();
        for (size_t f : patch) {
          const Vec3 nf = normal(faces[f]);
          mean += nf.dot(ref) >= 0.0 ? nf : Vec3(-nf);
        }
        if (!(mean.norm() > 0.0)) continue;
        mean.normalize();
        bool flat = true;
        for (size_t f : patch) flat = flat && std::abs(normal(faces[f]).normalized().dot(mean)) >= min_cos;
        found = flat;
      }
      // One patch per neighbourhood and round: the valences below are the round's.
      if (!found || !fresh) continue;
      const Vec3 u = (std::abs(mean.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(mean).normalized();
      const Vec3 w = mean.cross(u);
      std::unordered_map<int, Eigen::Vector2d> q;
      for (int v : pv) q[v] = Eigen::Vector2d(vertices[static_cast<size_t>(v)].dot(u), vertices[static_cast<size_t>(v)].dot(w));
      std::vector<Tri> tris = DelaunayInPatch(vertices, faces, patch, pv, q, min_quality);
      auto acceptable = [&](const std::vector<Tri>& cand) {
        return FoldRepairAccepted(vertices, faces, patch, cand, edge_faces, existing, on_rim, open_rim_folds, min_cos);
      };
      bool ok = acceptable(tris);
      if (!ok) {
        // A triangulation that keeps the edges shared with the faces around (Delaunay need not have them).
        tris = GreedyTriangulation(vertices, faces, patch, pv, q, edge_faces, min_quality);
        ok = !tris.empty() && acceptable(tris);
      }
      if (!ok) {
        // Fallback: the patch's outline (edges with one patch face) as one simple polygon, ear-clipped best
        // ear first (its interior vertices are dropped).
        tris = EarClip(vertices, patch, faces, q, min_quality);
        ok = !tris.empty() && acceptable(tris);
      }
      if (!ok) continue;
      for (size_t f : patch) gone[f] = 1;
      added.insert(added.end(), tris.begin(), tris.end());
      for (int v : pv) touched[static_cast<size_t>(v)] = 1;
      ++this_round;
    }
    if (this_round == 0) break;
    replaced += this_round;
    ReplaceFaces(faces, gone, added);
  }
  return replaced;
}

/// The faces around each edge of a face list, for the hole-closing steps: each edge's third vertices, and
/// each vertex's neighbours along boundary edges (edges with one face).
struct EdgeFans {
  std::map<EdgeKey, std::vector<int>> third;
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

/// Step 5: adds the face (a, b, c) wherever b has boundary edges (edges with one face) to a and to c and the
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
        const Tri t = Sorted({a, b, c});
        if (!done.insert(t).second || !fans.Fits(vertices, a, b, c, min_quality, min_cos)) continue;
        faces.push_back(t);
        ++added;
      }
  return added;
}

/// Step 5, cracks: a boundary edge (a, b) whose one face is (a, b, s), with a vertex m that is joined to a
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
    std::map<EdgeKey, size_t> face_of;    // edge -> (the last of) its faces
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
    for (const Tri& t : faces) existing.insert(Sorted(t));
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
      const Tri h1 = Sorted({a, best, s}), h2 = Sorted({best, b, s});
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

std::string Count(size_t n, const char* what) { return std::to_string(n) + " " + what; }

}  // namespace

void ThinMeshOptions::Check() const {
  if (min_component_faces > 1000000) throw UsageError("--min-component-faces must be at most 1e6");
  if (!(fold_flatness_deg >= 0.0 && fold_flatness_deg < 90.0)) throw UsageError("--fold-flatness must be in [0, 90)");
  if (!(degenerate_quality >= 0.0 && degenerate_quality < 0.5))
    throw UsageError("--degenerate-quality must be in [0, 0.5)");
}

TriangleMesh ThinMesh(const Udf& udf, const TriangleMesh& thick, const ThinMeshOptions& options, Monitor& monitor,
                      ThinMeshStats* stats_out) {
  options.Check();
  ThinMeshStats st;

  // 0. Degenerate faces, faces spanning a vertex on their edge, duplicate faces.
  std::vector<Tri> faces;
  faces.reserve(thick.faces.size());
  const auto quality_of = [&](const Tri& t) {
    return TriangleQuality(thick.vertices[static_cast<size_t>(t[0])], thick.vertices[static_cast<size_t>(t[1])],
                           thick.vertices[static_cast<size_t>(t[2])]);
  };
  // A degenerate face over three distinct vertices is three seeds on one line (a sharp edge or a branching
  // curve): its middle vertex lies on the edge between the other two. Keyed by that edge.
  std::map<std::pair<int, int>, int> middle;
  for (const Tri& t : thick.faces) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++st.degenerate_faces;
      continue;
    }
    const double quality = quality_of(t);
    if (IsDegenerate(quality, options.degenerate_quality)) {
      ++st.degenerate_faces;
      int far = 0;  // the vertex opposite the longest edge is the middle one
      double longest = -1.0;
      for (int k = 0; k < 3; ++k) {
        const double len = (thick.vertices[static_cast<size_t>(t[static_cast<size_t>((k + 1) % 3)])] -
                            thick.vertices[static_cast<size_t>(t[static_cast<size_t>((k + 2) % 3)])]).squaredNorm();
        if (len > longest) longest = len, far = k;
      }
      const int a = t[static_cast<size_t>((far + 1) % 3)], b = t[static_cast<size_t>((far + 2) % 3)];
      middle.emplace(std::make_pair(std::min(a, b), std::max(a, b)), t[static_cast<size_t>(far)]);
      continue;
    }
    faces.push_back(t);
  }
  // A face (a, b, s) over an edge whose middle vertex m is known spans over m: where the seeds along a curve
  // are denser than the dense samples resolve, the dual gets (a, b, s) instead of (a, m, s) and (m, b, s),
  // and thinning cannot recover the curve's edges. Such a face is split into those two (repeatedly: the
  // halves may span further vertices); the halves that exist already are dropped as duplicates below.
  const bool repairs = options.thinning != "paper";
  auto repair = [&](const char* name) { return repairs && options.repairs.find(name) != std::string::npos; };
  if (repair("split") && !middle.empty()) {
    std::vector<Tri> split;
    std::vector<Tri> stack(faces.rbegin(), faces.rend());
    while (!stack.empty()) {
      const Tri t = stack.back();
      stack.pop_back();
      bool done = false;
      for (int k = 0; k < 3 && !done; ++k) {
        const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)], c = t[static_cast<size_t>((k + 2) % 3)];
        const auto it = middle.find({std::min(a, b), std::max(a, b)});
        if (it == middle.end() || it->second == c) continue;
        const Tri h1{a, it->second, c}, h2{it->second, b, c};
        if (!(quality_of(h1) >= options.degenerate_quality) || !(quality_of(h2) >= options.degenerate_quality)) continue;
        ++st.faces_split;
        stack.push_back(h2);
        stack.push_back(h1);
        done = true;
      }
      if (!done) split.push_back(t);
    }
    faces.swap(split);
  }
  {
    std::unordered_set<Tri, TriHash> seen;
    std::vector<Tri> unique;
    unique.reserve(faces.size());
    for (const Tri& t : faces) {
      if (seen.insert(Sorted(t)).second) {
        unique.push_back(t);
      } else {
        ++st.duplicate_faces;
      }
    }
    faces.swap(unique);
  }
  monitor.Info(Count(thick.faces.size(), "faces in; dropped ") + Count(st.degenerate_faces, "degenerate faces; split ") +
               Count(st.faces_split, "faces over a vertex on their edge; dropped ") +
               Count(st.duplicate_faces, "duplicate faces"));

  std::vector<Vec3> centroid(faces.size());
  for (size_t f = 0; f < faces.size(); ++f)
    centroid[f] = (thick.vertices[static_cast<size_t>(faces[f][0])] + thick.vertices[static_cast<size_t>(faces[f][1])] +
                   thick.vertices[static_cast<size_t>(faces[f][2])]) /
                  3.0;
  std::vector<double> centroid_udf;
  std::vector<Vec3> centroid_grad;
  udf.Evaluate(centroid, centroid_udf, centroid_grad);

  Thinner thinner(std::move(faces), std::move(centroid_udf));
  for (;;) {
    ++st.rounds;
    bool changed = false;
    // 1. Tetrahedra, until a pass removes nothing (removing faces never creates a tetrahedron, but a pass
    // can make an edge of a stuck tetrahedron manifold).
    for (;;) {
      const auto tets = thinner.Tetrahedra();
      if (st.rounds == 1 && st.tetrahedra == 0) st.tetrahedra = tets.size();
      const size_t thinned = thinner.ThinPass(tets);
      st.tetrahedra_thinned += thinned;
      monitor.Info("round " + std::to_string(st.rounds) + ": " + Count(tets.size(), "closed tetrahedra, ") +
                   Count(thinned, "thinned (2 faces removed from each)"));
      if (thinned == 0) break;
      changed = true;
    }
    // 2. Small components, farthest from the surface first, until none can go.
    for (;;) {
      const auto comps = thinner.ManifoldComponents(options.min_component_faces);
      size_t removed = 0, removed_faces = 0, small = 0;
      for (const auto& comp : comps) {
        if (comp.size() >= options.min_component_faces) break;
        ++small;
        if (thinner.RemoveComponentIfSafe(comp)) {
          ++removed;
          removed_faces += comp.size();
        }
      }
      st.components_removed += removed;
      st.component_faces_removed += removed_faces;
      st.small_components_left = small - removed;
      if (small > 0)
        monitor.Info("round " + std::to_string(st.rounds) + ": " + Count(small, "components under ") +
                     std::to_string(options.min_component_faces) + " faces, " + Count(removed, "removed (") +
                     Count(removed_faces, "faces)"));
      if (removed == 0) break;
      changed = true;
    }
    if (!changed) break;
  }
  st.tetrahedra_left = thinner.Tetrahedra().size();
  if (st.tetrahedra_left > 0)
    monitor.Warn(Count(st.tetrahedra_left, "closed tetrahedra are left: none of their face pairs shares a manifold edge"));
  if (st.small_components_left > 0)
    monitor.Warn(Count(st.small_components_left, "small components are left: removing them would open a hole"));
  std::vector<Tri> kept;
  for (size_t f = 0; f < thinner.faces().size(); ++f)
    if (thinner.alive()[f]) kept.push_back(thinner.faces()[f]);
  // 4. Flat folds.
  const double fold_min_cos = std::cos(options.fold_flatness_deg * M_PI / 180.0);
  if (repair("folds") && options.fold_flatness_deg > 0.0) {
    st.folds_retriangulated = RetriangulateFlatFolds(thick.vertices, kept, fold_min_cos, options.degenerate_quality, false);
    monitor.Info(Count(st.folds_retriangulated, "flat folds re-triangulated"));
  }
  // 5. Cracks (T-junctions), then triangular holes: three boundary edges that form a cycle are a junction
  // whose face the thinning (or the dual) lost; a true boundary loop of three edges does not occur in a mesh
  // of this resolution.
  if (repair("holes")) {
    st.cracks_split = SplitFacesOverCracks(thick.vertices, kept, options.degenerate_quality, fold_min_cos, 0.1);
    if (st.cracks_split > 0) monitor.Info(Count(st.cracks_split, "faces split over a crack (T-junction)"));
    st.holes_closed = CloseTriangularHoles(thick.vertices, kept, options.degenerate_quality, fold_min_cos);
    if (st.holes_closed > 0) monitor.Info(Count(st.holes_closed, "triangular holes closed"));
  }
  // 6. Folds at open rims, once no other repair applies.
  if (repair("rims") && options.fold_flatness_deg > 0.0) {
    st.rim_folds_opened = RetriangulateFlatFolds(thick.vertices, kept, fold_min_cos, options.degenerate_quality, true);
    if (st.rim_folds_opened > 0) monitor.Info(Count(st.rim_folds_opened, "folds at open rims re-triangulated"));
  }
  Thinner oriented(std::move(kept), std::vector<double>());
  oriented.OrientComponents();

  TriangleMesh out;
  out.vertices = thick.vertices;
  out.faces = oriented.faces();
  out = RemoveUnreferencedVertices(out);
  monitor.Info(Count(out.vertices.size(), "vertices, ") + Count(out.faces.size(), "faces out"));
  if (stats_out) *stats_out = st;
  return out;
}

EdgeSet NonManifoldEdges(const TriangleMesh& mesh) {
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  EdgeSet out;
  std::unordered_map<int, int> remap;
  auto vertex = [&](int v) {
    const auto [it, fresh] = remap.emplace(v, static_cast<int>(out.vertices.size()));
    if (fresh) out.vertices.push_back(mesh.vertices[static_cast<size_t>(v)]);
    return it->second;
  };
  for (size_t e = 0; e < ef.edges.size(); ++e)
    if (ef.faces[e].size() >= 3) {
      const int a = vertex(ef.edges[e][0]);
      out.edges.push_back({a, vertex(ef.edges[e][1])});
    }
  return out;
}

}  // namespace voroudf

#include "stages/thin-mesh/thin_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "common/errors.h"
#include "common/face_cycles.h"
#include "common/mesh_topology.h"
#include "common/union_find.h"
#include "stages/thin-mesh/close_holes.h"
#include "stages/thin-mesh/off_surface.h"
#include "stages/thin-mesh/rim_flaps.h"

namespace voroudf {
namespace {

/// The mutable state of the thinning: faces, which are still present, and the valence of every edge.
class Thinner {
 public:
  /// vertices, layer_cos: for the layer test of RemoveComponentIfSafe (layer_cos <= -1 or no vertices: none).
  Thinner(std::vector<Tri> faces, std::vector<double> centroid_udf, const std::vector<Vec3>* vertices = nullptr,
          double layer_cos = -1.0)
      : faces_(std::move(faces)), udf_(std::move(centroid_udf)), alive_(faces_.size(), 1), vertices_(vertices),
        layer_cos_(layer_cos) {
    incidence_ = BuildEdgeFaces(faces_);
    valence_.resize(incidence_.edges.size());
    for (size_t e = 0; e < valence_.size(); ++e) valence_[e] = static_cast<int>(incidence_.faces[e].size());
    face_edges_.resize(faces_.size());
    for (size_t f = 0; f < faces_.size(); ++f) {
      const Tri& t = faces_[f];
      for (int v : t) {
        if (static_cast<size_t>(v) >= vertex_faces_.size()) vertex_faces_.resize(static_cast<size_t>(v) + 1, 0);
        ++vertex_faces_[static_cast<size_t>(v)];
      }
      face_edges_[f] = {incidence_.Find(t[0], t[1]), incidence_.Find(t[1], t[2]), incidence_.Find(t[2], t[0])};
      by_vertices_.emplace(SortedTri(t), static_cast<int>(f));
    }
  }

  const std::vector<Tri>& faces() const { return faces_; }
  /// The centroid UDF of the present face over the vertices of `t` (any order), if there is one.
  bool CentroidUdf(const Tri& t, double* udf) const {
    const int f = Present(SortedTri(t));
    if (f >= 0) *udf = udf_[static_cast<size_t>(f)];
    return f >= 0;
  }
  const std::vector<char>& alive() const { return alive_; }

  /// Closed tetrahedra among the present faces: for each, its 4 faces (abc, abd, acd, bcd with a<b<c<d),
  /// sorted by the vertex quadruple.
  std::vector<std::array<int, 4>> Tetrahedra() const {
    std::vector<std::pair<std::array<int, 4>, std::array<int, 4>>> found;
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!alive_[f]) continue;
      const Tri t = SortedTri(faces_[f]);
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

  /// Step 3b: opens every closed shell of present faces that lies within `rings` edges of one of its faces
  /// and has a face off the surface (OffSurface), at the first such face in decreasing centroid UDF. Each
  /// face in that order is removed when it is off the surface and its boundary is, over GF(2), the sum of the
  /// boundaries of the other present faces near it (FaceComplex::OnLocalTwoCycle). Removing a face of a 2-cycle lowers b2 by
  /// one and changes neither b0 nor b1, so no hole opens; removing faces only breaks cycles, so one pass
  /// finds them all. A shell whose faces all lie on the surface is a cavity of the surface and stays.
  /// Returns the faces removed.
  size_t OpenLocalShells(int rings) {
    if (!vertices_) return 0;
    FaceComplex complex(faces_);
    for (size_t g = 0; g < faces_.size(); ++g)
      if (!alive_[g]) complex.Remove(static_cast<int>(g));
    std::vector<int> order;
    for (size_t g = 0; g < faces_.size(); ++g)
      if (alive_[g]) order.push_back(static_cast<int>(g));
    std::stable_sort(order.begin(), order.end(),
                     [&](int x, int y) { return udf_[static_cast<size_t>(x)] > udf_[static_cast<size_t>(y)]; });
    size_t opened = 0;
    for (int g : order) {
      const Tri& t = faces_[static_cast<size_t>(g)];
      const std::vector<Vec3>& p = *vertices_;
      if (!OffSurface(udf_[static_cast<size_t>(g)], p[static_cast<size_t>(t[0])], p[static_cast<size_t>(t[1])],
                      p[static_cast<size_t>(t[2])]) ||
          !complex.OnLocalTwoCycle(g, rings))
        continue;
      Remove(g);
      complex.Remove(g);
      ++opened;
    }
    return opened;
  }

  /// Components connected across manifold edges, as face lists (each in increasing face order): first those
  /// with fewer than `min_faces` faces by decreasing mean centroid UDF, then the others by size.
  std::vector<std::vector<int>> ManifoldComponents(size_t min_faces) const {
    UnionFind sets(faces_.size());
    for (size_t e = 0; e < valence_.size(); ++e) {
      if (valence_[e] != 2) continue;
      int first = -1;
      for (int f : incidence_.faces[e]) {
        if (!alive_[static_cast<size_t>(f)]) continue;
        if (first < 0) {
          first = f;
        } else {
          sets.Union(first, f);
        }
      }
    }
    std::unordered_map<int, size_t> slot;
    std::vector<std::vector<int>> comps;
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!alive_[f]) continue;
      const int r = sets.Find(static_cast<int>(f));
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

  /// Removes the faces of `comp` unless that would leave one of its border edges with a single face, or,
  /// for a component without a free edge, unless it is a layer (IsLayer). With `collapse_only`, also unless
  /// the component hangs from a free (boundary) edge and its removal keeps the Euler characteristic: a
  /// dangling flap collapsed from its free edge, which changes no topology.
  bool RemoveComponentIfSafe(const std::vector<int>& comp, bool collapse_only) {
    std::unordered_map<int, int> uses;  // edge -> faces of comp on it
    std::unordered_map<int, int> corner_uses;  // vertex -> faces of comp on it
    for (int f : comp) {
      if (!alive_[static_cast<size_t>(f)]) return false;
      for (int e : face_edges_[static_cast<size_t>(f)]) ++uses[e];
      for (int v : faces_[static_cast<size_t>(f)]) ++corner_uses[v];
    }
    bool free_edge = false;
    long edges_gone = 0;
    for (const auto& [e, c] : uses) {
      const int v = valence_[static_cast<size_t>(e)];
      if (c < v && v - c < 2) return false;
      free_edge = free_edge || v == 1;
      edges_gone += c == v;
    }
    if (collapse_only) {
      if (!free_edge) return false;
      long vertices_gone = 0;
      for (const auto& [v, c] : corner_uses) vertices_gone += c == vertex_faces_[static_cast<size_t>(v)];
      // chi = V - E + F changes by -(vertices_gone - edges_gone + faces)
      if (vertices_gone - edges_gone + static_cast<long>(comp.size()) != 0) return false;
    } else if (!free_edge && !IsLayer(comp, uses)) {
      return false;
    }
    for (int f : comp) Remove(f);
    return true;
  }

  /// Whether every face of `comp` on one of its border edges lies over a face that stays on that edge: their
  /// third vertices, seen from the edge, within the layer angle. Then the component is a second layer (the
  /// cap of a bubble, a fold over a sheet) and removing it uncovers nothing; otherwise it is the only
  /// surface there, e.g. a strip of a sheet between branching curves. Always true without a layer angle.
  bool IsLayer(const std::vector<int>& comp, const std::unordered_map<int, int>& uses) const {
    if (!vertices_ || layer_cos_ <= -1.0) return true;
    const std::unordered_set<int> in(comp.begin(), comp.end());
    const std::vector<Vec3>& p = *vertices_;
    for (const auto& [e, c] : uses) {
      if (c == valence_[static_cast<size_t>(e)]) continue;  // inside the component
      const auto& ab = incidence_.edges[static_cast<size_t>(e)];
      const Vec3 a = p[static_cast<size_t>(ab[0])], axis = (p[static_cast<size_t>(ab[1])] - a).normalized();
      auto away = [&](int f) {  // from the edge towards the face's third vertex
        const Tri& t = faces_[static_cast<size_t>(f)];
        return AcrossLine(a, axis, p[static_cast<size_t>(ThirdVertex(t, ab[0], ab[1]))]);
      };
      for (int f : incidence_.faces[static_cast<size_t>(e)]) {
        if (!alive_[static_cast<size_t>(f)] || !in.count(f)) continue;
        const Vec3 mine = away(f);
        bool covered = false;
        for (int g : incidence_.faces[static_cast<size_t>(e)])
          covered = covered || (alive_[static_cast<size_t>(g)] && !in.count(g) && away(g).dot(mine) >= layer_cos_);
        if (!covered) return false;
      }
    }
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
    for (int v : faces_[static_cast<size_t>(f)]) --vertex_faces_[static_cast<size_t>(v)];
  }

  std::vector<Tri> faces_;
  std::vector<double> udf_;
  std::vector<char> alive_;
  EdgeFaces incidence_;
  std::vector<int> valence_;  ///< present faces per edge
  std::vector<int> vertex_faces_;  ///< present faces per vertex
  const std::vector<Vec3>* vertices_;
  double layer_cos_;
  std::vector<std::array<int, 3>> face_edges_;
  std::unordered_map<Tri, int, TriHash> by_vertices_;
};

/// Whether a face of triangle quality `quality` counts as degenerate (below `min_quality`, or of zero area).
bool IsDegenerate(double quality, double min_quality) { return !(quality >= min_quality) || quality == 0.0; }

std::string Count(size_t n, const char* what) { return std::to_string(n) + " " + what; }

}  // namespace

void ThinMeshOptions::Check() const {
  if (min_component_faces > 1000000) throw UsageError("--min-component-faces must be at most 1e6");
  if (!(overlap_angle_deg >= 0.0 && overlap_angle_deg < 90.0)) throw UsageError("--overlap-angle must be in [0, 90)");
  if (thinning != "paper" && thinning != "close-holes") throw UsageError("--thinning must be paper or close-holes");
  if (!(layer_angle_deg > 0.0 && layer_angle_deg <= 180.0)) throw UsageError("--layer-angle must be in (0, 180]");
  if (shell_rings < 0 || shell_rings > 4) throw UsageError("--shell-rings must be in [0, 4]");
  if (!(degenerate_quality >= 0.0 && degenerate_quality < 0.5))
    throw UsageError("--degenerate-quality must be in [0, 0.5)");
  relax.Check();
}

namespace {

// Step 0: degenerate faces (a repeated vertex, or quality below `min_quality`) and duplicates (same vertex
// set as an earlier face) dropped, the rest in order.
std::vector<Tri> CleanFaces(const TriangleMesh& thick, double min_quality, ThinMeshStats& st) {
  std::vector<Tri> faces;
  faces.reserve(thick.faces.size());
  std::unordered_set<Tri, TriHash> seen;
  for (const Tri& t : thick.faces) {
    const bool degenerate = t[0] == t[1] || t[1] == t[2] || t[0] == t[2] ||
                            IsDegenerate(TriangleQuality(thick.vertices[static_cast<size_t>(t[0])],
                                                         thick.vertices[static_cast<size_t>(t[1])],
                                                         thick.vertices[static_cast<size_t>(t[2])]),
                                         min_quality);
    if (degenerate) {
      ++st.degenerate_faces;
    } else if (!seen.insert(SortedTri(t)).second) {
      ++st.duplicate_faces;
    } else {
      faces.push_back(t);
    }
  }
  return faces;
}

// Step 2's pass: small components, farthest from the surface first, until none can go; with
// `collapse_only` only those whose removal is a collapse from a free edge (RemoveComponentIfSafe). Returns
// the faces removed.
size_t RemoveSmallComponents(Thinner& thinner, size_t min_faces, bool collapse_only, const std::string& what,
                             ThinMeshStats& st, Monitor& monitor) {
  size_t removed_faces = 0;
  for (;;) {
    const auto comps = thinner.ManifoldComponents(min_faces);
    size_t removed = 0, faces = 0, small = 0;
    for (const auto& comp : comps) {
      if (comp.size() >= min_faces) break;
      ++small;
      if (thinner.RemoveComponentIfSafe(comp, collapse_only)) {
        ++removed;
        faces += comp.size();
      }
    }
    removed_faces += faces;
    if (!collapse_only) {
      st.components_removed += removed;
      st.component_faces_removed += faces;
      st.small_components_left = small - removed;
    }
    if (small > 0)
      monitor.Info(what + Count(small, "components under ") + std::to_string(min_faces) + " faces, " +
                   Count(removed, "removed (") + Count(faces, "faces)"));
    if (removed == 0) return removed_faces;
  }
}

// Steps 1-3 (paper Sec. 3.4): tetrahedra, then small components, until neither changes anything.
void PaperThinning(Thinner& thinner, const ThinMeshOptions& options, ThinMeshStats& st, Monitor& monitor) {
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
      if (!tets.empty())
        monitor.Info("round " + std::to_string(st.rounds) + ": " + Count(tets.size(), "closed tetrahedra, ") +
                     Count(thinned, "thinned (2 faces removed from each)"));
      if (thinned == 0) break;
      changed = true;
    }
    // 2. Small components, farthest from the surface first, until none can go.
    const std::string round = "round " + std::to_string(st.rounds) + ": ";
    if (RemoveSmallComponents(thinner, options.min_component_faces, false, round, st, monitor) > 0) changed = true;
    if (!changed) break;
  }
}

// A Thinner over `faces`, with their centroids' UDF values (the order of removals) and the layer test of
// `options` (none with --thinning paper). The UDF is asked only for the faces `known` (optional) has not.
Thinner MakeThinner(const Udf& udf, const std::vector<Vec3>& vertices, std::vector<Tri> faces,
                    const ThinMeshOptions& options, const Thinner* known = nullptr) {
  std::vector<double> centroid_udf(faces.size(), 0.0);
  std::vector<size_t> ask;
  std::vector<Vec3> centroid;
  for (size_t f = 0; f < faces.size(); ++f) {
    if (known && known->CentroidUdf(faces[f], &centroid_udf[f])) continue;
    ask.push_back(f);
    centroid.push_back((vertices[static_cast<size_t>(faces[f][0])] + vertices[static_cast<size_t>(faces[f][1])] +
                        vertices[static_cast<size_t>(faces[f][2])]) /
                       3.0);
  }
  std::vector<double> asked;
  std::vector<Vec3> centroid_grad;
  udf.Evaluate(centroid, asked, centroid_grad);
  for (size_t k = 0; k < ask.size(); ++k) centroid_udf[ask[k]] = asked[k];
  const double layer_cos = options.thinning == "paper" ? -1.0 : std::cos(options.layer_angle_deg * M_PI / 180.0);
  return Thinner(std::move(faces), std::move(centroid_udf), &vertices, layer_cos);
}

std::vector<Tri> AliveFaces(const Thinner& thinner) {
  std::vector<Tri> kept;
  for (size_t f = 0; f < thinner.faces().size(); ++f)
    if (thinner.alive()[f]) kept.push_back(thinner.faces()[f]);
  return kept;
}

}  // namespace

TriangleMesh ThinMesh(const Udf& udf, const TriangleMesh& thick, const ThinMeshOptions& options, Monitor& monitor,
                      ThinMeshStats* stats_out) {
  options.Check();
  ThinMeshStats st;
  std::vector<Tri> faces = CleanFaces(thick, options.degenerate_quality, st);
  monitor.Info(Count(thick.faces.size(), "faces in; dropped ") + Count(st.degenerate_faces, "degenerate and ") +
               Count(st.duplicate_faces, "duplicate faces"));
  Thinner thinner = MakeThinner(udf, thick.vertices, std::move(faces), options);
  PaperThinning(thinner, options, st, monitor);
  if (options.thinning != "paper" && options.shell_rings > 0) {
    // 3b. Closed shells that no pair or component removal could thin, each opened at one face.
    st.shells_opened = thinner.OpenLocalShells(options.shell_rings);
    monitor.Info(Count(st.shells_opened, "closed shells opened (one face off the surface removed from each)"));
  }
  st.tetrahedra_left = thinner.Tetrahedra().size();
  if (st.tetrahedra_left > 0)
    monitor.Warn(Count(st.tetrahedra_left, "closed tetrahedra are left: none of their face pairs shares a manifold edge") +
                 (options.thinning != "paper" && options.shell_rings > 0 ? ", and none of their faces lies off the surface"
                                                                          : ""));
  if (st.small_components_left > 0)
    monitor.Warn(Count(st.small_components_left, "small components are left: removing them would open a hole"));
  std::vector<Tri> kept = AliveFaces(thinner);
  if (options.thinning != "paper") {
    // 4. Junction gaps: cracks (T-junctions), then triangular holes and notches (close_holes.h).
    const double min_cos = std::cos(options.overlap_angle_deg * M_PI / 180.0);
    st.cracks_split = SplitFacesOverCracks(thick.vertices, kept, options.degenerate_quality, min_cos, 0.1);
    st.holes_closed = CloseTriangularHoles(thick.vertices, kept, options.degenerate_quality, min_cos);
    monitor.Info(Count(st.cracks_split, "faces split over a crack (T-junction), ") +
                 Count(st.holes_closed, "triangular holes and notches closed"));
    // 5. What step 4 closed: its faces can close a tetrahedron where two corners or a corner and a curve
    // are a fraction of a spacing apart (step 1's rule thins it), and can leave the face the dual put at a
    // junction hanging from a free edge, its other edges now shared by 3 faces. Removing such a flap is a
    // collapse: it changes neither chi nor any other edge's count below 2.
    if (st.cracks_split + st.holes_closed > 0) {
      Thinner flaps = MakeThinner(udf, thick.vertices, std::move(kept), options, &thinner);
      for (;;) {
        const size_t thinned = flaps.ThinPass(flaps.Tetrahedra());
        st.tetrahedra_closed_thinned += thinned;
        if (thinned == 0) break;
      }
      st.flap_faces_removed = RemoveSmallComponents(flaps, options.min_component_faces, true, "dangling flaps: ", st, monitor);
      if (st.tetrahedra_closed_thinned > 0)
        monitor.Info(Count(st.tetrahedra_closed_thinned, "tetrahedra that step 4 closed thinned"));
      kept = AliveFaces(flaps);
    }
    if (options.fold_flaps) {
      // 5b. Folded flaps: a collapse each; the holes they bordered, one face larger, get step 4's closing.
      st.folded_flaps_removed = RemoveFoldedFlaps(thick.vertices, kept, options.overlap_angle_deg);
      if (st.folded_flaps_removed > 0)
        st.holes_closed_after_folds = CloseTriangularHoles(thick.vertices, kept, options.degenerate_quality, min_cos);
      monitor.Info(Count(st.folded_flaps_removed, "folded flaps removed, ") +
                   Count(st.holes_closed_after_folds, "holes closed after them"));
    }
  }
  if (options.thinning != "paper" && options.rim_flaps) {
    // 6. Flaps at the end of a branching curve, where it meets the rims of its sheets.
    st.rim_flaps_removed = RemoveRimFlaps(udf, thick.vertices, kept);
    monitor.Info(Count(st.rim_flaps_removed, "flaps at a rim removed"));
  }
  Thinner oriented(std::move(kept), std::vector<double>());
  oriented.OrientComponents();

  TriangleMesh out;
  out.vertices = thick.vertices;
  out.faces = oriented.faces();
  out = RemoveUnreferencedVertices(out);
  // 7. Sharp edges that cut across a curved feature, split onto it (if asked); then tangential relaxation:
  // even triangles (also round the split points), the same connectivity, every vertex on the zero set.
  st.chords = SplitFeatureChords(udf, out, options.chords, options.relax.feature_angle_deg, monitor);
  st.relax = RelaxTangentially(udf, out, options.relax, monitor);
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

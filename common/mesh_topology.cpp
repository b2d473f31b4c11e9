#include "common/mesh_topology.h"

#include "common/union_find.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace voroudf {

int EdgeFaces::Find(int a, int b) const {
  const auto it = index.find(EdgeKey(MakeEdge(a, b)));
  return it == index.end() ? -1 : it->second;
}

EdgeFaces BuildEdgeFaces(const std::vector<Tri>& faces) {
  std::vector<std::pair<uint64_t, int>> incidences;
  incidences.reserve(3 * faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    const Tri& t = faces[f];
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if (a == b) continue;
      incidences.emplace_back(EdgeKey(MakeEdge(a, b)), static_cast<int>(f));
    }
  }
  std::sort(incidences.begin(), incidences.end());
  incidences.erase(std::unique(incidences.begin(), incidences.end()), incidences.end());
  EdgeFaces ef;
  for (const auto& [key, f] : incidences) {
    if (ef.edges.empty() || EdgeKey(ef.edges.back()) != key) {
      ef.edges.push_back({static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu)});
      ef.faces.emplace_back();
    }
    ef.faces.back().push_back(f);
  }
  ef.index.reserve(ef.edges.size());
  for (size_t i = 0; i < ef.edges.size(); ++i) ef.index.emplace(EdgeKey(ef.edges[i]), static_cast<int>(i));
  return ef;
}

TopologyStats ComputeTopology(const TriangleMesh& mesh) {
  TopologyStats s;
  const size_t nv = mesh.vertices.size();
  s.num_faces = mesh.faces.size();
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  s.num_edges = ef.edges.size();

  std::vector<char> used(nv, 0), on_nm_edge(nv, 0);
  for (const Tri& t : mesh.faces)
    for (int v : t) used[v] = 1;
  s.num_vertices = static_cast<size_t>(std::count(used.begin(), used.end(), 1));
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const size_t valence = ef.faces[e].size();
    if (valence == 1) ++s.boundary_edges;
    if (valence >= 3) {
      ++s.nonmanifold_edges;
      on_nm_edge[ef.edges[e][0]] = on_nm_edge[ef.edges[e][1]] = 1;
    }
  }
  s.euler = static_cast<long long>(s.num_vertices) - static_cast<long long>(s.num_edges) +
            static_cast<long long>(s.num_faces);

  // Fans: the faces around v, joined when they share an edge incident to v.
  std::vector<std::vector<int>> vertex_faces(nv);
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int v : mesh.faces[f])
      if (vertex_faces[v].empty() || vertex_faces[v].back() != static_cast<int>(f))
        vertex_faces[v].push_back(static_cast<int>(f));
  for (size_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    if (on_nm_edge[v]) {
      ++s.nonmanifold_vertices;
      continue;
    }
    const auto& fs = vertex_faces[v];
    UnionFind uf(fs.size());
    // Faces around v sharing another vertex u share the edge (v, u).
    std::unordered_map<int, int> first_with;
    for (size_t i = 0; i < fs.size(); ++i) {
      for (int u : mesh.faces[fs[i]]) {
        if (u == static_cast<int>(v)) continue;
        const auto [it, inserted] = first_with.emplace(u, static_cast<int>(i));
        if (!inserted) uf.Union(it->second, static_cast<int>(i));
      }
    }
    int fans = 0;
    for (size_t i = 0; i < fs.size(); ++i) fans += uf.Find(static_cast<int>(i)) == static_cast<int>(i);
    if (fans > 1) ++s.nonmanifold_vertices;
  }

  UnionFind comp(nv);
  for (const Tri& t : mesh.faces) {
    comp.Union(t[0], t[1]);
    comp.Union(t[1], t[2]);
  }
  for (size_t v = 0; v < nv; ++v) s.components += used[v] && comp.Find(static_cast<int>(v)) == static_cast<int>(v);
  return s;
}

std::vector<int> EdgeConnectedComponents(const std::vector<Tri>& faces, int* num_components) {
  const EdgeFaces ef = BuildEdgeFaces(faces);
  UnionFind uf(faces.size());
  for (const auto& fs : ef.faces)
    for (size_t k = 1; k < fs.size(); ++k) uf.Union(fs[0], fs[k]);
  std::vector<int> id(faces.size(), -1), root_id(faces.size(), -1);
  int n = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const int r = uf.Find(static_cast<int>(f));
    if (root_id[r] < 0) root_id[r] = n++;
    id[f] = root_id[r];
  }
  if (num_components) *num_components = n;
  return id;
}

TriangleMesh RemoveUnreferencedVertices(const TriangleMesh& mesh) {
  std::vector<int> remap(mesh.vertices.size(), -1);
  for (const Tri& t : mesh.faces)
    for (int v : t) remap[v] = 0;
  TriangleMesh out;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (remap[v] < 0) continue;
    remap[v] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(mesh.vertices[v]);
  }
  out.faces.reserve(mesh.faces.size());
  for (const Tri& t : mesh.faces) out.faces.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

TriangleMesh WeldVertices(const TriangleMesh& mesh, double tolerance) {
  const size_t nv = mesh.vertices.size();
  std::vector<int> target(nv);
  std::iota(target.begin(), target.end(), 0);
  if (tolerance > 0 && nv > 0) {
    // Hash on a grid of cell `tolerance`; compare against the 27 neighbouring cells.
    auto cell_of = [&](const Vec3& p) {
      return std::array<long long, 3>{static_cast<long long>(std::floor(p.x() / tolerance)),
                                      static_cast<long long>(std::floor(p.y() / tolerance)),
                                      static_cast<long long>(std::floor(p.z() / tolerance))};
    };
    auto key_of = [](const std::array<long long, 3>& c) {
      return static_cast<uint64_t>(c[0]) * 73856093ull ^ static_cast<uint64_t>(c[1]) * 19349663ull ^
             static_cast<uint64_t>(c[2]) * 83492791ull;
    };
    std::unordered_map<uint64_t, std::vector<int>> grid;
    UnionFind uf(nv);
    const double tol2 = tolerance * tolerance;
    for (size_t v = 0; v < nv; ++v) {
      const auto c = cell_of(mesh.vertices[v]);
      for (long long dx = -1; dx <= 1; ++dx)
        for (long long dy = -1; dy <= 1; ++dy)
          for (long long dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find(key_of({c[0] + dx, c[1] + dy, c[2] + dz}));
            if (it == grid.end()) continue;
            for (int u : it->second)
              if ((mesh.vertices[u] - mesh.vertices[v]).squaredNorm() < tol2) uf.Union(u, static_cast<int>(v));
          }
      grid[key_of(c)].push_back(static_cast<int>(v));
    }
    for (size_t v = 0; v < nv; ++v) target[v] = uf.Find(static_cast<int>(v));
  }
  TriangleMesh welded;
  welded.vertices = mesh.vertices;
  for (const Tri& t : mesh.faces) {
    const Tri w{target[t[0]], target[t[1]], target[t[2]]};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;
    welded.faces.push_back(w);
  }
  return RemoveUnreferencedVertices(welded);
}

double TriangleQuality(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double la = (b - c).norm(), lb = (c - a).norm(), lc = (a - b).norm();
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double half_perimeter = 0.5 * (la + lb + lc);
  const double longest = std::max({la, lb, lc});
  if (area <= 0.0 || half_perimeter <= 0.0 || longest <= 0.0) return 0.0;
  return 6.0 / std::sqrt(3.0) * area / (half_perimeter * longest);
}

double MeanTriangleQuality(const TriangleMesh& mesh) {
  const size_t nf = mesh.faces.size();
  if (nf == 0) return 0.0;
  std::vector<double> q(nf);
#pragma omp parallel for schedule(static)
  for (long long f = 0; f < static_cast<long long>(nf); ++f) {
    const Tri& t = mesh.faces[static_cast<size_t>(f)];
    q[static_cast<size_t>(f)] = TriangleQuality(mesh.vertices[static_cast<size_t>(t[0])], mesh.vertices[static_cast<size_t>(t[1])],
                                                mesh.vertices[static_cast<size_t>(t[2])]);
  }
  double sum = 0;
  for (double x : q) sum += x;  // in face order, whatever the threads
  return sum / static_cast<double>(nf);
}

TriangleMesh CanonicalOrder(const TriangleMesh& mesh) {
  std::vector<int> order(mesh.vertices.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    const Vec3 &p = mesh.vertices[static_cast<size_t>(a)], &q = mesh.vertices[static_cast<size_t>(b)];
    if (p.x() != q.x()) return p.x() < q.x();
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.z() != q.z()) return p.z() < q.z();
    return a < b;
  });
  TriangleMesh out;
  std::vector<int> rank(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    rank[static_cast<size_t>(order[k])] = static_cast<int>(k);
    out.vertices.push_back(mesh.vertices[static_cast<size_t>(order[k])]);
  }
  for (const Tri& t : mesh.faces) {
    Tri r{rank[static_cast<size_t>(t[0])], rank[static_cast<size_t>(t[1])], rank[static_cast<size_t>(t[2])]};
    std::rotate(r.begin(), std::min_element(r.begin(), r.end()), r.end());
    out.faces.push_back(r);
  }
  std::sort(out.faces.begin(), out.faces.end());
  return out;
}

Vec3 AreaNormal(const std::vector<Vec3>& vertices, const Tri& t) {
  return (vertices[static_cast<size_t>(t[1])] - vertices[static_cast<size_t>(t[0])])
      .cross(vertices[static_cast<size_t>(t[2])] - vertices[static_cast<size_t>(t[0])]);
}

namespace {

// The face's unit normal, or zero for a face of no area.
Vec3 UnitNormal(const std::vector<Vec3>& vertices, const Tri& t) {
  const Vec3 c = AreaNormal(vertices, t);
  const double len = c.norm();
  return len > 0 ? Vec3(c / len) : Vec3::Zero();
}

// Whether face t runs along the directed edge a -> b.
bool Runs(const Tri& t, int a, int b) {
  for (int k = 0; k < 3; ++k)
    if (t[static_cast<size_t>(k)] == a && t[static_cast<size_t>((k + 1) % 3)] == b) return true;
  return false;
}

}  // namespace

std::vector<Edge> FeatureEdges(const TriangleMesh& mesh, double min_angle_deg) {
  return FeatureEdges(mesh, BuildEdgeFaces(mesh.faces), min_angle_deg);
}

std::vector<Edge> FeatureEdges(const TriangleMesh& mesh, const EdgeFaces& ef, double min_angle_deg) {
  const double max_cos = std::cos(min_angle_deg * M_PI / 180.0);
  std::vector<Edge> out;
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const auto& fs = ef.faces[e];
    if (fs.size() >= 3) {
      out.push_back(ef.edges[e]);
      continue;
    }
    if (fs.size() != 2) continue;
    const Tri& f0 = mesh.faces[static_cast<size_t>(fs[0])];
    const Tri& f1 = mesh.faces[static_cast<size_t>(fs[1])];
    const Vec3 n0 = UnitNormal(mesh.vertices, f0);
    Vec3 n1 = UnitNormal(mesh.vertices, f1);
    if (n0.isZero() || n1.isZero()) continue;
    const int a = ef.edges[e][0], b = ef.edges[e][1];
    // Consistently oriented faces run along the edge in opposite directions; otherwise turn one round.
    if (Runs(f0, a, b) == Runs(f1, a, b)) n1 = -n1;
    if (n0.dot(n1) < max_cos) out.push_back(ef.edges[e]);
  }
  return out;
}

}  // namespace voroudf

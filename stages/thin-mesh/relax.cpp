#include "stages/thin-mesh/relax.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/errors.h"
#include "common/mesh_topology.h"
#include "common/projection.h"
#include "common/union_find.h"

namespace voroudf {

void RelaxOptions::Check() const {
  if (iterations < 0 || iterations > 100) throw UsageError("--relax-iters must be in [0, 100]");
  if (!(step > 0.0 && step <= 1.0)) throw UsageError("--relax-step must be in (0, 1]");
  if (!(feature_angle_deg > 0.0 && feature_angle_deg < 180.0)) throw UsageError("--relax-feature-angle must be in (0, 180)");
  if (!(max_turn_deg > 0.0 && max_turn_deg < 180.0)) throw UsageError("relax: the largest face turn must be in (0, 180)");
}

namespace {

// The same settings as the other stages' projections (--proj-tol-rel 1e-5, --proj-floor-rel 1e-2,
// --proj-max-iters 50, --proj-twin-factor), whose points these vertices were.
ProjectionOptions SeedProjection(const Udf& udf) {
  ProjectionOptions p = RelativeProjection(udf.Domain().Diagonal(), 1e-5, 1e-2, 50);
  p.twin_factor = kProjTwinFactor;
  return p;
}

// Per vertex, its neighbours and faces (CSR-free: a few thousand vertices), and whether it may move.
struct Rings {
  std::vector<std::vector<int>> neighbours, faces;
  std::vector<char> movable;
};

Rings MovableVertices(const TriangleMesh& mesh, double feature_angle_deg) {
  const size_t n = mesh.vertices.size();
  Rings r;
  r.neighbours.resize(n);
  r.faces.resize(n);
  r.movable.assign(n, 1);
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int v : mesh.faces[f]) r.faces[static_cast<size_t>(v)].push_back(static_cast<int>(f));
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const int a = ef.edges[e][0], b = ef.edges[e][1];
    r.neighbours[static_cast<size_t>(a)].push_back(b);
    r.neighbours[static_cast<size_t>(b)].push_back(a);
    if (ef.faces[e].size() != 2) r.movable[static_cast<size_t>(a)] = r.movable[static_cast<size_t>(b)] = 0;
  }
  for (const Edge& e : FeatureEdges(mesh, ef, feature_angle_deg))
    r.movable[static_cast<size_t>(e[0])] = r.movable[static_cast<size_t>(e[1])] = 0;
  // One fan: the vertex's faces connected through its edges (two cones touching at a vertex are two).
  for (size_t v = 0; v < n; ++v) {
    if (!r.movable[v]) continue;
    const std::vector<int>& fs = r.faces[v];
    if (fs.empty()) {
      r.movable[v] = 0;
      continue;
    }
    UnionFind fans(fs.size());
    for (int w : r.neighbours[v]) {
      const int e = ef.Find(static_cast<int>(v), w);
      const std::vector<int>& two = ef.faces[static_cast<size_t>(e)];
      const auto at = [&](int f) { return static_cast<int>(std::find(fs.begin(), fs.end(), f) - fs.begin()); };
      fans.Union(at(two[0]), at(two[1]));
    }
    for (size_t k = 1; k < fs.size(); ++k)
      if (fans.Find(static_cast<int>(k)) != fans.Find(0)) r.movable[v] = 0;
  }
  return r;
}

// Undoes the accepted moves of every face's vertices that the moves (all at once) would turn by more than
// acos(min_cos), until no face turns that far. accept[i] is movers[i]'s.
void UndoTurnedFaces(const TriangleMesh& mesh, const std::vector<int>& movers, const std::vector<Vec3>& moved,
                     double min_cos, std::vector<char>* accept) {
  std::vector<int> slot(mesh.vertices.size(), -1);
  for (size_t i = 0; i < movers.size(); ++i) slot[static_cast<size_t>(movers[i])] = static_cast<int>(i);
  auto moving = [&](int v) {
    const int k = slot[static_cast<size_t>(v)];
    return k >= 0 && (*accept)[static_cast<size_t>(k)];
  };
  for (bool again = true; again;) {
    again = false;
    std::vector<Vec3> trial = mesh.vertices;
    for (size_t i = 0; i < movers.size(); ++i)
      if ((*accept)[i]) trial[static_cast<size_t>(movers[i])] = moved[i];
    for (const Tri& t : mesh.faces) {
      if (!moving(t[0]) && !moving(t[1]) && !moving(t[2])) continue;
      const Vec3 before = AreaNormal(mesh.vertices, t), after = AreaNormal(trial, t);
      if (after.norm() > 0 && after.dot(before) >= min_cos * after.norm() * before.norm()) continue;
      for (int v : t)
        if (moving(v)) {
          (*accept)[static_cast<size_t>(slot[static_cast<size_t>(v)])] = 0;
          again = true;
        }
    }
  }
}

}  // namespace

RelaxStats RelaxTangentially(const Udf& udf, TriangleMesh& mesh, const RelaxOptions& options, Monitor& monitor) {
  RelaxStats st;
  if (options.iterations == 0 || mesh.faces.empty()) return st;
  const Rings rings = MovableVertices(mesh, options.feature_angle_deg);
  std::vector<int> movers;
  for (size_t v = 0; v < rings.movable.size(); ++v)
    if (rings.movable[v]) movers.push_back(static_cast<int>(v));
  st.movable = movers.size();
  const ProjectionOptions projection = SeedProjection(udf);
  const double min_cos = std::cos(options.max_turn_deg * M_PI / 180.0);
  std::vector<Vec3>& x = mesh.vertices;
  for (int iter = 0; iter < options.iterations; ++iter) {
    // Targets: a step toward the ring's centroid, in the plane normal to the area-weighted face normal.
    std::vector<Vec3> target(movers.size()), moved(movers.size());
    const long m = static_cast<long>(movers.size());
#pragma omp parallel for schedule(static)
    for (long i = 0; i < m; ++i) {
      const size_t v = static_cast<size_t>(movers[static_cast<size_t>(i)]);
      Vec3 normal = Vec3::Zero(), centroid = Vec3::Zero();
      for (int f : rings.faces[v]) normal += AreaNormal(x, mesh.faces[static_cast<size_t>(f)]);
      for (int w : rings.neighbours[v]) centroid += x[static_cast<size_t>(w)];
      centroid /= static_cast<double>(rings.neighbours[v].size());
      Vec3 d = centroid - x[v];
      if (normal.norm() > 0) d -= d.dot(normal.normalized()) * normal.normalized();
      target[static_cast<size_t>(i)] = x[v] + options.step * d;
    }
    moved = target;
    const ProjectionResult r = ProjectToZeroSet(udf, moved, projection, Monitor::Null());
    std::vector<char> accept(movers.size(), 0);
    for (size_t i = 0; i < movers.size(); ++i) {
      const Vec3& from = x[static_cast<size_t>(movers[i])];
      accept[i] = r.converged[i] && (moved[i] - target[i]).norm() <= (target[i] - from).norm();
    }
    UndoTurnedFaces(mesh, movers, moved, min_cos, &accept);
    for (size_t i = 0; i < movers.size(); ++i) {
      if (accept[i]) {
        x[static_cast<size_t>(movers[i])] = moved[i];
        ++st.moves;
      } else {
        ++st.undone;
      }
    }
  }
  monitor.Info("relaxation: " + std::to_string(st.movable) + " of " + std::to_string(x.size()) +
               " vertices inside smooth patches, " + std::to_string(st.moves) + " moves kept, " +
               std::to_string(st.undone) + " undone (over " + std::to_string(options.iterations) + " steps)");
  return st;
}

}  // namespace voroudf

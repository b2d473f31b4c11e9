#include "stages/thin-mesh/feature_chords.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "common/mesh_topology.h"

namespace voroudf {
namespace {

const double kAlongSheetCos = std::cos(30.0 * M_PI / 180.0);

// Face t with edge (a, b) replaced by (a, v) and (v, b), orientation kept: two faces.
std::array<Tri, 2> SplitFace(const Tri& t, int a, int b, int v) {
  for (int k = 0; k < 3; ++k) {
    const int x = t[static_cast<size_t>(k)], y = t[static_cast<size_t>((k + 1) % 3)], z = t[static_cast<size_t>((k + 2) % 3)];
    if ((x == a && y == b) || (x == b && y == a)) return {Tri{x, v, z}, Tri{v, y, z}};
  }
  return {t, t};
}

}  // namespace

ChordSplitStats SplitFeatureChords(const Udf& udf, TriangleMesh& mesh, const ChordSplitOptions& options,
                                   double feature_angle_deg, Monitor& monitor) {
  ChordSplitStats st;
  if (!options.enabled || mesh.faces.empty()) return st;
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  // Each sharp manifold edge with its two faces and their third vertices, found once.
  struct Sharp {
    Edge edge;
    std::array<int, 2> face, third;
  };
  std::vector<Sharp> sharp;
  for (const Edge& e : FeatureEdges(mesh, ef, feature_angle_deg)) {
    const std::vector<int>& fs = ef.faces[static_cast<size_t>(ef.Find(e[0], e[1]))];
    if (fs.size() != 2) continue;
    const Sharp c{e, {fs[0], fs[1]},
                  {ThirdVertex(mesh.faces[static_cast<size_t>(fs[0])], e[0], e[1]),
                   ThirdVertex(mesh.faces[static_cast<size_t>(fs[1])], e[0], e[1])}};
    // Thin-mesh has dropped degenerate faces (a repeated vertex); this keeps it so here.
    if (c.third[0] >= 0 && c.third[1] >= 0) sharp.push_back(c);
  }
  st.sharp = sharp.size();
  if (sharp.empty()) return st;
  const std::vector<Vec3>& x = mesh.vertices;
  // One point on each side, a quarter of the edge into each face from the midpoint; each edge's midpoint,
  // unit direction and length, kept for the solve below.
  std::vector<Vec3> mid(sharp.size()), dir(sharp.size()), side(2 * sharp.size());
  std::vector<double> len(sharp.size());
  for (size_t k = 0; k < sharp.size(); ++k) {
    const Vec3 a = x[static_cast<size_t>(sharp[k].edge[0])], b = x[static_cast<size_t>(sharp[k].edge[1])];
    len[k] = (b - a).norm();
    dir[k] = (b - a) / len[k];
    mid[k] = 0.5 * (a + b);
    for (size_t j = 0; j < 2; ++j) {
      Vec3 w = x[static_cast<size_t>(sharp[k].third[j])] - mid[k];
      w -= w.dot(dir[k]) * dir[k];
      side[2 * k + j] = mid[k] + 0.25 * len[k] * (w.norm() > 0 ? Vec3(w.normalized()) : Vec3::Zero());
    }
  }
  std::vector<double> d_side;
  std::vector<Vec3> g_side;
  udf.Evaluate(side, d_side, g_side);
  // Each side's tangent plane: through its foot q - d(q) grad d(q), normal grad d(q). Where they meet in the
  // bisecting plane of the edge is the feature's point (a 3 x 3 solve); a chord when that is off the edge.
  std::vector<size_t> which;
  std::vector<Vec3> feature;
  const double min_sin = std::sin(20.0 * M_PI / 180.0);
  for (size_t k = 0; k < sharp.size(); ++k) {
    const Vec3& t = dir[k];
    const Vec3 n0 = g_side[2 * k], n1 = g_side[2 * k + 1];
    if (n0.squaredNorm() < 0.25 || n1.squaredNorm() < 0.25 || n0.normalized().cross(n1.normalized()).norm() < min_sin)
      continue;
    // Each face must lie along its sheet (normals within 30 degrees): otherwise the edge is not between the
    // two sheets of a feature but across a part the mesh does not follow.
    const Vec3 m0 = AreaNormal(x, mesh.faces[static_cast<size_t>(sharp[k].face[0])]);
    const Vec3 m1 = AreaNormal(x, mesh.faces[static_cast<size_t>(sharp[k].face[1])]);
    if (std::abs(m0.normalized().dot(n0.normalized())) < kAlongSheetCos ||
        std::abs(m1.normalized().dot(n1.normalized())) < kAlongSheetCos)
      continue;
    const Vec3 f0 = side[2 * k] - d_side[2 * k] * n0, f1 = side[2 * k + 1] - d_side[2 * k + 1] * n1;
    Eigen::Matrix3d m;
    m.row(0) = n0.transpose();
    m.row(1) = n1.transpose();
    m.row(2) = t.transpose();
    const Vec3 p = m.colPivHouseholderQr().solve(Vec3(n0.dot(f0), n1.dot(f1), t.dot(mid[k])));
    const double off = (p - mid[k]).norm();
    if (!p.allFinite() || !(off > options.sagitta_rel * len[k]) || off > 0.5 * len[k]) continue;
    ++st.chords;
    which.push_back(k);
    feature.push_back(p);
  }
  std::vector<double> d_feature;
  std::vector<Vec3> g_feature;
  if (!feature.empty()) udf.Evaluate(feature, d_feature, g_feature);
  // Split, each face once: a face with two chords takes its first.
  std::vector<char> touched(mesh.faces.size(), 0);
  const size_t faces_before = mesh.faces.size();
  for (size_t i = 0; i < which.size(); ++i) {
    const size_t k = which[i];
    if (!(d_feature[i] <= 0.25 * (feature[i] - mid[k]).norm())) continue;  // the planes' point is on the surface
    const std::array<int, 2>& fs = sharp[k].face;
    if (touched[static_cast<size_t>(fs[0])] || touched[static_cast<size_t>(fs[1])]) continue;
    const int v = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back(feature[i]);
    for (int f : fs) {
      touched[static_cast<size_t>(f)] = 1;
      const std::array<Tri, 2> two = SplitFace(mesh.faces[static_cast<size_t>(f)], sharp[k].edge[0], sharp[k].edge[1], v);
      mesh.faces[static_cast<size_t>(f)] = two[0];
      mesh.faces.push_back(two[1]);
    }
    ++st.split;
  }
  monitor.Info("feature chords: " + std::to_string(st.chords) + " of " + std::to_string(st.sharp) +
               " sharp edges cut across their feature; " + std::to_string(st.split) + " split onto it (" +
               std::to_string(mesh.faces.size() - faces_before) + " faces added)");
  return st;
}

}  // namespace voroudf

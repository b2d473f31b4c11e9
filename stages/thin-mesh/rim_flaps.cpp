#include "stages/thin-mesh/rim_flaps.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/mesh_topology.h"
#include "stages/thin-mesh/off_surface.h"

namespace voroudf {
namespace {

// The rim test: whether edge ab, with a face towards `inner` on it, lies on a rim of the surface. The
// UDF is probed around the midpoint of ab, at half the height of that face, in the directions perpendicular
// to ab from straight on beyond the edge to 30 degrees short of the face, every 15 degrees. A rim has no
// surface there: every probe is above 0.3 x the radius (at least half of it, down to 0.46 of it where the
// rim of a second sheet crossing at the end of a branching curve passes beside the midpoint). A crease or a
// branching curve has its other faces there, at most 7.5 degrees from a probe (at most 0.13 x the radius).
bool OnRim(const Udf& udf, const std::vector<Vec3>& p, int a, int b, int inner) {
  const Vec3 mid = 0.5 * (p[static_cast<size_t>(a)] + p[static_cast<size_t>(b)]);
  const Vec3 e = (p[static_cast<size_t>(b)] - p[static_cast<size_t>(a)]).normalized();
  Vec3 w = p[static_cast<size_t>(inner)] - mid;
  w -= w.dot(e) * e;
  const double radius = 0.5 * w.norm();
  if (!(radius > 0.0)) return false;
  w.normalize();
  const Vec3 side = e.cross(w);
  std::vector<Vec3> probe;
  for (int deg = -150; deg <= 150; deg += 15) {
    const double phi = deg * M_PI / 180.0;
    probe.push_back(mid + radius * (-std::cos(phi) * w + std::sin(phi) * side));
  }
  std::vector<double> d;
  std::vector<Vec3> grad;
  udf.Evaluate(probe, d, grad);
  return *std::min_element(d.begin(), d.end()) > 0.3 * radius;
}

// Faces removed one by one in face order, with each edge's live face count (both steps' bookkeeping).
struct LiveFaces {
  const std::vector<Tri>& faces;
  EdgeFaces inc;
  std::vector<int> count;
  std::vector<char> alive;

  explicit LiveFaces(const std::vector<Tri>& f) : faces(f), inc(BuildEdgeFaces(f)), count(inc.edges.size()), alive(f.size(), 1) {
    for (size_t e = 0; e < count.size(); ++e) count[e] = static_cast<int>(inc.faces[e].size());
  }
  std::array<int, 3> Edges(size_t f) const {
    const Tri& t = faces[f];
    std::array<int, 3> e;
    for (int k = 0; k < 3; ++k) e[static_cast<size_t>(k)] = inc.Find(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]);
    return e;
  }
  bool HasFreeEdge(const std::array<int, 3>& e) const {
    for (int x : e)
      if (count[static_cast<size_t>(x)] == 1) return true;
    return false;
  }
  void Remove(size_t f) {
    alive[f] = 0;
    for (int x : Edges(f)) --count[static_cast<size_t>(x)];
  }
  std::vector<Tri> Kept() const {
    std::vector<Tri> kept;
    for (size_t f = 0; f < faces.size(); ++f)
      if (alive[f]) kept.push_back(faces[f]);
    return kept;
  }
};

}  // namespace

size_t RemoveRimFlaps(const Udf& udf, const std::vector<Vec3>& v, std::vector<Tri>& faces) {
  LiveFaces live(faces);
  const EdgeFaces& inc = live.inc;
  std::vector<int>& count = live.count;
  // Centroid UDFs, in one batch, of the faces that can be flaps: counts only fall, so a face on no branching
  // edge now never stands on one.
  std::vector<double> centroid_udf(faces.size(), 0.0);
  std::vector<size_t> asked;
  std::vector<Vec3> centroid;
  for (size_t e = 0; e < count.size(); ++e)
    if (count[e] >= 3)
      for (int f : inc.faces[e]) asked.push_back(static_cast<size_t>(f));
  std::sort(asked.begin(), asked.end());
  asked.erase(std::unique(asked.begin(), asked.end()), asked.end());
  for (size_t f : asked)
    centroid.push_back((v[static_cast<size_t>(faces[f][0])] + v[static_cast<size_t>(faces[f][1])] +
                        v[static_cast<size_t>(faces[f][2])]) / 3.0);
  std::vector<double> asked_udf;
  std::vector<Vec3> asked_grad;
  if (!centroid.empty()) udf.Evaluate(centroid, asked_udf, asked_grad);
  for (size_t k = 0; k < asked.size(); ++k) centroid_udf[asked[k]] = asked_udf[k];
  size_t removed = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const Tri& t = faces[f];
    const std::array<int, 3> e = live.Edges(f);
    bool branching = false;
    for (int x : e) branching = branching || count[static_cast<size_t>(x)] >= 3;
    const bool free_edge = live.HasFreeEdge(e);
    if (!free_edge || !branching) continue;
    if (!OffSurface(centroid_udf[f], v[static_cast<size_t>(t[0])], v[static_cast<size_t>(t[1])],
                    v[static_cast<size_t>(t[2])]))
      continue;
    bool opens = false;
    for (int k = 0; k < 3 && !opens; ++k) {
      const size_t x = static_cast<size_t>(e[static_cast<size_t>(k)]);
      if (count[x] != 2) continue;
      for (int g : inc.faces[x]) {
        if (g == static_cast<int>(f) || !live.alive[static_cast<size_t>(g)]) continue;
        const Tri& o = faces[static_cast<size_t>(g)];
        const int a = inc.edges[x][0], b = inc.edges[x][1];
        opens = !OnRim(udf, v, a, b, o[0] + o[1] + o[2] - a - b);
      }
    }
    if (opens) continue;
    live.Remove(f);
    ++removed;
  }
  faces = live.Kept();
  return removed;
}

size_t RemoveFoldedFlaps(const std::vector<Vec3>& v, std::vector<Tri>& faces, double overlap_angle_deg) {
  const double min_cos = std::cos(overlap_angle_deg * M_PI / 180.0);
  LiveFaces live(faces);
  auto away = [&](int f, const Edge& ab) {  // from edge ab towards face f's third vertex
    const Tri& t = faces[static_cast<size_t>(f)];
    const Vec3 a = v[static_cast<size_t>(ab[0])], axis = (v[static_cast<size_t>(ab[1])] - a).normalized();
    return AcrossLine(a, axis, v[static_cast<size_t>(ThirdVertex(t, ab[0], ab[1]))]);
  };
  size_t removed = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const std::array<int, 3> e = live.Edges(f);
    if (!live.HasFreeEdge(e)) continue;
    bool folded = false;
    for (int x : e) {
      if (live.count[static_cast<size_t>(x)] < 3 || folded) continue;
      const Edge& ab = live.inc.edges[static_cast<size_t>(x)];
      const Vec3 mine = away(static_cast<int>(f), ab);
      for (int g : live.inc.faces[static_cast<size_t>(x)])
        folded = folded || (g != static_cast<int>(f) && live.alive[static_cast<size_t>(g)] && away(g, ab).dot(mine) >= min_cos);
    }
    if (!folded) continue;
    live.Remove(f);
    ++removed;
  }
  faces = live.Kept();
  return removed;
}

}  // namespace voroudf

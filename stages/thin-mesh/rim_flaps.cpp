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

}  // namespace

size_t RemoveRimFlaps(const Udf& udf, const std::vector<Vec3>& v, std::vector<Tri>& faces) {
  const EdgeFaces inc = BuildEdgeFaces(faces);
  std::vector<int> count(inc.edges.size());
  for (size_t e = 0; e < count.size(); ++e) count[e] = static_cast<int>(inc.faces[e].size());
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
  std::vector<char> alive(faces.size(), 1);
  size_t removed = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const Tri& t = faces[f];
    std::array<int, 3> e;
    for (int k = 0; k < 3; ++k) e[static_cast<size_t>(k)] = inc.Find(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]);
    bool free_edge = false, branching = false;
    for (int x : e) {
      free_edge = free_edge || count[static_cast<size_t>(x)] == 1;
      branching = branching || count[static_cast<size_t>(x)] >= 3;
    }
    if (!free_edge || !branching) continue;
    if (!OffSurface(centroid_udf[f], v[static_cast<size_t>(t[0])], v[static_cast<size_t>(t[1])],
                    v[static_cast<size_t>(t[2])]))
      continue;
    bool opens = false;
    for (int k = 0; k < 3 && !opens; ++k) {
      const size_t x = static_cast<size_t>(e[static_cast<size_t>(k)]);
      if (count[x] != 2) continue;
      for (int g : inc.faces[x]) {
        if (g == static_cast<int>(f) || !alive[static_cast<size_t>(g)]) continue;
        const Tri& o = faces[static_cast<size_t>(g)];
        const int a = inc.edges[x][0], b = inc.edges[x][1];
        opens = !OnRim(udf, v, a, b, o[0] + o[1] + o[2] - a - b);
      }
    }
    if (opens) continue;
    alive[f] = 0;
    for (int x : e) --count[static_cast<size_t>(x)];
    ++removed;
  }
  std::vector<Tri> kept;
  for (size_t f = 0; f < faces.size(); ++f)
    if (alive[f]) kept.push_back(faces[f]);
  faces = std::move(kept);
  return removed;
}

}  // namespace voroudf

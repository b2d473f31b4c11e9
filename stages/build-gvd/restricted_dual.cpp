#include "stages/build-gvd/restricted_dual.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "common/face_cycles.h"
#include "common/mesh_topology.h"

namespace voroudf {
namespace {

// Whether p lies strictly inside the circumcircle of (a, b, c), all four projected onto the plane normal to
// `chart` (their mean surface normal). The plane is that of the four points, not of the triangle, so that
// the test is the same for every triangle of the four: of a quadrilateral's two triangulations exactly one
// passes (unless the four are cocircular within `cocircular`, relative: then neither blocks).
bool InCircumcircle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, const Vec3& chart, double cocircular) {
  const Vec3 u = chart.unitOrthogonal(), v = chart.cross(u).normalized();
  auto flat = [&](const Vec3& q) { return Eigen::Vector2d((q - p).dot(u), (q - p).dot(v)); };
  const Eigen::Vector2d A = flat(a), B = flat(b), C = flat(c);  // p at the origin
  const double orient = (B - A).x() * (C - A).y() - (B - A).y() * (C - A).x();
  const double det = A.squaredNorm() * (B.x() * C.y() - B.y() * C.x()) - B.squaredNorm() * (A.x() * C.y() - A.y() * C.x()) +
                     C.squaredNorm() * (A.x() * B.y() - A.y() * B.x());
  const double scale = std::max({A.squaredNorm(), B.squaredNorm(), C.squaredNorm()});
  return det * (orient > 0 ? 1 : -1) > cocircular * scale * std::abs(orient);
}

// The Delaunay triangulation of a triangle (i, j, k) and a seed v inside its circumcircle, in the chart: with
// v inside the triangle, the three triangles from v; with v beyond (or on) the edge (p, q) opposite r, the
// flip (r, p, v), (r, v, q). Each sorted.
std::vector<Tri> DelaunayReplacement(const Tri& t, int v, const Vec3& chart, const std::vector<Vec3>& seeds) {
  const Vec3 u = chart.unitOrthogonal(), w = chart.cross(u).normalized();
  auto flat = [&](int q) {
    const Vec3& x = seeds[static_cast<size_t>(q)];
    return Eigen::Vector2d(x.dot(u), x.dot(w));
  };
  auto side = [&](int p, int q, int r) {  // orientation of (p, q, r) in the chart
    const Eigen::Vector2d P = flat(p), Q = flat(q), R = flat(r);
    return (Q - P).x() * (R - P).y() - (Q - P).y() * (R - P).x();
  };
  const double whole = side(t[0], t[1], t[2]);
  for (int k = 0; k < 3; ++k) {
    const int p = t[static_cast<size_t>(k)], q = t[static_cast<size_t>((k + 1) % 3)], r = t[static_cast<size_t>((k + 2) % 3)];
    if (side(p, q, v) * whole <= 0.0) return {SortedTri({r, p, v}), SortedTri({r, v, q})};
  }
  return {SortedTri({t[0], t[1], v}), SortedTri({t[1], t[2], v}), SortedTri({t[2], t[0], v})};
}

// The chart of four seeds, the plane their junction is triangulated in: the best-fit plane of the four,
// when they are nearly coplanar (its thickness at most `max_flatness` x its extent) and every one of them
// on a sheet has its surface normal within the angle of `min_cos` of the plane's normal (sign-blind: a
// UDF's gradient has no orientation). Zero otherwise: across a crease or where two sheets cross, the four
// lie on no common plane of the surface. Seeds on a sharp edge, corner or branching curve have no normal
// of their own (their gradient is one of their sheets') and no say in it.
Vec3 ChartNormal(const std::array<int, 4>& id, const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                 const std::vector<uint8_t>& on_sheet, double min_cos, double max_flatness) {
  Vec3 centre = Vec3::Zero();
  for (int s : id) centre += seeds[static_cast<size_t>(s)] / 4;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int s : id) cov += (seeds[static_cast<size_t>(s)] - centre) * (seeds[static_cast<size_t>(s)] - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (!(eig.eigenvalues()(0) <= max_flatness * max_flatness * eig.eigenvalues()(2))) return Vec3::Zero();
  const Vec3 plane = eig.eigenvectors().col(0);
  for (int s : id)
    if (on_sheet[static_cast<size_t>(s)] && !(std::abs(plane.dot(normals[static_cast<size_t>(s)])) >= min_cos))
      return Vec3::Zero();
  return plane;
}

// Geodesic neighbours: per seed, the seeds it shares a triple with, sorted.
std::vector<std::vector<int>> GeodesicNeighbours(size_t num_seeds, const std::vector<Tri>& triples) {
  std::vector<std::vector<int>> neighbours(num_seeds);
  for (const Tri& t : triples)
    for (int k = 0; k < 3; ++k)
      for (int m = 0; m < 3; ++m)
        if (m != k) neighbours[static_cast<size_t>(t[k])].push_back(t[m]);
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return neighbours;
}

// Seeds a and b lie on two sides of a link (two faces of a crease, two sheets where sheets cross, or the
// two sides of a sheet's curve) when the directions from the link to them, across it, differ by more than
// this: on one side of it (one face, a curved one included) they lie within a few tens of degrees.
constexpr double kLinkSideAngleDeg = 60.0;
const double kLinkSideMaxCos = std::cos(kLinkSideAngleDeg * M_PI / 180.0);

// Whether curve seeds c and d are consecutive on a chain: no curve seed among their common geodesic
// neighbours (left in *common) lies strictly inside the sphere on cd (the Gabriel rule).
bool Consecutive(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& is_curve,
                 const std::vector<std::vector<int>>& neighbours, int c, int d, std::vector<int>* common) {
  const auto &nc = neighbours[static_cast<size_t>(c)], &nd = neighbours[static_cast<size_t>(d)];
  common->clear();
  std::set_intersection(nc.begin(), nc.end(), nd.begin(), nd.end(), std::back_inserter(*common));
  const Vec3 &pc = seeds[static_cast<size_t>(c)], &pd = seeds[static_cast<size_t>(d)];
  for (int w : *common) {
    const Vec3& pw = seeds[static_cast<size_t>(w)];
    if (is_curve[static_cast<size_t>(w)] && (pc - pw).dot(pd - pw) < 0.0) return false;
  }
  return true;
}

// The chain links among the curve seeds (KeepChainLinks): consecutive geodesic neighbours.
std::vector<std::array<int, 2>> ChainLinks(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& is_curve,
                                           const std::vector<std::vector<int>>& neighbours) {
  std::vector<std::array<int, 2>> links;
  std::vector<int> common;
  for (size_t c = 0; c < seeds.size(); ++c) {
    if (!is_curve[c]) continue;
    for (int d : neighbours[c])
      if (d > static_cast<int>(c) && is_curve[static_cast<size_t>(d)] &&
          Consecutive(seeds, is_curve, neighbours, static_cast<int>(c), d, &common))
        links.push_back({static_cast<int>(c), d});
  }
  return links;
}

// The triples being decided, with their live count per edge.
struct LiveTriples {
  std::unordered_set<Tri, TriHash> present;
  std::unordered_map<uint64_t, int> per_edge;

  explicit LiveTriples(const std::vector<Tri>& triples) : present(triples.begin(), triples.end()) {
    for (const Tri& t : triples)
      for (int k = 0; k < 3; ++k) ++per_edge[EdgeKey(MakeEdge(t[k], t[(k + 1) % 3]))];
  }
  bool Has(int a, int b, int c) const { return present.count(SortedTri({a, b, c})) > 0; }
  int OnEdge(int a, int b) const {
    const auto it = per_edge.find(EdgeKey(MakeEdge(a, b)));
    return it == per_edge.end() ? 0 : it->second;
  }
  // The present triples on edge ab: their third seeds, from the geodesic neighbours.
  std::vector<int> Thirds(int a, int b, const std::vector<std::vector<int>>& neighbours) const {
    std::vector<int> third;
    const auto &na = neighbours[static_cast<size_t>(a)], &nb = neighbours[static_cast<size_t>(b)];
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(third));
    third.erase(std::remove_if(third.begin(), third.end(), [&](int x) { return !Has(a, b, x); }), third.end());
    return third;
  }
  // Replaces `drop` by `add` (those of it not present) unless that leaves an edge with one triple where it
  // had more: no new boundary edge. Returns whether it did.
  bool ReplaceUnlessItOpens(const std::vector<Tri>& drop, const std::vector<Tri>& add) {
    std::vector<Tri> fresh;
    for (const Tri& t : add)
      if (!present.count(t) && std::find(fresh.begin(), fresh.end(), t) == fresh.end()) fresh.push_back(t);
    std::unordered_map<uint64_t, int> delta;
    for (const Tri& t : drop)
      for (int k = 0; k < 3; ++k) --delta[EdgeKey(MakeEdge(t[k], t[(k + 1) % 3]))];
    for (const Tri& t : fresh)
      for (int k = 0; k < 3; ++k) ++delta[EdgeKey(MakeEdge(t[k], t[(k + 1) % 3]))];
    for (const auto& [e, d] : delta) {
      const auto it = per_edge.find(e);
      const int before = it == per_edge.end() ? 0 : it->second;
      if (before + d == 1 && before > 1) return false;
    }
    for (const Tri& t : drop) present.erase(t);
    for (const Tri& t : fresh) {
      present.insert(t);
      added.push_back(t);
    }
    for (const auto& [e, d] : delta) per_edge[e] += d;
    return true;
  }
  bool DropUnlessItOpens(const std::vector<Tri>& drop) { return ReplaceUnlessItOpens(drop, {}); }
  std::vector<Tri> added;  ///< the triples ReplaceUnlessItOpens added, in order
};

// A chain goes on through a curve seed c where its links to x and y make an angle above this at c; a
// smaller angle is a corner of the surface (two creases) or a bend, and the triangle (x, c, y) may be a face.
const double kJumpMaxCos = std::cos(135.0 * M_PI / 180.0);

// The chain links, as a set and per seed.
struct Chain {
  std::vector<std::array<int, 2>> links;
  std::unordered_set<uint64_t> is_link;
  std::vector<std::vector<int>> linked;  // per seed, the seeds it has a link with

  Chain(size_t num_seeds, std::vector<std::array<int, 2>> l) : links(std::move(l)), linked(num_seeds) {
    for (const auto& [a, b] : links) {
      is_link.insert(EdgeKey(MakeEdge(a, b)));
      linked[static_cast<size_t>(a)].push_back(b);
      linked[static_cast<size_t>(b)].push_back(a);
    }
  }
  bool Linked(int a, int b) const { return is_link.count(EdgeKey(MakeEdge(a, b))) > 0; }
};

// A jump: two seeds x, y linked to one curve seed c on either side of it (more than 135 degrees apart at c)
// and no link themselves. The triples on a jump, (x, y, z), are split at c together, unless that leaves an
// edge with one triple where it had more (KeepChainLinks). Returns the jumps taken.
size_t DropChainJumps(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& is_curve, const Chain& chain,
                      const std::vector<std::vector<int>>& neighbours, LiveTriples& live) {
  size_t jumps = 0;
  std::vector<Tri> drop, halves;
  for (size_t ci = 0; ci < chain.linked.size(); ++ci) {
    const auto& ends = chain.linked[ci];
    const int c = static_cast<int>(ci);
    for (size_t i = 0; i < ends.size(); ++i)
      for (size_t j = i + 1; j < ends.size(); ++j) {
        const int x = ends[i], y = ends[j];
        if (chain.Linked(x, y) || live.OnEdge(x, y) == 0) continue;
        const Vec3 cx = (seeds[static_cast<size_t>(x)] - seeds[ci]).normalized();
        const Vec3 cy = (seeds[static_cast<size_t>(y)] - seeds[ci]).normalized();
        if (!(cx.dot(cy) < kJumpMaxCos)) continue;  // a bend of the chain or two chains at a corner: no jump
        // Each triple on the jump is split at c: (x, y, z) becomes (x, c, z) and (c, y, z), the sliver (x, y, c)
        // nothing. A sheet seed's halves are added where the samples did not witness them (near a crossing a
        // sheet's half of a junction goes unseen); a curve seed's must be present (among the curve seeds of a
        // corner where chains meet, a triple is no sheet's).
        drop.clear();
        halves.clear();
        bool replaced = true;
        for (int z : live.Thirds(x, y, neighbours)) {
          drop.push_back(SortedTri({x, y, z}));
          if (z == c) continue;
          if (is_curve[static_cast<size_t>(z)]) {
            replaced = replaced && live.Has(x, c, z) && live.Has(c, y, z);
          } else {
            halves.push_back(SortedTri({x, c, z}));
            halves.push_back(SortedTri({c, y, z}));
          }
        }
        if (replaced && live.ReplaceUnlessItOpens(drop, halves)) ++jumps;
      }
  }
  return jumps;
}

// Where sheets cross at a gap of the chain: a closed tetrahedron (c, c', a, b) on a link cc', with a and b
// sheet seeds on two sides of it and ab carrying 4+ triples, keeps its two triples on the link
// (KeepChainLinks).
void KeepLinksAcrossCrossings(const std::vector<Vec3>& seeds, const Chain& chain, const std::vector<uint8_t>& is_curve,
                              const std::vector<std::vector<int>>& neighbours, LiveTriples& live) {
  for (const auto& [c, d] : chain.links) {
    const std::vector<int> third = live.Thirds(c, d, neighbours);
    const Vec3 axis = (seeds[static_cast<size_t>(d)] - seeds[static_cast<size_t>(c)]).normalized();
    auto across = [&](int x) {  // from the link towards x, across the link
      return AcrossLine(seeds[static_cast<size_t>(c)], axis, seeds[static_cast<size_t>(x)]);
    };
    for (size_t i = 0; i < third.size(); ++i)
      for (size_t j = i + 1; j < third.size(); ++j) {
        const int a = third[i], b = third[j];
        // A curve seed on the link's tetrahedron is the chain going on (a jump's business) or another chain.
        if (is_curve[static_cast<size_t>(a)] || is_curve[static_cast<size_t>(b)]) continue;
        if (!(across(a).dot(across(b)) < kLinkSideMaxCos)) continue;  // one side of the link: a chart's business
        // Only where ab is shared by 4+ triples: an edge of 2 (across a crease) thin-mesh's pair rule decides.
        if (!live.Has(c, a, b) || !live.Has(d, a, b) || live.OnEdge(a, b) < 4) continue;
        live.DropUnlessItOpens({SortedTri({c, a, b}), SortedTri({d, a, b})});
      }
  }
}

// Two curve seeds farther apart than this x the mean edge of the dual are no link of one chain: optimize-seeds
// fills gaps above 1.5 spacings (--feature-gap-max), so a link is at most that long.
constexpr double kMaxLinkSpacings = 1.5;

// Where a chain's link is missing or incomplete, the sheet seeds beside it span the junction instead: two
// curve seeds c, d, consecutive on a chain (no curve seed, neighbour of both, inside the sphere on cd) and at
// most kMaxLinkSpacings apart, make triples with pairs of sheet seeds S around cd (one pair at least with
// both, a pair with one only closed by a triple among S) — a diagonal ab across the chain, or where three
// sheets meet at a gap a double pyramid on (a, b, e) — and some (c, d, s) is not there. Where the seeds of
// each pair lie on two sides of cd, those triples and the ones among S become one triple (c, d, s) per sheet
// seed: the link, with each sheet's triangle on it (KeepChainLinks).
size_t SpanJunctionsByTheirLinks(const std::vector<Vec3>& seeds, const Chain& chain, const std::vector<uint8_t>& is_curve,
                                 const std::vector<std::vector<int>>& neighbours, const std::vector<Tri>& triples,
                                 LiveTriples& live) {
  if (chain.links.empty() || triples.empty()) return 0;
  // The spacing: the mean length of the dual's edges (each triple's three, so an edge counts per triple).
  double edge_sum = 0.0;
  for (const Tri& t : triples)
    for (int k = 0; k < 3; ++k) edge_sum += (seeds[static_cast<size_t>(t[k])] - seeds[static_cast<size_t>(t[(k + 1) % 3])]).norm();
  const double max_link = kMaxLinkSpacings * edge_sum / (3.0 * static_cast<double>(triples.size()));
  // Candidate pairs: curve seeds with a common sheet neighbour, near enough.
  std::vector<std::array<int, 2>> pairs;
  for (size_t si = 0; si < seeds.size(); ++si) {
    if (is_curve[si]) continue;
    const auto& ns = neighbours[si];
    for (size_t i = 0; i < ns.size(); ++i)
      for (size_t j = i + 1; j < ns.size(); ++j)
        if (is_curve[static_cast<size_t>(ns[i])] && is_curve[static_cast<size_t>(ns[j])] &&
            (seeds[static_cast<size_t>(ns[i])] - seeds[static_cast<size_t>(ns[j])]).norm() <= max_link)
          pairs.push_back({ns[i], ns[j]});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  size_t spanned = 0;
  std::vector<int> common;
  for (const auto& [c, d] : pairs) {
    if (!Consecutive(seeds, is_curve, neighbours, c, d, &common)) continue;
    std::vector<int> sheet;
    for (int w : common)
      if (!is_curve[static_cast<size_t>(w)]) sheet.push_back(w);
    if (sheet.size() < 2) continue;
    const Vec3 &pc = seeds[static_cast<size_t>(c)], &pd = seeds[static_cast<size_t>(d)];
    // The pairs of S that c or d spans, each across cd, at least one by both; a pair spanned by one of them
    // only must be closed by a triple among S (the other apex's side of the junction is that triangle).
    const Vec3 axis = (pd - pc).normalized();
    std::vector<Tri> drop;
    std::vector<int> used;
    bool closed = true, across = true, shared = false, link_whole = true;
    for (size_t i = 0; i < sheet.size() && closed; ++i)
      for (size_t j = i + 1; j < sheet.size() && closed; ++j) {
        const int a = sheet[i], b = sheet[j];
        const bool by_c = live.Has(c, a, b), by_d = live.Has(d, a, b);
        if (!by_c && !by_d) continue;
        if (by_c != by_d)
          closed = std::any_of(sheet.begin(), sheet.end(), [&](int e) { return e != a && e != b && live.Has(a, b, e); });
        shared = shared || (by_c && by_d);
        if (by_c) drop.push_back(SortedTri({c, a, b}));
        if (by_d) drop.push_back(SortedTri({d, a, b}));
        used.push_back(a);
        used.push_back(b);
        across = across && AcrossLine(pc, axis, seeds[static_cast<size_t>(a)]).dot(AcrossLine(pc, axis, seeds[static_cast<size_t>(b)])) <
                               kLinkSideMaxCos;
      }
    if (!closed || !across || !shared) continue;
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    std::vector<Tri> add;
    for (int s : used) {
      link_whole = link_whole && live.Has(c, d, s);
      add.push_back(SortedTri({c, d, s}));
    }
    if (link_whole) continue;  // a closed junction on a whole link: the crossing rule's or thin-mesh's
    for (size_t i = 0; i < used.size(); ++i)
      for (size_t j = i + 1; j < used.size(); ++j)
        for (size_t k = j + 1; k < used.size(); ++k)
          if (live.Has(used[i], used[j], used[k])) drop.push_back(SortedTri({used[i], used[j], used[k]}));
    spanned += live.ReplaceUnlessItOpens(drop, add);
  }
  return spanned;
}

// A triple the chart blocks, with its blocker and their chart: four seeds of one junction.
struct BlockedTriple {
  Tri t;
  int v;
  Vec3 chart;
};

// Where the samples saw a junction of four regions only in part, a hole is left whose outline is the four
// seeds: a blocked triple (p, q, r) the guard removed, its blocker v beyond pq (a convex quadrilateral), and
// no triple in it but the one triangle of their Delaunay triangulation the samples may have seen. It is
// filled with that triangulation in the chart, the flip (p, r, v), (r, v, q). The outline's edges must carry
// triples, all outside the quadrilateral in the chart (one each, or several where both ends are curve seeds:
// a link where sheets meet), and the diagonals no other, so the fill adds no fold and no branching edge on a
// sheet and closes exactly that hole. At least two of the four must be sheet seeds: among curve seeds alone
// the chain rules decide. `neighbours`: the geodesic neighbours of the witnessed triples (every pair of a
// flip is one). Returns how many holes were filled, counts the triangles added in `*added` and updates
// `triples`.
size_t CloseJunctionGaps(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& on_sheet,
                         const std::vector<std::vector<int>>& neighbours, const std::vector<BlockedTriple>& junctions,
                         std::vector<Tri>& triples, size_t* added) {
  LiveTriples live(triples);
  size_t closed = 0;
  for (const auto& [t, v, chart] : junctions) {
    const std::vector<Tri> flip = DelaunayReplacement(t, v, chart, seeds);
    if (flip.size() != 2) continue;
    int sheets = on_sheet[static_cast<size_t>(v)];
    for (int x : t) sheets += on_sheet[static_cast<size_t>(x)];
    if (sheets < 2) continue;
    int ends[2], n = 0, r = -1;  // p, q: in one triangle of the flip each; r: in both
    for (int x : t) {
      const auto in = std::count_if(flip.begin(), flip.end(),
                                    [&](const Tri& f) { return std::find(f.begin(), f.end(), x) != f.end(); });
      if (in == 1 && n < 2) ends[n++] = x;
      if (in == 2) r = x;
    }
    if (n != 2 || r < 0) continue;
    const int p = ends[0], q = ends[1];
    // A convex quadrilateral: v beyond pq only, so the flip's two triangles do not overlap.
    auto at = [&](int i) -> const Vec3& { return seeds[static_cast<size_t>(i)]; };
    auto same_side = [&](int a, int b, int x, int y) {
      const Vec3 across = chart.cross(at(b) - at(a));
      return across.dot(at(x) - at(a)) * across.dot(at(y) - at(a)) > 0;
    };
    if (!same_side(r, p, v, q) || !same_side(r, q, v, p)) continue;
    // The guard leaves no blocked triple with a free edge, so a hole beside one is the whole quadrilateral.
    if (live.present.count(t)) continue;
    auto part_of_fill = [&](const Tri& f) { return f == flip[0] || f == flip[1]; };
    // No other triple on a diagonal; on an edge ab of the outline none inside (towards c and d) in the chart,
    // and outside one, or several where a and b are curve seeds (a link where sheets meet).
    auto clear = [&](int a, int b, bool diagonal, int c, int d) {
      const Vec3 across = chart.cross(at(b) - at(a)).normalized();
      const double inside = across.dot(at(c) - at(a)) + across.dot(at(d) - at(a));
      int outside = 0;
      for (int w : live.Thirds(a, b, neighbours)) {
        if (part_of_fill(SortedTri({a, b, w}))) continue;
        const Vec3 dw = at(w) - at(a);
        const bool in_chart = std::abs(chart.dot(dw)) < std::abs(across.dot(dw));
        if (diagonal || (in_chart && across.dot(dw) * inside > 0)) return false;
        ++outside;
      }
      const bool link = !on_sheet[static_cast<size_t>(a)] && !on_sheet[static_cast<size_t>(b)];
      return diagonal || outside == 1 || (outside > 1 && link);
    };
    if (!clear(p, q, true, r, v) || !clear(r, v, true, p, q) || !clear(v, p, false, q, r) || !clear(v, q, false, p, r) ||
        !clear(r, p, false, q, v) || !clear(r, q, false, p, v))
      continue;
    if (live.present.count(flip[0]) && live.present.count(flip[1])) continue;  // nothing missing
    live.ReplaceUnlessItOpens({}, flip);  // adds only: opens nothing
    ++closed;
  }
  *added += live.added.size();
  triples.assign(live.present.begin(), live.present.end());
  return closed;
}

}  // namespace

std::vector<Tri> KeepChainLinks(const std::vector<Vec3>& seeds, const std::vector<uint8_t>& is_curve,
                                const std::vector<Tri>& triples, ChainLinkStats* stats_out) {
  ChainLinkStats stats;
  const std::vector<std::vector<int>> neighbours = GeodesicNeighbours(seeds.size(), triples);
  const Chain chain(seeds.size(), ChainLinks(seeds, is_curve, neighbours));
  stats.links = chain.links.size();
  LiveTriples live(triples);
  stats.jumps = DropChainJumps(seeds, is_curve, chain, neighbours, live);
  KeepLinksAcrossCrossings(seeds, chain, is_curve, neighbours, live);
  stats.junctions = SpanJunctionsByTheirLinks(seeds, chain, is_curve, neighbours, triples, live);
  std::vector<Tri> kept;
  kept.reserve(triples.size());
  for (const Tri& t : triples)
    if (live.present.count(t)) kept.push_back(t);
  stats.dropped = triples.size() - kept.size();
  const size_t given = kept.size();
  for (const Tri& t : live.added)  // the splits' halves still present (one dropped before may be back)
    if (live.present.count(t)) kept.push_back(t);
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  stats.added = kept.size() - given;
  if (stats_out) *stats_out = stats;
  return kept;
}

std::vector<Tri> LocallyDelaunayTriples(const std::vector<Vec3>& seeds, const std::vector<Vec3>& normals,
                                        const std::vector<uint8_t>& on_sheet, const std::vector<Tri>& witnessed,
                                        double chart_angle_deg, RestrictedDualStats* stats_out) {
  RestrictedDualStats stats;
  stats.witnessed = witnessed.size();
  const std::vector<std::vector<int>> neighbours = GeodesicNeighbours(seeds.size(), witnessed);
  constexpr double kCocircular = 1e-9;
  constexpr double kMaxFlatness = 0.25;
  const double min_cos = std::cos(chart_angle_deg * M_PI / 180.0);
  std::vector<Tri> candidates;  // the non-collinear triples
  std::vector<std::pair<int, Vec3>> blocker;  // per candidate: the seed that blocks it and their chart (-1: none)
  std::vector<int> common, both;
  for (const Tri& t : witnessed) {
    const Vec3 &a = seeds[static_cast<size_t>(t[0])], &b = seeds[static_cast<size_t>(t[1])], &c = seeds[static_cast<size_t>(t[2])];
    const Vec3 normal = (b - a).cross(c - a);
    if (!(normal.squaredNorm() > 1e-24 * (b - a).squaredNorm() * (c - a).squaredNorm())) {
      ++stats.degenerate;  // collinear: no circle, no triangle
      continue;
    }
    // The neighbours of all three seeds: those that could make a fourth corner of this junction.
    const auto& n0 = neighbours[static_cast<size_t>(t[0])];
    const auto& n1 = neighbours[static_cast<size_t>(t[1])];
    const auto& n2 = neighbours[static_cast<size_t>(t[2])];
    both.clear();
    std::set_intersection(n0.begin(), n0.end(), n1.begin(), n1.end(), std::back_inserter(both));
    common.clear();
    std::set_intersection(both.begin(), both.end(), n2.begin(), n2.end(), std::back_inserter(common));
    std::pair<int, Vec3> by{-1, Vec3::Zero()};
    for (int v : common) {
      if (v == t[0] || v == t[1] || v == t[2]) continue;
      const Vec3 chart = ChartNormal({t[0], t[1], t[2], v}, seeds, normals, on_sheet, min_cos, kMaxFlatness);
      if (chart.isZero()) continue;
      if (InCircumcircle(a, b, c, seeds[static_cast<size_t>(v)], chart, kCocircular)) {
        by = {v, chart};
        break;
      }
    }
    candidates.push_back(t);
    blocker.push_back(by);
  }
  // The hole guard: a blocked triple goes where that opens no hole — it lies on a closed shell of the
  // triples left (its Delaunay replacements are there: b2 falls) or has a free edge (a collapse). A removal
  // can free another blocked triple (an edge left to it alone), so passes repeat until none goes. Where a
  // blocked triple would open a hole, the triangles that replace it were never witnessed, and it stays;
  // unless it jumps a feature seed along a chain, where its Delaunay flip through that seed replaces it.
  auto blocked = [&](size_t f) { return blocker[f].first >= 0; };
  FaceComplex complex(candidates);
  for (bool removed = true; removed;) {
    removed = false;
    for (size_t f = 0; f < candidates.size(); ++f) {
      const int g = static_cast<int>(f);
      if (blocked(f) && complex.present(g) && (complex.HasFreeEdge(g) || complex.OnLocalTwoCycle(g, 1))) {
        complex.Remove(g);
        removed = true;
      }
    }
  }
  std::vector<Tri> kept;
  std::unordered_set<Tri, TriHash> have;
  for (size_t f = 0; f < candidates.size(); ++f)
    if (!blocked(f)) {
      kept.push_back(candidates[f]);
      have.insert(candidates[f]);
    }
  for (size_t f = 0; f < candidates.size(); ++f) {
    if (!blocked(f) || !complex.present(static_cast<int>(f))) continue;
    const Tri& t = candidates[f];
    const int v = blocker[f].first;
    const std::vector<Tri> flip = DelaunayReplacement(t, v, blocker[f].second, seeds);
    // A jump: the blocker is a feature seed beyond (or on) an edge of two feature seeds, so the triangle spans
    // it along a chain. The two vertices of that edge are each in one triangle of the flip.
    bool jump = flip.size() == 2 && !on_sheet[static_cast<size_t>(v)];
    for (int x : t) {
      const int in = static_cast<int>(std::count_if(flip.begin(), flip.end(), [&](const Tri& r) {
        return std::find(r.begin(), r.end(), x) != r.end();
      }));
      jump = jump && !(in == 1 && on_sheet[static_cast<size_t>(x)]);
    }
    if (!jump) {  // better a triangle that is not Delaunay than a hole
      ++stats.kept_against_holes;
      if (have.insert(t).second) kept.push_back(t);  // a flip above may have made it already
      continue;
    }
    ++stats.replaced;
    for (const Tri& r : flip)
      if (have.insert(r).second) {
        kept.push_back(r);
        ++stats.added;
      }
  }
  std::vector<BlockedTriple> junctions;
  for (size_t f = 0; f < candidates.size(); ++f)
    if (blocked(f)) junctions.push_back({candidates[f], blocker[f].first, blocker[f].second});
  stats.gaps_closed = CloseJunctionGaps(seeds, on_sheet, neighbours, junctions, kept, &stats.added);
  std::sort(kept.begin(), kept.end());
  stats.kept = kept.size();
  if (stats_out) *stats_out = stats;
  return kept;
}

}  // namespace voroudf

#include "stages/evaluate/crossings.h"

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

#include "common/union_find.h"

namespace voroudf {
namespace {

using FaceBox = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;

// Triangle f's bounding box grown by `pad` on every side, labelled f.
FaceBox BoxOfFace(const TriangleMesh& mesh, size_t f, double pad) {
  const Tri& t = mesh.faces[f];
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min({mesh.vertices[t[0]][k], mesh.vertices[t[1]][k], mesh.vertices[t[2]][k]}) - pad;
    hi[k] = std::max({mesh.vertices[t[0]][k], mesh.vertices[t[1]][k], mesh.vertices[t[2]][k]}) + pad;
  }
  return FaceBox(lo, hi, static_cast<int>(f));
}


// The interval [t0, t1] of the line o + t dir (in the plane of triangle a, b, c with unit normal n) that
// lies in the triangle, within `tolerance`; false if none.
bool ClipLine(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n, const Vec3& o, const Vec3& dir,
              double tolerance, double* t0, double* t1) {
  const std::array<Vec3, 3> corner{a, b, c};
  for (int k = 0; k < 3; ++k) {
    const Vec3& p = corner[static_cast<size_t>(k)];
    const Vec3 inward = n.cross(corner[static_cast<size_t>((k + 1) % 3)] - p).normalized();
    const double slope = dir.dot(inward), offset = (o - p).dot(inward) + tolerance;  // slope t + offset >= 0
    if (std::abs(slope) < 1e-12) {
      if (offset < 0) return false;
    } else if (slope > 0) {
      *t0 = std::max(*t0, -offset / slope);
    } else {
      *t1 = std::min(*t1, -offset / slope);
    }
  }
  return *t0 <= *t1;
}

// The segment where triangles f and g meet, when their planes cross: the line of the two planes clipped to
// both triangles (Moller 1997). Computed in doubles with a tolerance, by hand: CGAL's Triangle_3
// intersection with inexact constructions can build a non-finite point on nearly parallel triangles and
// then fail inside its own predicates, and with exact constructions it is too slow for the pairs of
// neighbouring triangles that every mesh has.
bool MeetingSegment(const TriangleMesh& mesh, const Tri& f, const Tri& g, double tolerance, double min_sine, Vec3* p,
                    Vec3* q) {
  const Vec3 &a0 = mesh.vertices[static_cast<size_t>(f[0])], &a1 = mesh.vertices[static_cast<size_t>(f[1])],
             &a2 = mesh.vertices[static_cast<size_t>(f[2])];
  const Vec3 &b0 = mesh.vertices[static_cast<size_t>(g[0])], &b1 = mesh.vertices[static_cast<size_t>(g[1])],
             &b2 = mesh.vertices[static_cast<size_t>(g[2])];
  const Vec3 ca = (a1 - a0).cross(a2 - a0), cb = (b1 - b0).cross(b2 - b0);
  if (!(ca.norm() > 0 && cb.norm() > 0)) return false;  // degenerate
  const Vec3 na = ca.normalized(), nb = cb.normalized();
  const Vec3 cross = na.cross(nb);
  if (!(cross.norm() > min_sine)) return false;  // within the angle: one sheet, no curve
  const double da = na.dot(a0), db = nb.dot(b0);
  const Vec3 o = (da * nb.cross(cross) + db * cross.cross(na)) / cross.squaredNorm();  // on both planes
  const Vec3 dir = cross.normalized();
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  // Clipped without the tolerance: with it, two triangles that share a corner would meet along a sliver of
  // tolerance / sin(angle) there. A piece shorter than 10 tolerances is a point.
  constexpr double kClipSlack = 1e-12;
  if (!ClipLine(a0, a1, a2, na, o, dir, kClipSlack, &t0, &t1) || !ClipLine(b0, b1, b2, nb, o, dir, kClipSlack, &t0, &t1))
    return false;
  if (!(t1 - t0 > 10 * tolerance)) return false;
  *p = o + t0 * dir;
  *q = o + t1 * dir;
  return true;
}

int SharedVertices(const Tri& a, const Tri& b) {
  int n = 0;
  for (int u : a)
    for (int v : b) n += u == v;
  return n;
}

// The directions (unit, normal to `line`) in which triangle `t` leaves the line through m: of the two
// directions across the line in its plane, those that point into the triangle from m (into its tangent
// cone there: inwards from every edge m lies on). Two where m is inside it, one where m is on an edge
// (along the line: the side the triangle is on; across it: the triangle's side of the line, its neighbour
// over that edge having the other), none where its plane does not hold the line or m is off it.
void HalfSheets(const TriangleMesh& mesh, const Tri& t, const Vec3& m, const Vec3& line, double tolerance,
                std::vector<Vec3>* out) {
  constexpr double kParallel = 1e-6;
  const Vec3 &a = mesh.vertices[static_cast<size_t>(t[0])], &b = mesh.vertices[static_cast<size_t>(t[1])],
             &c = mesh.vertices[static_cast<size_t>(t[2])];
  const Vec3 cross = (b - a).cross(c - a);
  if (!(cross.norm() > 0)) return;
  const Vec3 n = cross.normalized();
  if (std::abs(n.dot(line)) > kParallel || std::abs((m - a).dot(n)) > tolerance) return;
  const std::array<Vec3, 3> corner{a, b, c};
  const Vec3 across = n.cross(line).normalized();
  bool in_plus = true, in_minus = true;
  for (int k = 0; k < 3; ++k) {
    const Vec3& p = corner[static_cast<size_t>(k)];
    const Vec3 inward = n.cross(corner[static_cast<size_t>((k + 1) % 3)] - p).normalized();  // counter-clockwise
    const double d = (m - p).dot(inward);
    if (d < -tolerance) return;  // outside
    if (d > tolerance) continue;  // m is not on this edge
    in_plus = in_plus && across.dot(inward) > kParallel;
    in_minus = in_minus && -across.dot(inward) > kParallel;
  }
  if (in_plus) out->push_back(across);
  if (in_minus) out->push_back(-across);
}

// Directions within the angle whose cosine is `same` are one half-sheet.
size_t DistinctDirections(const std::vector<Vec3>& dirs, double same) {
  size_t distinct = 0;
  for (size_t i = 0; i < dirs.size(); ++i) {
    bool seen = false;
    for (size_t j = 0; j < i && !seen; ++j) seen = dirs[i].dot(dirs[j]) > same;
    distinct += !seen;
  }
  return distinct;
}

}  // namespace

CurveSegments CrossingCurves(const TriangleMesh& mesh, double tolerance, double min_angle_deg) {
  const double min_sine = std::sin(min_angle_deg * M_PI / 180.0), same = std::cos(min_angle_deg * M_PI / 180.0);
  const size_t nf = mesh.faces.size();
  std::vector<FaceBox> boxes;  // box_self_intersection_d reorders them
  std::vector<Eigen::AlignedBox3d> bound;  // per face
  boxes.reserve(nf);
  bound.reserve(nf);
  for (size_t f = 0; f < nf; ++f) {
    const FaceBox& box = boxes.emplace_back(BoxOfFace(mesh, f, tolerance));
    bound.emplace_back(Vec3(box.min_coord(0), box.min_coord(1), box.min_coord(2)),
                       Vec3(box.max_coord(0), box.max_coord(1), box.max_coord(2)));
  }
  // Every pair of triangles whose boxes meet: the candidates, and the triangles near a candidate's segment
  // (a triangle through the segment's midpoint meets both triangles, so its box is paired with theirs).
  std::vector<std::pair<int, int>> pairs;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const FaceBox& x, const FaceBox& y) {
    pairs.emplace_back(std::min(x.info(), y.info()), std::max(x.info(), y.info()));
  });
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<std::vector<int>> near(nf);
  for (const auto& [f, g] : pairs) {
    near[static_cast<size_t>(f)].push_back(g);
    near[static_cast<size_t>(g)].push_back(f);
  }

  CurveSegments out;
  // Segments already judged, by the grid cells they pass through: the same piece found from another pair
  // (the walls of two touching parts each meet the other's face along one line) is judged once, kept once.
  std::vector<std::array<Vec3, 2>> judged;
  std::unordered_map<int64_t, std::vector<size_t>> judged_by_cell;
  constexpr double cell = 0.01;  // of the normalised frame's unit box
  auto key = [&](const Vec3& p, int dx, int dy, int dz) {
    const int64_t x = static_cast<int64_t>(std::floor(p.x() / cell)) + dx;
    const int64_t y = static_cast<int64_t>(std::floor(p.y() / cell)) + dy;
    const int64_t z = static_cast<int64_t>(std::floor(p.z() / cell)) + dz;
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  auto judged_through = [&](const Vec3& m) -> bool {  // a segment through m was judged already
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = judged_by_cell.find(key(m, dx, dy, dz));
          if (it == judged_by_cell.end()) continue;
          for (size_t e : it->second) {
            const Vec3 &a = judged[e][0], ab = judged[e][1] - judged[e][0];
            const double s = std::clamp((m - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
            if ((a + s * ab - m).norm() <= tolerance) return true;
          }
        }
    return false;
  };
  auto judge = [&](const Vec3& p, const Vec3& q, bool keep) {
    const size_t e = judged.size();
    judged.push_back({p, q});
    const int steps = std::max(1, static_cast<int>(std::ceil((q - p).norm() / (0.5 * cell))));
    for (int k = 0; k <= steps; ++k) {
      std::vector<size_t>& in = judged_by_cell[key(p + (q - p) * (static_cast<double>(k) / steps), 0, 0, 0)];
      if (in.empty() || in.back() != e) in.push_back(e);
    }
    if (!keep) return;
    const int first = static_cast<int>(out.vertices.size());
    out.vertices.push_back(p);
    out.vertices.push_back(q);
    out.edges.push_back({first, first + 1});
  };
  std::vector<Vec3> dirs;
  for (const auto& [f, g] : pairs) {
    const Tri& tf = mesh.faces[static_cast<size_t>(f)];
    const Tri& tg = mesh.faces[static_cast<size_t>(g)];
    if (SharedVertices(tf, tg) >= 2) continue;  // neighbours across an edge
    Vec3 p, q;
    if (!MeetingSegment(mesh, tf, tg, tolerance, min_sine, &p, &q)) continue;
    const Vec3 m = 0.5 * (p + q), line = (q - p).normalized();
    if (judged_through(m)) continue;
    dirs.clear();
    auto add = [&](int h) {  // only triangles whose box holds m can pass through it
      if (bound[static_cast<size_t>(h)].contains(m)) HalfSheets(mesh, mesh.faces[static_cast<size_t>(h)], m, line, tolerance, &dirs);
    };
    add(f);
    add(g);
    for (int h : near[static_cast<size_t>(f)])
      if (h != g) add(h);
    for (int h : near[static_cast<size_t>(g)])
      if (h != f && !std::binary_search(near[static_cast<size_t>(f)].begin(), near[static_cast<size_t>(f)].end(), h))
        add(h);
    judge(p, q, DistinctDirections(dirs, same) >= 3);
  }
  return out;
}

namespace {

using Vec2 = Eigen::Vector2d;

// Distance between segments ab and cd in the plane (they do not cross: two triangles' cuts by one plane
// cross only where the triangles do, and there the distance is 0 at the common point, which this finds).
double SegmentDistance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  auto to_segment = [](const Vec2& p, const Vec2& u, const Vec2& v) {
    const Vec2 uv = v - u;
    const double len2 = uv.squaredNorm();
    const double s = len2 > 0 ? std::clamp((p - u).dot(uv) / len2, 0.0, 1.0) : 0.0;
    return (u + s * uv - p).norm();
  };
  auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a), d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return 0.0;
  return std::min({to_segment(a, c, d), to_segment(b, c, d), to_segment(c, a, b), to_segment(d, a, b)});
}

// Triangle t's cut by the plane through m with unit normal `axis`, in the plane's frame (e1, e2) around m,
// clipped to the disc of radius r; false if it misses the disc or lies in the plane. `exits` gets the
// angles at which the piece reaches the circle.
bool CutInDisc(const TriangleMesh& mesh, const Tri& t, const Vec3& m, const Vec3& axis, const Vec3& e1, const Vec3& e2,
               double r, std::array<Vec2, 2>* piece, std::vector<double>* exits) {
  std::array<double, 3> side;
  std::array<Vec3, 3> v;
  for (int k = 0; k < 3; ++k) {
    v[static_cast<size_t>(k)] = mesh.vertices[static_cast<size_t>(t[static_cast<size_t>(k)])] - m;
    side[static_cast<size_t>(k)] = v[static_cast<size_t>(k)].dot(axis);
  }
  const double scale = std::max({v[0].norm(), v[1].norm(), v[2].norm()}), eps = 1e-12 * scale;
  if (std::abs(side[0]) <= eps && std::abs(side[1]) <= eps && std::abs(side[2]) <= eps) return false;  // in the plane
  std::vector<Vec3> hits;
  for (int k = 0; k < 3; ++k) {
    const size_t i = static_cast<size_t>(k), j = static_cast<size_t>((k + 1) % 3);
    if (std::abs(side[i]) <= eps) {
      hits.push_back(v[i]);
    } else if ((side[i] > eps && side[j] < -eps) || (side[i] < -eps && side[j] > eps)) {
      hits.push_back(v[i] + (v[j] - v[i]) * (side[i] / (side[i] - side[j])));
    }
  }
  if (hits.size() < 2) return false;
  const Vec2 p(hits[0].dot(e1), hits[0].dot(e2)), q(hits[1].dot(e1), hits[1].dot(e2));
  // |p + u (q - p)| <= r for u in [u0, u1] within [0, 1].
  const Vec2 d = q - p;
  const double a = d.squaredNorm(), b = p.dot(d), c = p.squaredNorm() - r * r;
  if (!(a > 0)) return false;
  const double disc = b * b - a * c;
  if (disc <= 0) return false;
  const double u0 = (-b - std::sqrt(disc)) / a, u1 = (-b + std::sqrt(disc)) / a;
  const double lo = std::max(0.0, u0), hi = std::min(1.0, u1);
  if (!(lo < hi)) return false;
  (*piece)[0] = p + lo * d;
  (*piece)[1] = p + hi * d;
  if (u0 >= 0.0) exits->push_back(std::atan2((*piece)[0].y(), (*piece)[0].x()));
  if (u1 <= 1.0) exits->push_back(std::atan2((*piece)[1].y(), (*piece)[1].x()));
  return true;
}

// How many exits (angles) lie more than `min_gap` apart around the circle.
size_t DistinctExits(std::vector<double> angles, double min_gap) {
  if (angles.empty()) return 0;
  std::sort(angles.begin(), angles.end());
  size_t distinct = 1;
  for (size_t k = 1; k < angles.size(); ++k) distinct += angles[k] - angles[k - 1] > min_gap;
  if (distinct > 1 && angles.front() + 2 * M_PI - angles.back() <= min_gap) --distinct;  // around through ±π
  return distinct;
}

// The cross-section of the union of `mesh`'s triangles by the plane through each point normal to its
// direction, within the disc of `radius`: its pieces, joined where closer than `join`, each joined piece as
// its distinct exits from the disc and whether it passes within `join` of the centre.
struct Section {
  std::vector<size_t> exits;
  std::vector<char> through_centre;
};
std::vector<Section> CrossSections(const TriangleMesh& mesh, const std::vector<Vec3>& points,
                                   const std::vector<Vec3>& directions, double radius, double join) {
  std::vector<Section> out(points.size());
  if (points.empty()) return out;
  std::vector<FaceBox> faces, queries;
  for (size_t f = 0; f < mesh.faces.size(); ++f) faces.push_back(BoxOfFace(mesh, f, 0.0));
  for (size_t i = 0; i < points.size(); ++i) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = points[i][k] - radius;
      hi[k] = points[i][k] + radius;
    }
    queries.emplace_back(lo, hi, static_cast<int>(i));
  }
  std::vector<std::vector<int>> near(points.size());
  CGAL::box_intersection_d(faces.begin(), faces.end(), queries.begin(), queries.end(),
                           [&](const FaceBox& f, const FaceBox& q) { near[static_cast<size_t>(q.info())].push_back(f.info()); });
  const double min_gap = join / radius;  // exits closer than `join` on the circle are one
#pragma omp parallel for schedule(dynamic, 4)
  for (long li = 0; li < static_cast<long>(points.size()); ++li) {
    const size_t i = static_cast<size_t>(li);
    std::vector<int>& cand = near[i];
    std::sort(cand.begin(), cand.end());  // the box intersection's order is not fixed
    const Vec3 axis = directions[i].normalized();
    const Vec3 e1 = (std::abs(axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(axis).normalized();
    const Vec3 e2 = axis.cross(e1);
    std::vector<std::array<Vec2, 2>> pieces;
    std::vector<std::vector<double>> exits;
    for (int f : cand) {
      std::array<Vec2, 2> piece;
      std::vector<double> piece_exits;
      if (!CutInDisc(mesh, mesh.faces[static_cast<size_t>(f)], points[i], axis, e1, e2, radius, &piece, &piece_exits))
        continue;
      pieces.push_back(piece);
      exits.push_back(std::move(piece_exits));
    }
    UnionFind sets(pieces.size());
    for (size_t a = 0; a < pieces.size(); ++a)
      for (size_t b = a + 1; b < pieces.size(); ++b)
        if (SegmentDistance(pieces[a][0], pieces[a][1], pieces[b][0], pieces[b][1]) <= join)
          sets.Union(static_cast<int>(a), static_cast<int>(b));
    std::vector<std::vector<double>> by_set(pieces.size());
    std::vector<char> centre(pieces.size(), 0);
    for (size_t a = 0; a < pieces.size(); ++a) {
      const size_t set = static_cast<size_t>(sets.Find(static_cast<int>(a)));
      by_set[set].insert(by_set[set].end(), exits[a].begin(), exits[a].end());
      if (SegmentDistance(pieces[a][0], pieces[a][1], Vec2::Zero(), Vec2::Zero()) <= join) centre[set] = 1;
    }
    for (size_t set = 0; set < pieces.size(); ++set) {
      if (static_cast<size_t>(sets.Find(static_cast<int>(set))) != set) continue;
      out[i].exits.push_back(DistinctExits(by_set[set], min_gap));
      out[i].through_centre.push_back(centre[set]);
    }
  }
  return out;
}

}  // namespace

std::vector<char> BranchesAcross(const TriangleMesh& mesh, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& directions, double radius, double join) {
  const std::vector<Section> sections = CrossSections(mesh, points, directions, radius, join);
  std::vector<char> out(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t exits : sections[i].exits) out[i] = out[i] || exits >= 3;
  return out;
}

std::vector<size_t> ExitsThrough(const TriangleMesh& mesh, const std::vector<Vec3>& points,
                                 const std::vector<Vec3>& directions, double radius, double join) {
  const std::vector<Section> sections = CrossSections(mesh, points, directions, radius, join);
  std::vector<size_t> out(points.size(), 0);
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t k = 0; k < sections[i].exits.size(); ++k)
      if (sections[i].through_centre[k]) out[i] = std::max(out[i], sections[i].exits[k]);
  return out;
}

}  // namespace voroudf

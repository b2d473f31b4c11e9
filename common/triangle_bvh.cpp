#include "common/triangle_bvh.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

// The traversal keeps its running best in registers only if the per-triangle test is inlined at each of
// its call sites, which GCC does not do on its own for a lambda called from four places.
#if defined(__GNUC__)
#define VOROUDF_ALWAYS_INLINE __attribute__((always_inline))
#else
#define VOROUDF_ALWAYS_INLINE
#endif

namespace voroudf {
namespace {

// A triangle whose corner angle at `a` has sin^2 below this is treated as its three edges. The choice
// balances two errors of ~1e-5 of the edge length at the threshold: the segment fallback is off by at
// most the triangle's smallest altitude (<= L sin), while Ericson's face-region barycentrics lose
// about eps / sin^2 to cancellation.
constexpr double kDegenerateSin2 = 1e-10;
constexpr int kBins = 16;
// Past this depth the build splits at the median, so the traversal stack (kStackSize) never overflows.
constexpr int kMedianDepth = 96;
constexpr int kStackSize = 128;

Vec3 ClosestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0.0)) return a;
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + t * ab;
}

Vec3 ClosestOnEdges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 q[3] = {ClosestOnSegment(p, a, b), ClosestOnSegment(p, b, c), ClosestOnSegment(p, c, a)};
  int best = 0;
  double best_d = (p - q[0]).squaredNorm();
  for (int k = 1; k < 3; ++k) {
    const double d = (p - q[k]).squaredNorm();
    if (d < best_d) best_d = d, best = k;
  }
  return q[best];
}

// Barycentric (v, w) of the closest point a + v ab + w ac (Ericson, Sec. 5.1.5), written with the
// precomputed d00 = ab.ab, d01 = ab.ac, d11 = ac.ac so that a query costs two dot products: with
// d1 = ab.ap and d2 = ac.ap, Ericson's d3..d6 are d1 - d00, d2 - d01, d1 - d01 and d2 - d11.
// Every denominator is d00, d11, |bc|^2 or det = d00 d11 - d01^2, all positive for a non-degenerate triangle.
inline void EricsonBarycentric(double d1, double d2, double d00, double d01, double d11, double inv_det, double* v,
                               double* w) {
  if (d1 <= 0.0 && d2 <= 0.0) { *v = 0.0; *w = 0.0; return; }  // vertex a
  const double d3 = d1 - d00, d4 = d2 - d01;
  if (d3 >= 0.0 && d4 <= d3) { *v = 1.0; *w = 0.0; return; }  // vertex b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { *v = std::min(d1 / d00, 1.0); *w = 0.0; return; }  // edge ab
  const double d5 = d1 - d01, d6 = d2 - d11;
  if (d6 >= 0.0 && d5 <= d6) { *v = 0.0; *w = 1.0; return; }  // vertex c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { *v = 0.0; *w = std::min(d2 / d11, 1.0); return; }  // edge ac
  const double va = d3 * d6 - d5 * d4;
  const double e43 = d4 - d3, e56 = d5 - d6;
  if (va <= 0.0 && e43 >= 0.0 && e56 >= 0.0) {  // edge bc; e43 + e56 = |bc|^2 > 0
    const double t = std::min(e43 / (e43 + e56), 1.0);
    *v = 1.0 - t;
    *w = t;
    return;
  }
  *v = vb * inv_det;  // face interior; va + vb + vc = det
  *w = vc * inv_det;
}

float RoundDown(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float RoundUp(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

double SurfaceArea(const Eigen::AlignedBox3d& b) {
  if (b.isEmpty()) return 0.0;
  const Vec3 e = b.sizes();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

}  // namespace

Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  const double d00 = ab.dot(ab), d01 = ab.dot(ac), d11 = ac.dot(ac);
  const double det = d00 * d11 - d01 * d01;
  if (!(d00 > 0.0) || !(d11 > 0.0) || !(det > kDegenerateSin2 * d00 * d11) || !((c - b).squaredNorm() > 0.0))
    return ClosestOnEdges(p, a, b, c);
  const Vec3 ap = p - a;
  double v, w;
  EricsonBarycentric(ab.dot(ap), ac.dot(ap), d00, d01, d11, 1.0 / det, &v, &w);
  return a + v * ab + w * ac;
}

TriangleBvh::TriangleBvh(const std::vector<Vec3>& vertices, const std::vector<Tri>& faces) {
  assert(!faces.empty());
  const int n = static_cast<int>(faces.size());
  std::vector<Vec3> centroid(n);
  std::vector<Eigen::AlignedBox3d> box(n);
  normal_.resize(n);
  for (int f = 0; f < n; ++f) {
    const Vec3& a = vertices[faces[f][0]];
    const Vec3& b = vertices[faces[f][1]];
    const Vec3& c = vertices[faces[f][2]];
    centroid[f] = (a + b + c) / 3.0;
    box[f] = Eigen::AlignedBox3d(a);
    box[f].extend(b).extend(c);
    const Vec3 nrm = (b - a).cross(c - a);
    const double len = nrm.norm();
    if (len > 0.0 && std::isfinite(len)) {
      normal_[f] = nrm / len;
    } else {
      // Degenerate: orthogonal to the longest edge, deterministic.
      Vec3 e = b - a;
      if ((c - b).squaredNorm() > e.squaredNorm()) e = c - b;
      if ((a - c).squaredNorm() > e.squaredNorm()) e = a - c;
      if (e.squaredNorm() > 0.0) {
        Eigen::Index axis;
        e.cwiseAbs().minCoeff(&axis);
        normal_[f] = e.cross(Vec3::Unit(axis)).normalized();
      } else {
        normal_[f] = Vec3::UnitZ();
      }
    }
  }
  // Rounding in a computed distance is a few ulps of the coordinates' magnitude; 1e-12 of it is far above.
  double magnitude = 0.0;
  for (const Eigen::AlignedBox3d& b : box) magnitude = std::max({magnitude, b.min().cwiseAbs().maxCoeff(), b.max().cwiseAbs().maxCoeff()});
  tie_slack_ = 1e-12 * magnitude;
  std::vector<int> order(n);
  for (int f = 0; f < n; ++f) order[f] = f;
  nodes_.reserve(2 * static_cast<size_t>(n));
  tris_.reserve(n);
  face_of_.reserve(n);
  const ChildRef root = Build(order, 0, n, centroid, box, 0);
  if (root.count > 0) {  // a single leaf: hang it under an inner root beside an empty box
    nodes_.emplace_back();
    SetChild(0, 0, root);
    SetChild(0, 1, ChildRef{0, 0, Eigen::AlignedBox3d()});
  }

  for (int slot = 0; slot < n; ++slot) {
    const Tri& t = faces[face_of_[slot]];
    const Vec3& a = vertices[t[0]];
    const Vec3 ab = vertices[t[1]] - a, ac = vertices[t[2]] - a;
    PackedTri& pt = tris_.emplace_back();
    for (int k = 0; k < 3; ++k) pt.a[k] = a[k], pt.ab[k] = ab[k], pt.ac[k] = ac[k];
    pt.d00 = ab.dot(ab);
    pt.d01 = ab.dot(ac);
    pt.d11 = ac.dot(ac);
    const double det = pt.d00 * pt.d11 - pt.d01 * pt.d01;
    const bool ok = pt.d00 > 0.0 && pt.d11 > 0.0 && det > kDegenerateSin2 * pt.d00 * pt.d11 &&
                    (ac - ab).squaredNorm() > 0.0;
    pt.inv_det = ok ? 1.0 / det : 0.0;
    const Vec3 nrm = ok ? Vec3(ab.cross(ac).normalized()) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) pt.n[k] = nrm[k];
    if (!ok) ++num_degenerate_;
  }
}

TriangleBvh::ChildRef TriangleBvh::Build(std::vector<int>& order, int begin, int end, const std::vector<Vec3>& centroid,
                       const std::vector<Eigen::AlignedBox3d>& box, int depth) {
  depth_ = std::max(depth_, depth + 1);
  Eigen::AlignedBox3d bounds, cbounds;
  for (int i = begin; i < end; ++i) {
    bounds.extend(box[order[i]]);
    cbounds.extend(centroid[order[i]]);
  }
  const int count = end - begin;
  if (count <= kMaxLeafSize) {
    const ChildRef leaf{static_cast<int32_t>(face_of_.size()), count, bounds};
    for (int i = begin; i < end; ++i) face_of_.push_back(order[i]);
    return leaf;
  }
  const int node = static_cast<int>(nodes_.size());
  nodes_.emplace_back();

  // Binned SAH over the three axes (Wald 2007); the median split when the centroids coincide along
  // every axis (duplicate faces) or the tree is already deep.
  int best_axis = -1, best_split = -1;
  double best_cost = std::numeric_limits<double>::infinity();
  const Vec3 cext = cbounds.sizes();
  if (depth < kMedianDepth) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!(cext[axis] > 0.0)) continue;
      const double scale = kBins / cext[axis];
      Eigen::AlignedBox3d bin_box[kBins];
      int bin_count[kBins] = {0};
      for (int i = begin; i < end; ++i) {
        const int b = std::min(kBins - 1, static_cast<int>((centroid[order[i]][axis] - cbounds.min()[axis]) * scale));
        bin_box[b].extend(box[order[i]]);
        ++bin_count[b];
      }
      double right_area[kBins];
      int right_count[kBins];
      Eigen::AlignedBox3d acc;
      int cnt = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.extend(bin_box[b]);
        cnt += bin_count[b];
        right_area[b] = SurfaceArea(acc);
        right_count[b] = cnt;
      }
      acc.setEmpty();
      cnt = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.extend(bin_box[b]);
        cnt += bin_count[b];
        if (cnt == 0 || right_count[b + 1] == 0) continue;
        const double cost = SurfaceArea(acc) * cnt + right_area[b + 1] * right_count[b + 1];
        if (cost < best_cost) best_cost = cost, best_axis = axis, best_split = b;
      }
    }
  }
  int mid;
  if (best_axis >= 0) {
    const double scale = kBins / cext[best_axis];
    const double lo = cbounds.min()[best_axis];
    const auto it = std::partition(order.begin() + begin, order.begin() + end, [&](int f) {
      return std::min(kBins - 1, static_cast<int>((centroid[f][best_axis] - lo) * scale)) <= best_split;
    });
    mid = static_cast<int>(it - order.begin());
  } else {
    Eigen::Index axis;
    cext.maxCoeff(&axis);
    mid = begin + count / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](int a, int b) { return centroid[a][axis] < centroid[b][axis] || (centroid[a][axis] == centroid[b][axis] && a < b); });
  }
  SetChild(node, 0, Build(order, begin, mid, centroid, box, depth + 1));
  SetChild(node, 1, Build(order, mid, end, centroid, box, depth + 1));
  return ChildRef{node, 0, bounds};
}

void TriangleBvh::SetChild(int node, int c, const ChildRef& ref) {
  Node& nd = nodes_[node];
  nd.child[c] = ref.index;
  nd.count[c] = ref.count;
  for (int k = 0; k < 3; ++k) {
    // An empty box (the missing sibling of a one-leaf tree) stays +inf/-inf: infinitely far, never visited.
    nd.lo[k][c] = ref.box.isEmpty() ? std::numeric_limits<float>::infinity() : RoundDown(ref.box.min()[k]);
    nd.hi[k][c] = ref.box.isEmpty() ? -std::numeric_limits<float>::infinity() : RoundUp(ref.box.max()[k]);
  }
}



namespace {

// Squared distances from (px, py, pz) to the two child boxes of a node, lower bounds in double of the
// float boxes (which are rounded outwards). SSE2 (every x86-64) does both children at once.
template <typename NodeT>
inline void ChildSqDistances(const NodeT& nd, double px, double py, double pz, double* d0, double* d1) {
#ifdef __SSE2__
  const __m128d zero = _mm_setzero_pd();
  auto axis = [&](const float* lo, const float* hi, double p) {
    const __m128d vp = _mm_set1_pd(p);
    const __m128d l = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(lo))));
    const __m128d h = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(hi))));
    const __m128d d = _mm_max_pd(_mm_max_pd(_mm_sub_pd(l, vp), _mm_sub_pd(vp, h)), zero);
    return _mm_mul_pd(d, d);
  };
  const __m128d sum = _mm_add_pd(_mm_add_pd(axis(nd.lo[0], nd.hi[0], px), axis(nd.lo[1], nd.hi[1], py)),
                                 axis(nd.lo[2], nd.hi[2], pz));
  _mm_storel_pd(d0, sum);
  _mm_storeh_pd(d1, sum);
#else
  double s[2];
  for (int c = 0; c < 2; ++c) {
    const double dx = std::max({static_cast<double>(nd.lo[0][c]) - px, 0.0, px - static_cast<double>(nd.hi[0][c])});
    const double dy = std::max({static_cast<double>(nd.lo[1][c]) - py, 0.0, py - static_cast<double>(nd.hi[1][c])});
    const double dz = std::max({static_cast<double>(nd.lo[2][c]) - pz, 0.0, pz - static_cast<double>(nd.hi[2][c])});
    s[c] = dx * dx + dy * dy + dz * dz;
  }
  *d0 = s[0];
  *d1 = s[1];
#endif
}

// The answer for a query that is not a point: NaN distance and point, no face.
TriangleBvh::Hit NoHit() {
  TriangleBvh::Hit none;
  none.sq_distance = std::numeric_limits<double>::quiet_NaN();
  none.point = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  return none;
}

}  // namespace

TriangleBvh::Hit TriangleBvh::Closest(const Vec3& p, int hint) const {
  if (!p.allFinite()) return NoHit();  // NaN would slip through the SIMD max(., 0) and visit every box
  const double px = p.x(), py = p.y(), pz = p.z();
  double best = std::numeric_limits<double>::infinity();
  // Boxes and planes are pruned only beyond `bound` = (sqrt(best) + tie_slack_)^2, so that every triangle
  // whose distance could round to a tie with the best is examined: the result is then the minimum of
  // (squared distance, slot) over all triangles, independent of the traversal's starting bound.
  double bound = best;
  double bx = 0, by = 0, bz = 0;
  int best_slot = -1;

  auto test_triangle = [&](int s) VOROUDF_ALWAYS_INLINE {
    const PackedTri& t = tris_[s];
    const double apx = px - t.a[0], apy = py - t.a[1], apz = pz - t.a[2];
    // The distance to the triangle's plane bounds the distance from below: many triangles of a
    // visited leaf are rejected by it without the region tests.
    const double plane = apx * t.n[0] + apy * t.n[1] + apz * t.n[2];
    if (plane * plane > bound) return;
    double qx, qy, qz;
    if (t.inv_det != 0.0) {
      const double d1 = t.ab[0] * apx + t.ab[1] * apy + t.ab[2] * apz;
      const double d2 = t.ac[0] * apx + t.ac[1] * apy + t.ac[2] * apz;
      double v, w;
      EricsonBarycentric(d1, d2, t.d00, t.d01, t.d11, t.inv_det, &v, &w);
      qx = t.a[0] + v * t.ab[0] + w * t.ac[0];
      qy = t.a[1] + v * t.ab[1] + w * t.ac[1];
      qz = t.a[2] + v * t.ab[2] + w * t.ac[2];
    } else {
      const Vec3 a(t.a[0], t.a[1], t.a[2]);
      const Vec3 q = ClosestOnEdges(p, a, a + Vec3(t.ab[0], t.ab[1], t.ab[2]), a + Vec3(t.ac[0], t.ac[1], t.ac[2]));
      qx = q.x(), qy = q.y(), qz = q.z();
    }
    const double dx = px - qx, dy = py - qy, dz = pz - qz;
    const double sq = dx * dx + dy * dy + dz * dz;
    if (sq < best || (sq == best && s < best_slot)) {
      if (sq < best) {
        const double r = std::sqrt(sq) + tie_slack_;
        bound = r * r;
      }
      best = sq, bx = qx, by = qy, bz = qz, best_slot = s;
    }
  };
  if (hint >= 0 && hint < static_cast<int>(tris_.size())) test_triangle(hint);

  auto test_leaf = [&](int first, int count) VOROUDF_ALWAYS_INLINE {
    for (int s = first, e = first + count; s < e; ++s) {
      test_triangle(s);
    }
  };

  struct Entry {
    int32_t index, count;
    double sq;
  };
  Entry stack[kStackSize];
  int top = 0;
  int node = 0;
  for (;;) {
    const Node& nd = nodes_[node];
    double d0, d1;
    ChildSqDistances(nd, px, py, pz, &d0, &d1);
    const int nc = d1 < d0 ? 1 : 0;  // nearer child first; the left one on ties
    const double dnear = nc ? d1 : d0, dfar = nc ? d0 : d1;
    const int near_index = nd.child[nc], near_count = nd.count[nc];
    const int far_index = nd.child[1 - nc], far_count = nd.count[1 - nc];
    if (dnear <= bound) {
      if (near_count == 0) {
        if (dfar <= bound) stack[top++] = {far_index, far_count, dfar};
        node = near_index;
        continue;
      }
      test_leaf(near_index, near_count);
      if (dfar <= bound) {
        if (far_count == 0) {
          node = far_index;
          continue;
        }
        test_leaf(far_index, far_count);
      }
    }
    // Pop the next box that can still hold something closer; leaves are tested on the spot.
    node = -1;
    while (top > 0) {
      const Entry e = stack[--top];
      if (!(e.sq <= bound)) continue;
      if (e.count > 0) {
        test_leaf(e.index, e.count);
        continue;
      }
      node = e.index;
      break;
    }
    if (node < 0) break;
  }
  return Hit{best, Vec3(bx, by, bz), best_slot >= 0 ? face_of_[best_slot] : -1, best_slot};
}

Vec3 TriangleBvh::FaceNormal(int face) const { return normal_[face]; }

}  // namespace voroudf

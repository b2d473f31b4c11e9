#include "stages/evaluate/evaluate.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>

#include "common/knn.h"
#include "common/morton.h"
#include "common/errors.h"
#include "common/rng.h"
#include "common/triangle_bvh.h"
#include "stages/evaluate/crossings.h"

namespace voroudf {
namespace {

// Exact-distance queries: blocks of consecutive Morton-ordered points, one hint chain per block.
constexpr size_t kBvhBlock = 4096;

// Surface-sample RNG streams of the two meshes: disjoint, so a mesh against itself shows the sampling floor
// of the protocol instead of an artificial 0.
constexpr uint64_t kRefStream = 0;
constexpr uint64_t kMeshStream = 1ull << 40;

using Cell = std::array<long long, 3>;
struct CellHash {
  size_t operator()(const Cell& c) const {
    return static_cast<size_t>(SplitMix64(static_cast<uint64_t>(c[0]) ^ SplitMix64(static_cast<uint64_t>(c[1]) ^
                                                                                 SplitMix64(static_cast<uint64_t>(c[2])))));
  }
};

void CheckFaceIndices(const TriangleMesh& mesh, const std::string& what) {
  const long long nv = static_cast<long long>(mesh.vertices.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int v : mesh.faces[f])
      if (v < 0 || v >= nv)
        throw InputError(what, "face " + std::to_string(f) + " has vertex index " + std::to_string(v) +
                                   " out of range [0, " + std::to_string(nv) + ")");
}

double TotalArea(const TriangleMesh& mesh) {
  double area = 0;
  for (const Tri& t : mesh.faces) {
    const Vec3& a = mesh.vertices[t[0]];
    area += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
  }
  return area;
}

std::string Number(double x) {
  if (std::isinf(x)) return "\"inf\"";
  if (std::isnan(x)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

}  // namespace

void EvaluateOptions::Check() const {
  if (samples < 1 || samples > 100000000) throw UsageError("--samples must be in [1, 1e8]");
  if (nm_samples < 1 || nm_samples > 100000000) throw UsageError("--nm-samples must be in [1, 1e8]");
  if (!(edge_radius > 0 && edge_radius < 1)) throw UsageError("edge radius must be in (0, 1)");
  if (!(edge_cos > 0 && edge_cos <= 1)) throw UsageError("edge cosine threshold must be in (0, 1]");
  if (!(weld_tolerance >= 0 && weld_tolerance < 0.1)) throw UsageError("weld tolerance must be in [0, 0.1)");
  if (empty_edge_points < 1) throw UsageError("the ECD stand-in needs at least one point");
  if (edge_samples < 1 || edge_samples > 100000000) throw UsageError("--edge-samples must be in [1, 1e8]");
  if (!(feature_angle_deg > 0 && feature_angle_deg < 180)) throw UsageError("--feature-angle must be in (0, 180)");
  if (ref_nm_curves != "union" && ref_nm_curves != "edges")
    throw UsageError("--ref-nm-curves must be union or edges, not '" + ref_nm_curves + "'");
}

Frame ReferenceFrame(const TriangleMesh& reference) {
  if (reference.faces.empty()) throw InputError("reference", "has no face");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Tri& t : reference.faces)
    for (int v : t) {
      lo = lo.cwiseMin(reference.vertices[v]);
      hi = hi.cwiseMax(reference.vertices[v]);
    }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent > 0) || !std::isfinite(extent)) throw InputError("reference", "all its vertices coincide (bounding box of size 0)");
  Frame frame;
  frame.center = 0.5 * (lo + hi);
  frame.scale = 1.0 / extent;
  frame.ref_diagonal = (hi - lo).norm() * frame.scale;
  return frame;
}

TriangleMesh ApplyFrame(const Frame& frame, const TriangleMesh& mesh) {
  TriangleMesh out;
  out.faces = mesh.faces;
  out.vertices.resize(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) out.vertices[i] = frame.Apply(mesh.vertices[i]);
  return out;
}

SurfaceSamples SampleSurface(const TriangleMesh& mesh, size_t count, uint64_t seed, uint64_t stream) {
  const size_t nf = mesh.faces.size();
  std::vector<double> cumulative(nf);
  std::vector<Vec3> normal(nf, Vec3::Zero());
  double total = 0;
  size_t last_positive = 0;
  for (size_t f = 0; f < nf; ++f) {
    const Tri& t = mesh.faces[f];
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3 cross = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    const double twice_area = cross.norm();
    if (twice_area > 0) {
      normal[f] = cross / twice_area;
      total += 0.5 * twice_area;
      last_positive = f;
    }
    cumulative[f] = total;
  }
  SurfaceSamples s;
  if (!(total > 0) || count == 0) return s;
  s.points.resize(count);
  s.normals.resize(count);
  s.faces.resize(count);
#pragma omp parallel for schedule(static)
  for (long long i = 0; i < static_cast<long long>(count); ++i) {
    Rng rng(seed, stream + static_cast<uint64_t>(i));
    const double r = rng.Uniform() * total;
    // upper_bound skips zero-area faces: their cumulative value equals their predecessor's.
    size_t f = static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin());
    if (f >= nf || normal[f].isZero()) f = last_positive;  // r rounded up to the total
    const Tri& t = mesh.faces[f];
    const double su = std::sqrt(rng.Uniform()), v = rng.Uniform();
    s.points[i] = (1 - su) * mesh.vertices[t[0]] + su * (1 - v) * mesh.vertices[t[1]] + su * v * mesh.vertices[t[2]];
    s.normals[i] = normal[f];
    s.faces[i] = static_cast<int>(f);
  }
  return s;
}

std::vector<double> NearestDistances(const std::vector<Vec3>& from, const std::vector<Vec3>& to, Monitor& monitor) {
  std::vector<double> distance(from.size());
  if (from.empty()) return distance;
  const std::vector<int> nearest = NearestIndices(to, from, monitor);
  for (size_t i = 0; i < from.size(); ++i) distance[i] = (from[i] - to[static_cast<size_t>(nearest[i])]).norm();
  return distance;
}

std::vector<double> DistancesToTriangles(const std::vector<Vec3>& points, const TriangleMesh& mesh, Monitor& monitor) {
  std::vector<double> distance(points.size());
  if (points.empty()) return distance;
  const TriangleBvh bvh(mesh.vertices, mesh.faces);
  const std::vector<size_t> order = MortonOrder(points, BoundingBox(points));
  const long long blocks = static_cast<long long>((points.size() + kBvhBlock - 1) / kBvhBlock);
#pragma omp parallel for schedule(dynamic, 1)
  for (long long b = 0; b < blocks; ++b) {
    const size_t begin = static_cast<size_t>(b) * kBvhBlock, end = std::min(points.size(), begin + kBvhBlock);
    int hint = -1;
    for (size_t i = begin; i < end; ++i) {
      const TriangleBvh::Hit hit = bvh.Closest(points[order[i]], hint);
      hint = hit.slot;
      distance[order[i]] = std::sqrt(hit.sq_distance);
    }
    monitor.Advance(end - begin);
  }
  return distance;
}

std::vector<double> DistancesToSegments(const std::vector<Vec3>& points, const std::vector<Vec3>& vertices,
                                        const std::vector<Edge>& edges, Monitor& monitor) {
  if (edges.empty()) throw Error("DistancesToSegments: no segment");
  TriangleMesh segments;
  segments.vertices = vertices;
  segments.faces.reserve(edges.size());
  for (const Edge& e : edges) segments.faces.push_back({e[0], e[1], e[1]});
  return DistancesToTriangles(points, segments, monitor);
}

DistanceSummary Summarize(const std::vector<double>& d) {
  if (d.empty()) throw NumericalError("distance summary of an empty set");
  DistanceSummary s;
  double sum = 0;
  for (double x : d) {
    sum += x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / static_cast<double>(d.size());
  std::vector<double> sorted = d;
  const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(d.size())));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(rank - 1), sorted.end());
  s.p99 = sorted[rank - 1];
  return s;
}

ChamferDistances Chamfer(const std::vector<Vec3>& a, const std::vector<Vec3>& b, Monitor& monitor) {
  if (a.empty() || b.empty()) throw NumericalError("Chamfer distance of an empty point set");
  ChamferDistances c;
  const std::vector<double> dab = NearestDistances(a, b, monitor);
  const std::vector<double> dba = NearestDistances(b, a, monitor);
  double sum = 0;
  for (double d : dab) {
    sum += d;
    c.max_ab = std::max(c.max_ab, d);
  }
  c.mean_ab = sum / static_cast<double>(dab.size());
  sum = 0;
  for (double d : dba) {
    sum += d;
    c.max_ba = std::max(c.max_ba, d);
  }
  c.mean_ba = sum / static_cast<double>(dba.size());
  return c;
}

std::vector<Vec3> EdgePoints(const SurfaceSamples& samples, double radius, double cos_threshold, Monitor& monitor) {
  const size_t n = samples.points.size();
  std::vector<Vec3> edge;
  if (n == 0) return edge;
  if (!samples.faces.empty() && samples.faces.size() != n) throw Error("EdgePoints: one face per sample expected");
  auto group = [&](size_t i) -> long long {
    return samples.faces.empty() ? static_cast<long long>(i) : samples.faces[i];
  };
  // Cells of side 2 radius: the ball around a sample lies in the 2x2x2 cells on the side of its cell's
  // centre it is on (8 hash look-ups per sample instead of 27 with cells of side radius).
  const double side = 2 * radius;
  std::vector<Cell> cell(n);
  std::vector<std::array<signed char, 3>> toward(n);
#pragma omp parallel for schedule(static)
  for (long long i = 0; i < static_cast<long long>(n); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x = samples.points[i][k] / side;
      cell[i][k] = static_cast<long long>(std::floor(x));
      toward[i][k] = x - std::floor(x) < 0.5 ? -1 : 1;
    }
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) {
    if (cell[x] != cell[y]) return cell[x] < cell[y];
    if (group(x) != group(y)) return group(x) < group(y);
    return x < y;
  });
  // Per cell its range in `order`; per position the end of its run of samples of one face.
  std::unordered_map<Cell, std::pair<size_t, size_t>, CellHash> ranges;
  std::vector<size_t> run_end(n);
  for (size_t k = n; k-- > 0;) {
    const bool same_run = k + 1 < n && cell[order[k + 1]] == cell[order[k]] && group(order[k + 1]) == group(order[k]);
    run_end[k] = same_run ? run_end[k + 1] : k + 1;
  }
  for (size_t k = 0; k < n;) {
    size_t e = k + 1;
    while (e < n && cell[order[e]] == cell[order[k]]) ++e;
    ranges.emplace(cell[order[k]], std::make_pair(k, e));
    k = e;
  }
  const double r2 = radius * radius;
  std::vector<char> is_edge(n, 0);
#pragma omp parallel for schedule(dynamic, 1024)
  for (long long i = 0; i < static_cast<long long>(n); ++i) {
    const Vec3& p = samples.points[i];
    const Vec3& ni = samples.normals[i];
    bool found = false;
    for (int d = 0; d < 8 && !found; ++d) {
      const Cell c{cell[i][0] + (d & 1) * toward[i][0], cell[i][1] + ((d >> 1) & 1) * toward[i][1],
                   cell[i][2] + ((d >> 2) & 1) * toward[i][2]};
      const auto it = ranges.find(c);
      if (it == ranges.end()) continue;
      for (size_t k = it->second.first; k < it->second.second && !found; k = run_end[k]) {
        if (!(std::abs(ni.dot(samples.normals[order[k]])) < cos_threshold)) continue;
        for (size_t m = k; m < run_end[k] && !found; ++m) found = (samples.points[order[m]] - p).squaredNorm() < r2;
      }
    }
    is_edge[i] = found;
    if ((i & 1023) == 1023) monitor.Advance(1024);
  }
  monitor.Advance(n % 1024);
  for (size_t i = 0; i < n; ++i)
    if (is_edge[i]) edge.push_back(samples.points[i]);
  return edge;
}

std::vector<Edge> NonManifoldEdges(const TriangleMesh& mesh) {
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  std::vector<Edge> out;
  for (size_t e = 0; e < ef.edges.size(); ++e)
    if (ef.faces[e].size() >= 3) out.push_back(ef.edges[e]);
  return out;
}

std::vector<Edge> SharpEdges(const TriangleMesh& mesh, double cos_threshold) {
  const EdgeFaces ef = BuildEdgeFaces(mesh.faces);
  std::vector<Vec3> normal(mesh.faces.size(), Vec3::Zero());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Tri& t = mesh.faces[f];
    const Vec3 cross = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (cross.norm() > 0) normal[f] = cross.normalized();
  }
  std::vector<Edge> out;
  for (size_t e = 0; e < ef.edges.size(); ++e) {
    const std::vector<int>& fs = ef.faces[e];
    bool sharp = false;
    for (size_t i = 0; i < fs.size() && !sharp; ++i)
      for (size_t j = i + 1; j < fs.size() && !sharp; ++j)
        sharp = !normal[fs[i]].isZero() && !normal[fs[j]].isZero() &&
                std::abs(normal[fs[i]].dot(normal[fs[j]])) < cos_threshold;
    if (sharp) out.push_back(ef.edges[e]);
  }
  return out;
}

std::vector<Vec3> SampleEdges(const TriangleMesh& mesh, const std::vector<Edge>& edges, size_t count,
                              double* total_length, std::vector<Vec3>* directions) {
  std::vector<double> cumulative(edges.size());
  double total = 0;
  for (size_t e = 0; e < edges.size(); ++e) {
    total += (mesh.vertices[edges[e][1]] - mesh.vertices[edges[e][0]]).norm();
    cumulative[e] = total;
  }
  if (total_length) *total_length = total;
  std::vector<Vec3> points;
  if (!(total > 0) || count == 0) return points;
  points.resize(count);
  if (directions) directions->resize(count);
  for (size_t k = 0; k < count; ++k) {
    const double s = (static_cast<double>(k) + 0.5) * total / static_cast<double>(count);
    size_t e = static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), s) - cumulative.begin());
    e = std::min(e, edges.size() - 1);
    const Vec3& a = mesh.vertices[edges[e][0]];
    const Vec3& b = mesh.vertices[edges[e][1]];
    const double length = (b - a).norm();
    const double start = e == 0 ? 0.0 : cumulative[e - 1];
    const double t = length > 0 ? std::clamp((s - start) / length, 0.0, 1.0) : 0.0;
    points[k] = a + t * (b - a);
    if (directions) (*directions)[k] = b - a;
  }
  return points;
}

std::vector<Vec3> SampleNonManifoldEdges(const TriangleMesh& mesh, size_t count, double* total_length) {
  return SampleEdges(mesh, NonManifoldEdges(mesh), count, total_length);
}

TopologyStats WeldedTopology(const TriangleMesh& mesh, double tolerance) {
  return ComputeTopology(WeldVertices(mesh, tolerance));
}

namespace {

// Exact CD/HD/p99 (samples to the other mesh's triangles) and the exact ECD (sharp-edge samples to the other
// mesh's sharp edges), docs/evaluate.md "Exact metrics". `*_welded` are the welded meshes in the frame.
ExactMetrics ExactDistances(const TriangleMesh& mesh, const TriangleMesh& ref, const TriangleMesh& mesh_welded,
                            const TriangleMesh& ref_welded, const SurfaceSamples& mesh_samples,
                            const SurfaceSamples& ref_samples, const EvaluateOptions& options, Metrics& m,
                            Monitor& monitor) {
  ExactMetrics e;
  const double diagonal = m.frame.ref_diagonal;
  {
    Task task(monitor, "exact CD/HD", ref_samples.points.size() + mesh_samples.points.size());
    const DistanceSummary rm = Summarize(DistancesToTriangles(ref_samples.points, mesh, monitor));
    const DistanceSummary mr = Summarize(DistancesToTriangles(mesh_samples.points, ref, monitor));
    e.cd_x1e3 = (rm.mean + mr.mean) * 1e3;
    e.hd_ref_mesh_x1e3 = rm.max / diagonal * 1e3;
    e.hd_mesh_ref_x1e3 = mr.max / diagonal * 1e3;
    e.hd_x1e3 = std::max(e.hd_ref_mesh_x1e3, e.hd_mesh_ref_x1e3);
    e.p99_x1e3 = std::max(rm.p99, mr.p99) / diagonal * 1e3;
  }
  const std::vector<Edge> ref_sharp = SharpEdges(ref_welded, options.edge_cos);
  std::vector<Edge> mesh_sharp = SharpEdges(mesh_welded, options.edge_cos);
  const std::vector<Vec3> ref_points = SampleEdges(ref_welded, ref_sharp, options.edge_samples, &m.ref.sharp_length);
  std::vector<Vec3> mesh_points = SampleEdges(mesh_welded, mesh_sharp, options.edge_samples, &m.mesh.sharp_length);
  if (ref_points.empty()) return e;  // no sharp edge in the reference: 0, as the sampled ECD
  // A mesh with no sharp edge is compared as one point at the origin (the sampled ECD's stand-in), so a
  // method that loses every crease is penalised instead of skipped.
  std::vector<Vec3> mesh_vertices = mesh_welded.vertices;
  if (mesh_points.empty()) {
    mesh_points.assign(1, Vec3::Zero());
    mesh_vertices.assign(1, Vec3::Zero());
    mesh_sharp.assign(1, Edge{0, 0});
  }
  Task task(monitor, "exact ECD", ref_points.size() + mesh_points.size());
  const DistanceSummary rm = Summarize(DistancesToSegments(ref_points, mesh_vertices, mesh_sharp, monitor));
  const DistanceSummary mr = Summarize(DistancesToSegments(mesh_points, ref_welded.vertices, ref_sharp, monitor));
  e.ecd_x1e2 = (rm.mean + mr.mean) * 1e2;
  return e;
}

// The sampled CD, HD and ECD of the reference against its own samples of the mesh's stream.
FloorMetrics SampledFloor(const TriangleMesh& ref, const SurfaceSamples& ref_samples,
                          const std::vector<Vec3>& ref_edge, const EvaluateOptions& options, double diagonal,
                          Monitor& monitor) {
  FloorMetrics f;
  const SurfaceSamples other = SampleSurface(ref, options.samples, options.seed, kMeshStream);
  Task task(monitor, "floor", 4 * options.samples);
  const ChamferDistances c = Chamfer(ref_samples.points, other.points, monitor);
  f.cd_x1e3 = c.SumOfMeans() * 1e3;
  f.hd_x1e3 = c.MaxOfMaxima() / diagonal * 1e3;
  const std::vector<Vec3> other_edge = EdgePoints(other, options.edge_radius, options.edge_cos, monitor);
  if (!ref_edge.empty() && !other_edge.empty()) f.ecd_x1e2 = Chamfer(ref_edge, other_edge, monitor).SumOfMeans() * 1e2;
  return f;
}

// The reference's branching curves, as `edges` over the returned vertices: its edges of 3+ faces and, with
// --ref-nm-curves union, the curves where its triangles cross or touch (CrossingCurves). Sets
// m.ref.nonmanifold_length (the edges of 3+ faces) and m.ref_crossing_length.
TriangleMesh ReferenceBranchingCurves(const TriangleMesh& ref_welded, const EvaluateOptions& options, Metrics& m,
                                      Monitor& monitor, std::vector<Edge>* edges) {
  TriangleMesh curves;
  curves.vertices = ref_welded.vertices;
  *edges = NonManifoldEdges(ref_welded);
  SampleEdges(curves, *edges, 0, &m.ref.nonmanifold_length);  // the length only
  if (options.ref_nm_curves != "union") return curves;
  const CurveSegments crossing = CrossingCurves(ref_welded, options.weld_tolerance, options.feature_angle_deg);
  const int base = static_cast<int>(curves.vertices.size());
  curves.vertices.insert(curves.vertices.end(), crossing.vertices.begin(), crossing.vertices.end());
  for (const Edge& e : crossing.edges) {
    edges->push_back({base + e[0], base + e[1]});
    m.ref_crossing_length += (crossing.vertices[e[1]] - crossing.vertices[e[0]]).norm();
  }
  if (!crossing.edges.empty())
    monitor.Info("reference: " + std::to_string(crossing.edges.size()) +
                 Format(" crossing segments of length %.6g where its triangles cross or touch (non-manifold in the "
                     "UDF)", m.ref_crossing_length));
  return curves;
}

// How many of the mesh's non-manifold edges `nm_edges` have their midpoint farther than the mesh's median edge
// length h from every reference curve (all of them if the reference has none) and, with --ref-nm-curves
// union, no branching of the reference's union across them within 2 h (BranchesAcross: where parts touch
// tangentially or coincide, there is no line where two triangles cross to find).
size_t SpuriousEdges(const TriangleMesh& mesh, const std::vector<Edge>& nm_edges, const TriangleMesh& ref_welded,
                     const TriangleMesh& curves, const std::vector<Edge>& curve_edges, const EvaluateOptions& options,
                     Monitor& monitor) {
  if (nm_edges.empty()) return 0;
  std::vector<Vec3> mid;
  for (const Edge& e : nm_edges) mid.push_back(0.5 * (mesh.vertices[e[0]] + mesh.vertices[e[1]]));
  const double far = MedianEdgeLength(mesh);
  std::vector<char> off(nm_edges.size(), 1);
  if (!curve_edges.empty()) {
    const std::vector<double> d = DistancesToSegments(mid, curves.vertices, curve_edges, monitor);
    for (size_t k = 0; k < d.size(); ++k) off[k] = d[k] > far;
  }
  if (options.ref_nm_curves != "union") return static_cast<size_t>(std::count(off.begin(), off.end(), 1));
  std::vector<Vec3> at, along;
  for (size_t k = 0; k < nm_edges.size(); ++k)
    if (off[k]) {
      at.push_back(mid[k]);
      along.push_back(mesh.vertices[nm_edges[k][1]] - mesh.vertices[nm_edges[k][0]]);
    }
  const std::vector<char> branch = BranchesAcross(ref_welded, at, along, 2.0 * far, 0.01 * far);
  const size_t spurious = static_cast<size_t>(std::count(branch.begin(), branch.end(), 0));
  if (spurious < at.size())
    monitor.Info(std::to_string(at.size() - spurious) +
                 " non-manifold edges away from the reference's crossing curves lie where its parts touch "
                 "without crossing (BranchesAcross): not spurious");
  return spurious;
}

}  // namespace

Metrics Evaluate(const TriangleMesh& mesh_in, const TriangleMesh& reference_in, const EvaluateOptions& options,
                 Monitor& monitor) {
  options.Check();
  CheckFaceIndices(reference_in, "reference");
  CheckFaceIndices(mesh_in, "mesh");
  Metrics m;
  m.frame = ReferenceFrame(reference_in);
  const TriangleMesh ref = ApplyFrame(m.frame, reference_in);
  const TriangleMesh mesh = ApplyFrame(m.frame, mesh_in);
  monitor.Info(Format("frame: reference bbox centre (%.6g, %.6g, %.6g)", m.frame.center.x(), m.frame.center.y(),
                   m.frame.center.z()) +
               Format(", scale %.6g, normalised diagonal %.6g", m.frame.scale, m.frame.ref_diagonal));
  if (!(TotalArea(ref) > 0)) throw InputError("reference", "has no face of non-zero area");
  if (!(TotalArea(mesh) > 0))
    throw NumericalError("the mesh under test has no face of non-zero area (" + std::to_string(mesh.faces.size()) +
                         " faces): nothing to compare with the reference");

  m.mesh.vertices = mesh.vertices.size();
  m.mesh.faces = mesh.faces.size();
  m.ref.vertices = ref.vertices.size();
  m.ref.faces = ref.faces.size();
  m.mesh.tq = MeanTriangleQuality(mesh);
  m.ref.tq = MeanTriangleQuality(ref);

  // Welding first (also for the non-manifold edges of NM-CD): meshes written with one vertex per face
  // corner (STL-like OBJ exports) would otherwise have no shared edge at all.
  const TriangleMesh mesh_welded = WeldVertices(mesh, options.weld_tolerance);
  const TriangleMesh ref_welded = WeldVertices(ref, options.weld_tolerance);
  m.mesh.topology = ComputeTopology(mesh_welded);
  m.ref.topology = ComputeTopology(ref_welded);
  m.td = std::llabs(m.mesh.topology.euler - m.ref.topology.euler);

  SurfaceSamples ref_samples, mesh_samples;
  {
    Task task(monitor, "sampling", 2);
    ref_samples = SampleSurface(ref, options.samples, options.seed, kRefStream);
    task.Advance();
    mesh_samples = SampleSurface(mesh, options.samples, options.seed, kMeshStream);
    task.Advance();
  }
  {
    Task task(monitor, "CD/HD", 2 * options.samples);
    const ChamferDistances c = Chamfer(ref_samples.points, mesh_samples.points, monitor);
    m.cd_x1e3 = c.SumOfMeans() * 1e3;
    m.hd_x1e3 = c.MaxOfMaxima() / m.frame.ref_diagonal * 1e3;
    monitor.Info(Format("CD: mean ref->mesh %.6g + mean mesh->ref %.6g; HD: one-sided maxima %.6g", c.mean_ab, c.mean_ba,
                     c.max_ab) + Format(" and %.6g", c.max_ba));
  }

  std::vector<Vec3> ref_edge, mesh_edge;
  {
    Task task(monitor, "edge points", 2 * options.samples);
    ref_edge = EdgePoints(ref_samples, options.edge_radius, options.edge_cos, monitor);
    mesh_edge = EdgePoints(mesh_samples, options.edge_radius, options.edge_cos, monitor);
  }
  m.ref.edge_points = ref_edge.size();
  m.mesh.edge_points = mesh_edge.size();
  if (ref_edge.empty()) {
    m.ecd_x1e2 = 0.0;
  } else {
    if (mesh_edge.empty()) mesh_edge.assign(options.empty_edge_points, Vec3::Zero());
    Task task(monitor, "ECD", ref_edge.size() + mesh_edge.size());
    m.ecd_x1e2 = Chamfer(ref_edge, mesh_edge, monitor).SumOfMeans() * 1e2;
  }

  std::vector<Edge> ref_curve_edges;
  const TriangleMesh ref_curves = ReferenceBranchingCurves(ref_welded, options, m, monitor, &ref_curve_edges);
  const std::vector<Vec3> ref_nm = SampleEdges(ref_curves, ref_curve_edges, options.nm_samples, nullptr);
  const std::vector<Edge> mesh_nm_edges = NonManifoldEdges(mesh_welded);
  const std::vector<Vec3> mesh_nm = SampleEdges(mesh_welded, mesh_nm_edges, options.nm_samples, &m.mesh.nonmanifold_length);
  m.spurious_nonmanifold_edges =
      SpuriousEdges(mesh_welded, mesh_nm_edges, ref_welded, ref_curves, ref_curve_edges, options, monitor);
  if (ref_nm.empty() && mesh_nm.empty()) {
    m.nmcd_x1e3 = 0.0;
  } else if (ref_nm.empty() || mesh_nm.empty()) {
    m.nmcd_x1e3 = std::numeric_limits<double>::infinity();
  } else {
    Task task(monitor, "NM-CD", ref_nm.size() + mesh_nm.size());
    m.nmcd_x1e3 = Chamfer(ref_nm, mesh_nm, monitor).SumOfMeans() * 1e3;
  }
  m.exact = ExactDistances(mesh, ref, mesh_welded, ref_welded, mesh_samples, ref_samples, options, m, monitor);
  m.features = FeatureRecall(mesh_welded, ref_welded, options.feature_angle_deg, options.edge_samples,
                             m.frame.ref_diagonal, monitor);
  if (options.floor) {
    m.has_floor = true;
    m.floor = SampledFloor(ref, ref_samples, ref_edge, options, m.frame.ref_diagonal, monitor);
  }
  monitor.Info(Format("exact: CD %.6g (x1e3)  HD %.6g (x1e3)  p99 %.6g (x1e3)", m.exact.cd_x1e3, m.exact.hd_x1e3,
                   m.exact.p99_x1e3) + Format("  ECD %.6g (x1e2)", m.exact.ecd_x1e2));
  monitor.Info(Format("features: recall %.4g of length %.4g, corners ", m.features.recall, m.features.feature_length) +
               std::to_string(m.features.corners_matched) + "/" + std::to_string(m.features.corners) +
               Format(", boundary recall %.4g, boundary max %.4g (x1e3)", m.features.boundary_recall,
                   m.features.boundary_max_x1e3));
  monitor.Info(Format("CD %.6g (x1e3)  HD %.6g (x1e3)  ECD %.6g (x1e2)", m.cd_x1e3, m.hd_x1e3, m.ecd_x1e2) +
               Format("  TQ %.4g  TD %.0f  NM-CD %.6g (x1e3)", m.mesh.tq, static_cast<double>(m.td), m.nmcd_x1e3));
  return m;
}

std::string MetricsJson(const Metrics& m, const EvaluateOptions& options, const std::string& mesh_path,
                        const std::string& reference_path, double seconds) {
  std::string out = "{";
  bool first = true;
  auto raw = [&](const char* key, const std::string& value) {
    out += (first ? "\"" : ", \"") + std::string(key) + "\": " + value;
    first = false;
  };
  auto num = [&](const char* key, double value) { raw(key, Number(value)); };
  auto count = [&](const char* key, long long value) { raw(key, std::to_string(value)); };
  raw("mesh", JsonString(mesh_path));
  raw("reference", JsonString(reference_path));
  count("samples", static_cast<long long>(options.samples));
  count("nm_samples", static_cast<long long>(options.nm_samples));
  raw("seed", std::to_string(options.seed));
  num("frame_scale", m.frame.scale);
  count("vertices", static_cast<long long>(m.mesh.vertices));
  count("faces", static_cast<long long>(m.mesh.faces));
  num("cd_x1e3", m.cd_x1e3);
  num("hd_x1e3", m.hd_x1e3);
  num("ecd_x1e2", m.ecd_x1e2);
  num("tq", m.mesh.tq);
  count("td", m.td);
  num("nmcd_x1e3", m.nmcd_x1e3);
  count("spurious_nonmanifold_edges", static_cast<long long>(m.spurious_nonmanifold_edges));
  num("cd_exact_x1e3", m.exact.cd_x1e3);
  num("hd_exact_x1e3", m.exact.hd_x1e3);
  num("p99_exact_x1e3", m.exact.p99_x1e3);
  num("hd_exact_ref_mesh_x1e3", m.exact.hd_ref_mesh_x1e3);
  num("hd_exact_mesh_ref_x1e3", m.exact.hd_mesh_ref_x1e3);
  num("ecd_exact_x1e2", m.exact.ecd_x1e2);
  num("feature_recall", m.features.recall);
  count("corners", static_cast<long long>(m.features.corners));
  count("corners_matched", static_cast<long long>(m.features.corners_matched));
  num("feature_mean_x1e3", m.features.feature_mean_x1e3);
  num("feature_max_x1e3", m.features.feature_max_x1e3);
  num("feature_length", m.features.feature_length);
  num("boundary_recall", m.features.boundary_recall);
  num("boundary_max_x1e3", m.features.boundary_max_x1e3);
  num("boundary_length", m.features.boundary_length);
  num("feature_tolerance", m.features.tolerance);
  num("ref_diagonal", m.frame.ref_diagonal);
  if (m.has_floor) {
    num("cd_floor_x1e3", m.floor.cd_x1e3);
    num("hd_floor_x1e3", m.floor.hd_x1e3);
    num("ecd_floor_x1e2", m.floor.ecd_x1e2);
  }
  count("euler_mesh", m.mesh.topology.euler);
  count("euler_ref", m.ref.topology.euler);
  auto report = [&](const std::string& prefix, const MeshReport& r) {
    count((prefix + "nonmanifold_edges").c_str(), static_cast<long long>(r.topology.nonmanifold_edges));
    count((prefix + "nonmanifold_vertices").c_str(), static_cast<long long>(r.topology.nonmanifold_vertices));
    count((prefix + "boundary_edges").c_str(), static_cast<long long>(r.topology.boundary_edges));
    count((prefix + "components").c_str(), static_cast<long long>(r.topology.components));
    count((prefix + "edge_points").c_str(), static_cast<long long>(r.edge_points));
    num((prefix + "nonmanifold_length").c_str(), r.nonmanifold_length);
    num((prefix + "sharp_length").c_str(), r.sharp_length);
  };
  report("", m.mesh);
  count("ref_vertices", static_cast<long long>(m.ref.vertices));
  count("ref_faces", static_cast<long long>(m.ref.faces));
  num("ref_tq", m.ref.tq);
  report("ref_", m.ref);
  num("ref_crossing_length", m.ref_crossing_length);
  if (seconds >= 0) num("seconds", seconds);
  return out + "}\n";
}

}  // namespace voroudf

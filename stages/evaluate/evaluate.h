#pragma once
// Stage 5 (DESIGN.md "evaluate"; paper Sec. 4 "Evaluation Metrics", "Topology Error", "Non-Manifold
// Chamfer Error" and Supplementary "Evaluation Metrics"): the metrics of a mesh against a reference mesh.
// Every definition, with its frame, sample counts and factors, is in docs/evaluate.md.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/mesh_topology.h"
#include "common/monitor.h"
#include "common/types.h"
#include "stages/evaluate/features.h"

namespace voroudf {

struct EvaluateOptions {
  size_t samples = 100000;       ///< area-uniform surface samples per mesh (--samples)
  size_t nm_samples = 10000;     ///< samples along the non-manifold edges per mesh, by length (--nm-samples)
  uint64_t seed = 0;             ///< seed of the surface samples' RNG (--seed)
  double edge_radius = 0.004;    ///< ECD neighbourhood radius in the normalised frame (NMC protocol)
  double edge_cos = 0.2;         ///< ECD: a neighbour with |n.n'| below this makes an edge point (NMC)
  double weld_tolerance = 1e-7;  ///< TD and topology counts: weld distance in the normalised frame
  size_t empty_edge_points = 486;  ///< ECD: origin points standing in when the mesh has no edge point (NMC)
  size_t edge_samples = 10000;   ///< exact ECD: samples per mesh along its sharp edges, by length (--edge-samples)
  bool floor = false;            ///< also the sampled metrics of the reference against itself (--floor)
  double feature_angle_deg = 30.0;  ///< feature recall: an edge whose dihedral departs from flat by more (--feature-angle)
  /// The reference's non-manifold curves (--ref-nm-curves): "union", its edges of 3+ faces and the curves where
  /// its triangles cross or touch (CrossingCurves: the UDF is the distance to their union); "edges", the
  /// edges of 3+ faces alone (DESIGN.md's definition).
  std::string ref_nm_curves = "union";

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// The similarity x -> (x - center) * scale that puts the reference's bounding box, centred, into
/// [-0.5, 0.5]^3 with its largest extent exactly 1.
struct Frame {
  Vec3 center = Vec3::Zero();
  double scale = 1.0;
  double ref_diagonal = 0.0;  ///< the reference's bbox diagonal after the map (<= sqrt 3)

  Vec3 Apply(const Vec3& p) const { return (p - center) * scale; }
};

/// The frame of `reference`, from the bounding box of the vertices its faces use.
/// Throws InputError if it has no face or its vertices all coincide (max extent 0).
Frame ReferenceFrame(const TriangleMesh& reference);

/// `mesh` with every vertex mapped by `frame`; faces unchanged.
TriangleMesh ApplyFrame(const Frame& frame, const TriangleMesh& mesh);

/// Points on a surface with the unit normal of the face each lies on.
struct SurfaceSamples {
  std::vector<Vec3> points;
  std::vector<Vec3> normals;
  std::vector<int> faces;  ///< the face each sample lies on (may be left empty for hand-made samples)
};

/// `count` area-uniform samples: face by the cumulative-area table, position by uniform barycentric
/// coordinates (sqrt trick, Osada et al. 2002). Sample i draws from Rng(seed, stream + i) alone, so the
/// result is independent of the thread count. Faces of zero area carry no sample.
/// \returns an empty set if the total area is 0 (or count is 0). \pre face indices are valid
SurfaceSamples SampleSurface(const TriangleMesh& mesh, size_t count, uint64_t seed, uint64_t stream);

/// For each point of `from`, the Euclidean distance to its nearest point of `to` (FLANN single kd-tree,
/// exact search; distances recomputed in double). \pre `to` is not empty
std::vector<double> NearestDistances(const std::vector<Vec3>& from, const std::vector<Vec3>& to,
                                     Monitor& monitor);

/// For each point, the exact Euclidean distance to the closest point of `mesh`'s triangles (TriangleBvh;
/// a degenerate triangle counts as its edges, so a face (a, b, b) is the segment a-b). Queries run in
/// Morton order, each hinted with its predecessor's hit, which changes the cost and never the result.
/// \pre `mesh` has a face and valid indices
std::vector<double> DistancesToTriangles(const std::vector<Vec3>& points, const TriangleMesh& mesh, Monitor& monitor);

/// For each point, the exact distance to the nearest of the segments `edges` of `vertices`
/// (DistancesToTriangles on the degenerate faces (a, b, b)). \pre `edges` is non-empty
std::vector<double> DistancesToSegments(const std::vector<Vec3>& points, const std::vector<Vec3>& vertices,
                                        const std::vector<Edge>& edges, Monitor& monitor);

/// Mean, maximum and 99th percentile (nearest rank: the ceil(0.99 n)-th smallest) of one-sided distances.
struct DistanceSummary {
  double mean = 0, max = 0, p99 = 0;
};
/// \pre `d` is non-empty. The sum is taken in index order.
DistanceSummary Summarize(const std::vector<double>& d);

/// Both directions of the point-set Chamfer/Hausdorff distances between `a` and `b`.
struct ChamferDistances {
  double mean_ab = 0, mean_ba = 0;  ///< mean over a of d(a, B), mean over b of d(b, A)
  double max_ab = 0, max_ba = 0;    ///< one-sided Hausdorff distances
  double SumOfMeans() const { return mean_ab + mean_ba; }
  double MaxOfMaxima() const { return max_ab > max_ba ? max_ab : max_ba; }
};
/// \pre both sets are non-empty. Sums are taken in index order, so results do not depend on threads.
ChamferDistances Chamfer(const std::vector<Vec3>& a, const std::vector<Vec3>& b, Monitor& monitor);

/// Edge points of the Neural Marching Cubes protocol (Chen & Zhang 2021): the samples that have another
/// sample at distance < `radius` whose normal makes |n.n'| < `cos_threshold` (sign-blind, as face
/// orientation is arbitrary on open and non-manifold meshes). Returned in sample order.
/// Exact, with memory O(samples) whatever their density: a hash grid of cell 2 `radius`, samples grouped by
/// face in each cell so that a face whose normal cannot qualify is skipped whole, and each sample stops at
/// its first qualifying neighbour. (A radius search that lists every neighbour, as FLANN's does, needs
/// samples^2 memory when a mesh is small against the reference's frame.)
/// \pre samples.faces is empty or has one entry per point
std::vector<Vec3> EdgePoints(const SurfaceSamples& samples, double radius, double cos_threshold, Monitor& monitor);

/// Non-manifold edges: edges shared by 3 or more faces, in BuildEdgeFaces order.
std::vector<Edge> NonManifoldEdges(const TriangleMesh& mesh);

/// Sharp edges, the polyline counterpart of the ECD edge points: edges with two incident faces of non-zero
/// area whose unit normals make |n.n'| < `cos_threshold` (sign-blind; on a non-manifold edge any pair counts,
/// so two sheets crossing steeply make their common edge sharp). Boundary edges are not sharp.
/// In BuildEdgeFaces order. \pre the mesh is welded (a crease between unshared vertices has no edge)
std::vector<Edge> SharpEdges(const TriangleMesh& mesh, double cos_threshold);

/// `count` points spread evenly by arc length over `edges` (stratified: the point k sits at length
/// (k + 1/2) L / count along the edges laid end to end, L their total length). Deterministic.
/// \param total_length receives L (may be null). \returns an empty set if there is no edge or L = 0.
/// \param directions receives each sample's edge direction b - a (may be null).
std::vector<Vec3> SampleEdges(const TriangleMesh& mesh, const std::vector<Edge>& edges, size_t count,
                              double* total_length, std::vector<Vec3>* directions = nullptr);

/// SampleEdges over NonManifoldEdges(mesh).
std::vector<Vec3> SampleNonManifoldEdges(const TriangleMesh& mesh, size_t count, double* total_length);

/// Topology after WeldVertices(mesh, tolerance): vertices closer than `tolerance` merged, faces that
/// collapsed dropped, unreferenced vertices dropped. Its `euler` is the chi of TD.
TopologyStats WeldedTopology(const TriangleMesh& mesh, double tolerance);

/// What is reported for each of the two meshes.
struct MeshReport {
  size_t vertices = 0;         ///< as read
  size_t faces = 0;            ///< as read
  TopologyStats topology;      ///< after welding in the normalised frame
  double tq = 0;               ///< MeanTriangleQuality
  size_t edge_points = 0;      ///< ECD edge points among the surface samples
  double nonmanifold_length = 0;  ///< total length of the non-manifold edges in the normalised frame
  double sharp_length = 0;     ///< total length of the sharp edges (SharpEdges) in the normalised frame
};

/// Exact distances between the two meshes (no sampling floor): one mesh's samples to the other's triangles.
struct ExactMetrics {
  double cd_x1e3 = 0;        ///< mean ref samples -> mesh triangles + mean mesh samples -> ref triangles, x1e3
  double hd_x1e3 = 0;        ///< max of the two one-sided maxima / reference bbox diagonal, x1e3
  double p99_x1e3 = 0;       ///< max of the two one-sided 99th percentiles / reference bbox diagonal, x1e3
  double hd_ref_mesh_x1e3 = 0;  ///< one-sided: the worst reference sample (a part the mesh misses)
  double hd_mesh_ref_x1e3 = 0;  ///< one-sided: the worst mesh sample (a stray or misplaced triangle)
  double ecd_x1e2 = 0;       ///< sharp-edge samples -> the other mesh's sharp edges, both means summed, x1e2
};

/// The sampled CD, HD and ECD of the reference against itself (its samples of the mesh's RNG stream in
/// place of the mesh's): the part of the sampled metrics that is sampling noise.
struct FloorMetrics {
  double cd_x1e3 = 0, hd_x1e3 = 0, ecd_x1e2 = 0;
};

struct Metrics {
  double cd_x1e3 = 0;    ///< L1 Chamfer, sum of the two means, x1e3
  double hd_x1e3 = 0;    ///< max one-sided Hausdorff / reference bbox diagonal, x1e3
  double ecd_x1e2 = 0;   ///< edge Chamfer (sum of means) x1e2
  double nmcd_x1e3 = 0;  ///< non-manifold Chamfer (sum of means) x1e3; +infinity if only one side has such edges
  double ref_crossing_length = 0;  ///< length of the reference's crossing curves (CrossingCurves), in the frame
  /// The mesh's non-manifold edges whose midpoint lies farther than the mesh's median edge length from every
  /// non-manifold curve of the reference: branching the reference does not have.
  size_t spurious_nonmanifold_edges = 0;
  long long td = 0;      ///< |chi(mesh) - chi(ref)|
  ExactMetrics exact;
  FeatureMetrics features;
  bool has_floor = false;  ///< `floor` computed (EvaluateOptions::floor)
  FloorMetrics floor;
  MeshReport mesh, ref;
  Frame frame;
};

/// All metrics of `mesh` against `reference` (DESIGN.md "evaluate", docs/evaluate.md).
/// Throws InputError (exit 3) if `reference` cannot define the frame or has no area, or a face index is out
/// of range; NumericalError (exit 4) if `mesh` has no face of non-zero area (nothing to compare).
/// Deterministic: the same inputs and options give the same numbers whatever the thread count.
Metrics Evaluate(const TriangleMesh& mesh, const TriangleMesh& reference, const EvaluateOptions& options,
                 Monitor& monitor);

/// One flat JSON object on one line (keys in a fixed order, docs/evaluate.md), newline-terminated.
/// An infinite NM-CD is the string "inf" (float("inf") in Python). `seconds` < 0 leaves the timing out,
/// keeping the bytes reproducible.
std::string MetricsJson(const Metrics& metrics, const EvaluateOptions& options, const std::string& mesh_path,
                        const std::string& reference_path, double seconds);

}  // namespace voroudf

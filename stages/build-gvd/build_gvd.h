#pragma once
// Stage 3 (DESIGN.md; paper Sec. 3.3, "Mesh Reconstruction via the Dual of a Geodesic Voronoi Diagram"):
// dense samples on the zero set, a pruned kNN graph over them, a multi-source geodesic sweep from the seeds,
// and the dual triangles of the resulting (approximate) geodesic Voronoi diagram: the "thick" mesh that
// thin-mesh then thins.
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/monitor.h"
#include "common/projection.h"
#include "common/types.h"
#include "common/udf.h"
#include "formats/labels_io.h"
#include "formats/seeds_io.h"

namespace voroudf {

struct BuildGvdOptions {
  /// Dense samples drawn per sheet seed before projection (--samples-per-seed): space_fraction of them in the
  /// box, the rest in its ball; a curve or corner seed's ball gets curve_sample_weight times as many. Where
  /// the samples are too sparse for the regions, junctions go unseen (holes, boundary edges); the regions of
  /// curve seeds are the narrowest (docs/build-gvd.md, "Why these defaults").
  double samples_per_seed = 100.0;
  /// Ball samples of a seed of rank 2 or 3 in the seeds file, as a multiple of a sheet seed's with the same
  /// ball radius (--curve-sample-weight; 1: shares by the ball alone).
  double curve_sample_weight = 3.0;
  /// Fraction of the dense samples drawn uniformly in the domain box (--space-fraction); the rest are drawn
  /// in balls around the seeds. Box samples project preferentially onto sharp edges, corners and open
  /// boundaries (whole wedges of space project onto them), which is where the graph must connect sheets;
  /// ball samples follow the seed density.
  double space_fraction = 0.25;
  /// --curve-samples: "tangent", the ball samples of curve and corner seeds (rank 2, 3) are drawn again in
  /// the tangent plane where they landed, for an even density on each sheet up to where sheets cross;
  /// "ball", every ball sample as it lands.
  std::string curve_samples = "tangent";
  /// --ball-shares: how the ball samples are shared out among the seeds. "area": in proportion to the
  /// ball's radius², an even density on the surface wherever the seeds are; "seed": the same number per
  /// seed, a density that follows the seeds' (seeds packed round a thin part, sample-seeds --thin-boost,
  /// keep as many samples per Voronoi region as elsewhere).
  std::string ball_shares = "area";
  /// Radius of the ball around each seed, as a multiple of the distance to its 6th-nearest seed (about one
  /// seed spacing on a sheet) (--ball-scale).
  double ball_scale = 1.0;
  int knn = 20;  ///< neighbours per sample in the graph (--knn; paper: 20)
  /// An edge is pruned when the UDF at its midpoint exceeds the larger of its ends' by more than eps_udf_rel *
  /// domain diagonal (--eps-udf-rel).
  double eps_udf_rel = 2e-3;
  /// An edge is pruned when |cos(edge, gradient)| at either endpoint exceeds this (--eps-grad).
  double eps_grad = 0.97;
  /// An edge is also pruned when |cos(edge, gradient)| exceeds this at both endpoints (--eps-grad-both; 1: off):
  /// it crosses a wall thinner than the graph's reach, from one sheet to the parallel one behind it. One end
  /// on a crease or crossing carries the other face's normal, but the far end's normal is then across the
  /// edge, so creases and crossings keep their edges.
  double eps_grad_both = 0.8;
  /// An edge is also pruned when |cos(edge, gradient)| exceeds this at both endpoints and the two gradients are
  /// parallel within 30 degrees (--eps-grad-wall; 1: off): it joins two parallel sheets (the two faces of a
  /// wall, the lips of a slit) more than this x its length apart. A chord of one smooth sheet rises from its
  /// tangent plane by |cos| = length / (2 x radius) and its ends' normals turn by twice that angle, so the rule
  /// leaves a sheet's own edges alone wherever the samples are finer than its radius; at a crease or a crossing
  /// the normals are not parallel. Sheets closer than the projection's twin separation (a noisy field's error;
  /// 0 on an exact field) are one surface, not a wall: the test skips them.
  double eps_grad_wall = 0.4;
  /// --dual: "delaunay", the witnessed triples that are locally Delaunay (restricted_dual.h: one
  /// triangulation per junction); "paper", every witnessed triple (the paper's thick dual).
  std::string dual = "delaunay";
  /// --chart-angle: with --dual delaunay, the four seeds of a junction share a chart (their tangent plane
  /// decides which triangles it keeps) when their normals agree within this angle, degrees.
  double chart_angle_deg = 25.0;
  /// --region-flatness: with --dual delaunay, a seed's region is a sheet (its normal counts for charts) when
  /// its samples' least spread is at most this x their largest.
  double region_flatness = 0.15;
  /// --chain-links: with --dual delaunay, drop the triples that jump a seed of a feature chain or cut across
  /// it where sheets cross (restricted_dual.h, KeepChainLinks).
  bool chain_links = true;
  uint64_t seed = 0;           ///< RNG seed of the dense samples (--seed)
  double proj_tol_rel = 1e-5;  ///< samples converge once d < proj_tol_rel * diagonal (--proj-tol-rel)
  int proj_max_iters = 50;     ///< projection steps before a sample is dropped (--proj-max-iters)
  double proj_floor_rel = 1e-2;  ///< a kink's bottom with d below this x diagonal is on the zero set (--proj-floor-rel)
  /// zero sheets closer than this x the field's measured floor are one surface (common/projection.h) (--proj-twin-factor)
  double proj_twin_factor = kProjTwinFactor;

  /// Throws UsageError for values that cannot work.
  void Check() const;
};

/// What BuildGvd did, for logs and tests.
struct BuildGvdStats {
  size_t samples_drawn = 0;
  size_t samples_projected = 0;   ///< converged onto the zero set
  size_t samples_redrawn = 0;     ///< ball samples of curve seeds replaced by their tangent-plane redraw (step 1b)
  size_t samples_duplicate = 0;   ///< dropped because another node sits at (numerically) the same place
  size_t seeds_duplicate = 0;     ///< seeds in the same Morton cell as an earlier seed, left out (no faces)
  size_t nodes = 0;               ///< graph nodes: seeds + kept samples
  size_t edges_knn = 0;           ///< undirected kNN edges before pruning
  size_t edges_pruned_udf = 0;    ///< of those, pruned by the midpoint UDF test
  size_t midpoints_uncertain = 0; ///< edges whose ends' Lipschitz bound could not settle the midpoint test
  size_t midpoints_queried = 0;   ///< of those, the ones the node nearest the midpoint could not settle either
  size_t edges_pruned_grad = 0;   ///< pruned by the gradient test (and not by the UDF test)
  size_t unreached = 0;           ///< nodes no seed reaches (label -1)
  size_t triangles = 0;
};

struct GvdResult {
  TriangleMesh thick;      ///< vertices = the seeds, in file order; faces sorted, each vertex triple once
  LabeledSamples samples;  ///< every graph node (seeds included) in space-filling-curve order; edges if asked
  BuildGvdStats stats;
};

/// Builds the approximate geodesic Voronoi diagram of `seeds` on the zero set of `udf` and its dual
/// triangles (paper Sec. 3.3).
///
///  1. space_fraction * samples_per_seed * N points uniform in udf.Domain(), and (1 - space_fraction) *
///     samples_per_seed per sheet seed, curve_sample_weight times that per curve or corner seed, uniform in a
///     ball around each seed (radius: ball_scale x distance to its 6th-nearest seed; samples per ball in
///     proportion to radius^2 x that weight, so that the density on the surface is even but for the weight); each projected with x <- x - d n (common/projection.h); unconverged ones dropped.
///     Point i draws from the counter-based stream (seed, i), so the draw does not depend on the threads.
///     With curve_samples "tangent", the ball samples of rank-2 and rank-3 seeds are then drawn again in a
///     disc of the ball's radius in the tangent plane where they landed and projected again; a redraw that
///     lands on a sheet of another normal (or fails) keeps the first landing point.
///  2. The seeds join the samples as graph nodes (each labelled with its own index at distance 0: the seeds
///     are the sources of the sweep). Nodes are sorted along a Morton curve; a sample that shares a Morton
///     cell (2^-21 of the box) with an earlier node is dropped as a duplicate (whole wedges of space project
///     onto the same corner point); so is a seed on top of an earlier seed (it gets no faces).
///  3. kNN graph (FLANN, exact kd-tree, k = knn) made undirected; an edge is pruned when
///     d(midpoint) > eps_udf_rel * diagonal, |cos(edge, n)| > eps_grad at either endpoint or > eps_grad_both
///     at both, or > eps_grad_wall at both with parallel gradients (a wall).
///  4. Multi-source Dijkstra with Euclidean edge lengths labels every node with its geodesically nearest seed;
///     unreachable nodes get label -1 and are counted.
///  5. For every node labelled i and every two distinct labels j, k (both != i, both >= 0) among its graph
///     neighbours, the triangle (i, j, k), each vertex triple once.
///
/// \param udf    the field; its domain box sets every relative length
/// \param seeds  the sources (N >= 1), usually from optimize-seeds; positions and ranks are used
/// \param with_graph  also return the pruned edges in result.samples.edges (indices into result.samples)
/// \pre options.Check() passes. Throws InputError when `seeds` is empty, NumericalError when no triangle results.
/// Deterministic: the same inputs and options give the same result whatever the thread count.
GvdResult BuildGvd(const Udf& udf, const SeedCloud& seeds, const BuildGvdOptions& options, bool with_graph,
                   Monitor& monitor);

}  // namespace voroudf

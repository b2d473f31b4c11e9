#include "stages/build-gvd/build_gvd.h"

#include <omp.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <cmath>
#include <functional>
#include <iterator>
#include <unordered_map>
#include <numeric>
#include <utility>

#include "common/errors.h"
#include "common/knn.h"
#include "common/mesh_topology.h"
#include "common/morton.h"
#include "common/projection.h"
#include "common/rng.h"
#include "stages/build-gvd/geodesic_sweep.h"
#include "stages/build-gvd/restricted_dual.h"

namespace voroudf {
namespace {

constexpr size_t kSweepRangeNodes = 32768;

// The surface normal of every seed's Voronoi region, from the principal axes of its samples (the axis of
// least spread), and whether the region is a sheet: its least spread at most `flatness` x its largest.
// A region across a crease, around a corner or along a branching curve is no sheet and gets no normal.
// Geometric on purpose: a seed's own UDF gradient is undefined where it sits on the zero set, and on an
// open rim or a crease it is one side's (or in-plane, pointing away from the rim).
void RegionNormals(const std::vector<Vec3>& node, const std::vector<int>& label, size_t num_seeds, double flatness,
                   std::vector<Vec3>* normal, std::vector<uint8_t>* on_sheet) {
  std::vector<Vec3> sum(num_seeds, Vec3::Zero());
  std::vector<Eigen::Matrix3d> outer(num_seeds, Eigen::Matrix3d::Zero());
  std::vector<size_t> count(num_seeds, 0);
  for (size_t u = 0; u < node.size(); ++u) {
    if (label[u] < 0) continue;
    const size_t s = static_cast<size_t>(label[u]);
    sum[s] += node[u];
    outer[s] += node[u] * node[u].transpose();
    ++count[s];
  }
  normal->assign(num_seeds, Vec3::Zero());
  on_sheet->assign(num_seeds, 0);
  for (size_t s = 0; s < num_seeds; ++s) {
    if (count[s] < 4) continue;
    const double m = static_cast<double>(count[s]);
    const Vec3 mean = sum[s] / m;
    const Eigen::Matrix3d cov = outer[s] / m - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    (*normal)[s] = eig.eigenvectors().col(0);
    (*on_sheet)[s] = eig.eigenvalues()(0) <= flatness * flatness * eig.eigenvalues()(2);
  }
}

}  // namespace

void BuildGvdOptions::Check() const {
  if (!(samples_per_seed >= 1.0 && samples_per_seed <= 1e5)) throw UsageError("--samples-per-seed must be in [1, 1e5]");
  if (!(space_fraction >= 0.0 && space_fraction <= 1.0)) throw UsageError("--space-fraction must be in [0, 1]");
  if (!(ball_scale > 0.0 && ball_scale <= 100.0)) throw UsageError("--ball-scale must be in (0, 100]");
  if (knn < 3 || knn > 200) throw UsageError("--knn must be in [3, 200]");
  if (!(eps_udf_rel > 0.0 && eps_udf_rel < 1.0)) throw UsageError("--eps-udf-rel must be in (0, 1)");
  if (!(eps_grad > 0.0 && eps_grad <= 1.0)) throw UsageError("--eps-grad must be in (0, 1]");
  if (!(eps_grad_both > 0.0 && eps_grad_both <= 1.0)) throw UsageError("--eps-grad-both must be in (0, 1]");
  if (!(eps_grad_wall > 0.0 && eps_grad_wall <= 1.0)) throw UsageError("--eps-grad-wall must be in (0, 1]");
  if (curve_samples != "tangent" && curve_samples != "ball") throw UsageError("--curve-samples must be tangent or ball");
  if (ball_shares != "area" && ball_shares != "seed") throw UsageError("--ball-shares must be area or seed");
  if (!(curve_sample_weight > 0.0 && curve_sample_weight <= 100.0))
    throw UsageError("--curve-sample-weight must be in (0, 100]");
  CheckRelativeProjection(proj_tol_rel, proj_floor_rel, proj_max_iters, proj_twin_factor);
}

namespace {

// --eps-grad-wall: two normals within this angle are one plane's (optimize-seeds' --crease-angle-deg default:
// below it two planes are no crease).
constexpr double kWallParallelDeg = 30.0;
const double kWallParallelCos = std::cos(kWallParallelDeg * M_PI / 180.0);

// Step 1b redraws the ball samples of these: seeds on a crease, a branching curve or a corner.
bool IsCurveSeed(const SeedCloud& seeds, size_t s) { return seeds.rank[s] >= kRankEdge; }

// What step 1b needs of each ball sample (index i - in_space): its seed, and (with --curve-samples
// tangent, for a curve seed's sample) a point of the unit disc drawn from the sample's own stream, after
// its ball point; and each seed's ball radius.
struct TangentDraws {
  std::vector<int> owner;
  std::vector<std::array<double, 2>> disc;
  std::vector<double> radius;
};

// Step 1: the dense samples before projection, the first `*in_space` of them uniform in the box.
std::vector<Vec3> DrawSamples(const SeedCloud& seeds, const Box& box, const BuildGvdOptions& options, size_t* in_space_out,
                              TangentDraws* tangent_out) {
  const size_t num_seeds = seeds.size();
  const double diag = box.Diagonal();
  // Ball radius per seed: the distance to its 6th-nearest seed (one ring of neighbours
  // on a sheet), so the balls overlap and adapt to the local seed density; capped for isolated seeds.
  int k_seeds = 0;
  const std::vector<int> seed_nn = KNearestAmong(seeds.position, 6, &k_seeds, Monitor::Null(), "seed neighbours");
  std::vector<double> radius(num_seeds, 0.05 * diag);
  for (size_t i = 0; i < num_seeds && k_seeds > 0; ++i) {
    const int far = seed_nn[i * static_cast<size_t>(k_seeds) + static_cast<size_t>(k_seeds - 1)];
    radius[i] = std::min(0.1 * diag, options.ball_scale * (seeds.position[static_cast<size_t>(far)] - seeds.position[i]).norm());
    if (!(radius[i] > 0.0)) radius[i] = 1e-4 * diag;  // coincident seeds
  }
  // A curve or corner seed's ball gets curve_sample_weight times a sheet seed's samples: its region is
  // narrow (curve seeds are spaced along their curve, not by the sheet) and holds the Voronoi vertices where
  // sheets meet, which a sheet seed's share at the sheets' density leaves unseen (docs/build-gvd.md).
  const auto rank_weight = [&](size_t s) { return IsCurveSeed(seeds, s) ? options.curve_sample_weight : 1.0; };
  double ball_weight_sum = 0.0;
  for (size_t s = 0; s < num_seeds; ++s) ball_weight_sum += rank_weight(s);
  const size_t unweighted = static_cast<size_t>(std::llround(options.samples_per_seed * static_cast<double>(num_seeds)));
  const size_t in_space = static_cast<size_t>(std::llround(options.space_fraction * static_cast<double>(unweighted)));
  const size_t total = in_space + static_cast<size_t>(std::llround(static_cast<double>(unweighted - in_space) *
                                                                   ball_weight_sum / static_cast<double>(num_seeds)));
  // Each seed's ball gets samples in proportion to radius^2, the area its ball covers on a sheet, so the
  // sample density on the surface is even where the seeds are not (e.g. before optimisation, or on a torus'
  // saddle, where uniform draws are sparse); with --ball-shares seed, as many per seed, so that seeds packed
  // closer on purpose keep their regions' samples. ball_end[s] is one past seed s's last ball sample.
  std::vector<size_t> ball_end(num_seeds);
  {
    const bool by_seed = options.ball_shares == "seed";
    auto weight = [&](size_t s) { return (by_seed ? 1.0 : radius[s] * radius[s]) * rank_weight(s); };
    double weight_total = 0.0;
    for (size_t s = 0; s < num_seeds; ++s) weight_total += weight(s);
    double prefix = 0.0;
    for (size_t s = 0; s < num_seeds; ++s) {
      prefix += weight(s);
      ball_end[s] = static_cast<size_t>(std::llround(static_cast<double>(total - in_space) * prefix / weight_total));
    }
    ball_end[num_seeds - 1] = total - in_space;
  }
  const bool redraw = options.curve_samples == "tangent";
  TangentDraws tangent;
  tangent.owner.resize(total - in_space);
  if (redraw) tangent.disc.resize(total - in_space);
  std::vector<Vec3> samples(total);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(total); ++li) {
    const size_t i = static_cast<size_t>(li);
    Rng rng(options.seed, i);
    if (i < in_space) {
      for (int c = 0; c < 3; ++c) samples[i][c] = rng.Uniform(box.min[c], box.max[c]);
      continue;
    }
    const size_t s = static_cast<size_t>(std::upper_bound(ball_end.begin(), ball_end.end(), i - in_space) - ball_end.begin());
    Vec3 u;
    do {
      for (int c = 0; c < 3; ++c) u[c] = rng.Uniform(-1.0, 1.0);
    } while (u.squaredNorm() > 1.0);
    samples[i] = seeds.position[s] + radius[s] * u;
    tangent.owner[i - in_space] = static_cast<int>(s);
    if (!redraw || !IsCurveSeed(seeds, s)) continue;
    double a, b;
    do {
      a = rng.Uniform(-1.0, 1.0);
      b = rng.Uniform(-1.0, 1.0);
    } while (a * a + b * b > 1.0);
    tangent.disc[i - in_space] = {a, b};
  }
  tangent.radius = std::move(radius);
  *in_space_out = in_space;
  *tangent_out = std::move(tangent);
  return samples;
}

// Step 1b (--curve-samples tangent): the ball samples of the seeds on curves and corners (rank 2 and 3 in
// the seeds file) are drawn again, each in the disc of its ball's radius in the tangent plane where it
// landed, around its seed's foot on that plane, and projected again. A ball's points project onto the
// nearest sheet, so where sheets cross or meet at a concave crease each gets a wedge's points only and the
// density on it falls to zero at the curve (three-discs, 5k seeds: 17 % of the mean within 0.2 spacings of
// an axis), right where the curve's Voronoi vertices lie. Redrawn, each sheet keeps its share of the ball's
// samples and gets them evenly up to the curve. A redrawn point whose projection fails, or that lands where
// the normal is not the first landing point's (another sheet, a crease or a rim: a wedge point's gradient
// is not a sheet normal), is not used: the first landing point stays, so creases and rims keep the ball's
// wedge samples. Returns how many were replaced.
size_t RedrawInTangentDiscs(const Udf& udf, const SeedCloud& seeds, const TangentDraws& tangent, size_t in_space,
                            const ProjectionOptions& proj, std::vector<Vec3>& samples, ProjectionResult& projected,
                            Monitor& monitor) {
  const size_t count = tangent.owner.size();
  std::vector<size_t> which;
  which.reserve(count);
  for (size_t k = 0; k < count; ++k)
    if (projected.converged[in_space + k] && projected.gradient[in_space + k].norm() > 0.5 &&
        IsCurveSeed(seeds, static_cast<size_t>(tangent.owner[k])))
      which.push_back(k);
  std::vector<Vec3> redrawn(which.size());
#pragma omp parallel for schedule(static)
  for (long lj = 0; lj < static_cast<long>(which.size()); ++lj) {
    const size_t k = which[static_cast<size_t>(lj)], i = in_space + k;
    const Vec3 n = projected.gradient[i].normalized();
    const Vec3& seed = seeds.position[static_cast<size_t>(tangent.owner[k])];
    const Vec3 centre = seed - (seed - samples[i]).dot(n) * n;
    const Vec3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    const double r = tangent.radius[static_cast<size_t>(tangent.owner[k])];
    redrawn[static_cast<size_t>(lj)] = centre + r * (tangent.disc[k][0] * t1 + tangent.disc[k][1] * t2);
  }
  const ProjectionResult again = ProjectToZeroSet(udf, redrawn, proj, monitor);
  const double same_sheet = std::cos(25.0 * M_PI / 180.0);
  size_t replaced = 0;
  for (size_t j = 0; j < which.size(); ++j) {
    if (!again.converged[j]) continue;
    const size_t i = in_space + which[j];
    if (std::abs(again.gradient[j].dot(projected.gradient[i])) <
        same_sheet * again.gradient[j].norm() * projected.gradient[i].norm())
      continue;
    samples[i] = redrawn[j];
    projected.distance[i] = again.distance[j];
    projected.gradient[i] = again.gradient[j];
    ++replaced;
  }
  monitor.Info(Format("%zu samples around curve and corner seeds drawn again in their tangent planes, %zu of them kept",
                      which.size(), replaced));
  return replaced;
}

// Step 2: the graph nodes, seeds first (so that they win Morton-cell ties), then converged samples, sorted
// along a Morton curve; a node in the Morton cell of an earlier one is dropped. node_seed: the seed index of
// a seed node, -1 for a sample. node_d, node_n: a sample node's UDF value and gradient from the projection
// (its last evaluation, at that point); 0 and zero for a seed node, which the caller asks the UDF for.
void MakeNodes(const SeedCloud& seeds, const std::vector<Vec3>& samples, const ProjectionResult& projected,
               const Box& box, BuildGvdStats& stats, std::vector<Vec3>* node_out, std::vector<int>* node_seed_out,
               std::vector<double>* node_d_out, std::vector<Vec3>* node_n_out) {
  const size_t num_seeds = seeds.size(), total = samples.size();
  std::vector<Vec3> raw;
  raw.reserve(num_seeds + projected.num_converged);
  raw.insert(raw.end(), seeds.position.begin(), seeds.position.end());
  for (size_t i = 0; i < total; ++i)
    if (projected.converged[i]) raw.push_back(samples[i]);
  std::vector<uint64_t> code(raw.size());
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(raw.size()); ++i) code[static_cast<size_t>(i)] = MortonCode(raw[static_cast<size_t>(i)], box);
  const std::vector<size_t> order = MortonOrder(raw, box);  // by (code, index), sorted on every thread
  // Which projected sample each node is (its index in `samples`), for the UDF values the projection left.
  std::vector<size_t> sample_of(raw.size(), 0);
  for (size_t i = 0, r = num_seeds; i < total; ++i)
    if (projected.converged[i]) sample_of[r++] = i;
  // A node in the Morton cell of the one before it goes: a seed on top of an earlier seed would only add
  // zero-area triangles and a second layer of faces. Then the kept ones' places, and their copies in parallel.
  std::vector<size_t> place(order.size() + 1, 0);
  for (size_t k = 0; k < order.size(); ++k) {
    const bool duplicate = k > 0 && code[order[k - 1]] == code[order[k]];
    if (duplicate) ++(order[k] < num_seeds ? stats.seeds_duplicate : stats.samples_duplicate);
    place[k + 1] = place[k] + (duplicate ? 0 : 1);
  }
  const size_t kept = place.back();
  std::vector<Vec3> node(kept), node_n(kept);
  std::vector<int> node_seed(kept);  // seed index of a seed node, -1 for a sample
  std::vector<double> node_d(kept);
#pragma omp parallel for schedule(static)
  for (long lk = 0; lk < static_cast<long>(order.size()); ++lk) {
    const size_t k = static_cast<size_t>(lk), r = order[k], at = place[k];
    if (place[k + 1] == at) continue;
    const bool is_seed = r < num_seeds;
    node[at] = raw[r];
    node_seed[at] = is_seed ? static_cast<int>(r) : -1;
    node_d[at] = is_seed ? 0.0 : projected.distance[sample_of[r]];
    node_n[at] = is_seed ? Vec3::Zero() : projected.gradient[sample_of[r]];
  }
  *node_out = std::move(node);
  *node_seed_out = std::move(node_seed);
  *node_d_out = std::move(node_d);
  *node_n_out = std::move(node_n);
}

// Step 3: the kNN graph (k = options.knn), undirected, with the edges that leave the surface or jump
// between sheets pruned; the kept edges as sorted adjacency lists (CSR).
struct Graph {
  std::vector<std::pair<int, int>> edges;  // every undirected kNN edge once (empty unless asked for the --graph output)
  std::vector<char> keep;                  // per edge: survived the pruning
  std::vector<size_t> offset;              // CSR: node i's neighbours are adj[offset[i] .. offset[i + 1])
  std::vector<int> adj;
};

// Step 3a: every undirected edge of the kNN graph (k = knn_wanted, `kk` the k found), each once.
std::vector<std::pair<int, int>> UndirectedKnnEdges(const std::vector<Vec3>& node, int knn_wanted, int* kk,
                                                     Monitor& monitor) {
  const size_t n = node.size();
  std::vector<int> knn = KNearestAmong(node, knn_wanted, kk, monitor, "kNN graph");
  const int k_found = *kk;
  monitor.Debug("kNN queries done");
  // Undirected edges, each once: (i, j) from i's list when j > i, or when i is not in j's list. No global
  // sort (it took longer than the queries); the order is by i, then by distance, whatever the threads.
  auto in_list = [&](size_t owner, int x) {
    const int* row = knn.data() + owner * static_cast<size_t>(k_found);
    return std::find(row, row + k_found, x) != row + k_found;
  };
  // Which of i's list entries give i an edge, as bits, found once: the list search is most of the listing's
  // time.
  const size_t words = (static_cast<size_t>(k_found) + 63) / 64;
  std::vector<uint64_t> owns(n * words, 0);
  std::vector<size_t> edge_begin(n + 1, 0);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(n); ++li) {
    const size_t i = static_cast<size_t>(li);
    uint64_t* bits = owns.data() + i * words;
    size_t count = 0;
    for (int j = 0; j < k_found; ++j) {
      const int o = knn[i * static_cast<size_t>(k_found) + static_cast<size_t>(j)];
      if (o >= 0 && (o > static_cast<int>(i) || !in_list(static_cast<size_t>(o), static_cast<int>(i)))) {
        bits[j / 64] |= uint64_t{1} << (j % 64);
        ++count;
      }
    }
    edge_begin[i + 1] = count;
  }
  for (size_t i = 0; i < n; ++i) edge_begin[i + 1] += edge_begin[i];
  std::vector<std::pair<int, int>> edges(edge_begin[n]);
#pragma omp parallel for schedule(static)
  for (long li = 0; li < static_cast<long>(n); ++li) {
    const size_t i = static_cast<size_t>(li);
    size_t at = edge_begin[i];
    for (int j = 0; j < k_found; ++j) {
      if (!(owns[i * words + static_cast<size_t>(j) / 64] >> (j % 64) & 1)) continue;
      const int o = knn[i * static_cast<size_t>(k_found) + static_cast<size_t>(j)];
      edges[at++] = {std::min(static_cast<int>(i), o), std::max(static_cast<int>(i), o)};
    }
  }
  std::vector<uint64_t>().swap(owns);
  monitor.Debug("undirected edges listed");
  return edges;  // the lists go here: with the edges they are the memory peak (0.8 GB each at 50k seeds)
}

// Step 3b: which edges stay: those that leave the surface (midpoint test) or jump between sheets
// (gradient tests) are pruned; the counts go to stats.
std::vector<char> KeptEdges(const Udf& udf, const std::vector<Vec3>& node, const std::vector<double>& node_d,
                            const std::vector<Vec3>& node_n, const std::vector<std::pair<int, int>>& edges,
                            const BuildGvdOptions& options, double diag, double twin_within, BuildGvdStats& stats,
                            Monitor& monitor) {
  // The midpoint test measures the rise of d above the edge's ends, d(mid) - max(d(a), d(b)), so that a field
  // with a floor (nodes at a kink's bottom with d = e > 0, common/projection.h) is judged like an exact one
  // (nodes at d ~ 0). It needs a query only where it can fail: a UDF is 1-Lipschitz, so d(mid) ≤ min(d(a),
  // d(b)) + |ab|/2 and the rise is at most |ab|/2 - |d(a) - d(b)|; most graph edges are shorter than 2 eps_udf
  // (k = 20 neighbours among 200 samples per seed reach about 0.17 seed spacings). On fandisk with 3k seeds
  // 7.4 k of 6.5 M edges are queried and build-gvd takes 2.8 s instead of 4.1 s, with the same output bytes.
  const double eps_udf = options.eps_udf_rel * diag;
  std::vector<char> may_fail(edges.size(), 0);
#pragma omp parallel for schedule(static)
  for (long le = 0; le < static_cast<long>(edges.size()); ++le) {
    const size_t a = static_cast<size_t>(edges[static_cast<size_t>(le)].first);
    const size_t b = static_cast<size_t>(edges[static_cast<size_t>(le)].second);
    may_fail[static_cast<size_t>(le)] = 0.5 * (node[b] - node[a]).norm() - std::abs(node_d[a] - node_d[b]) > eps_udf;
  }
  std::vector<size_t> queried;
  for (size_t e = 0; e < edges.size(); ++e)
    if (may_fail[e]) queried.push_back(e);
  std::vector<char>().swap(may_fail);
  auto rise_bound_ok = [&](size_t e, double d_mid_bound) {
    const double ends = std::max(node_d[static_cast<size_t>(edges[e].first)], node_d[static_cast<size_t>(edges[e].second)]);
    return d_mid_bound - ends <= eps_udf;
  };
  std::vector<Vec3> mid(queried.size());
#pragma omp parallel for schedule(static)
  for (long q = 0; q < static_cast<long>(queried.size()); ++q) {
    const auto& ed = edges[queried[static_cast<size_t>(q)]];
    mid[static_cast<size_t>(q)] = 0.5 * (node[static_cast<size_t>(ed.first)] + node[static_cast<size_t>(ed.second)]);
  }
  // Any node c bounds d(mid) ≤ d(c) + |mid - c| by the same Lipschitz argument; the node nearest the midpoint
  // usually lies within a sample spacing of it and settles the test without a query (a kd-tree search is far
  // cheaper than a learned UDF's evaluation).
  const size_t could_fail = queried.size();
  if (!queried.empty()) {
    const std::vector<int> nearest = NearestIndices(node, mid, Monitor::Null());
    size_t out = 0;
    for (size_t q = 0; q < queried.size(); ++q) {
      const size_t c = static_cast<size_t>(nearest[q]);
      if (rise_bound_ok(queried[q], node_d[c] + (mid[q] - node[c]).norm())) continue;
      queried[out] = queried[q];
      mid[out++] = mid[q];
    }
    queried.resize(out);
    mid.resize(out);
  }
  std::vector<double> mid_d;
  {
    std::vector<Vec3> mid_n;
    udf.Evaluate(mid, mid_d, mid_n);
  }
  std::vector<Vec3>().swap(mid);
  std::vector<char> too_far(edges.size(), 0);
  for (size_t q = 0; q < queried.size(); ++q) too_far[queried[q]] = !rise_bound_ok(queried[q], mid_d[q]);
  stats.midpoints_uncertain = could_fail;
  stats.midpoints_queried = queried.size();
  monitor.Debug(Format("midpoints: %zu of %zu edges could fail the test by their ends, %zu by the nearest node; those "
                       "evaluated", could_fail, edges.size(), queried.size()));
  std::vector<char> keep(edges.size(), 0);
  size_t pruned_udf = 0, pruned_grad = 0;
#pragma omp parallel for schedule(static) reduction(+ : pruned_udf, pruned_grad)
  for (long le = 0; le < static_cast<long>(edges.size()); ++le) {
    const size_t e = static_cast<size_t>(le);
    const size_t a = static_cast<size_t>(edges[e].first), b = static_cast<size_t>(edges[e].second);
    if (too_far[e]) {
      ++pruned_udf;
      continue;
    }
    const Vec3 dir = node[b] - node[a];
    const double len = dir.norm();
    if (len > 0.0) {
      const double ca = std::abs(node_n[a].dot(dir)) / len, cb = std::abs(node_n[b].dot(dir)) / len;
      // Two sheets closer than the field's twin separation are one surface seen through its error (the
      // zero sheets of |d + e| either side of it): no wall between them.
      const bool wall = ca > options.eps_grad_wall && cb > options.eps_grad_wall &&
                        std::abs(node_n[a].dot(node_n[b])) > kWallParallelCos && ca * len > twin_within;
      if (ca > options.eps_grad || cb > options.eps_grad || (ca > options.eps_grad_both && cb > options.eps_grad_both) ||
          wall) {
        ++pruned_grad;
        continue;
      }
    }
    keep[e] = 1;
  }
  std::vector<char>().swap(too_far);
  stats.edges_pruned_udf = pruned_udf;
  stats.edges_pruned_grad = pruned_grad;
  return keep;
}

// Step 3c: the kept edges as adjacency lists in CSR form, each neighbour list sorted.
void Adjacency(size_t n, const std::vector<std::pair<int, int>>& edges, const std::vector<char>& keep,
               std::vector<size_t>* offset_out, std::vector<int>* adj_out) {
  // Each thread reads every edge but writes only the ends in its own range of nodes: the scattered writes,
  // most of the time, are shared out, and the result is the one-thread result whatever the threads.
  const auto for_each_end = [&](auto&& visit) {
#pragma omp parallel
    {
      const size_t parts = static_cast<size_t>(omp_get_num_threads()), part = static_cast<size_t>(omp_get_thread_num());
      const size_t lo = n * part / parts, hi = n * (part + 1) / parts;
      for (size_t e = 0; e < edges.size(); ++e) {
        if (!keep[e]) continue;
        const size_t a = static_cast<size_t>(edges[e].first), b = static_cast<size_t>(edges[e].second);
        if (a >= lo && a < hi) visit(a, edges[e].second);
        if (b >= lo && b < hi) visit(b, edges[e].first);
      }
    }
  };
  std::vector<size_t> offset(n + 1, 0);
  for_each_end([&](size_t at, int) { ++offset[at + 1]; });
  for (size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
  std::vector<int> adj(offset[n]);
  {
    std::vector<size_t> fill(offset.begin(), offset.end() - 1);
    for_each_end([&](size_t at, int other) { adj[fill[at]++] = other; });
#pragma omp parallel for schedule(static)
    for (long li = 0; li < static_cast<long>(n); ++li)
      std::sort(adj.begin() + static_cast<long>(offset[static_cast<size_t>(li)]),
                adj.begin() + static_cast<long>(offset[static_cast<size_t>(li) + 1]));
  }
  *offset_out = std::move(offset);
  *adj_out = std::move(adj);
}

Graph PrunedGraph(const Udf& udf, const std::vector<Vec3>& node, const std::vector<double>& node_d,
                  const std::vector<Vec3>& node_n, const BuildGvdOptions& options, double diag, double twin_within,
                  bool with_edge_list, BuildGvdStats& stats, Monitor& monitor) {
  const size_t n = node.size();
  int kk = 0;
  std::vector<std::pair<int, int>> edges = UndirectedKnnEdges(node, options.knn, &kk, monitor);
  stats.edges_knn = edges.size();
  std::vector<char> keep = KeptEdges(udf, node, node_d, node_n, edges, options, diag, twin_within, stats, monitor);
  std::vector<size_t> offset;
  std::vector<int> adj;
  Adjacency(n, edges, keep, &offset, &adj);
  const double eps_udf = options.eps_udf_rel * diag;
  const size_t pruned_udf = stats.edges_pruned_udf, pruned_grad = stats.edges_pruned_grad;
  monitor.Info(Format("kNN graph (k=%d): %zu edges; pruned %zu with midpoint UDF > %.3g, %zu with |cos(edge, "
                      "gradient)| > %.3g at an end, > %.3g at both or > %.3g at both with parallel gradients; %zu left",
                      kk, stats.edges_knn, pruned_udf, eps_udf, pruned_grad, options.eps_grad, options.eps_grad_both,
                      options.eps_grad_wall, offset[n] / 2));
  if (!with_edge_list) {  // only --graph writes them
    std::vector<std::pair<int, int>>().swap(edges);
    std::vector<char>().swap(keep);
  }
  return Graph{std::move(edges), std::move(keep), std::move(offset), std::move(adj)};
}

// Step 5: the witnessed triples, every (i, j, k) with a node of label i and graph neighbours of labels j
// and k (all distinct, all >= 0), sorted, each once.
std::vector<Tri> WitnessedTriples(const Graph& g, const std::vector<int>& label) {
  const size_t n = label.size();
  // Per thread lists, then one sort: the result does not depend on the scheduling.
  std::vector<std::vector<Tri>> per_thread(static_cast<size_t>(omp_get_max_threads()));
#pragma omp parallel
  {
    std::vector<Tri>& out = per_thread[static_cast<size_t>(omp_get_thread_num())];
    std::vector<int> others;
#pragma omp for schedule(dynamic, 1024)
    for (long li = 0; li < static_cast<long>(n); ++li) {
      const size_t u = static_cast<size_t>(li);
      const int i = label[u];
      if (i < 0) continue;
      others.clear();
      for (size_t a = g.offset[u]; a < g.offset[u + 1]; ++a) {
        const int l = label[static_cast<size_t>(g.adj[a])];
        if (l >= 0 && l != i) others.push_back(l);
      }
      std::sort(others.begin(), others.end());
      others.erase(std::unique(others.begin(), others.end()), others.end());
      for (size_t p = 0; p < others.size(); ++p)
        for (size_t q = p + 1; q < others.size(); ++q) {
          Tri t{i, others[p], others[q]};
          std::sort(t.begin(), t.end());
          out.push_back(t);
        }
    }
    // Each thread's list sorted and made unique on its thread, then the lists merged: one sort of them all
    // was a tenth of build-gvd's serial time.
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  std::vector<Tri> faces, merged;
  for (auto& v : per_thread) {
    merged.clear();
    std::merge(faces.begin(), faces.end(), v.begin(), v.end(), std::back_inserter(merged));
    merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
    faces.swap(merged);
  }
  return faces;
}

// Steps 1-2: the dense samples projected onto the zero set and the seeds, as graph nodes with their UDF
// values and gradients (MakeNodes' order); the counts go to stats.
struct Nodes {
  std::vector<Vec3> position;
  std::vector<int> seed;  // the seed a node is, or -1 for a sample
  std::vector<double> d;
  std::vector<Vec3> n;
  double twin_within = 0.0;  // the projection's twin separation: sheets closer are one surface (0: exact field)
};

Nodes DenseNodes(const Udf& udf, const SeedCloud& seeds, const BuildGvdOptions& options, BuildGvdStats& stats,
                 Monitor& monitor) {
  const Box box = udf.Domain();
  const double diag = box.Diagonal();
  const size_t num_seeds = seeds.size();
  size_t in_space = 0;
  TangentDraws tangent;
  std::vector<Vec3> samples = DrawSamples(seeds, box, options, &in_space, &tangent);
  const size_t total = samples.size();
  stats.samples_drawn = total;
  ProjectionOptions proj = RelativeProjection(diag, options.proj_tol_rel, options.proj_floor_rel, options.proj_max_iters);
  proj.twin_factor = options.proj_twin_factor;
  ProjectionResult projected = ProjectToZeroSet(udf, samples, proj, monitor);
  proj.twin_within = projected.twin_within;  // the redrawn samples see the same field
  if (projected.twin_within > 0.0)
    monitor.Info(TwinSheetsSummary(projected, diag, "samples"));
  stats.samples_projected = projected.num_converged;
  if (options.curve_samples == "tangent")
    stats.samples_redrawn = RedrawInTangentDiscs(udf, seeds, tangent, in_space, proj, samples, projected, monitor);

  // 2. Nodes.
  Nodes nodes;
  std::vector<Vec3>& node = nodes.position;
  std::vector<int>& node_seed = nodes.seed;
  std::vector<double>& node_d = nodes.d;
  std::vector<Vec3>& node_n = nodes.n;
  MakeNodes(seeds, samples, projected, box, stats, &node, &node_seed, &node_d, &node_n);
  nodes.twin_within = proj.twin_within;
  const size_t n = node.size();
  stats.nodes = n;
  if (stats.seeds_duplicate > 0)
    monitor.Warn(Format("%zu seeds coincide with an earlier seed (same 2^-21 Morton cell) and are left out",
                        stats.seeds_duplicate));
  monitor.Info(Format("%zu dense samples drawn (%zu in the box, %zu around seeds), %zu on the zero set, "
                      "%zu duplicates dropped; graph of %zu nodes (%zu seeds)",
                      total, in_space, total - in_space, stats.samples_projected, stats.samples_duplicate, n,
                      num_seeds - stats.seeds_duplicate));
  // UDF values and gradients at the nodes (on the zero set a surface normal of either orientation): a
  // sample's are the projection's last evaluation, at that very point (MakeNodes); only the seeds are asked
  // (a third of the stage's queries were the samples' again).
  {
    std::vector<Vec3> at_seeds;
    for (size_t i = 0; i < n; ++i)
      if (node_seed[i] >= 0) at_seeds.push_back(node[i]);
    std::vector<double> seed_d;
    std::vector<Vec3> seed_n;
    udf.Evaluate(at_seeds, seed_d, seed_n);
    for (size_t i = 0, k = 0; i < n; ++i)
      if (node_seed[i] >= 0) {
        node_d[i] = seed_d[k];
        node_n[i] = seed_n[k++];
      }
  }
  monitor.Debug("node gradients evaluated");
  return nodes;
}

// Steps 5-6: the witnessed triples; with --dual delaunay the locally Delaunay ones, with --chain-links
// less those that jump a feature chain.
std::vector<Tri> DualTriangles(const Graph& graph, const std::vector<int>& label, const std::vector<Vec3>& node,
                               const SeedCloud& seeds, const BuildGvdOptions& options, Monitor& monitor) {
  const size_t num_seeds = seeds.size();
  std::vector<Tri> faces = WitnessedTriples(graph, label);
  monitor.Debug("witnessed triples listed");
  if (options.dual == "delaunay") {
    RestrictedDualStats rd;
    std::vector<Vec3> seed_normal;
    std::vector<uint8_t> on_sheet;
    RegionNormals(node, label, num_seeds, options.region_flatness, &seed_normal, &on_sheet);
    // A seed optimize-seeds put on a feature (rank 2 or 3) has no say either, even with a flat region.
    for (size_t i = 0; i < num_seeds; ++i) on_sheet[i] = on_sheet[i] && seeds.rank[i] <= kRankSheet;
    faces = LocallyDelaunayTriples(seeds.position, seed_normal, on_sheet, faces, options.chart_angle_deg, &rd);
    monitor.Info(Format("locally Delaunay: %zu triples of %zu witnessed (%zu collinear; of those whose removal would open "
                        "a hole, %zu kept and %zu jumping a feature seed flipped; %zu holes at a junction filled; %zu triangles new)",
                        rd.kept, rd.witnessed, rd.degenerate, rd.kept_against_holes, rd.replaced, rd.gaps_closed, rd.added));
    if (options.chain_links) {
      std::vector<uint8_t> is_curve(num_seeds);
      for (size_t i = 0; i < num_seeds; ++i) is_curve[i] = IsCurveSeed(seeds, i);
      ChainLinkStats cl;
      faces = KeepChainLinks(seeds.position, is_curve, faces, &cl);
      monitor.Info(Format("chain links: %zu between curve seeds; %zu triples dropped (%zu jumps over a curve seed, "
                          "split at it, and %zu junctions spanned by their link, with %zu triples the samples "
                          "did not see; the rest across crossings)",
                          cl.links, cl.dropped, cl.jumps, cl.junctions, cl.added));
    }
  }
  return faces;
}

}  // namespace

GvdResult BuildGvd(const Udf& udf, const SeedCloud& seeds, const BuildGvdOptions& options, bool with_graph,
                   Monitor& monitor) {
  options.Check();
  const size_t num_seeds = seeds.size();
  if (num_seeds == 0) throw InputError("the seeds file has no seeds");
  if (num_seeds > static_cast<size_t>(std::numeric_limits<int>::max() / 4))
    throw InputError("too many seeds for 32-bit mesh indices");
  const double diag = udf.Domain().Diagonal();
  GvdResult result;
  BuildGvdStats& stats = result.stats;

  // 1-2. Dense samples projected onto the zero set, and the seeds: the graph's nodes.
  Nodes nodes = DenseNodes(udf, seeds, options, stats, monitor);
  std::vector<Vec3>& node = nodes.position;
  const size_t n = node.size();

  // 3-4. Graph and sweep.
  const Graph graph =
      PrunedGraph(udf, node, nodes.d, nodes.n, options, diag, nodes.twin_within, with_graph, stats, monitor);
  std::vector<double> dist;
  std::vector<int> label;
  // Ranges of about 32 k nodes: each range's values (1.2 MB) stay in a core's cache while it is swept, and
  // the ranges run in parallel; fandisk's sweep went from 0.5 s to 0.14 s on two threads (0.22 s on one).
  // A function of the graph alone, so the result does not depend on the thread count.
  const size_t parts = std::max<size_t>(1, n / kSweepRangeNodes);
  GeodesicSweep(graph.offset, graph.adj, node, nodes.seed, parts, &dist, &label, monitor);
  monitor.Debug("geodesic sweep done");
  for (size_t i = 0; i < n; ++i) stats.unreached += label[i] < 0 ? 1 : 0;
  if (stats.unreached > 0)
    monitor.Warn(Format("%zu of %zu samples are not reached from any seed (label -1)", stats.unreached, n));

  // 5-6. The dual's triangles.
  std::vector<Tri>& faces = result.thick.faces;
  faces = DualTriangles(graph, label, node, seeds, options, monitor);
  stats.triangles = faces.size();
  result.thick.vertices = seeds.position;
  monitor.Info(Format("%zu dual triangles over %zu seeds", faces.size(), num_seeds));
  if (faces.empty())
    throw NumericalError("no dual triangle: the Voronoi regions of the seeds never meet three at a time (too few "
                         "seeds, or the graph is pruned apart: check --eps-udf-rel and --eps-grad)");

  LabeledSamples& ls = result.samples;
  ls.position = std::move(node);
  ls.label = std::move(label);
  // Unreached nodes get -1: readers refuse non-finite values.
  for (double& d : dist)
    if (!std::isfinite(d)) d = -1.0;
  ls.dist = std::move(dist);
  if (with_graph) {
    ls.edges.reserve(graph.offset[n] / 2);
    for (size_t e = 0; e < graph.edges.size(); ++e)
      if (graph.keep[e]) ls.edges.push_back({graph.edges[e].first, graph.edges[e].second});
  }
  return result;
}

}  // namespace voroudf

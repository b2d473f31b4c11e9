#pragma once
// Exact nearest neighbours among 3-D points: the one kNN wrapper (FLANN's single kd-tree, DESIGN.md), for
// build-gvd's graph and evaluate's sample distances. Exact search, so answers do not depend on the threads;
// queries go in blocks so that progress can be reported and memory stays bounded.
#include <string>
#include <vector>

#include "common/monitor.h"
#include "common/types.h"

namespace voroudf {

/// The k nearest other points of every point (itself excluded), k' = min(k, n - 1) each, in increasing
/// distance: a row-major n x k' table of indices (-1 where fewer were found). `*k_out` receives k'.
/// Sorting the points along a space-filling curve first makes the queries about twice as fast (DESIGN.md).
std::vector<int> KNearestAmong(const std::vector<Vec3>& points, int k, int* k_out, Monitor& monitor,
                               const std::string& task_name);

/// For each query, the index of its nearest point of `data` (exact; ties to the one FLANN meets first,
/// which is fixed for fixed inputs). Queries run in Morton order for cache locality, which changes no
/// result. \pre `data` is not empty
std::vector<int> NearestIndices(const std::vector<Vec3>& data, const std::vector<Vec3>& queries, Monitor& monitor);

/// Farthest-point sampling (Eldar, Lindenbaum, Porat & Zeevi 1997, "The farthest point strategy for
/// progressive image sampling"): starting from points[0], repeatedly takes the point farthest from all taken
/// so far (ties: the lower index), until `count` are taken. Returns their indices in increasing order and, in
/// `*covering_radius` if given, the distance at which the last one was taken: every point lies within it of a
/// taken one, and no two taken points are closer (so the subset is at most twice as sparse as the best
/// covering of that size, Gonzalez 1985). Exact (a kd-tree bounds each update to the current radius); depends
/// only on the points. All indices if count >= points.size().
/// With `spacing` (one value in (0, 1] per point), distances from point i are divided by spacing[i]: the
/// subset is even in that sizing metric, about 1/spacing² times denser where spacing < 1, and the covering
/// radius is in it too.
std::vector<size_t> FarthestPointSubset(const std::vector<Vec3>& points, size_t count, double* covering_radius = nullptr,
                                        const std::vector<double>* spacing = nullptr);

}  // namespace voroudf

#pragma once
// Step 4 of build-gvd (docs/build-gvd.md, "Sweep"): every graph node's geodesically nearest seed.
#include <cstddef>
#include <vector>

#include "common/monitor.h"
#include "common/types.h"

namespace voroudf {

/// Multi-source shortest paths (Dijkstra 1959) over an undirected graph with Euclidean edge lengths, from
/// the nodes with node_seed[i] >= 0 (at distance 0, labelled node_seed[i]).
///
/// Result: for every node, the least (distance, label) pair over all paths from a source, compared
/// distance first, then label (so a tie between two seeds goes to the lower index), where a path's distance
/// is the floating-point sum of its edge lengths in path order; unreached nodes get INFINITY and -1.
///
/// The nodes are split into `parts` ranges of consecutive indices (build-gvd's nodes are in Morton order,
/// so a range is a compact piece of space). Each range is swept alone, in parallel, over its own edges;
/// then one sequential sweep from the nodes that an edge between two ranges improves finishes the job.
/// Every value held is the length of a real path, and the end state has no edge that would improve its
/// far end: that is the least pair over all paths, whatever `parts` is. (Floating-point addition is
/// monotone, so the distances are unique; a label could differ only where two paths of different seeds
/// round to the same distance after different prefixes.) The answer depends on the graph alone, never on
/// the thread count; `parts` is chosen by the caller from the graph's size.
///
/// \param offset, adj  CSR adjacency: node i's neighbours are adj[offset[i] .. offset[i+1]), both directions
///                     of every edge present
/// \param node         positions (edge length: Euclidean distance)
/// \param node_seed    seed index of a source node, -1 for the others
/// \param parts        ranges swept in parallel, >= 1
/// \pre offset.size() == node.size() + 1 == node_seed.size() + 1
void GeodesicSweep(const std::vector<size_t>& offset, const std::vector<int>& adj, const std::vector<Vec3>& node,
                   const std::vector<int>& node_seed, size_t parts, std::vector<double>* dist,
                   std::vector<int>* label, Monitor& monitor);

}  // namespace voroudf

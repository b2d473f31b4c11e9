#pragma once
// Morton (Z-order) codes: sorting points along this space-filling curve makes consecutive spatial queries
// touch the same tree nodes and cache lines (DESIGN.md measures ~2.5x for kNN). Used by the mesh UDF's
// batches, build-gvd's graph and evaluate's nearest-neighbour queries.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// 63-bit Morton code of `p`: each axis of `box` quantised to 21 bits (points outside are clamped to it;
/// a non-finite point gets code 0). Axis x takes the lowest bit of each triple.
uint64_t MortonCode(const Vec3& p, const Box& box);

/// Indices of `points` sorted by (MortonCode in `box`, index): a deterministic order.
std::vector<size_t> MortonOrder(const Vec3* points, size_t count, const Box& box);
inline std::vector<size_t> MortonOrder(const std::vector<Vec3>& points, const Box& box) {
  return MortonOrder(points.data(), points.size(), box);
}

/// The bounding box of `points` (empty input: a zero box at the origin).
Box BoundingBox(const std::vector<Vec3>& points);

}  // namespace voroudf

#pragma once
// The one test thin-mesh uses to tell a face that spans between sheets, or across a bubble, from a face of
// the surface: its centroid's UDF against its size. Shared by step 3b (thin_mesh.cpp, OpenLocalShells) and
// step 6 (rim_flaps).
#include <algorithm>

#include "common/types.h"

namespace voroudf {

/// A face is off the surface when its centroid's UDF is above this x its longest edge: a face of a sheet,
/// even a curved one at the seed spacing, has a few hundredths at most; a face across a branching line, from
/// one sheet to another, about a third.
constexpr double kOffSurfaceRel = 0.1;

/// Whether the face (a, b, c), whose centroid has UDF `centroid_udf`, lies off the surface (kOffSurfaceRel).
inline bool OffSurface(double centroid_udf, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double longest = std::max({(a - b).norm(), (b - c).norm(), (c - a).norm()});
  return centroid_udf > kOffSurfaceRel * longest;
}

}  // namespace voroudf

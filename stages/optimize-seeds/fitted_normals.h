#pragma once
// Tangent planes of the cell samples fitted to the surface points they point at, for fields whose gradients
// are wrong while their values are right (docs/optimize-seeds.md, "Fitted sample planes").
#include <cstddef>
#include <vector>

#include "stages/optimize-seeds/voronoi_cells.h"

namespace voroudf {

struct SamplePlaneFit {
  int neighbours = 10;          ///< k: foot points per fit (the sample's own and its k − 1 nearest that agree)
  double agree_deg = 45.0;      ///< only samples whose gradients are this close to the sample's own take part
  int min_neighbours = 5;       ///< fewer agreeing foot points in the cell: the sample keeps its gradient's plane
  /// a fit whose foot points spread across their plane by more than this × along it (√(λ₀/λ₁)) is no plane;
  /// a sample whose foot point is farther than this × that spread from a plane does not take it
  double max_thickness = 0.25;
  int anchor_stride = 2;        ///< planes are fitted at every this-th sample; the others take the nearest one's (4: worse CD and TD)
};

/// Per sample of a CellSamples: the normal and value of its tangent plane, and over all samples the median
/// angle between the gradient and that normal (0 where the gradient's plane was kept): the field's gradient
/// error where its surface is a plane within a fit.
struct SamplePlanes {
  std::vector<Vec3> normal;
  std::vector<double> distance;
  double median_angle = 0.0;  ///< radians
  std::vector<char> fitted;   ///< per sample: 1 if it took a fitted plane, 0 if it kept its gradient's
};

/// Sample m of a cell, at p_m with value d_m and gradient g_m, stands for the plane through its foot point
/// f_m = p_m − d_m g_m with normal g_m (paper Eq. `energy_l1`: |g_mᵀ(p_m − x) − d_m|). A gradient turned by
/// θ tilts that plane by θ, but moves the foot point off the surface by only d_m (1 − cos θ) (3.4 % of d_m at
/// 15°): the foot points keep the surface where the gradients lose it. So each sample's plane becomes the
/// total-least-squares plane of the foot points of its own cell nearest its own (PCA; Hoppe et al. 1992),
/// among the samples whose gradients agree with its own within `agree_deg` (the same face of a crease),
/// fitted a second time to those samples' points p − d n̂ along the first plane's normal n̂ (the foot points
/// sit on their samples' side, which offsets the first plane; along the surface's normal the values put each
/// point on the surface): gradient ← the second plane's unit normal n̂ (turned towards g_m), distance ←
/// n̂ᵀ(p_m − c̄), c̄ the centroid of those points. On a plane with exact values this is the plane whatever the
/// gradients.
/// A fit whose foot points are no plane (√(λ₀/λ₁) > max_thickness: sheets closer than the neighbourhood, a
/// corner) is dropped; a sample takes the plane of the nearest fitted anchor that agrees with it and whose plane
/// its own foot point lies on (within max_thickness × the fit's spread), else keeps its gradient's plane.
/// The cells are left as they are: UseSamplePlanes puts the result in.
SamplePlanes FitSamplePlanes(const CellSamples& cells, const SamplePlaneFit& fit);

/// The cells' gradients and values become `planes`' normals and distances (swapped in).
void UseSamplePlanes(CellSamples& cells, SamplePlanes& planes);

/// Where a value error doubles the zero set (|d + e|: sheets |e| either side of the surface where e < 0; where
/// e > 0 the foot points overshoot the surface by e), every sample's plane is off the surface by -e along its
/// own normal, on its own side, and the samples of the two sides give two families of planes 2|e| apart: the L1
/// energy is level between them, so a seed stays wherever it is inside that slab (a curve seed up to |e| /
/// sin(half the dihedral) along a face from its edge). Each sample's plane moves halfway to the foot point of
/// the other side's sample (gradient more than 130° from its own) nearest its normal line, gap = n̂ᵀ(f_m −
/// f_other): distance += gap / 2, the mid-surface of the twins, where |gap| < `within` (the projection's twin
/// separation; farther, they are two surfaces). Foot points within 8 `tolerance` of the sample's own plane are
/// not the other side's: a sample between the twins points at the same sheet as the samples beyond it. Cells
/// whose samples all face one way keep their planes. Only for fields whose projection merges twins (the
/// caller's test): an exact field's two sides give the same planes, and where a field's floors come without
/// twins (a grid's rounded valleys) the foot points are off near the surface only, not by -e for every sample.
/// With `mid_planes` (the planes came from FitSamplePlanes) each sample instead takes the mid-plane of its own
/// and its partner's, normal ∝ n̂_m − n̂_other, value the mean of the two planes' signed distances at p_m: a
/// fitted plane is the field's zero sheet on its own side, which the value error's slope tilts one way on one
/// side and the mirror way on the other, and a kept gradient's error is averaged with the partner's. With exact
/// gradients (no fit) the normals are the surface's and only the values move.
/// \pre within > 0
void CenterTwinPlanes(CellSamples& cells, double within, double tolerance, bool mid_planes = false);

/// How far a field's value errors tilt its zero set (radians), from the values `floor` at `points` where a
/// projection stopped at a floor or ridge (|d + e| = |e| there, common/projection.h): atan(s / cos 45°), s
/// the median over the points of |Δ floor| / |Δ x| to the nearest other such point (a slope along a random
/// direction; its median is |∇e| cos 45° for a fixed gradient). The foot points lie on the field's zero
/// set, so their planes are off the surface by about this much where the gradients are exact. 0 with fewer
/// than 16 points.
double ValueErrorTilt(const std::vector<Vec3>& points, const std::vector<double>& floor);

/// --sample-planes auto's rule: fit when the gradients' measured angle to the fitted planes, `measured`,
/// exceeds `min_angle` and 4 × `value_tilt`. Value errors alone make the gradients measure up to 2.4 × the tilt
/// ValueErrorTilt estimates (noisy:value= from 1e-3 to 1e-2, CAD, cloth and non-manifold shapes: the foot
/// points scatter as the error varies along each sample's height, besides the tilt), and there the gradients
/// are the better planes; beyond 4 × that, the rest is the gradients' own error. Radians.
inline bool FitPaysOff(double measured, double value_tilt, double min_angle) {
  return measured > min_angle && measured > 4.0 * value_tilt;
}

}  // namespace voroudf

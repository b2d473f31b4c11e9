// optimize-seeds: the L1 tangent solver against known optima and brute force, the tangent-plane rank, the
// projected repulsion, the whole optimisation on built-in shapes, and the real executable end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "common/counting_udf.h"
#include "common/errors.h"
#include "common/mesh_udf.h"
#include "common/projection.h"
#include "common/rng.h"
#include "common/shapes.h"
#include "common/udf_spec.h"
#include "formats/mesh_io.h"
#include "formats/seeds_io.h"
#include "stages/optimize-seeds/fitted_normals.h"
#include "stages/optimize-seeds/l1_tangent.h"
#include "stages/optimize-seeds/optimize_seeds.h"
#include "stages/optimize-seeds/repulsion.h"
#include "stages/optimize-seeds/seed_index.h"
#include "stages/optimize-seeds/voronoi_cells.h"
#include "stages/sample-seeds/sample_seeds.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::NearestNeighbourCv;
using test::TempDir;

// ------------------------------------------------------------------------------------ fitted sample planes

// One cell of M samples in a ball of radius r about the origin, on the field d = |z| of the plane z = 0, each
// gradient turned by `deg` degrees in a random direction (0: exact).
CellSamples PlaneCell(double deg, size_t m, double r, uint64_t seed) {
  CellSamples cells;
  Rng rng(seed, 0);
  cells.sample_offset = {0, m};
  for (size_t k = 0; k < m; ++k) {
    Vec3 p;
    do p = Vec3(rng.Uniform(-r, r), rng.Uniform(-r, r), rng.Uniform(-r, r)); while (p.norm() > r);
    const Vec3 n(0, 0, p.z() < 0 ? -1.0 : 1.0);
    const double phi = rng.Uniform(0, 2 * M_PI), a = deg * M_PI / 180;
    cells.point.push_back(p);
    cells.distance.push_back(std::abs(p.z()));
    cells.gradient.push_back(std::cos(a) * n + std::sin(a) * Vec3(std::cos(phi), std::sin(phi), 0.0));
  }
  return cells;
}

// A turned gradient tilts its sample's plane by the whole angle but moves the foot point off the plane by
// only d (1 - cos θ): the planes fitted to the foot points are the face's, within a few degrees.
TEST(FittedSamplePlanes, GradientsTurnedBy15DegreesGiveTheFacesPlaneBack) {
  CellSamples cells = PlaneCell(15.0, 100, 0.1, 3);
  SamplePlanes planes = FitSamplePlanes(cells, SamplePlaneFit{});
  EXPECT_NEAR(planes.median_angle * 180 / M_PI, 15.0, 2.0);
  EXPECT_DOUBLE_EQ(FitSamplePlanes(cells, SamplePlaneFit{}).median_angle, planes.median_angle);  // cells untouched
  UseSamplePlanes(cells, planes);
  std::vector<double> tilt;
  for (size_t k = 0; k < cells.point.size(); ++k) {
    const double side = cells.point[k].z() < 0 ? -1.0 : 1.0;
    tilt.push_back(std::acos(std::min(1.0, side * cells.gradient[k].z())) * 180 / M_PI);
    // The value is the sample's distance from its fitted plane: |z| within the foot points' spread.
    EXPECT_NEAR(cells.distance[k], std::abs(cells.point[k].z()), 0.01) << "sample " << k;
  }
  std::sort(tilt.begin(), tilt.end());
  EXPECT_LT(tilt[tilt.size() / 2], 3.0) << "median tilt of the fitted planes (the gradients': 15)";
  EXPECT_LT(tilt.back(), 10.0);
}

// Two parallel sheets z = +-a closer than a fit's neighbourhood: samples above the upper sheet and those
// just below the middle both point up, and their foot points lie on both sheets. A plane through them would
// sit between the sheets; such a fit is no plane, and the samples keep their own.
TEST(FittedSamplePlanes, FootPointsOnTwoSheetsGiveNoPlane) {
  const double a = 0.015;
  CellSamples cells = PlaneCell(0.0, 100, 0.1, 5);
  for (size_t k = 0; k < cells.point.size(); ++k) {
    const double z = cells.point[k].z(), to = z >= 0 ? a : -a;  // the nearer sheet
    cells.distance[k] = std::abs(z - to);
    cells.gradient[k] = Vec3(0, 0, z >= to ? 1.0 : -1.0);
  }
  const CellSamples exact = cells;
  SamplePlanes planes = FitSamplePlanes(cells, SamplePlaneFit{});
  EXPECT_EQ(planes.median_angle, 0.0);
  UseSamplePlanes(cells, planes);
  for (size_t k = 0; k < cells.point.size(); ++k) {
    EXPECT_LT((cells.gradient[k] - exact.gradient[k]).norm(), 1e-9) << "sample " << k;
    EXPECT_NEAR(cells.distance[k], exact.distance[k], 1e-12) << "sample " << k;
  }
}

// A value error with slope c along the surface tilts the zero set by atan c: floors read from random points
// of a plane with e = 1e-3 + c x give it back (the slope to the nearest point along a random direction has
// median c cos 45°).
TEST(FittedSamplePlanes, TheValueErrorsTiltIsTheirSlopeAlongTheSurface) {
  Rng rng(6, 0);
  std::vector<Vec3> points;
  std::vector<double> floor, flat;
  for (int k = 0; k < 2000; ++k) {
    points.emplace_back(rng.Uniform(-1, 1), rng.Uniform(-1, 1), 0.0);
    floor.push_back(1e-3 + 0.1 * points.back().x());
    flat.push_back(1e-3);
  }
  EXPECT_NEAR(ValueErrorTilt(points, floor), std::atan(0.1), 0.1 * std::atan(0.1));
  EXPECT_EQ(ValueErrorTilt(points, flat), 0.0);
  points.resize(15), floor.resize(15);
  EXPECT_EQ(ValueErrorTilt(points, floor), 0.0);  // too few to say
  EXPECT_TRUE(FitPaysOff(0.26, 0.02, 8 * M_PI / 180));   // 15° against a 1.1° tilt
  EXPECT_FALSE(FitPaysOff(0.08, 0.035, 8 * M_PI / 180)); // 4.6° against 2°: the value errors' own scatter
  EXPECT_FALSE(FitPaysOff(0.10, 0.0, 8 * M_PI / 180));   // 5.7°: below the floor
}

// PlaneCell's samples seen through |d + e| with a constant e: for e < 0 zero sheets at z = +-|e| (samples
// between them point at the nearer one), for e > 0 a floor whose foot points overshoot the plane by e.
CellSamples ShiftedPlaneCell(double e, uint64_t seed) {
  CellSamples cells = PlaneCell(0.0, 100, 0.1, seed);
  for (size_t k = 0; k < cells.point.size(); ++k) {
    const double z = cells.point[k].z(), side = z < 0 ? -1.0 : 1.0;
    cells.distance[k] = std::abs(std::abs(z) + e);
    cells.gradient[k] = Vec3(0, 0, std::abs(z) + e < 0 ? -side : side);
  }
  return cells;
}

// The plane of sample k passes through z = 0: n_z (p_z - 0) = distance.
double OffThePlane(const CellSamples& cells, size_t k) {
  return cells.gradient[k].dot(cells.point[k]) - cells.distance[k];
}

TEST(FittedSamplePlanes, TwinsAndFloorsAreCentredOnTheSurface) {
  for (double e : {-2e-3, 3e-3}) {
    CellSamples cells = ShiftedPlaneCell(e, 8);
    size_t off = 0, between = 0;
    for (size_t k = 0; k < cells.point.size(); ++k) {
      off += std::abs(OffThePlane(cells, k)) > 0.5 * std::abs(e);
      between += std::abs(cells.point[k].z()) < -e;
    }
    EXPECT_GT(off, 90u) << "e " << e;  // each side's planes |e| off the surface
    if (e < 0) {
      EXPECT_GT(between, 0u);
    }
    CenterTwinPlanes(cells, 5 * std::abs(e), 1e-9);
    for (size_t k = 0; k < cells.point.size(); ++k)
      EXPECT_NEAR(OffThePlane(cells, k), 0.0, 1e-12) << "e " << e << ", sample " << k << " at " << cells.point[k].transpose();
  }
}

// Planes through |d + e| with e = e0 + c x: each side's zero set, σ z + e(x) = 0 for the side σ = ±1, is
// tilted by atan c, the two sides' the mirror image of each other, and their mid-plane is the surface.
// Fitted planes (those zero sets) take that mid-plane, normal ±z, whatever e0's sign; gradient planes keep
// their normals and only move their values.
TEST(FittedSamplePlanes, FittedPlanesTakeTheMidPlaneWhereMirroredTiltsCancel) {
  const double c = 0.05;
  for (double e0 : {-2e-3, 3e-3}) {
    CellSamples cells = PlaneCell(0.0, 100, 0.1, 8);
    for (size_t k = 0; k < cells.point.size(); ++k) {
      Vec3& p = cells.point[k];
      const double side = p.z() < 0 ? -1.0 : 1.0;
      if (std::abs(p.z()) < 0.02) p.z() = 0.02 * side;  // beyond the twins
      const Vec3 n = Vec3(c, 0, side) / std::sqrt(1 + c * c);
      cells.gradient[k] = n;
      cells.distance[k] = n.dot(p) + e0 / std::sqrt(1 + c * c);
    }
    const CellSamples tilted = cells;
    CenterTwinPlanes(cells, 0.05, 1e-9, true);
    for (size_t k = 0; k < cells.point.size(); ++k) {
      EXPECT_NEAR(std::abs(cells.gradient[k].z()), 1.0, 1e-12) << "e0 " << e0 << ", sample " << k;
      EXPECT_NEAR(OffThePlane(cells, k), 0.0, 1e-12) << "e0 " << e0 << ", sample " << k;
    }
    // Gradient planes (no fit): every normal stays, only the values move.
    cells = tilted;
    CenterTwinPlanes(cells, 0.05, 1e-9);
    EXPECT_EQ(cells.gradient, tilted.gradient);
    EXPECT_NE(cells.distance, tilted.distance);
  }
}

// Foot points along gradients turned by 15° lie d (1 - cos 15°) above the plane on their samples' side: a
// plane fitted to them alone sits off the surface by 3.4 % of the samples' heights (here a mean of 2e-3,
// up to 5e-3, for heights up to 0.1). Refitted to the points p - d n̂ it is off only by what the first
// normal's error leaves (1 - cos of a few degrees).
TEST(FittedSamplePlanes, TurnedGradientsDoNotOffsetTheFittedPlane) {
  const CellSamples cells = PlaneCell(15.0, 100, 0.1, 3);
  SamplePlanes planes = FitSamplePlanes(cells, SamplePlaneFit{});
  CellSamples fitted = cells;
  const std::vector<char> which = planes.fitted;
  UseSamplePlanes(fitted, planes);
  size_t on = 0;
  double worst = 0.0, sum = 0.0;
  for (size_t k = 0; k < fitted.point.size(); ++k) {
    if (!which[k]) continue;  // kept its gradient's plane
    ++on;
    const double off = std::abs(OffThePlane(fitted, k));
    worst = std::max(worst, off);
    sum += off;
  }
  EXPECT_GT(on, 80u);
  EXPECT_LT(sum / static_cast<double>(on), 1e-4);
  EXPECT_LT(worst, 5e-4);
}

TEST(FittedSamplePlanes, SheetsFartherApartThanTheTwinsAreLeftAsTheyAre) {
  const CellSamples wall = ShiftedPlaneCell(-2e-3, 9);  // sheets 4e-3 apart
  CellSamples cells = wall;
  CenterTwinPlanes(cells, 3e-3, 1e-9);
  EXPECT_EQ(cells.distance, wall.distance);
  const CellSamples exact = PlaneCell(0.0, 100, 0.1, 9);
  cells = exact;
  CenterTwinPlanes(cells, 3e-3, 1e-9);
  EXPECT_EQ(cells.distance, exact.distance);
}

TEST(FittedSamplePlanes, ExactGradientsOnAPlaneAreLeftAsTheyAre) {
  const CellSamples exact = PlaneCell(0.0, 100, 0.1, 4);
  CellSamples cells = exact;
  SamplePlanes planes = FitSamplePlanes(cells, SamplePlaneFit{});
  EXPECT_LT(planes.median_angle, 1e-6);
  EXPECT_EQ(std::count(planes.fitted.begin(), planes.fitted.end(), 1), static_cast<long>(cells.point.size()));
  UseSamplePlanes(cells, planes);
  for (size_t k = 0; k < cells.point.size(); ++k) {
    EXPECT_LT((cells.gradient[k] - exact.gradient[k]).norm(), 1e-9) << "sample " << k;
    EXPECT_NEAR(cells.distance[k], exact.distance[k], 1e-12) << "sample " << k;
  }
}

// ---------------------------------------------------------------------------------------------- L1 solver

SeedCloud Initial(const Udf& udf, size_t count, uint64_t seed);

// Samples of exact tangent planes through the origin with normals `planes`, seen from random points around
// x0 (as UDF samples of the surface would be: n = ±plane normal, d = |distance|), in coordinates centred on x0.
L1TangentProblem PlanesProblem(const std::vector<Vec3>& planes, const Vec3& x0, int per_plane, double gamma) {
  L1TangentProblem p;
  p.gamma = gamma;
  Rng rng(7, 0);
  for (const Vec3& n : planes) {
    for (int k = 0; k < per_plane; ++k) {
      const Vec3 q = x0 + Vec3(rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1), rng.Uniform(-0.1, 0.1));
      const double signed_distance = n.dot(q);
      const Vec3 a = signed_distance >= 0 ? n : Vec3(-n);
      p.a.push_back(a);
      p.b.push_back(a.dot(q - x0) - std::abs(signed_distance));
    }
  }
  return p;
}

L1TangentOptions Tight() {
  L1TangentOptions o;
  o.gap_tolerance = 1e-11;  // position error ≤ sqrt(1e-11 / γ) ≈ 1e-6
  o.max_sweeps = 20000;
  o.max_newton_steps = 400;
  return o;
}

// Normals of a cell: `planes` unit normals, each turned by `deg` degrees in a random direction.
std::vector<Vec3> TurnedNormals(const std::vector<Vec3>& planes, double deg, int per_plane, Rng& rng) {
  std::vector<Vec3> out;
  for (const Vec3& n : planes)
    for (int m = 0; m < per_plane; ++m) {
      const Vec3 t = n.unitOrthogonal(), u = n.cross(t);
      const double phi = rng.Uniform(0, 2 * M_PI), a = deg * M_PI / 180;
      out.push_back(std::cos(a) * n + std::sin(a) * (std::cos(phi) * t + std::sin(phi) * u));
    }
  return out;
}

TEST(TangentRank, TheUnexplainedSpreadIsTakenOutOfTheRankTest) {
  Rng rng(3, 0);
  const Vec3 z(0, 0, 1), x(1, 0, 0);
  std::vector<TangentRank> sheets, creases;
  for (int c = 0; c < 40; ++c) {
    const auto sheet = TurnedNormals({z}, 30, 100, rng), crease = TurnedNormals({z, x}, 30, 50, rng);
    sheets.push_back(ComputeTangentRank(sheet.data(), sheet.size(), 0.4));
    creases.push_back(ComputeTangentRank(crease.data(), crease.size(), 0.4));
  }
  EXPECT_EQ(sheets[0].rank, 2);  // the paper's test takes a sheet with 30-degree gradient errors for a crease
  std::vector<TangentRank> all = sheets;
  all.insert(all.end(), creases.begin(), creases.end() - 10);  // mostly sheets, as surfaces are
  const double spread = UnexplainedNormalSpread(all);
  EXPECT_NEAR(spread, std::sin(M_PI / 6) / std::sqrt(2.0), 0.05);
  for (TangentRank r : sheets) {
    RecountRank(r, 0.4, spread);
    EXPECT_EQ(r.rank, 1);
  }
  for (TangentRank r : creases) {
    RecountRank(r, 0.4, spread);
    EXPECT_EQ(r.rank, 2);
  }
  // Exact normals: no spread, the paper's test.
  std::vector<TangentRank> exact;
  for (int c = 0; c < 10; ++c) {
    const auto sheet = TurnedNormals({z}, 0, 100, rng);
    exact.push_back(ComputeTangentRank(sheet.data(), sheet.size(), 0.4));
  }
  EXPECT_LT(UnexplainedNormalSpread(exact), 1e-7);
}

TEST(L1Tangent, TwoPlanesPutTheOptimumOnTheirEdge) {
  const Vec3 x0(0.02, -0.03, 0.04);
  const auto p = PlanesProblem({Vec3::UnitX(), Vec3::UnitY()}, x0, 50, 10.0);
  const auto s = SolveL1Tangent(p, Tight());
  ASSERT_TRUE(s.converged) << s.primal << " " << s.dual << " " << s.sweeps << " y " << s.y.transpose();
  const Vec3 x = x0 + s.y;
  // Separable objective: 50|x| + 50|y| + γ‖x − x0‖² → x = y = 0 (soft threshold 2.5 ≫ |x0|), z = x0.z.
  EXPECT_NEAR(x.x(), 0.0, 1e-6);
  EXPECT_NEAR(x.y(), 0.0, 1e-6);
  EXPECT_NEAR(x.z(), x0.z(), 1e-6);
  EXPECT_LE(s.dual, s.primal);
}

TEST(L1Tangent, ThreePlanesPutTheOptimumOnTheirCorner) {
  const Vec3 x0(0.03, 0.01, -0.02);
  const Vec3 tilted = Vec3(1.0, 1.0, 1.0).normalized();  // not orthogonal: coordinates are coupled
  const auto p = PlanesProblem({Vec3::UnitX(), Vec3::UnitY(), tilted}, x0, 30, 10.0);
  const auto s = SolveL1Tangent(p, Tight());
  ASSERT_TRUE(s.converged);
  EXPECT_LT((x0 + s.y).norm(), 1e-6);
}

TEST(L1Tangent, ABindingConstraintPutsTheOptimumOnTheCellBoundary) {
  const Vec3 x0(0.1, 0.05, 0.3);
  auto p = PlanesProblem({Vec3::UnitX(), Vec3::UnitY()}, x0, 50, 10.0);
  // The cell: x ≥ 0.06 (in centred coordinates −y_x ≤ 0.04), plus a loose one that must stay inactive.
  p.c = {-Vec3::UnitX(), Vec3::UnitZ()};
  p.h = {0.04, 0.5};
  const auto s = SolveL1Tangent(p, Tight());
  ASSERT_TRUE(s.converged) << s.primal << " " << s.dual << " " << s.sweeps << " y " << s.y.transpose();
  const Vec3 x = x0 + s.y;
  EXPECT_NEAR(x.x(), 0.06, 1e-6);
  EXPECT_NEAR(x.y(), 0.0, 1e-6);
  EXPECT_NEAR(x.z(), 0.3, 1e-6);
  EXPECT_LE(p.c[0].dot(s.y), p.h[0] + 1e-12);
}

TEST(L1Tangent, MatchesBruteForceGridSearchOnRandomInstances) {
  for (uint64_t trial = 0; trial < 25; ++trial) {
    Rng rng(99, trial);
    L1TangentProblem p;
    p.gamma = rng.Uniform(0.5, 20.0);
    const int m = 3 + static_cast<int>(rng.Below(12));
    for (int k = 0; k < m; ++k) {
      p.a.push_back(Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)).normalized());
      p.b.push_back(rng.Uniform(-0.3, 0.3));
    }
    const int constraints = static_cast<int>(rng.Below(5));
    for (int k = 0; k < constraints; ++k) {
      p.c.push_back(Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)).normalized());
      p.h.push_back(rng.Uniform(0.01, 0.2));
    }
    const auto s = SolveL1Tangent(p, Tight());
    ASSERT_TRUE(s.converged) << "trial " << trial;
    for (size_t k = 0; k < p.c.size(); ++k) EXPECT_LE(p.c[k].dot(s.y), p.h[k] + 1e-12);
    // The independent coordinate-ascent solver agrees (strong convexity: ‖Δy‖ ≤ sqrt(gaps / γ)).
    const auto ca = SolveL1TangentByCoordinateAscent(p, Tight());
    ASSERT_TRUE(ca.converged) << "trial " << trial;
    EXPECT_LT((ca.y - s.y).norm(), 2.0 * std::sqrt(1e-11 / p.gamma) + 1e-12) << "trial " << trial;
    EXPECT_NEAR(s.primal, L1TangentObjective(p, s.y), 1e-12);

    // Grid search over the feasible set, coarse then twice finer around the best point. The optimum lies
    // in the ball ‖y‖ ≤ sqrt(P(0)/γ) because P(y*) ≤ P(0).
    auto feasible = [&](const Vec3& y) {
      for (size_t k = 0; k < p.c.size(); ++k)
        if (p.c[k].dot(y) > p.h[k]) return false;
      return true;
    };
    Vec3 centre = Vec3::Zero();
    double half = std::sqrt(L1TangentObjective(p, Vec3::Zero()) / p.gamma);
    double best = INFINITY;
    const int steps = 40;
    for (int level = 0; level < 3; ++level) {
      Vec3 best_y = centre;
      for (int i = 0; i <= steps; ++i)
        for (int j = 0; j <= steps; ++j)
          for (int k = 0; k <= steps; ++k) {
            const Vec3 y = centre + half * Vec3(2.0 * i / steps - 1, 2.0 * j / steps - 1, 2.0 * k / steps - 1);
            if (!feasible(y)) continue;
            const double v = L1TangentObjective(p, y);
            if (v < best) best = v, best_y = y;
          }
      centre = best_y;
      half *= 4.0 / steps;
    }
    // The solver is at least as good as the grid, and the grid cannot beat the dual bound.
    EXPECT_LE(s.primal, best + 1e-12) << "trial " << trial;
    EXPECT_GE(best, s.dual - 1e-12) << "trial " << trial;
    EXPECT_LE(s.primal - s.dual, 1e-11) << "trial " << trial;
  }
}

TEST(L1Tangent, ConvergesOnTheNearlyParallelPlanesOfACurvedSurface) {
  // Tangent planes of the sphere |x| = 0.5 seen from 100 points near x0 = (0.5, 0, 0) and the disc z = 0:
  // the optimum is on the equator; the planes differ by a few degrees only.
  const Vec3 x0(0.49, 0.01, 0.012);
  L1TangentProblem p;
  p.gamma = 10.0;
  Rng rng(3, 1);
  for (int k = 0; k < 100; ++k) {
    const Vec3 q = x0 + Vec3(rng.Uniform(-0.03, 0.03), rng.Uniform(-0.03, 0.03), rng.Uniform(-0.03, 0.03));
    const double to_sphere = std::abs(q.norm() - 0.5), to_disc = std::abs(q.z());
    Vec3 n;
    double d;
    if (to_sphere < to_disc) {
      n = q.normalized() * (q.norm() > 0.5 ? 1.0 : -1.0);
      d = to_sphere;
    } else {
      n = Vec3(0, 0, q.z() > 0 ? 1.0 : -1.0);
      d = to_disc;
    }
    p.AddTerm(n, n.dot(q - x0) - d);
  }
  const auto s = SolveL1Tangent(p, Tight());
  ASSERT_TRUE(s.converged);
  EXPECT_LT(s.sweeps, 200);
  const Vec3 x = x0 + s.y;
  EXPECT_NEAR(x.z(), 0.0, 1e-6);
  EXPECT_NEAR(std::hypot(x.x(), x.y()), 0.5, 2e-3);  // on the equator, up to the planes' chord error
}

TEST(L1Tangent, MergedPlanesGiveTheSameOptimumAsRepeatedSamples) {
  const Vec3 x0(0.03, -0.02, 0.01);
  const auto repeated = PlanesProblem({Vec3::UnitX(), Vec3(1, 1, 0).normalized()}, x0, 40, 10.0);
  L1TangentProblem merged;
  for (size_t m = 0; m < repeated.a.size(); ++m) merged.AddTerm(repeated.a[m], repeated.b[m]);
  // Two planes, each seen from both sides: four distinct terms with weights summing to 80.
  ASSERT_EQ(merged.a.size(), 4u);
  EXPECT_DOUBLE_EQ(merged.w[0] + merged.w[1] + merged.w[2] + merged.w[3], 80.0);
  const Vec3 probe(0.01, 0.02, -0.03);
  EXPECT_NEAR(L1TangentObjective(merged, probe), L1TangentObjective(repeated, probe), 1e-12);
  const auto a = SolveL1Tangent(repeated, Tight());
  const auto b = SolveL1Tangent(merged, Tight());
  ASSERT_TRUE(a.converged && b.converged);
  EXPECT_LT((a.y - b.y).norm(), 1e-6);
  EXPECT_NEAR(a.primal, b.primal, 1e-10);
}

TEST(L1Tangent, NoSamplesNoMove) {
  L1TangentProblem p;
  p.c = {Vec3::UnitX()};
  p.h = {0.1};
  const auto s = SolveL1Tangent(p, Tight());
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(s.y, Vec3::Zero());
}

// ---------------------------------------------------------------------------------------------- rank

TEST(TangentRank, CountsThePlanesAndGivesTheirNullSpace) {
  std::vector<Vec3> sheet(40, Vec3(0, 0, 1));
  for (size_t k = 0; k < sheet.size(); k += 2) sheet[k] = -sheet[k];  // both sides of the sheet
  auto r = ComputeTangentRank(sheet.data(), sheet.size(), 0.25);
  EXPECT_EQ(r.rank, 1);
  EXPECT_NEAR(std::abs(r.v.col(0).z()), 1.0, 1e-12);
  EXPECT_NEAR(r.v.col(1).z(), 0.0, 1e-12);
  EXPECT_NEAR(r.v.col(2).z(), 0.0, 1e-12);

  std::vector<Vec3> edge(sheet);
  for (size_t k = 0; k < 15; ++k) edge.push_back(Vec3(1, 0, 0));
  r = ComputeTangentRank(edge.data(), edge.size(), 0.25);
  EXPECT_EQ(r.rank, 2);
  EXPECT_NEAR(std::abs(r.v.col(2).y()), 1.0, 1e-12);  // the edge direction

  std::vector<Vec3> corner(edge);
  for (size_t k = 0; k < 10; ++k) corner.push_back(Vec3(0, 1, 0));
  EXPECT_EQ(ComputeTangentRank(corner.data(), corner.size(), 0.25).rank, 3);

  // A few stray normals stay below the threshold: s2/s1 = sqrt(2/40) < 0.25.
  std::vector<Vec3> almost(sheet);
  almost.push_back(Vec3(1, 0, 0));
  almost.push_back(Vec3(1, 0, 0));
  EXPECT_EQ(ComputeTangentRank(almost.data(), almost.size(), 0.25).rank, 1);
  EXPECT_EQ(ComputeTangentRank(almost.data(), 0, 0.25).rank, 0);
}

// A curve seed's step keeps only its part across the curve (the null direction, here about y, is removed),
// unless one of the cell's gradients leaves the curve's normal plane by 17.5 degrees or more (|n·t| >= 0.3):
// a third plane ahead, a corner or a kink of the curve the step must reach. Gradients shorter than 0.5 (a
// source that cannot tell) do not count.
TEST(TangentRank, ACurveSeedStepsAcrossItsCurveUnlessItsCellSeesAThirdPlane) {
  std::vector<Vec3> edge;
  for (size_t k = 0; k < 40; ++k) edge.push_back(k % 2 ? Vec3(0, 0, 1) : Vec3(1, 0, 0));
  edge.push_back(Vec3(0, 0.1, 0));  // too short to count
  edge.push_back(Vec3(0, 0.1, 0));
  edge.push_back(Vec3(0, 0.25, 0.968));  // 14.5 degrees out of the normal plane: a curved edge's curved face
  const TangentRank r = ComputeTangentRank(edge.data(), edge.size(), 0.4);
  ASSERT_EQ(r.rank, 2);
  const Vec3 y(1e-3, 2e-3, 3e-3);
  const Vec3 t = r.v.col(2);
  ASSERT_GT(std::abs(t.y()), 0.99);  // the curve runs along y
  const Vec3 across = StepAcrossCurve(y, r, edge.data(), edge.size());
  EXPECT_NEAR(across.dot(t), 0.0, 1e-15) << "a move along the curve is left";
  EXPECT_NEAR((y - across).cross(t).norm(), 0.0, 1e-15) << "the move across the curve is changed";

  std::vector<Vec3> corner(edge);
  corner.push_back(Vec3(0.3, 0.9, 0).normalized());
  EXPECT_EQ(StepAcrossCurve(y, r, corner.data(), corner.size()), y) << "a third plane: free step";

  std::vector<Vec3> sheet(20, Vec3(0, 0, 1));
  const TangentRank flat = ComputeTangentRank(sheet.data(), sheet.size(), 0.4);
  EXPECT_EQ(StepAcrossCurve(y, flat, sheet.data(), sheet.size()), y) << "only curve seeds are restricted";
}

// Normals of a cell on a crease between two planes turned by `angle` about the y axis, `share` of them on the
// second plane and `wedge` of them spread evenly between the two (the samples beyond a convex crease),
// each side of each plane alike.
std::vector<Vec3> CreaseNormals(double angle, double share, double wedge, size_t count) {
  std::vector<Vec3> n;
  for (size_t k = 0; k < count; ++k) {
    const double u = (static_cast<double>(k) + 0.5) / static_cast<double>(count);
    double a = 0.0;
    if (u < wedge) a = angle * u / wedge;
    else if (u < wedge + share) a = angle;
    const Vec3 v(std::sin(a), 0.0, std::cos(a));
    n.push_back(k % 2 ? v : Vec3(-v));
  }
  return n;
}

// Cell samples (point, UDF value, gradient) of an exact field in the disc of radius `reach` around `centre` in
// the xz plane, on a 13 × 13 grid; `foot` maps a point to its nearest surface point.
struct FakeCell {
  std::vector<Vec3> point, gradient;
  std::vector<double> distance;
};
template <class Foot>
FakeCell SampleCell(const Vec3& centre, double reach, Foot foot) {
  FakeCell c;
  for (int i = -6; i <= 6; ++i)
    for (int k = -6; k <= 6; ++k) {
      const Vec3 p = centre + reach / 6.0 * Vec3(i, 0.37 * ((i + k) % 3), k);
      const Vec3 f = foot(p);
      const double d = (p - f).norm();
      if (d < 1e-9 || (p - centre).norm() > reach) continue;
      c.point.push_back(p), c.distance.push_back(d), c.gradient.push_back((p - f) / d);
    }
  return c;
}

// A tube narrower than the cell turns its normals by 100° and more within it: rank 2 by the singular values,
// yet one sheet, whose normal lines all meet the tube's axis. A convex crease's (its face samples' normal
// lines are parallel) and a crossing of two sheets' are rank 2 and do not meet on one axis.
TEST(TangentRank, ATubeNarrowerThanTheCellIsACurvedSheetAndACreaseIsNot) {
  auto test = [](const FakeCell& c) {
    const TangentRank r = ComputeTangentRank(c.gradient.data(), c.gradient.size(), 0.4);
    return std::make_pair(r.rank, NormalsMeetOnOneAxis(c.point.data(), c.distance.data(), c.gradient.data(),
                                                       c.point.size(), r, 0.2));
  };
  const double radius = 0.03;  // a tube along y through the origin, the cell's centre on its top
  const auto tube = SampleCell(Vec3(0, 0, radius), 0.05, [&](const Vec3& p) {
    const Vec3 q(p.x(), 0.0, p.z());
    return Vec3(radius * q.normalized().x(), p.y(), radius * q.normalized().z());
  });
  EXPECT_EQ(test(tube), std::make_pair(2, true));
  // A convex 90° edge along y: the quarter space x < 0, z < 0, the cell centred on the edge.
  const auto edge = SampleCell(Vec3(0, 0, 0), 0.05, [](const Vec3& p) {
    if (p.x() < 0 && p.z() < 0) return p.x() > p.z() ? Vec3(0, p.y(), p.z()) : Vec3(p.x(), p.y(), 0);
    return Vec3(std::min(p.x(), 0.0), p.y(), std::min(p.z(), 0.0));
  });
  EXPECT_EQ(test(edge), std::make_pair(2, false));
  // Two planes x = 0 and z = 0 crossing along y.
  const auto cross = SampleCell(Vec3(0, 0, 0), 0.05, [](const Vec3& p) {
    return std::abs(p.x()) < std::abs(p.z()) ? Vec3(0, p.y(), p.z()) : Vec3(p.x(), p.y(), 0);
  });
  EXPECT_EQ(test(cross), std::make_pair(2, false));
}

TEST(TangentRank, ShallowCreaseSeenByTheTwoPlaneTestAndCurvedSheetNot) {
  const double deg = M_PI / 180.0, share = SecondPlaneShare(0.4);
  EXPECT_NEAR(share, 0.16 / 1.16, 1e-12);
  // At the share SecondPlaneShare gives, the singular-value test sees a 90° crease just so.
  const auto right = CreaseNormals(90 * deg, share + 0.01, 0.0, 400);
  EXPECT_EQ(ComputeTangentRank(right.data(), right.size(), 0.4).rank, 2);
  for (double angle : {32.0, 35.0, 40.0}) {
    const auto n = CreaseNormals(angle * deg, 0.45, 0.1, 100);
    const TangentRank r = ComputeTangentRank(n.data(), n.size(), 0.4);
    EXPECT_EQ(r.rank, 1) << angle << "°: tan(θ/2) < 0.4, the paper's test misses it";
    EXPECT_TRUE(SeesTwoPlanes(n.data(), n.size(), r, 30 * deg, BlindCreaseAngle(0.4), share, 6.0)) << angle;
  }
  // Above 2·atan(τ) = 43.6° the singular-value test sees the crease itself; the two-plane test stays out.
  EXPECT_NEAR(BlindCreaseAngle(0.4) / deg, 43.6028, 1e-3);
  const auto steep = CreaseNormals(60 * deg, 0.45, 0.1, 100);
  const TangentRank steep_rank = ComputeTangentRank(steep.data(), steep.size(), 0.4);
  EXPECT_EQ(steep_rank.rank, 2);
  EXPECT_FALSE(SeesTwoPlanes(steep.data(), steep.size(), steep_rank, 30 * deg, BlindCreaseAngle(0.4), share, 6.0));
  // Below the angle, below the share, or one sheet curved by 40°, 80° or 100° (normals evenly spread).
  auto below = CreaseNormals(25 * deg, 0.45, 0.1, 100);
  EXPECT_FALSE(SeesTwoPlanes(below.data(), below.size(), ComputeTangentRank(below.data(), below.size(), 0.4),
                             30 * deg, BlindCreaseAngle(0.4), share, 6.0));
  auto few = CreaseNormals(40 * deg, 0.08, 0.0, 100);
  EXPECT_FALSE(SeesTwoPlanes(few.data(), few.size(), ComputeTangentRank(few.data(), few.size(), 0.4), 30 * deg,
                             BlindCreaseAngle(0.4), share, 6.0));
  for (double spread : {40.0, 80.0, 100.0}) {
    const auto curved = CreaseNormals(spread * deg, 0.0, 1.0, 100);
    EXPECT_FALSE(SeesTwoPlanes(curved.data(), curved.size(), ComputeTangentRank(curved.data(), curved.size(), 0.4),
                               30 * deg, BlindCreaseAngle(0.4), share, 6.0))
        << spread;
  }
}

// ---------------------------------------------------------------------------------------------- repulsion

std::vector<Vec3> RandomPoints(size_t n, uint64_t seed, double extent) {
  std::vector<Vec3> p(n);
  for (size_t i = 0; i < n; ++i) {
    Rng rng(seed, i);
    p[i] = Vec3(rng.Uniform(-extent, extent), rng.Uniform(-extent, extent), rng.Uniform(-extent, extent));
  }
  return p;
}

NeighbourLists AllPairs(size_t n) {
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
  return NeighbourLists::FromPairs(n, pairs);
}

TEST(Repulsion, GradientMatchesFiniteDifferences) {
  const auto x = RandomPoints(12, 3, 0.1);
  const auto lists = AllPairs(x.size());
  const double sigma = 0.05;
  std::vector<Vec3> g;
  const double e = RepulsionEnergy(x, lists, sigma, &g);
  EXPECT_GT(e, 0.0);
  for (size_t i = 0; i < x.size(); ++i)
    for (int d = 0; d < 3; ++d) {
      auto plus = x, minus = x;
      plus[i][d] += 1e-6;
      minus[i][d] -= 1e-6;
      const double fd = (RepulsionEnergy(plus, lists, sigma, nullptr) - RepulsionEnergy(minus, lists, sigma, nullptr)) / 2e-6;
      EXPECT_NEAR(g[i][d], fd, 1e-5 * std::max(1.0, std::abs(fd)));
    }
}

TEST(Repulsion, NeighbourListsAreSymmetric) {
  const auto lists = NeighbourLists::FromPairs(4, {{0, 1}, {2, 1}, {1, 0}, {3, 3}});
  EXPECT_EQ(lists.offset, (std::vector<size_t>{0, 1, 3, 4, 4}));
  EXPECT_EQ(lists.index, (std::vector<int>{1, 0, 2, 1}));
}

TEST(Repulsion, SeedsMoveOnlyInTheirNullSpaceAndTheEnergyDrops) {
  // Seeds on the line y = z = 0 allowed to move along x only, plus free seeds off the line.
  std::vector<Vec3> x;
  std::vector<MoveSpace> spaces;
  for (int i = 0; i < 8; ++i) {
    x.emplace_back(0.01 * i + 0.002 * (i % 3), 0.0, 0.0);
    MoveSpace s;
    s.dim = 1;
    s.basis.col(0) = Vec3::UnitX();
    spaces.push_back(s);
  }
  for (const Vec3& p : RandomPoints(5, 4, 0.05)) {
    x.push_back(p);
    MoveSpace s;
    s.dim = 3;
    s.basis.setIdentity();
    spaces.push_back(s);
  }
  MoveSpace fixed;  // rank 3: does not move
  x.emplace_back(0.035, 0.001, 0.0);
  spaces.push_back(fixed);
  const auto lists = AllPairs(x.size());
  RepulsionOptions options;
  const auto r = MinimizeRepulsion(x, spaces, lists, 0.01, options);
  EXPECT_LT(r.final_energy, 0.5 * r.initial_energy);
  EXPECT_GT(r.iterations, 0);
  EXPECT_NEAR(r.final_energy, RepulsionEnergy(r.positions, lists, 0.01, nullptr), 1e-9);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(r.positions[i].y(), 0.0);
    EXPECT_EQ(r.positions[i].z(), 0.0);
  }
  EXPECT_EQ(r.positions.back(), x.back());
  bool moved = false;
  for (int i = 0; i < 8; ++i) moved |= std::abs(r.positions[i].x() - x[i].x()) > 1e-4;
  EXPECT_TRUE(moved);
  // The trust region bounds every displacement.
  options.max_step = 0.3;
  const auto clamped = MinimizeRepulsion(x, spaces, lists, 0.01, options);
  for (size_t i = 0; i < x.size(); ++i) EXPECT_LE((clamped.positions[i] - x[i]).norm(), 0.3 * 0.01 * (1 + 1e-12));
  EXPECT_GT(clamped.clamped, 0u);
}

// Distance from p to the nearest of the cube's 12 edges and its 8 corners (cube [-0.5,0.5]^3).
double CubeEdgeDistance(const Vec3& p) {
  Vec3 q = p.cwiseAbs();
  std::sort(q.data(), q.data() + 3);
  return std::hypot(0.5 - q[1], 0.5 - q[2]);
}
double CubeCornerDistance(const Vec3& p) { return (p.cwiseAbs() - Vec3::Constant(0.5)).norm(); }

TEST(Repulsion, ProjectedStepKeepsRankTwoSeedsOnTheCubeEdge) {
  // Seeds on the edge x = y = 0.5 and on the two faces beside it; ranks and null spaces from real cell
  // samples; a repulsion solve; every seed that the rank calls an edge seed stays on the edge line.
  const auto cube = MakeShape("cube");
  std::vector<Vec3> seeds;
  for (int k = 0; k < 12; ++k) seeds.emplace_back(0.5, 0.5, -0.3 + 0.05 * k + 0.01 * (k % 2));
  Rng rng(5, 0);
  for (int k = 0; k < 60; ++k) {
    const double t = rng.Uniform(0.04, 0.3), z = rng.Uniform(-0.35, 0.35);
    seeds.push_back(k % 2 ? Vec3(0.5, 0.5 - t, z) : Vec3(0.5 - t, 0.5, z));
  }
  const SeedIndex index(seeds);
  const CellSamples cells = SampleVoronoiCells(*cube, seeds, index, CellSamplingOptions(), 1, 0);
  std::vector<MoveSpace> spaces(seeds.size());
  int edge_seeds = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    const auto r = ComputeTangentRank(cells.gradient.data() + cells.sample_offset[i],
                                      cells.sample_offset[i + 1] - cells.sample_offset[i], 0.4);
    spaces[i].dim = 3 - r.rank;
    for (int d = 0; d < spaces[i].dim; ++d) spaces[i].basis.col(d) = r.v.col(r.rank + d);
    if (i < 12) {
      EXPECT_EQ(r.rank, 2) << "edge seed " << i;
      edge_seeds += r.rank == 2;
    }
  }
  ASSERT_GT(edge_seeds, 8);
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < seeds.size(); ++i)
    for (size_t j = i + 1; j < seeds.size(); ++j)
      if ((seeds[i] - seeds[j]).norm() < 0.15) pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
  const auto lists = NeighbourLists::FromPairs(seeds.size(), pairs);
  RepulsionOptions options;
  options.max_step = 0.5;  // as optimize-seeds uses it: seeds stay on the cube
  const auto r = MinimizeRepulsion(seeds, spaces, lists, 0.04, options);
  ASSERT_GT(r.iterations, 0);
  auto line_distance = [](const Vec3& p) { return std::hypot(p.x() - 0.5, p.y() - 0.5); };
  std::vector<Vec3> moved = r.positions;
  ProjectionOptions proj;
  proj.tolerance = 1e-9;
  ProjectToZeroSet(*cube, moved, proj, Monitor::Null());
  double slid = 0.0;
  for (int i = 0; i < 12; ++i) {
    if (spaces[i].dim != 1) continue;
    EXPECT_LT(line_distance(r.positions[i]), 1e-12) << "seed " << i << " left the edge";
    EXPECT_LT(line_distance(moved[i]), 1e-12);
    slid = std::max(slid, std::abs(r.positions[i].z() - seeds[i].z()));
  }
  EXPECT_GT(slid, 1e-3) << "the edge seeds did not move along the edge at all";
}

TEST(VoronoiCells, SamplesLieInTheirCellAndUnchangedCellsAreKept) {
  const auto sphere = MakeShape("sphere");
  std::vector<Vec3> seeds = Initial(*sphere, 300, 8).position;
  auto check_membership = [&](const CellSamples& cells) {
    for (size_t i = 0; i < seeds.size(); ++i) {
      EXPECT_GT(cells.sample_offset[i + 1] - cells.sample_offset[i], 0u) << "cell " << i;
      for (size_t m = cells.sample_offset[i]; m < cells.sample_offset[i + 1]; ++m) {
        const Vec3& q = cells.point[m];
        ASSERT_LE((q - seeds[i]).norm(), cells.radius[i] * (1 + 1e-12));
        for (size_t j = 0; j < seeds.size(); ++j)
          ASSERT_LE((q - seeds[i]).norm(), (q - seeds[j]).norm() + 1e-12) << "sample of cell " << i << " nearer seed " << j;
        EXPECT_NEAR(cells.distance[m], sphere->Distance(q), 1e-12);
      }
    }
  };
  const SeedIndex index0(seeds);
  const CellSamples first = SampleVoronoiCells(*sphere, seeds, index0, CellSamplingOptions(), 1, 0);
  check_membership(first);
  // Nothing moved: every cell is kept.
  const CellSamples same = SampleVoronoiCells(*sphere, seeds, index0, CellSamplingOptions(), 1, 1, &first, &seeds);
  EXPECT_EQ(same.redrawn, 0u);
  EXPECT_EQ(same.point, first.point);
  // One seed moves: only cells near it are redrawn, and every cell is still exact.
  const std::vector<Vec3> before = seeds;
  seeds[0] = (seeds[0] + Vec3(0.01, 0.0, 0.0)).normalized() * 0.5;
  const SeedIndex index1(seeds);
  const CellSamples after = SampleVoronoiCells(*sphere, seeds, index1, CellSamplingOptions(), 1, 2, &first, &before);
  EXPECT_GE(after.redrawn, 1u);
  EXPECT_LT(after.redrawn, 60u);  // of 300
  check_membership(after);
}

TEST(VoronoiCells, CellsFollowTheirSeedsWhenEarlierSeedsAreRemoved) {
  const auto sphere = MakeShape("sphere");
  const std::vector<Vec3> before = Initial(*sphere, 300, 8).position;
  const SeedIndex index0(before);
  const CellSamples first = SampleVoronoiCells(*sphere, before, index0, CellSamplingOptions(), 1, 0);
  // Seeds 3 and 150 are dropped: every later seed's index shifts.
  std::vector<Vec3> seeds;
  for (size_t i = 0; i < before.size(); ++i)
    if (i != 3 && i != 150) seeds.push_back(before[i]);
  CellSamples carried = first;
  std::vector<Vec3> carried_seeds = before;
  CarryCells(seeds, CellSamplingOptions(), carried, carried_seeds);
  ASSERT_EQ(carried_seeds.size(), seeds.size());
  // A fresh draw for the new seeds: every carried cell must be the same set, with the same neighbours.
  const SeedIndex index1(seeds);
  const CellSamples fresh = SampleVoronoiCells(*sphere, seeds, index1, CellSamplingOptions(), 1, 5);
  size_t kept = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    EXPECT_EQ(carried_seeds[i], seeds[i]);  // no seed moved
    if (carried.radius[i] == 0.0) continue;  // given up: redrawn
    ++kept;
    EXPECT_EQ(carried.radius[i], fresh.radius[i]) << "cell " << i;
    std::vector<int> a(carried.neighbour.begin() + static_cast<long>(carried.neighbour_offset[i]),
                       carried.neighbour.begin() + static_cast<long>(carried.neighbour_offset[i + 1]));
    std::vector<int> b(fresh.neighbour.begin() + static_cast<long>(fresh.neighbour_offset[i]),
                       fresh.neighbour.begin() + static_cast<long>(fresh.neighbour_offset[i + 1]));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << "cell " << i;
    // Its samples are the ones seed i had before the removal.
    const size_t old_i = i < 3 ? i : i < 149 ? i + 1 : i + 2;
    EXPECT_TRUE(std::equal(carried.point.begin() + static_cast<long>(carried.sample_offset[i]),
                           carried.point.begin() + static_cast<long>(carried.sample_offset[i + 1]),
                           first.point.begin() + static_cast<long>(first.sample_offset[old_i]),
                           first.point.begin() + static_cast<long>(first.sample_offset[old_i + 1])));
  }
  // Only the cells around the two removed seeds are given up, and only those are redrawn.
  EXPECT_GT(kept, 250u);
  const CellSamples after = SampleVoronoiCells(*sphere, seeds, index1, CellSamplingOptions(), 1, 6, &carried, &carried_seeds);
  EXPECT_EQ(after.redrawn, seeds.size() - kept);
  for (size_t i = 0; i < seeds.size(); ++i)
    for (size_t m = after.sample_offset[i]; m < after.sample_offset[i + 1]; ++m)
      for (const Vec3& other : seeds)
        ASSERT_LE((after.point[m] - seeds[i]).norm(), (after.point[m] - other).norm() + 1e-12);
}

TEST(VoronoiCells, ReusedBuffersGiveTheSameCellsRoundAfterRound) {
  // Rounds that move seeds, keep cells and drop seeds (CarryCells), once with one set of buffers that each
  // round's result is built in (a spent result's arrays, of other sizes and stale contents) and once afresh:
  // the same cells to the bit, with a pool and without.
  const auto sphere = MakeShape("sphere");
  for (const bool with_pool : {true, false}) {
    SamplePool pool_a(3, 0.06), pool_b(3, 0.06);
    CellSamplingOptions a, b;
    if (with_pool) a.pool = &pool_a, b.pool = &pool_b;
    std::vector<Vec3> seeds = Initial(*sphere, 300, 8).position, previous_seeds;
    CellSamples cells_a, cells_b;
    CellSamplingBuffers buffers;
    for (uint64_t round = 0; round < 5; ++round) {
      if (round == 3) {  // drop two seeds, as the feature steps do: the cells follow their seeds
        std::vector<Vec3> fewer;
        for (size_t i = 0; i < seeds.size(); ++i)
          if (i != 7 && i != 120) fewer.push_back(seeds[i]);
        seeds = fewer;
        std::vector<Vec3> seeds_b = previous_seeds;
        CarryCells(seeds, a, cells_a, previous_seeds, &buffers.spare);
        CarryCells(seeds, b, cells_b, seeds_b);
      } else if (round > 0) {  // move a tenth of the seeds along the sphere
        for (size_t i = round; i < seeds.size(); i += 10) seeds[i] = (seeds[i] + Vec3(0.0, 0.004, 0.002)).normalized() * 0.5;
      }
      const SeedIndex index(seeds);
      CellSamples next_a = SampleVoronoiCells(*sphere, seeds, index, a, 1, round, round ? &cells_a : nullptr,
                                              round ? &previous_seeds : nullptr, &buffers);
      const CellSamples next_b = SampleVoronoiCells(*sphere, seeds, index, b, 1, round, round ? &cells_b : nullptr,
                                                    round ? &previous_seeds : nullptr);
      buffers.spare = std::move(cells_a);
      cells_a = std::move(next_a);
      cells_b = next_b;
      previous_seeds = seeds;
      ASSERT_EQ(cells_a.sample_offset, cells_b.sample_offset) << "round " << round;
      EXPECT_EQ(cells_a.point, cells_b.point) << "round " << round;
      EXPECT_EQ(cells_a.distance, cells_b.distance) << "round " << round;
      EXPECT_EQ(cells_a.gradient, cells_b.gradient) << "round " << round;
      EXPECT_EQ(cells_a.neighbour_offset, cells_b.neighbour_offset) << "round " << round;
      EXPECT_EQ(cells_a.neighbour, cells_b.neighbour) << "round " << round;
      EXPECT_EQ(cells_a.radius, cells_b.radius) << "round " << round;
      EXPECT_EQ(cells_a.redrawn, cells_b.redrawn) << "round " << round;
      EXPECT_EQ(cells_a.reused, cells_b.reused) << "round " << round;
      if (round > 0 && round != 3) {
        EXPECT_LT(cells_a.redrawn, seeds.size()) << "round " << round;
      }
    }
  }
}

// Early samples: a cell that clearly sees one plane keeps the first samples of the very draw it would
// have made whole; a cell on a cube edge or corner (two or three planes) gets all M.
TEST(VoronoiCells, EarlySamplesArePrefixesAndFeatureCellsStayWhole) {
  const auto cube = MakeShape("cube");
  const std::vector<Vec3> seeds = Initial(*cube, 400, 3).position;
  const SeedIndex index(seeds);
  CellSamplingOptions whole, early = whole;
  early.early_samples = 20;
  early.early_rank_threshold = 0.2;
  const CellSamples a = SampleVoronoiCells(*cube, seeds, index, whole, 1, 0);
  const CellSamples b = SampleVoronoiCells(*cube, seeds, index, early, 1, 0);
  size_t kept_early = 0, feature_cells = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    const size_t na = a.sample_offset[i + 1] - a.sample_offset[i], nb = b.sample_offset[i + 1] - b.sample_offset[i];
    for (size_t m = 0; m < nb; ++m) {
      ASSERT_EQ(b.point[b.sample_offset[i] + m], a.point[a.sample_offset[i] + m]) << "cell " << i;
      ASSERT_EQ(b.distance[b.sample_offset[i] + m], a.distance[a.sample_offset[i] + m]);
    }
    const TangentRank r = ComputeTangentRank(a.gradient.data() + a.sample_offset[i], na, 0.4);
    if (b.early_kept[i]) {
      ++kept_early;
      EXPECT_EQ(nb, 20u);
      EXPECT_EQ(r.rank, 1) << "cell " << i << " sees a feature with all its samples but stopped early";
    } else {
      EXPECT_EQ(nb, na);
    }
    feature_cells += r.rank >= 2;
  }
  EXPECT_EQ(b.early_cells, kept_early);
  EXPECT_GT(kept_early, seeds.size() / 2);
  EXPECT_GT(feature_cells, 20u);
}

// ---------------------------------------------------------------------------------------------- shapes

SeedCloud Initial(const Udf& udf, size_t count, uint64_t seed) {
  SampleSeedsOptions o;
  o.count = count;
  o.seed = seed;
  o.spread_pool = 1;  // uniform random seeds, the paper's start: the tests measure how the optimizer evens them
  return SampleSeeds(udf, o, Monitor::Null());
}

TEST(OptimizeSeeds, CubeSeedsFindTheEdgesAndCornersAndSpreadEvenly) {
  const auto cube = MakeShape("cube");
  const SeedCloud in = Initial(*cube, 800, 3);
  OptimizeSeedsOptions options;
  options.seed = 1;
  const SeedCloud out = OptimizeSeeds(*cube, in, options, Monitor::Null());
  ASSERT_GT(out.size(), 790u);
  const double diag = cube->Domain().Diagonal();
  const double tol = 1e-5 * diag;
  std::set<std::array<int, 3>> corners;
  std::vector<int> per_edge(12, 0);
  size_t rank2 = 0, rank2_on_edge = 0;
  double mean_nn = 0.0;
  const double cv_out = NearestNeighbourCv(out.position, &mean_nn);
  for (size_t i = 0; i < out.size(); ++i) {
    const Vec3& p = out.position[i];
    ASSERT_LT(cube->Distance(p), tol) << "seed " << i << " is off the surface";
    EXPECT_NEAR(out.normal[i].norm(), 1.0, 1e-9);
    EXPECT_GE(out.rank[i], 1);
    if (out.rank[i] == 3) {
      EXPECT_LT(CubeCornerDistance(p), tol) << "rank-3 seed away from the corners";
      corners.insert({p.x() > 0, p.y() > 0, p.z() > 0});
    }
    if (out.rank[i] == 2) {
      ++rank2;
      const double e = CubeEdgeDistance(p);
      EXPECT_LT(e, 0.5 * mean_nn) << "rank-2 seed far from every edge";
      if (e < tol) {
        ++rank2_on_edge;
        // Which edge: the axis along which |p| is not 0.5.
        const Vec3 q = p.cwiseAbs();
        int axis = 0;
        for (int k = 1; k < 3; ++k)
          if (q[k] < q[axis]) axis = k;
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        ++per_edge[4 * axis + 2 * (p[a] > 0) + (p[b] > 0)];
      }
    }
  }
  EXPECT_EQ(corners.size(), 8u) << "corners recovered";
  EXPECT_GE(static_cast<double>(rank2_on_edge), 0.95 * static_cast<double>(rank2));
  for (int e = 0; e < 12; ++e) EXPECT_GE(per_edge[e], 5) << "edge " << e;
  const double cv_in = NearestNeighbourCv(in.position);
  EXPECT_LT(cv_out, cv_in / 2.0) << "spacing not more uniform: CV " << cv_in << " -> " << cv_out;
}

// Every rank-2 seed lies on one of the feature curves (distance given by `feature`), and at least
// `min_on_curve` seeds lie on the curve measured by `curve` (the non-manifold one).
// The spacing's coefficient of variation must drop by `cv_factor`.
void ExpectRankTwoOnFeatures(const std::string& shape, const std::function<double(const Vec3&)>& feature,
                             const std::function<double(const Vec3&)>& curve, size_t min_on_curve, double cv_factor) {
  const auto udf = MakeShape(shape);
  const SeedCloud in = Initial(*udf, 600, 4);
  OptimizeSeedsOptions options;
  options.max_outer_iters = 6;
  const SeedCloud out = OptimizeSeeds(*udf, in, options, Monitor::Null());
  const double tol = 1e-5 * udf->Domain().Diagonal();
  double mean_nn = 0.0;
  const double cv_out = NearestNeighbourCv(out.position, &mean_nn);
  size_t rank2 = 0, on_feature = 0, on_curve = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    ASSERT_LT(udf->Distance(out.position[i]), tol) << shape;
    if (curve(out.position[i]) < tol) ++on_curve;
    if (out.rank[i] != 2) continue;
    ++rank2;
    EXPECT_LT(feature(out.position[i]), 0.5 * mean_nn) << shape << ": rank-2 seed away from the features";
    on_feature += feature(out.position[i]) < tol;
  }
  EXPECT_GE(static_cast<double>(on_feature), 0.9 * static_cast<double>(rank2)) << shape;
  EXPECT_GE(on_curve, min_on_curve) << shape;
  // Feature clearance: no seed beside a feature seed, except sheet seeds beside each other (the limit is
  // taken on the spacing before the drop, which the few dropped seeds change by well under 10 %).
  auto level = [&](size_t i) { return std::max<int>(out.rank[i], 1); };
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t j = 0; j < out.size(); ++j)
      if (j != i && level(j) >= 2) {
        EXPECT_GE((out.position[i] - out.position[j]).norm(), 0.9 * options.feature_clearance * mean_nn)
            << shape << ": ranks " << level(i) << " and " << level(j);
      }
  EXPECT_LT(cv_out, NearestNeighbourCv(in.position) / cv_factor) << shape;
}

// The open disc's rim is a circle. On a field with value errors (|d + e|), the free L1 step of a rim seed
// slides along the rim to where the error's plane families cross, the steps of neighbouring rim seeds meet
// and the feature-seed thinning drops one of each pair (57 of the exact field's 106 rim seeds were left,
// measured); --l1-curve-step auto steps across the curve on a field with a floor and keeps them, on the
// rim (as the default, across, does on any field). On the exact field auto is the paper's free step.
TEST(OptimizeSeeds, ANoisyDiscKeepsItsRimSeedsWhenCurveSeedsStepAcrossTheirCurve) {
  const auto exact = MakeShape("disc");
  const auto noisy = OpenUdf("noisy:value=1e-3:shape:disc");
  auto rim_seeds = [&](const Udf& udf, const std::string& step, double* farthest) {
    OptimizeSeedsOptions o;
    o.l1_curve_step = step;
    const SeedCloud out = OptimizeSeeds(udf, Initial(udf, 800, 3), o, Monitor::Null());
    size_t n = 0;
    *farthest = 0.0;
    for (size_t i = 0; i < out.size(); ++i) {
      if (out.rank[i] != kRankEdge) continue;
      ++n;
      const Vec3& p = out.position[i];
      *farthest = std::max(*farthest, std::hypot(std::hypot(p.x(), p.y()) - 0.5, p.z()));
    }
    return static_cast<double>(n);
  };
  double far_exact = 0.0, far_noisy = 0.0, far_free = 0.0;
  const double clean = rim_seeds(*exact, "auto", &far_exact);
  const double across = rim_seeds(*noisy, "auto", &far_noisy);
  const double free = rim_seeds(*noisy, "free", &far_free);
  const double diag = exact->Domain().Diagonal();
  EXPECT_GT(clean, 80.0);
  EXPECT_LT(far_exact, 1e-5 * diag);
  EXPECT_GE(across, 0.9 * clean) << "rim seeds: exact " << clean << ", noisy " << across;
  EXPECT_LT(far_noisy, 5e-3 * diag) << "a rim seed off the rim";
  EXPECT_LT(free, 0.8 * clean) << "the free step no longer loses rim seeds: is the test still needed?";
}

// Gradient errors of 30° make most of a sphere's cells look like curves to the paper's rank test; filling
// feature chains along them added seeds all over the sheets (800 in, 1,522 out, measured). The fills stop
// at 2 % more seeds than the input, so the count holds.
TEST(OptimizeSeeds, GradientErrorsThatFoolTheRankTestDoNotInflateTheCount) {
  const auto noisy = OpenUdf("noisy:grad=30,seed=0:shape:sphere");
  const SeedCloud out = OptimizeSeeds(*noisy, Initial(*noisy, 800, 3), OptimizeSeedsOptions{}, Monitor::Null());
  EXPECT_LE(out.size(), 820u);
  EXPECT_GE(out.size(), 700u);
}

// A value error doubles the cube's faces (|d + e|: sheets |e| off each face, a cylinder round each edge). The
// twin merge, the centred sample planes and the curve seeds kept at their L1 targets put the edge seeds on the
// edges, not |e| out on the cylinder nor along a face.
TEST(OptimizeSeeds, EdgeSeedsOfACubeWithValueErrorsLieOnItsEdges) {
  const auto noisy = OpenUdf("noisy:value=2e-3,seed=0:shape:cube");
  const double sigma = 2e-3 * noisy->Domain().Diagonal();
  const SeedCloud out = OptimizeSeeds(*noisy, Initial(*noisy, 600, 3), OptimizeSeedsOptions{}, Monitor::Null());
  std::vector<double> e;
  for (size_t i = 0; i < out.size(); ++i)
    if (out.rank[i] == 2) e.push_back(CubeEdgeDistance(out.position[i]));
  ASSERT_GT(e.size(), 60u);
  std::sort(e.begin(), e.end());
  // Projected onto the twins instead: median 0.59 sigma, 90th percentile 1.71 sigma.
  EXPECT_LT(e[e.size() / 2], 0.55 * sigma) << "median distance of the rank-2 seeds from the edges";
  EXPECT_LT(e[e.size() * 9 / 10], 1.2 * sigma) << "90th percentile";
}

// Gradients turned by 15° tilt the planes whose crossing puts a seed on a cube edge; the planes fitted to
// the foot points (--sample-planes auto, the default, measures the error and fits) put the edge seeds back
// on the edges. On the exact cube auto measures no error and keeps the paper's planes: the same seeds.
TEST(OptimizeSeeds, FittedSamplePlanesPutTheEdgeSeedsOfANoisyCubeBackOnTheEdges) {
  const auto noisy = OpenUdf("noisy:grad=15,seed=0:shape:cube");
  auto edge_error = [&](const std::string& planes) {
    OptimizeSeedsOptions o;
    o.sample_planes = planes;
    const SeedCloud out = OptimizeSeeds(*noisy, Initial(*noisy, 600, 3), o, Monitor::Null());
    std::vector<double> e;
    for (size_t i = 0; i < out.size(); ++i)
      if (out.rank[i] == 2) e.push_back(CubeEdgeDistance(out.position[i]));
    std::sort(e.begin(), e.end());
    return e.empty() ? INFINITY : e[e.size() / 2];
  };
  const double fitted = edge_error("auto"), turned = edge_error("gradient");
  EXPECT_LT(fitted, 0.5 * turned) << "median distance of the rank-2 seeds from the edges";

  const auto cube = MakeShape("cube");
  OptimizeSeedsOptions a, g;
  g.sample_planes = "gradient";
  const SeedCloud by_auto = OptimizeSeeds(*cube, Initial(*cube, 300, 5), a, Monitor::Null());
  const SeedCloud by_gradient = OptimizeSeeds(*cube, Initial(*cube, 300, 5), g, Monitor::Null());
  ASSERT_EQ(by_auto.size(), by_gradient.size());
  for (size_t i = 0; i < by_auto.size(); ++i) EXPECT_EQ(by_auto.position[i], by_gradient.position[i]);
}

// --repulsion-cells first draws no cells in an outer iteration's later repulsion rounds: fewer queries, and
// the ranks those rounds keep still put every corner and as many seeds on the edges.
TEST(OptimizeSeeds, RepulsionRoundsOnTheFirstRoundsCellsAskLessAndKeepTheFeatures) {
  const auto cube = MakeShape("cube");
  const SeedCloud in = Initial(*cube, 800, 3);
  auto run = [&](const std::string& mode, uint64_t* queries) {
    auto usage = std::make_shared<UdfUsage>();
    const CountingUdf udf(MakeShape("cube"), usage);
    OptimizeSeedsOptions o;
    o.seed = 1;
    o.repulsion_cells = mode;
    const SeedCloud out = OptimizeSeeds(udf, in, o, Monitor::Null());
    *queries = usage->queries.load();
    return out;
  };
  uint64_t every_q = 0, first_q = 0;
  const SeedCloud every = run("every", &every_q), first = run("first", &first_q);
  EXPECT_LT(first_q, every_q * 9 / 10) << "first " << first_q << " vs every " << every_q << " queries";
  auto count = [&](const SeedCloud& s, uint8_t rank) {
    size_t n = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      EXPECT_LT(cube->Distance(s.position[i]), 1e-5 * cube->Domain().Diagonal());
      n += s.rank[i] == rank;
    }
    return static_cast<double>(n);
  };
  EXPECT_EQ(count(first, 3), 8.0);
  EXPECT_NEAR(count(first, 2), count(every, 2), 0.15 * count(every, 2));
  EXPECT_LT(NearestNeighbourCv(first.position, nullptr), 1.15 * NearestNeighbourCv(every.position, nullptr));
}

TEST(OptimizeSeeds, CrossingPlanesRankTwoSeedsOnTheIntersectionLineOrTheRims) {
  // Squares [-0.5,0.5]^2 in z = 0 and x = 0: the line x = z = 0 (4 sheets), and the open rims.
  auto line = [](const Vec3& p) { return std::hypot(p.x(), p.z()); };
  auto rim = [](const Vec3& p) {
    // Distance to the boundary of the square the point lies on, measured in that square's plane.
    const double u = std::abs(p.z()) <= std::abs(p.x()) ? std::abs(p.x()) : std::abs(p.z());
    return std::abs(std::min(0.5 - u, 0.5 - std::abs(p.y())));
  };
  // Every initial point beyond a square's rim projects onto the rim, and rank-2 rim seeds only slide along
  // it, so the rims stay denser than the sheets: a smaller factor than on closed surfaces.
  ExpectRankTwoOnFeatures("crossing-planes", [&](const Vec3& p) { return std::min(line(p), rim(p)); }, line, 12, 1.5);
}

// Each end of crossing-planes' line, where four rims meet, gets one seed exactly on it and none crowding it:
// without the thinning on the last steps' targets two rank-3 seeds sat 0.1-0.4 spacings from the end, each
// holding the other off it (docs/optimize-seeds.md, "Feature clearance").
TEST(OptimizeSeeds, CrossingPlanesLineEndsGetOneSeedEach) {
  const auto udf = MakeShape("crossing-planes");
  for (uint64_t seed : {1, 2}) {
    const SeedCloud out = OptimizeSeeds(*udf, Initial(*udf, 1000, seed), OptimizeSeedsOptions{}, Monitor::Null());
    double mean_nn = 0.0;
    NearestNeighbourCv(out.position, &mean_nn);
    for (double y : {-0.5, 0.5}) {
      const Vec3 end(0.0, y, 0.0);
      std::vector<double> d;
      for (const Vec3& p : out.position) d.push_back((p - end).norm());
      std::sort(d.begin(), d.end());
      EXPECT_LT(d[0], 1e-4 * udf->Domain().Diagonal()) << "seed " << seed << ", end y = " << y;
      EXPECT_GT(d[1], 0.35 * mean_nn) << "seed " << seed << ", end y = " << y;
    }
  }
}

TEST(OptimizeSeeds, SphereWithDiscRankTwoSeedsOnTheEquator) {
  auto equator = [](const Vec3& p) { return std::hypot(std::hypot(p.x(), p.y()) - 0.5, p.z()); };
  ExpectRankTwoOnFeatures("sphere-disc", equator, equator, 20, 2.0);
}

// A closed "house": the box [-1,1]² × [0,1] with a roof whose two faces rise 17.5° each way to a ridge along
// x, so the ridge turns by 35° — below the 44° the singular-value test can see — and the eaves by 72.5°.
const double kHouseRidge = 1.0 + std::tan(17.5 * M_PI / 180.0);  // the ridge's height
std::unique_ptr<MeshUdf> HouseUdf() {
  const double ridge = kHouseRidge;
  TriangleMesh m;
  m.vertices = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0),   // floor
                Vec3(-1, -1, 1), Vec3(1, -1, 1), Vec3(1, 1, 1), Vec3(-1, 1, 1),   // eaves
                Vec3(-1, 0, ridge), Vec3(1, 0, ridge)};                           // ridge
  m.faces = {{0, 2, 1}, {0, 3, 2}, {0, 1, 5}, {0, 5, 4}, {2, 3, 7}, {2, 7, 6},    // floor, long walls
             {1, 2, 6}, {1, 6, 5}, {5, 6, 9}, {3, 0, 4}, {3, 4, 7}, {7, 4, 8},    // gable ends
             {4, 5, 9}, {4, 9, 8}, {6, 7, 8}, {6, 8, 9}};                          // roof
  return std::make_unique<MeshUdf>(m, "house");
}

// The ridge gets a chain of rank-2 seeds on it (gaps of 1.1-2 spacings measured; none wider than 2.5 asked),
// only with the two-plane test (without it, the widest gap is over 4).
TEST(OptimizeSeeds, AShallowCreaseGetsAChainOfCurveSeeds) {
  const auto udf = HouseUdf();
  auto ridge = [](const Vec3& p) { return std::hypot(p.y(), p.z() - kHouseRidge); };
  for (double crease_angle : {30.0, 0.0}) {
    OptimizeSeedsOptions options;
    options.crease_angle_deg = crease_angle;
    const SeedCloud out = OptimizeSeeds(*udf, Initial(*udf, 800, 2), options, Monitor::Null());
    double spacing = 0.0;
    NearestNeighbourCv(out.position, &spacing);
    std::vector<double> along;  // x of the curve seeds on the ridge
    for (size_t i = 0; i < out.size(); ++i)
      if (out.rank[i] == 2 && ridge(out.position[i]) < 0.05 * spacing) along.push_back(out.position[i].x());
    along.push_back(-1.0);
    along.push_back(1.0);
    std::sort(along.begin(), along.end());
    double gap = 0.0;
    for (size_t k = 1; k < along.size(); ++k) gap = std::max(gap, along[k] - along[k - 1]);
    if (crease_angle > 0.0) {
      EXPECT_LT(gap, 2.5 * spacing) << along.size() - 2 << " ridge seeds, spacing " << spacing << testing::PrintToString(along);
    } else {
      EXPECT_GT(gap, 4.0 * spacing) << "the paper's test alone found the 35° ridge: " << along.size() - 2;
    }
  }
}

// Curved features: with --feature-chord-tol, the chain of seeds on sphere-disc's equator (a circle of radius
// 0.5, about 4.5 spacings at 200 seeds) follows it to within the tolerance: every chord between consecutive
// equator seeds that is long enough to be split (2.5 × the feature clearance) has its midpoint within
// the tolerance of the circle; without it such chords cut inside the circle by more. The count holds.
// The refinement is not certain to reach the tolerance on every chord of every run (a seed added in one
// round can move its neighbours' chords, and the crowding and clearance rules leave some chords as they
// are): over input draws 1-16 it did in 7 of 16, so the test asks for 2 of draws 1-6. A draw whose plain
// chain has no chord long enough to split (all within 1.1 spacings: one of draws 1-6) shows nothing and is
// left out; at most two may be.
TEST(OptimizeSeeds, FeatureChordsFollowACurvedFeatureWithinTheTolerance) {
  const auto udf = MakeShape("sphere-disc");
  const double tol = 0.02;
  struct Chain {
    size_t seeds = 0;
    double spacing = 0.0, worst = 0.0;  // worst: the largest 0.5 − |chord midpoint| over splittable chords
  };
  auto chain = [&](const SeedCloud& in, double chord_tol) {
    OptimizeSeedsOptions options;
    options.feature_chord_tol = chord_tol;
    // Ceres' 50 L-BFGS iterations per repulsion round, which move every seed by the step limit: with the
    // default 3 the equator's curve seeds settle evenly and its chords are within the tolerance without the
    // rule in 4 of the 6 draws, leaving the rule nothing to do.
    options.lbfgs_max_iters = 50;
    // The bend rule alone: with the gap rule and the across step a 200-seed equator's chains are filled by
    // both rules at once, and which chords stay long depends on which fills first.
    options.feature_gap_max = 0.0;
    options.l1_curve_step = "free";
    const SeedCloud out = OptimizeSeeds(*udf, in, options, Monitor::Null());
    Chain c;
    c.seeds = out.size();
    NearestNeighbourCv(out.position, &c.spacing);
    std::vector<double> angle;
    for (size_t i = 0; i < out.size(); ++i) {
      const Vec3& p = out.position[i];
      if (out.rank[i] < 2) continue;
      EXPECT_LT(std::hypot(std::hypot(p.x(), p.y()) - 0.5, p.z()), 1e-4) << "rank-2 seed off the equator";
      angle.push_back(std::atan2(p.y(), p.x()));
    }
    std::sort(angle.begin(), angle.end());
    EXPECT_GE(angle.size(), 8u);
    const double splittable = 1.1 * 2.5 * options.feature_clearance * c.spacing;
    for (size_t k = 0; k < angle.size(); ++k) {
      const double gap = k + 1 < angle.size() ? angle[k + 1] - angle[k] : angle[0] + 2 * M_PI - angle[k];
      if (2 * 0.5 * std::sin(0.5 * gap) >= splittable) c.worst = std::max(c.worst, 0.5 * (1.0 - std::cos(0.5 * gap)));
    }
    return c;
  };
  int within = 0, straight = 0;
  for (uint64_t draw = 1; draw <= 6; ++draw) {
    const SeedCloud in = Initial(*udf, 200, draw);
    const Chain plain = chain(in, 0.0);
    if (plain.worst <= 1.5 * tol * plain.spacing) {
      ++straight;
      continue;
    }
    const Chain refined = chain(in, tol);
    // Seeds are added on the chords, and as many sheet seeds dropped in the outer loop (the count holds, up
    // to the few seeds the feature-seed thinning drops after the last feature steps: 10 of 198 at most).
    EXPECT_NEAR(static_cast<double>(refined.seeds), static_cast<double>(plain.seeds), 0.06 * plain.seeds) << "draw " << draw;
    within += refined.worst <= 1.2 * tol * refined.spacing;
  }
  EXPECT_LE(straight, 2) << "the test shape must bend away from its chords";
  EXPECT_GE(within, 2);
}

// Feature chains (--feature-gap-max 1.5, the default): along every edge of the cube, from corner to corner,
// no two consecutive feature seeds are farther apart than 1.5 mean spacings (5 % slack: the spacing is the
// one before seeds were added). Without the rule, with the paper's L1 step, some chains have longer gaps
// (1.52–1.67 spacings at 1,000 seeds, draws 1–3), so the test can fail.
TEST(OptimizeSeeds, FeatureChainsHaveNoGapLongerThanTheLimit) {
  const auto cube = MakeShape("cube");
  auto largest_gap = [&](const SeedCloud& in, double gap_max) {
    OptimizeSeedsOptions options;
    options.feature_gap_max = gap_max;
    if (gap_max == 0.0) options.l1_curve_step = "free";
    // Ceres' 50 L-BFGS iterations per repulsion round, which move every seed by the step limit: with the
    // default 3 the curve seeds settle evenly and no gap is left for the rule to fill (1.12 spacings at most).
    options.lbfgs_max_iters = 50;
    const SeedCloud out = OptimizeSeeds(*cube, in, options, Monitor::Null());
    double spacing = 0.0;
    NearestNeighbourCv(out.position, &spacing);
    double largest = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (double su : {-0.5, 0.5})
        for (double sv : {-0.5, 0.5}) {
          std::vector<double> along = {-0.5, 0.5};
          for (size_t i = 0; i < out.size(); ++i)
            if (out.rank[i] >= 2 && std::abs(out.position[i][u] - su) < 1e-3 && std::abs(out.position[i][v] - sv) < 1e-3)
              along.push_back(out.position[i][axis]);
          std::sort(along.begin(), along.end());
          for (size_t k = 1; k < along.size(); ++k) largest = std::max(largest, (along[k] - along[k - 1]) / spacing);
        }
    }
    return largest;
  };
  double without = 0.0;
  for (uint64_t draw = 1; draw <= 3; ++draw) {
    const SeedCloud in = Initial(*cube, 1000, draw);
    EXPECT_LE(largest_gap(in, 1.5), 1.5 * 1.05) << "draw " << draw;
    without = std::max(without, largest_gap(in, 0.0));
  }
  EXPECT_GT(without, 1.5 * 1.05) << "the test needs a chain with a gap without the rule";
}

TEST(OptimizeSeeds, SeedsBesideAHigherRankedFeatureSeedAreDropped) {
  const std::vector<Vec3> position = {{0, 0, 0},   {0.05, 0, 0},  {0.02, 0.01, 0}, {0.3, 0, 0},
                                      {0.3, 0.02, 0}, {0.6, 0, 0}, {0.6, 0.01, 0}, {0.62, 0, 0}};
  // 0, 1: curve seeds 0.05 apart; 2: a sheet seed beside them; 3: a sheet seed beside corner 4; 5, 6: two
  // corner seeds 0.01 apart; 7: a curve seed 0.02 from corner 5.
  const std::vector<uint8_t> rank = {2, 2, 1, 1, 3, 3, 3, 2};
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.03), (std::vector<char>{0, 0, 1, 1, 0, 0, 1, 1}));
  // The misfit decides which corner seed stays (here 6); seed 7 is within the limit of both corners.
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.03, {0, 0, 0, 0, 0, 0.5, 0.1, 0}),
            (std::vector<char>{0, 0, 1, 1, 0, 1, 0, 1}));
  // Curve seeds alone are thinned in input order to the limit; nothing goes at a small enough limit.
  EXPECT_EQ(SeedsBesideFeatures(position, std::vector<uint8_t>(8, 2), 0.03), (std::vector<char>{0, 0, 1, 0, 1, 0, 1, 1}));
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.005), std::vector<char>(8, 0));
  // Sheet seeds never crowd each other out.
  EXPECT_EQ(SeedsBesideFeatures(position, std::vector<uint8_t>(8, 1), 0.03), std::vector<char>(8, 0));
}

// A sheet seed between two curve seeds lies near the curve though far from both: the segment between them
// stands for the curve when it runs along their tangents, and not when it cuts across a face.
TEST(OptimizeSeeds, SheetSeedsBetweenTwoCurveSeedsAreDropped) {
  const std::vector<Vec3> position = {{0, 0, 0}, {0.05, 0, 0}, {0.025, 0.01, 0},   // along a curve
                                      {1.05, 0, 0}, {1, 0.05, 0}, {1.03, 0.03, 0}};  // two edges' seeds
  const std::vector<uint8_t> rank = {2, 2, 1, 2, 2, 1};
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY();
  const std::vector<Vec3> tangent = {x, x, Vec3::Zero(), x, y, Vec3::Zero()};
  // Seed 2 is 0.027 from both curve seeds (over the limit 0.02) but 0.01 from the segment between them.
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.02, {}, tangent), (std::vector<char>{0, 0, 1, 0, 0, 0}));
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.02), std::vector<char>(6, 0));
  // Seed 5 is 0.007 from the segment between seeds 3 and 4, which crosses the face: not a curve, unless
  // their tangents ran along it.
  std::vector<Vec3> along = tangent;
  along[3] = along[4] = (position[4] - position[3]).normalized();
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.02, {}, along), (std::vector<char>{0, 0, 1, 0, 0, 1}));
}

// Two curve seeds lie on one curve when their chord bisects their tangents (a circular arc's chords do, at
// any length), on two when it leaves the bisector: two parallel edges of a strip.
TEST(OptimizeSeeds, ChordsOffTheTangentsBisectorJoinTwoCurves) {
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY();
  for (double angle : {0.2, 0.5, 1.0}) {  // on the unit circle: one curve, whatever the separation asked
    const Vec3 b(std::cos(angle), std::sin(angle), 0), t_b(-std::sin(angle), std::cos(angle), 0);
    EXPECT_FALSE(OnTwoCurves(Vec3(1, 0, 0), y, b, t_b, TwoCurves{1e-6})) << angle;
  }
  // Parallel lines 0.1 apart: the seed across at 0.3 along is 18° off the tangents, at 1.0 along 6°.
  EXPECT_TRUE(OnTwoCurves(Vec3::Zero(), x, Vec3(0.3, 0.1, 0), -x, TwoCurves{0.09}));
  EXPECT_FALSE(OnTwoCurves(Vec3::Zero(), x, Vec3(0.3, 0.1, 0), -x, TwoCurves{0.09, 20.0})) << "tangents trusted to 10°";
  EXPECT_FALSE(OnTwoCurves(Vec3::Zero(), x, Vec3(0.3, 0.1, 0), x, TwoCurves{0.11})) << "closer than the separation asked";
  EXPECT_FALSE(OnTwoCurves(Vec3::Zero(), x, Vec3(1.0, 0.1, 0), x, TwoCurves{0.05}));
  EXPECT_FALSE(OnTwoCurves(Vec3::Zero(), x, Vec3(0.3, 0.1, 0), Vec3::Zero(), TwoCurves{0.05})) << "no tangent";
  EXPECT_FALSE(OnTwoCurves(Vec3::Zero(), x, Vec3(0.3, 0.1, 0), x, TwoCurves{})) << "off";
  // The feature-seed thinning keeps both rims' seeds with a separation, one of them without.
  const std::vector<Vec3> position = {{0, 0, 0}, {0.01, 0.015, 0}};
  const std::vector<uint8_t> rank = {2, 2};
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.03, {}, {x, x}, TwoCurves{0.01}), (std::vector<char>{0, 0}));
  EXPECT_EQ(SeedsBesideFeatures(position, rank, 0.03, {}, {x, x}, TwoCurves{}), (std::vector<char>{0, 1}));
}

// A plate whose edge faces are half a spacing wide: each of its 8 long rims gets its own chain of curve
// seeds (no gap over 2.5 spacings). Without the two-curve rule the rims of one edge face crowd each other
// out and share one chain, with gaps of several spacings on each. Three draws, of which two must pass: the
// optimizer is chaotic at this scale (an L1 step differing by 1e-6 of the diagonal gives another draw), and
// about one draw in eight leaves one gap of ~3 spacings on one rim (with the rule: 1.5 in 7 of draws 1-8; without:
// 5.8-12 in all; measured with 50 L-BFGS iterations per repulsion round and a slab 0.03 thick, which with the
// evener spacing of 3 iterations is just under 0.45 spacings: hence 0.034).
std::unique_ptr<MeshUdf> SlabUdf(double thickness) {
  TriangleMesh m;
  m.vertices = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0),
                Vec3(-1, -1, thickness), Vec3(1, -1, thickness), Vec3(1, 1, thickness), Vec3(-1, 1, thickness)};
  m.faces = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
             {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return std::make_unique<MeshUdf>(m, "slab");
}

TEST(OptimizeSeeds, BothRimsOfANarrowEdgeFaceGetAChain) {
  const double thickness = 0.034;
  const auto udf = SlabUdf(thickness);
  auto widest_gap = [&](const SeedCloud& in, double curve_separation) {
    OptimizeSeedsOptions options;
    options.curve_separation = curve_separation;
    const SeedCloud out = OptimizeSeeds(*udf, in, options, Monitor::Null());
    double spacing = 0.0;
    NearestNeighbourCv(out.position, &spacing);
    EXPECT_GT(thickness, 0.45 * spacing) << "the edge faces must be wide enough for two chains";
    double widest = 0.0;
    for (int axis = 0; axis < 2; ++axis)  // rims along x (at y = ±1) and along y (at x = ±1)
      for (double side : {-1.0, 1.0})
        for (double z : {0.0, thickness}) {
          std::vector<double> along = {-1.0, 1.0};
          for (size_t i = 0; i < out.size(); ++i) {
            const Vec3& p = out.position[i];
            if (out.rank[i] >= 2 && std::abs(p[1 - axis] - side) < 0.05 * spacing && std::abs(p.z() - z) < 0.05 * spacing)
              along.push_back(p[axis]);
          }
          std::sort(along.begin(), along.end());
          for (size_t k = 1; k < along.size(); ++k) widest = std::max(widest, (along[k] - along[k - 1]) / spacing);
        }
    return widest;
  };
  int chained = 0;
  for (uint64_t draw = 1; draw <= 3; ++draw) {
    const SeedCloud in = Initial(*udf, 800, draw);
    chained += widest_gap(in, 0.45) < 2.5;
    EXPECT_GT(widest_gap(in, 0.0), 4.0) << "the test needs rims that share a chain without the rule";
  }
  EXPECT_GE(chained, 2);
}

// The stopping rules fire before the caps: the inner loop at the first round whose projected gradient
// does not decrease by δ, the outer loop at the first iteration where σ stops growing and the spacing
// CV improves by less than outer_tol (and not before it).
TEST(OptimizeSeeds, StoppingRulesEndTheLoopsBeforeTheirCaps) {
  const auto sphere = MakeShape("sphere");
  const SeedCloud in = Initial(*sphere, 500, 5);
  OptimizeSeedsOptions options;
  options.seed = 2;
  options.max_outer_iters = 20;
  std::vector<OuterIterationReport> reports;
  OptimizeSeeds(*sphere, in, options, Monitor::Null(),
                [&](const OuterIterationReport& r, const SeedCloud&) { reports.push_back(r); });
  ASSERT_GE(reports.size(), 2u);
  EXPECT_LT(reports.size(), 20u) << "outer loop ran to its cap";
  size_t inner_before_cap = 0;
  for (const auto& r : reports) inner_before_cap += r.inner_rounds < options.max_inner_iters;
  EXPECT_GT(inner_before_cap, 0u) << "every inner loop ran to its cap";
  auto no_update = [&](size_t k) {
    return reports[k].sigma <= reports[k - 1].sigma * (1 + options.outer_tol) &&
           reports[k].spacing_cv >= reports[k - 1].spacing_cv * (1 - options.outer_tol);
  };
  const size_t last = reports.size() - 1;
  if (reports.size() < 20u) {
    EXPECT_TRUE(no_update(last) || reports[last].max_inner_move <= options.move_tol * reports[last].sigma);
    for (size_t k = 1; k < last; ++k) EXPECT_FALSE(no_update(k)) << "should have stopped after iteration " << k + 1;
  }
  EXPECT_LT(reports[last].spacing_cv, NearestNeighbourCv(in.position) / 2.0);
}

TEST(OptimizeSeeds, BadOptionsAndInputs) {
  OptimizeSeedsOptions o;
  o.gamma = 0;
  EXPECT_THROW(o.Check(), UsageError);
  o = OptimizeSeedsOptions();
  o.rank_threshold = 1.5;
  EXPECT_THROW(o.Check(), UsageError);
  o = OptimizeSeedsOptions();
  o.feature_clearance = 2;
  EXPECT_THROW(o.Check(), UsageError);
  o = OptimizeSeedsOptions();
  o.sigma_min_spacing = 0.8;  // above the cap of 0.5
  EXPECT_THROW(o.Check(), UsageError);
  o = OptimizeSeedsOptions();
  o.crease_angle_deg = 45;  // at or above 2 atan(0.4) = 43.6 degrees the two-plane test would never fire
  EXPECT_THROW(o.Check(), UsageError);
  o.crease_angle_deg = -1;
  EXPECT_THROW(o.Check(), UsageError);
  o.crease_angle_deg = 43;
  EXPECT_NO_THROW(o.Check());
  o = OptimizeSeedsOptions();
  o.feature_gap_max = 0.5;  // below a spacing every chain link would be a gap
  EXPECT_THROW(o.Check(), UsageError);
  o.feature_gap_max = 3.0;  // beyond the chain search radius no link is that long
  EXPECT_THROW(o.Check(), UsageError);
  o.feature_gap_max = 0.0;
  EXPECT_NO_THROW(o.Check());
  o = OptimizeSeedsOptions();
  o.sample_planes = "fitted";  // fit, gradient or auto
  EXPECT_THROW(o.Check(), UsageError);
  const auto sphere = MakeShape("sphere");
  SeedCloud one;
  one.Resize(1);
  EXPECT_THROW(OptimizeSeeds(*sphere, one, OptimizeSeedsOptions(), Monitor::Null()), InputError);
  SeedCloud twins;
  twins.Resize(2);
  twins.position[0] = twins.position[1] = Vec3(0.5, 0, 0);
  EXPECT_THROW(OptimizeSeeds(*sphere, twins, OptimizeSeedsOptions(), Monitor::Null()), InputError);
}

// ---------------------------------------------------------------------------------------------- executable

class OptimizeSeedsExe : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = RunProgram("sample-seeds", {"--udf", "shape:three-discs", "--count", "300", "--seed", "2", "--spread-pool", "1", "-o", seeds0_});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  std::vector<std::string> Args(const std::string& in, const std::string& out) {
    return {"--udf", "shape:three-discs", "-i", in, "-o", out, "--max-outer-iters", "3"};
  }
  TempDir dir_;
  TempDir inputs_;
  std::string seeds0_ = inputs_ / "seeds0.ply";
};

TEST_F(OptimizeSeedsExe, WritesSeedsOnTheSurfaceWithRanksAndATrace) {
  const std::string out = dir_ / "seeds.ply";
  auto args = Args(seeds0_, out);
  args.insert(args.end(), {"--trace", dir_ / "trace"});
  const auto r = RunProgram("optimize-seeds", args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("outer 1:"), std::string::npos) << r.err;
  const SeedCloud seeds = ReadSeeds(out);
  // Seeds crowding the curves and the point where the three curves meet are dropped, and said so; the
  // feature chains add a few where a curve's chain has a gap (309 at --seed 2 of sample-seeds).
  EXPECT_GE(seeds.size(), 265u);
  EXPECT_LE(seeds.size(), 330u);
  // The count is 300 less the seeds dropped and plus those added, each said (the fills inside the outer loop
  // at debug level): the thinning drops some here whatever the fills add.
  EXPECT_NE(r.err.find(" seeds dropped by the feature-seed thinning"), std::string::npos) << r.err;
  const auto udf = MakeShape("three-discs");
  size_t ranked = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    EXPECT_LT(udf->Distance(seeds.position[i]), 1e-5 * udf->Domain().Diagonal() + 1e-6);
    ranked += seeds.rank[i] >= 1;
  }
  EXPECT_EQ(ranked, seeds.size());
  // Outer iteration 1 keeps every seed; the chains are filled before iterations 2 and 3.
  EXPECT_EQ(ReadSeeds(dir_ / "trace/iter-001.ply").size(), 300u);
  for (const char* name : {"iter-002.ply", "iter-003.ply"})
    EXPECT_GE(ReadSeeds(dir_ / ("trace/" + std::string(name))).size(), 300u) << name;
  EXPECT_NE(test::ReadBytes(out).find("comment stage optimize-seeds"), std::string::npos);
  // --trace is debugging output: not in the provenance, and the output is the same bytes without it.
  EXPECT_EQ(test::ReadBytes(out).find("--trace"), std::string::npos);
  const std::string plain = dir_ / "plain.ply";
  const auto r2 = RunProgram("optimize-seeds", Args(seeds0_, plain));
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  EXPECT_EQ(test::ReadBytes(out), test::ReadBytes(plain));
}

TEST_F(OptimizeSeedsExe, SameSeedSameBytesWhateverTheThreadCount) {
  auto a = Args(seeds0_, dir_ / "a.ply");
  auto b = Args(seeds0_, dir_ / "b.ply");
  b.insert(b.end(), {"--threads", "1"});
  auto c = Args(seeds0_, dir_ / "c.ply");
  c.insert(c.end(), {"--seed", "9"});
  ASSERT_EQ(RunProgram("optimize-seeds", a).exit_code, 0);
  ASSERT_EQ(RunProgram("optimize-seeds", b).exit_code, 0);
  ASSERT_EQ(RunProgram("optimize-seeds", c).exit_code, 0);
  EXPECT_EQ(test::ReadBytes(dir_ / "a.ply"), test::ReadBytes(dir_ / "b.ply"));
  EXPECT_NE(test::ReadBytes(dir_ / "a.ply"), test::ReadBytes(dir_ / "c.ply"));
}

TEST_F(OptimizeSeedsExe, BadInputsExitThreeAndLeaveNoFile) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex ";
  const std::string props = "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  test::WriteBytes(inputs_ / "empty.ply", header + "0" + props);
  test::WriteBytes(inputs_ / "one.ply", header + "1" + props + "0.5 0 0\n");
  test::WriteBytes(inputs_ / "nan.ply", header + "3" + props + "0.5 0 0\nnan 0 0\n0 0.5 0\n");
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  mesh.faces = {{0, 1, 2}};
  WriteMeshPly(inputs_ / "mesh.ply", mesh, Provenance{"test", "", ""});
  for (const char* name : {"empty.ply", "one.ply", "nan.ply", "mesh.ply", "missing.ply"}) {
    const auto r = RunProgram("optimize-seeds", Args(inputs_ / name, dir_ / "out.ply"));
    EXPECT_EQ(r.exit_code, kExitBadInput) << name << ": " << r.err;
    EXPECT_NE(r.err.find("optimize-seeds: error:"), std::string::npos) << r.err;
    EXPECT_TRUE(dir_.List().empty()) << name << ": a failed run left a file behind";
  }
  const auto usage = RunProgram("optimize-seeds", {"--udf", "shape:cube", "-i", seeds0_, "-o", dir_ / "o.ply", "--gamma", "-1"});
  EXPECT_EQ(usage.exit_code, kExitUsage) << usage.err;
  EXPECT_TRUE(dir_.List().empty());
}

TEST_F(OptimizeSeedsExe, HelpExplainsTheOptions) {
  const auto r = RunProgram("optimize-seeds", {"--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--udf", "--input", "--output", "--samples-per-cell", "--gamma", "--delta", "--trace",
                           "--max-outer-iters", "--rank-threshold", "--crease-angle-deg", "--seed", "--threads"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

// The seed kd-tree against brute force in float coordinates (what the tree holds): the k nearest, nearest
// first, the query's own point included; every point within a radius, nearest first; k clamped to the size.
TEST(SeedIndex, AnswersAsBruteForceInFloat) {
  Rng rng(7, 0);
  std::vector<Vec3> points(2000);
  for (Vec3& p : points) p = Vec3(rng.Uniform(), rng.Uniform(), rng.Uniform());
  const SeedIndex index(points);
  auto squared = [&](const Vec3& q, size_t i) {
    float sum = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float d = static_cast<float>(points[i][a]) - static_cast<float>(q[a]);
      sum += d * d;
    }
    return sum;
  };
  std::vector<int> found;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 q = trial % 2 ? points[static_cast<size_t>(trial)] : Vec3(rng.Uniform(), rng.Uniform(), rng.Uniform());
    std::vector<std::pair<float, int>> all;
    for (size_t i = 0; i < points.size(); ++i) all.emplace_back(squared(q, i), static_cast<int>(i));
    std::sort(all.begin(), all.end());
    index.Nearest(q, 12, found);
    ASSERT_EQ(found.size(), 12u);
    for (size_t j = 0; j < found.size(); ++j) EXPECT_EQ(squared(q, static_cast<size_t>(found[j])), all[j].first);
    if (trial % 2) {
      EXPECT_EQ(found[0], trial);
    }
    const double radius = 0.08;
    index.WithinRadius(q, radius, found);
    const float radius_sq = static_cast<float>(radius * radius);
    const auto inside = static_cast<size_t>(
        std::count_if(all.begin(), all.end(), [&](const auto& e) { return e.first < radius_sq; }));
    ASSERT_EQ(found.size(), inside);
    for (size_t j = 0; j < found.size(); ++j) EXPECT_EQ(squared(q, static_cast<size_t>(found[j])), all[j].first);
  }
  index.Nearest(points[0], 5000, found);
  EXPECT_EQ(found.size(), points.size());
}

}  // namespace
}  // namespace voroudf

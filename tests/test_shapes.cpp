// Built-in analytic UDFs against closed-form distances, brute force over surface samples, finite
// differences of the distance, and the conventions on the surface and the medial axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "common/errors.h"
#include "common/rng.h"
#include "common/shapes.h"
#include "common/udf_spec.h"

namespace voroudf {
namespace {

double SphereD(const Vec3& p) { return std::abs(p.norm() - 0.5); }
double DiscD(double along_normal, double radial) {
  return std::hypot(std::max(radial - 0.5, 0.0), along_normal);
}
double DiscZ(const Vec3& p) { return DiscD(p.z(), std::hypot(p.x(), p.y())); }
double DiscX(const Vec3& p) { return DiscD(p.x(), std::hypot(p.y(), p.z())); }
double DiscY(const Vec3& p) { return DiscD(p.y(), std::hypot(p.z(), p.x())); }
double SquareD(double normal, double a, double b) {
  return std::sqrt(normal * normal + std::pow(std::max(std::abs(a) - 0.5, 0.0), 2) +
                   std::pow(std::max(std::abs(b) - 0.5, 0.0), 2));
}
double CubeD(const Vec3& p) {
  const Vec3 q = p.cwiseAbs() - Vec3::Constant(0.5);
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return std::abs(outside + inside);  // |signed distance to a box|
}
double HemisphereD(const Vec3& p) {
  if (p.z() >= 0) return SphereD(p);
  return std::hypot(std::hypot(p.x(), p.y()) - 0.5, p.z());  // below the cut: distance to the rim circle
}
double TorusD(const Vec3& p) { return std::abs(std::hypot(std::hypot(p.x(), p.y()) - 0.35, p.z()) - 0.15); }
double RingD(const Vec3& p) { return std::abs(std::hypot(std::hypot(p.x(), p.y()) - 0.48, p.z()) - 0.03); }

// shape:fold: the half square x in [-0.5, 0] of z = 0, and its mirror image turned up by 35° about the y axis
// (in coordinates along the turned half, u = x cos + z sin, w = -x sin + z cos).
double FoldD(const Vec3& p) {
  const double c = std::cos(35.0 * M_PI / 180.0), s = std::sin(35.0 * M_PI / 180.0);
  auto half = [](double u, double y, double w) {  // distance to [-0.5, 0] x [-0.5, 0.5] in the plane w = 0
    return std::sqrt(w * w + std::pow(std::max({u, -0.5 - u, 0.0}), 2) + std::pow(std::max(std::abs(y) - 0.5, 0.0), 2));
  };
  return std::min(half(p.x(), p.y(), p.z()), half(-(p.x() * c + p.z() * s), p.y(), -p.x() * s + p.z() * c));
}

// shape:feature-prism: |signed distance| to the solid prism |z| <= 0.3 over the polygon (docs/udf-sources.md),
// from the 2-D signed distance to the polygon (edges, crossing-number sign) and the slab's.
double FeaturePrismD(const Vec3& p) {
  const double xd = -0.5 + 0.6 * std::tan(20.0 * M_PI / 180.0);
  const std::vector<std::array<double, 2>> poly = {{-0.5, -0.5}, {0.44, -0.5}, {0.5, -0.44}, {0.5, -0.1}, {xd, -0.1}, {-0.5, 0.5}};
  double edge = INFINITY;
  bool inside = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const double ax = poly[j][0], ay = poly[j][1], bx = poly[i][0], by = poly[i][1];
    const double t = std::clamp(((p.x() - ax) * (bx - ax) + (p.y() - ay) * (by - ay)) /
                                    ((bx - ax) * (bx - ax) + (by - ay) * (by - ay)), 0.0, 1.0);
    edge = std::min(edge, std::hypot(p.x() - ax - t * (bx - ax), p.y() - ay - t * (by - ay)));
    if ((ay > p.y()) != (by > p.y()) && p.x() < ax + (p.y() - ay) * (bx - ax) / (by - ay)) inside = !inside;
  }
  const double d2 = inside ? -edge : edge, dz = std::abs(p.z()) - 0.3;
  return std::abs(std::hypot(std::max(d2, 0.0), std::max(dz, 0.0)) + std::min(std::max(d2, dz), 0.0));
}

struct Case {
  const char* name;
  std::function<double(const Vec3&)> exact;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      {"sphere", SphereD},
      {"cube", CubeD},
      {"feature-prism", FeaturePrismD},
      {"disc", DiscZ},
      {"hemisphere", HemisphereD},
      {"crossing-planes", [](const Vec3& p) { return std::min(SquareD(p.z(), p.x(), p.y()), SquareD(p.x(), p.y(), p.z())); }},
      {"sphere-disc", [](const Vec3& p) { return std::min(SphereD(p), DiscZ(p)); }},
      {"three-discs", [](const Vec3& p) { return std::min({DiscZ(p), DiscX(p), DiscY(p)}); }},
      {"torus", TorusD},
      {"sphere-ring", [](const Vec3& p) { return std::min(std::abs(p.norm() - 0.35), RingD(p)); }},
      {"fold", FoldD},
  };
  return cases;
}

class ShapeTest : public ::testing::TestWithParam<Case> {};

TEST_P(ShapeTest, DistanceMatchesClosedForm) {
  const auto udf = MakeShape(GetParam().name);
  Rng rng(1, 0);
  for (int i = 0; i < 4000; ++i) {
    const Vec3 p(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
    EXPECT_NEAR(udf->Distance(p), GetParam().exact(p), 1e-12) << p.transpose();
  }
}

TEST_P(ShapeTest, GradientIsUnitAndPointsAwayFromTheClosestPoint) {
  const auto udf = MakeShape(GetParam().name);
  Rng rng(2, 0);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
    Vec3 n;
    const double d = udf->Distance(p, &n);
    ASSERT_NEAR(n.norm(), 1.0, 1e-12);
    // x - d n is a surface point.
    EXPECT_LT(udf->Distance(p - d * n), 1e-12) << p.transpose();
  }
}

TEST_P(ShapeTest, GradientAgreesWithFiniteDifferencesAwayFromTheMedialAxis) {
  const auto udf = MakeShape(GetParam().name);
  Rng rng(3, 0);
  const double h = 1e-6;
  int checked = 0;
  for (int i = 0; i < 4000 && checked < 300; ++i) {
    const Vec3 p(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
    Vec3 n;
    const double d = udf->Distance(p, &n);
    if (d < 1e-3) continue;
    Vec3 fd;
    for (int k = 0; k < 3; ++k) {
      Vec3 e = Vec3::Zero();
      e[k] = h;
      fd[k] = (udf->Distance(p + e) - udf->Distance(p - e)) / (2 * h);
    }
    // On (or within h of) the medial axis the one-sided slopes differ and |fd| < 1: skip those.
    if (std::abs(fd.norm() - 1.0) > 1e-4) continue;
    EXPECT_LT((fd - n).norm(), 1e-4) << p.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

TEST_P(ShapeTest, SurfacePointsHaveZeroDistanceAndAUnitNormal) {
  const auto udf = MakeShape(GetParam().name);
  Rng rng(4, 0);
  for (int i = 0; i < 500; ++i) {
    Vec3 p(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
    Vec3 n;
    p -= udf->Distance(p, &n) * n;
    const double d = udf->Distance(p, &n);
    EXPECT_LT(d, 1e-12);
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
  }
}

INSTANTIATE_TEST_SUITE_P(AllShapes, ShapeTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           std::string n = param_info.param.name;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

TEST(Shapes, NearTheNonManifoldLineOfCrossingPlanes) {
  const auto udf = MakeShape("crossing-planes");
  Rng rng(5, 0);
  for (int i = 0; i < 1000; ++i) {
    const double ex = rng.Uniform(-1e-3, 1e-3), ez = rng.Uniform(-1e-3, 1e-3), y = rng.Uniform(-0.45, 0.45);
    const Vec3 p(ex, y, ez);
    Vec3 n;
    EXPECT_NEAR(udf->Distance(p, &n), std::min(std::abs(ex), std::abs(ez)), 1e-15);
    // The gradient points straight away from the nearer sheet.
    if (std::abs(ex) < std::abs(ez)) EXPECT_NEAR(std::abs(n.x()), 1.0, 1e-12);
    else EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-12);
  }
}

TEST(Shapes, NearTheNonManifoldCurvesOfThreeDiscsAndSphereDisc) {
  const auto discs = MakeShape("three-discs");
  const auto sd = MakeShape("sphere-disc");
  Rng rng(6, 0);
  for (int i = 0; i < 1000; ++i) {
    // Near the x axis (where the y=0 and z=0 discs cross).
    const Vec3 p(rng.Uniform(-0.45, 0.45), rng.Uniform(-1e-3, 1e-3), rng.Uniform(-1e-3, 1e-3));
    EXPECT_NEAR(discs->Distance(p), std::min({std::abs(p.y()), std::abs(p.z()), DiscX(p)}), 1e-15);
    // Near the equator of the sphere with the inner disc.
    const double t = rng.Uniform(0, 2 * M_PI), dr = rng.Uniform(-1e-3, 1e-3), dz = rng.Uniform(-1e-3, 1e-3);
    const Vec3 q((0.5 + dr) * std::cos(t), (0.5 + dr) * std::sin(t), dz);
    EXPECT_NEAR(sd->Distance(q), std::min(std::abs(q.norm() - 0.5), DiscZ(q)), 1e-15);
  }
}

TEST(Shapes, MedialAxisAndSurfaceConventions) {
  Vec3 n;
  // Centre of the sphere: every direction is a gradient; one unit vector is returned.
  EXPECT_DOUBLE_EQ(MakeShape("sphere")->Distance(Vec3::Zero(), &n), 0.5);
  EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  // Centre of the cube: distance 0.5 to all six faces.
  EXPECT_DOUBLE_EQ(MakeShape("cube")->Distance(Vec3::Zero(), &n), 0.5);
  EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  // On the disc the gradient is the disc's normal.
  EXPECT_EQ(MakeShape("disc")->Distance(Vec3(0.1, 0.2, 0.0), &n), 0.0);
  EXPECT_NEAR(std::abs(n.z()), 1.0, 1e-15);
  // On a cube corner: distance 0, a unit normal of one of the faces.
  EXPECT_EQ(MakeShape("cube")->Distance(Vec3(0.5, 0.5, 0.5), &n), 0.0);
  EXPECT_NEAR(n.cwiseAbs().maxCoeff(), 1.0, 1e-15);
}

TEST(Shapes, DomainAndSpecs) {
  const auto udf = OpenUdf("shape:torus");
  EXPECT_EQ(udf->Domain().min, Vec3::Constant(-0.6));
  EXPECT_EQ(udf->Domain().max, Vec3::Constant(0.6));
  EXPECT_NE(udf->Describe().find("shape:torus"), std::string::npos);
  try {
    OpenUdf("shape:dodecahedron");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("known: sphere, cube"), std::string::npos) << e.what();
  }
  EXPECT_THROW(OpenUdf("field.xyz"), InputError);
}

TEST(Shapes, BatchedEvaluationEqualsSingleQueries) {
  const auto udf = MakeShape("three-discs");
  Rng rng(8, 0);
  std::vector<Vec3> pts(10000);
  for (auto& p : pts) p = Vec3(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6));
  std::vector<double> d;
  std::vector<Vec3> g;
  udf->Evaluate(pts, d, g);
  for (size_t i = 0; i < pts.size(); i += 97) {
    Vec3 n;
    EXPECT_EQ(d[i], udf->Distance(pts[i], &n));
    EXPECT_EQ(g[i], n);
  }
}

}  // namespace
}  // namespace voroudf

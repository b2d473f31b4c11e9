// Grid UDF (common/grid_udf.h): a 64^3 sampled sphere reproduced to a stated tolerance, the gradient against
// finite differences of the interpolant, the .npy reader's refusals, the box sources, and sample-seeds end
// to end on a .npy file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/errors.h"
#include "common/grid_udf.h"
#include "common/rng.h"
#include "common/udf_spec.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;

const Box kBox{Vec3::Constant(-0.6), Vec3::Constant(0.6)};

double SphereD(const Vec3& p) { return std::abs(p.norm() - 0.5); }

std::vector<float> SampleSphere(size_t n, const Box& box = kBox) {
  std::vector<float> v(n * n * n);
  const Vec3 h = box.Extent() / double(n - 1);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      for (size_t k = 0; k < n; ++k)
        v[(i * n + j) * n + k] = static_cast<float>(SphereD(box.min + Vec3(i * h.x(), j * h.y(), k * h.z())));
  return v;
}

Vec3 RandomIn(Rng& rng, const Box& b) {
  return {rng.Uniform(b.min.x(), b.max.x()), rng.Uniform(b.min.y(), b.max.y()), rng.Uniform(b.min.z(), b.max.z())};
}

// The stated tolerances (docs/udf-sources.md): h = 1.2/63 = 0.019 on the 64^3 sphere.
TEST(GridUdf, SphereAt64IsReproducedToTheStatedTolerance) {
  const GridUdf udf(SampleSphere(64), {64, 64, 64}, kBox, {}, "sphere64");
  const double h = udf.spacing().x();
  Rng rng(1, 1);
  double max_far = 0, max_near = 0, max_angle_far = 0, max_angle_near = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 p = RandomIn(rng, kBox);
    Vec3 g;
    const double d = udf.Distance(p, &g);
    const double exact = SphereD(p);
    const double err = std::abs(d - exact);
    if (p.norm() < 0.1) continue;  // the cone point at the centre (medial axis), smeared over a few cells
    if (exact > 2 * h) {
      max_far = std::max(max_far, err);
      const Vec3 ge = (p.norm() > 0.5 ? 1.0 : -1.0) * p.normalized();
      max_angle_far = std::max(max_angle_far, std::acos(std::clamp(g.dot(ge), -1.0, 1.0)));
    } else {
      max_near = std::max(max_near, err);
      // Sign-blind: within a quarter cell of the sphere the normal comes from the Hessian, either way round.
      max_angle_near = std::max(max_angle_near, std::acos(std::min(1.0, std::abs(g.dot(p.normalized())))));
    }
  }
  // The zero set survives: d on the exact sphere.
  double max_on = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3 dir = Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1)).normalized();
    max_on = std::max(max_on, udf.Distance(0.5 * dir));
  }
  std::printf("grid 64^3 sphere, h = %.4f: max |err| %.2e (d > 2h), %.2e (d <= 2h), on the sphere %.2e; "
              "max gradient angle %.2e rad (d > 2h), %.2e rad (d <= 2h, sign-blind)\n", h, max_far, max_near, max_on,
              max_angle_far, max_angle_near);
  EXPECT_LT(max_far, 5e-5);
  EXPECT_LT(max_near, 1.5e-3);
  EXPECT_LT(max_on, 1.5e-3);
  EXPECT_LT(max_angle_far, 1e-2);
  EXPECT_LT(max_angle_near, 5e-2);
}

TEST(GridUdf, NodesAreInterpolatedExactly) {
  const std::vector<float> v = SampleSphere(16);
  const GridUdf udf(v, {16, 16, 16}, kBox, {}, "sphere16");
  const double h = udf.spacing().x();
  for (size_t i = 0; i < 16; i += 3)
    for (size_t j = 0; j < 16; j += 5)
      for (size_t k = 0; k < 16; ++k) {
        const double d = udf.Distance(kBox.min + h * Vec3(i, j, k));
        EXPECT_NEAR(d, v[(i * 16 + j) * 16 + k], 1e-6) << i << " " << j << " " << k;
      }
}

TEST(GridUdf, GradientAgreesWithFiniteDifferencesOfTheInterpolant) {
  // Anisotropic grid and box, so that a mix-up of axes or spacings would show.
  const Box box{Vec3(-0.6, -0.55, -0.7), Vec3(0.6, 0.65, 0.5)};
  const size_t nx = 40, ny = 33, nz = 47;
  std::vector<float> v(nx * ny * nz);
  for (size_t i = 0; i < nx; ++i)
    for (size_t j = 0; j < ny; ++j)
      for (size_t k = 0; k < nz; ++k) {
        const Vec3 p = box.min + Vec3(i * 1.2 / (nx - 1), j * 1.2 / (ny - 1), k * 1.2 / (nz - 1));
        v[(i * ny + j) * nz + k] = static_cast<float>(std::abs((p - Vec3(0.05, 0, -0.1)).norm() - 0.4));
      }
  const GridUdf udf(v, {nx, ny, nz}, box, {}, "aniso");
  Rng rng(2, 2);
  const double e = 1e-6;
  int checked = 0;
  // Points outside the box too (the extension d(clamp x) + |x - clamp x| has a consistent gradient).
  const Box wider = box.Inflated(0.2);
  for (int n = 0; n < 3000; ++n) {
    const Vec3 p = RandomIn(rng, wider);
    Vec3 g;
    const double d = udf.Distance(p, &g);
    // Near the zero set the gradient is the Hessian's normal, and the centre is the medial axis.
    if (d < 0.03 || (p - Vec3(0.05, 0, -0.1)).norm() < 0.1) continue;
    Vec3 fd;
    for (int k = 0; k < 3; ++k) fd[k] = (udf.Distance(p + e * Vec3::Unit(k)) - udf.Distance(p - e * Vec3::Unit(k))) / (2 * e);
    ++checked;
    ASSERT_LT((g - fd.normalized()).norm(), 1e-5) << p.transpose() << " g " << g.transpose() << " fd " << fd.transpose();
    if (box.Contains(p)) {
      ASSERT_NEAR(fd.norm(), 1.0, 0.05) << "a UDF's gradient has unit length";
    }
  }
  EXPECT_GT(checked, 2000);
}

TEST(GridUdf, OutsideTheBoxTheDistanceToTheBoxIsAdded) {
  const GridUdf udf(SampleSphere(32), {32, 32, 32}, kBox, {}, "sphere32");
  const Vec3 p(0.9, 0.0, 0.0);  // 0.3 past the face x = 0.6
  Vec3 g;
  EXPECT_NEAR(udf.Distance(p, &g), udf.Distance(Vec3(0.6, 0, 0)) + 0.3, 1e-12);
  EXPECT_NEAR(g.x(), 1.0, 1e-6);
}

TEST(GridUdf, GivenGradientArrayIsUsed) {
  const size_t n = 8;
  std::vector<float> grad(3 * n * n * n, 0.0f);
  for (size_t i = 0; i < n * n * n; ++i) grad[3 * i + 1] = 2.0f;  // +y everywhere, not unit length
  const GridUdf udf(SampleSphere(n), {n, n, n}, kBox, grad, "given");
  Vec3 g;
  udf.Distance(Vec3(0.3, 0.1, -0.2), &g);
  EXPECT_NEAR((g - Vec3::UnitY()).norm(), 0.0, 1e-9);
}

class GridFiles : public ::testing::Test {
 protected:
  std::string WriteSphere(const std::string& name, size_t n) {
    const std::string path = dir_ / name;
    WriteNpyFloat32(path, {n, n, n}, SampleSphere(n));
    return path;
  }
  TempDir dir_;
};

TEST_F(GridFiles, BoxFromOptionOrSidecarJsonAndGradientFile) {
  const std::string path = WriteSphere("s.npy", 24);
  UdfSourceOptions o;
  o.grid_box = "-0.6,-0.6,-0.6,0.6,0.6,0.6";
  const auto a = OpenUdf(path, o);
  EXPECT_EQ(a->Domain().min, kBox.min);
  EXPECT_NE(a->Describe().find("--udf-box"), std::string::npos);
  test::WriteBytes(dir_ / "s.json", "{\"note\": \"sampled sphere\",\n \"box\": [[-0.6, -0.6, -0.6], [0.6, 0.6, 0.6]]}\n");
  const auto b = OpenUdf(path);
  EXPECT_EQ(b->Domain().max, kBox.max);
  EXPECT_NEAR(a->Distance(Vec3(0.1, 0.2, 0.3)), b->Distance(Vec3(0.1, 0.2, 0.3)), 0.0);
  // --udf-normalize maps the box to [-0.5, 0.5]^3 and scales d.
  o.grid_box.clear();
  o.normalize = true;
  const auto c = OpenUdf(path, o);
  EXPECT_TRUE(c->Domain().max.isApprox(Vec3::Constant(0.5)));
  EXPECT_NEAR(c->Distance(Vec3(0.1, 0.2, 0.3)), b->Distance(1.2 * Vec3(0.1, 0.2, 0.3)) / 1.2, 1e-12);
  // A gradient file beside it is used.
  std::vector<float> grad(3 * 24 * 24 * 24, 0.0f);
  for (size_t i = 0; i < grad.size(); i += 3) grad[i + 2] = 1.0f;
  WriteNpyFloat32(dir_ / "s_grad.npy", {24, 24, 24, 3}, grad);
  Vec3 g;
  OpenUdf(path)->Distance(Vec3(0.3, 0.1, 0.0), &g);
  EXPECT_NEAR((g - Vec3::UnitZ()).norm(), 0.0, 1e-9);
  WriteNpyFloat32(dir_ / "s_grad.npy", {24, 24, 24}, std::vector<float>(24 * 24 * 24, 1.0f));
  EXPECT_THROW(OpenUdf(path), InputError);
}

TEST_F(GridFiles, WrongDtypeRankOrderBoxAndTruncationAreRefused) {
  UdfSourceOptions o;
  o.grid_box = "-1,-1,-1,1,1,1";
  // Missing box.
  const std::string ok = WriteSphere("ok.npy", 8);
  EXPECT_THROW(OpenUdf(ok), InputError);
  // Malformed --udf-box is a usage error; an empty box too.
  UdfSourceOptions bad = o;
  bad.grid_box = "0,0,0,1,1";
  EXPECT_THROW(OpenUdf(ok, bad), UsageError);
  bad.grid_box = "0,0,0,1,1,0";
  EXPECT_THROW(OpenUdf(ok, bad), UsageError);
  bad.grid_box = "0,0,0,1,1,x";
  EXPECT_THROW(OpenUdf(ok, bad), UsageError);
  // Malformed sidecar.
  test::WriteBytes(dir_ / "ok.json", "{\"box\": [[0,0,0],[1,1]]}");
  EXPECT_THROW(OpenUdf(ok), InputError);
  EXPECT_NO_THROW(OpenUdf(ok, o));
  // Wrong rank.
  WriteNpyFloat32(dir_ / "flat.npy", {8, 64}, std::vector<float>(512, 1.0f));
  EXPECT_THROW(OpenUdf(dir_ / "flat.npy", o), InputError);
  // Wrong dtype: a float64 array, written by hand as NumPy would.
  auto npy = [&](const std::string& name, const std::string& dict, size_t data_bytes) {
    std::string header = dict;
    header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');
    header += '\n';
    std::string bytes("\x93NUMPY\x01\x00", 8);
    bytes += static_cast<char>(header.size() & 0xff);
    bytes += static_cast<char>(header.size() >> 8);
    bytes += header + std::string(data_bytes, '\0');
    test::WriteBytes(dir_ / name, bytes);
    return dir_ / name;
  };
  EXPECT_NO_THROW(OpenUdf(npy("f4.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4, 4), }", 256), o));
  EXPECT_THROW(OpenUdf(npy("f8.npy", "{'descr': '<f8', 'fortran_order': False, 'shape': (4, 4, 4), }", 512), o), InputError);
  EXPECT_THROW(OpenUdf(npy("be.npy", "{'descr': '>f4', 'fortran_order': False, 'shape': (4, 4, 4), }", 256), o), InputError);
  EXPECT_THROW(OpenUdf(npy("ft.npy", "{'descr': '<f4', 'fortran_order': True, 'shape': (4, 4, 4), }", 256), o), InputError);
  EXPECT_THROW(OpenUdf(npy("short.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 4, 4), }", 255), o), InputError);
  EXPECT_THROW(OpenUdf(npy("thin.npy", "{'descr': '<f4', 'fortran_order': False, 'shape': (4, 1, 4), }", 64), o), InputError);
  test::WriteBytes(dir_ / "text.npy", "not numpy at all");
  EXPECT_THROW(OpenUdf(dir_ / "text.npy", o), InputError);
  EXPECT_THROW(OpenUdf(dir_ / "missing.npy", o), InputError);
  // NaN samples.
  std::vector<float> nan(64, 1.0f);
  nan[5] = NAN;
  WriteNpyFloat32(dir_ / "nan.npy", {4, 4, 4}, nan);
  EXPECT_THROW(OpenUdf(dir_ / "nan.npy", o), InputError);
}

TEST_F(GridFiles, ReadsWhatNumpyWritesWithTheDocumentedAxisConvention) {
  // NumPy itself writes the file (np.save, meshgrid 'ij'), a field that differs along each axis.
  const std::string script = dir_ / "make.py";
  test::WriteBytes(script,
                   "import numpy as np, sys\n"
                   "xs, ys, zs = np.linspace(-1, 1, 9), np.linspace(0, 2, 11), np.linspace(-3, 1, 13)\n"
                   "X, Y, Z = np.meshgrid(xs, ys, zs, indexing='ij')\n"
                   "np.save(sys.argv[1] + '/lin.npy', (1 + 0.1 * X + 0.2 * Y + 0.05 * Z).astype(np.float32))\n"
                   "np.save(sys.argv[1] + '/f8.npy', np.zeros((4, 4, 4)))\n"
                   "np.save(sys.argv[1] + '/ft.npy', np.asfortranarray(np.zeros((4, 5, 6), np.float32)))\n");
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script + " " + dir_.path()).c_str()), 0);
  UdfSourceOptions o;
  o.grid_box = "-1,0,-3,1,2,1";
  const auto udf = OpenUdf(dir_ / "lin.npy", o);
  // d = 1 + 0.1 x + 0.2 y + 0.05 z is reproduced (d^2 is quadratic: Keys' kernel is exact) with its gradient.
  Rng rng(9, 9);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p = RandomIn(rng, udf->Domain());
    Vec3 g;
    EXPECT_NEAR(udf->Distance(p, &g), 1 + 0.1 * p.x() + 0.2 * p.y() + 0.05 * p.z(), 1e-6) << p.transpose();
    EXPECT_LT((g - Vec3(0.1, 0.2, 0.05).normalized()).norm(), 1e-5);
  }
  EXPECT_THROW(OpenUdf(dir_ / "f8.npy", o), InputError);
  EXPECT_THROW(OpenUdf(dir_ / "ft.npy", o), InputError);
}

TEST_F(GridFiles, SampleSeedsRunsOnAGridAndRefusesABadOne) {
  const std::string path = WriteSphere("sphere.npy", 64);
  test::WriteBytes(dir_ / "sphere.json", "{\"box\": [[-0.6,-0.6,-0.6],[0.6,0.6,0.6]]}");
  // A sampled field only reaches zero to its reproduction error (~1e-3 here): the projection tolerance
  // must be at that scale.
  const auto r = RunProgram("sample-seeds", {"--udf", path, "--count", "400", "--seed", "2", "--proj-tol-rel", "1e-3",
                                             "-o", dir_ / "seeds.ply"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("domain [-0.6,-0.6,-0.6]-[0.6,0.6,0.6]"), std::string::npos) << r.err;
  const SeedCloud seeds = ReadSeeds(dir_ / "seeds.ply");
  EXPECT_GT(seeds.size(), 380u);
  for (size_t i = 0; i < seeds.size(); ++i) {
    EXPECT_LT(SphereD(seeds.position[i]), 3e-3);
    EXPECT_NEAR(std::abs(seeds.normal[i].dot(seeds.position[i].normalized())), 1.0, 1e-2);
  }
  const auto f = RunProgram("sample-seeds", {"--udf", dir_ / "nojson.npy", "-o", dir_ / "x.ply"});
  EXPECT_EQ(f.exit_code, 3);
  WriteNpyFloat32(dir_ / "rank2.npy", {8, 64}, std::vector<float>(512, 1.0f));
  const auto g = RunProgram("sample-seeds", {"--udf", dir_ / "rank2.npy", "--udf-box", "0,0,0,1,1,1", "-o", dir_ / "x.ply"});
  EXPECT_EQ(g.exit_code, 3) << g.err;
  EXPECT_NE(g.err.find("rank 2"), std::string::npos) << g.err;
  const auto u = RunProgram("sample-seeds", {"--udf", path, "--udf-box", "0,0,0,1,1", "-o", dir_ / "x.ply"});
  EXPECT_EQ(u.exit_code, 2) << u.err;
  EXPECT_FALSE(test::Exists(dir_ / "x.ply"));
}

}  // namespace
}  // namespace voroudf

#include "common/noisy_udf.h"

#include <cmath>
#include <sstream>
#include <vector>

#include "common/errors.h"
#include "common/rng.h"
#include "common/udf_spec.h"

namespace voroudf {
namespace {

// Written by hand: no installed library has a seeded, stateless smooth noise. Value noise on a lattice
// (Perlin's "value noise" variant): a random number per lattice node from a hash of (seed, field, node), blended
// with C2 quintic weights w_i over the 8 nodes of the cell. Dividing by sqrt(sum w_i^2) makes the blend of
// unit-variance node values unit-variance at *every* point, not only at the nodes.
class LatticeNoise {
 public:
  LatticeNoise(uint64_t seed, double spacing, const Vec3& origin)
      : seed_(seed), inv_spacing_(1.0 / spacing), origin_(origin) {}

  // Four smooth fields at p: [0] zero mean, unit variance, approximately Gaussian (Irwin-Hall of four
  // uniforms per node); [1..3] a vector whose direction is isotropic (uniform node values in [-1, 1]^3).
  void Fields(const Vec3& p, double* value, Vec3* direction) const {
    const Vec3 q = (p - origin_) * inv_spacing_;
    const Vec3 floor_q(std::floor(q.x()), std::floor(q.y()), std::floor(q.z()));
    const Vec3 f = q - floor_q;
    double w[3][2];
    for (int a = 0; a < 3; ++a) {
      const double t = f[a], s = t * t * t * (t * (t * 6 - 15) + 10);  // quintic fade: C2 across cells
      w[a][0] = 1 - s;
      w[a][1] = s;
    }
    const auto ix = static_cast<int64_t>(floor_q.x()), iy = static_cast<int64_t>(floor_q.y()),
               iz = static_cast<int64_t>(floor_q.z());
    double sum_v = 0, sum_w2 = 0;
    Vec3 sum_d = Vec3::Zero();
    for (int c = 0; c < 8; ++c) {
      const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
      const double weight = w[0][dx] * w[1][dy] * w[2][dz];
      const uint64_t node = Hash(ix + dx, iy + dy, iz + dz);
      const uint64_t h1 = SplitMix64(node), h2 = SplitMix64(node ^ 0xD1B54A32D192ED03ull);
      double irwin_hall = 0;
      for (int k = 0; k < 4; ++k) irwin_hall += static_cast<double>((h1 >> (16 * k)) & 0xFFFF) / 65535.0;
      sum_v += weight * (irwin_hall - 2.0) * std::sqrt(3.0);  // 4 uniforms: mean 2, variance 1/3
      for (int a = 0; a < 3; ++a)
        sum_d[a] += weight * (static_cast<double>((h2 >> (21 * a)) & 0x1FFFFF) / 1048575.5 - 1.0);
      sum_w2 += weight * weight;
    }
    *value = sum_v / std::sqrt(sum_w2);
    *direction = sum_d;
  }

 private:
  uint64_t Hash(int64_t x, int64_t y, int64_t z) const {
    uint64_t h = SplitMix64(seed_ ^ 0x6A09E667F3BCC909ull);
    h = SplitMix64(h ^ static_cast<uint64_t>(x));
    h = SplitMix64(h ^ static_cast<uint64_t>(y));
    return SplitMix64(h ^ static_cast<uint64_t>(z));
  }

  uint64_t seed_;
  double inv_spacing_;
  Vec3 origin_;
};

class NoisyUdf : public Udf {
 public:
  NoisyUdf(std::unique_ptr<Udf> inner, const UdfNoise& noise)
      : inner_(std::move(inner)),
        noise_(noise),
        diagonal_(inner_->Domain().Diagonal()),
        // A lattice offset drawn from the seed, so that nodes do not line up with an axis-aligned surface.
        lattice_(noise.seed, noise.scale_rel * diagonal_, Offset(noise.seed, noise.scale_rel * diagonal_)),
        cos_a_(std::cos(noise.grad_deg * M_PI / 180.0)),
        sin_a_(std::sin(noise.grad_deg * M_PI / 180.0)) {}

  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    inner_->EvaluateChunk(points, count, distance, gradient);
    Perturb(points, count, distance, gradient);
  }
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override {
    inner_->Evaluate(points, count, distance, gradient);
    const auto n = static_cast<int64_t>(count);
    constexpr int64_t kChunk = 4096;
#pragma omp parallel for schedule(static) if (n > kChunk)
    for (int64_t begin = 0; begin < n; begin += kChunk)
      Perturb(points + begin, static_cast<size_t>(std::min(kChunk, n - begin)), distance + begin, gradient + begin);
  }
  using Udf::Evaluate;
  Box Domain() const override { return inner_->Domain(); }
  std::string Describe() const override {
    std::ostringstream out;
    out << "noisy (value " << noise_.value_rel << " x diagonal = " << noise_.value_rel * diagonal_ << ", gradient "
        << noise_.grad_deg << " deg, correlation length " << noise_.scale_rel * diagonal_ << ", seed " << noise_.seed
        << ") " << inner_->Describe();
    return out.str();
  }

 private:
  static Vec3 Offset(uint64_t seed, double spacing) {
    Rng rng(seed, 0x4E4F495345ull);
    return Vec3(rng.Uniform(), rng.Uniform(), rng.Uniform()) * spacing;
  }

  void Perturb(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
    const double sigma = noise_.value_rel * diagonal_;
    for (size_t i = 0; i < count; ++i) {
      double n;
      Vec3 direction;
      lattice_.Fields(points[i], &n, &direction);
      const double shifted = distance[i] + sigma * n;
      distance[i] = std::abs(shifted);
      Vec3& g = gradient[i];
      if (shifted < 0) g = -g;  // the nearest zero of |d + e| now lies the other way
      if (noise_.grad_deg == 0.0 || g.squaredNorm() == 0.0) continue;
      Vec3 across = direction - direction.dot(g) * g;
      if (across.squaredNorm() < 1e-24) across = g.unitOrthogonal();
      g = cos_a_ * g + sin_a_ * across.normalized();
    }
  }

  std::unique_ptr<Udf> inner_;
  UdfNoise noise_;
  double diagonal_;
  LatticeNoise lattice_;
  double cos_a_, sin_a_;
};

}  // namespace

void UdfNoise::Check() const {
  if (!(value_rel >= 0.0 && value_rel <= 1.0)) throw UsageError("noisy: value= must be in [0, 1] (of the diagonal)");
  if (!(grad_deg >= 0.0 && grad_deg <= 90.0)) throw UsageError("noisy: grad= must be in [0, 90] degrees");
  if (!(scale_rel > 0.0 && scale_rel <= 10.0)) throw UsageError("noisy: scale= must be in (0, 10] (of the diagonal)");
}

UdfNoise ParseUdfNoise(const std::string& options) {
  UdfNoise noise;
  std::istringstream items(options);
  std::string item;
  while (std::getline(items, item, ',')) {
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq), text = eq == std::string::npos ? "" : item.substr(eq + 1);
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (eq == std::string::npos || used != text.size() || text.empty())
      throw UsageError("noisy: '" + item + "' is not KEY=NUMBER (keys: value, grad, scale, seed)");
    if (key == "value") noise.value_rel = value;
    else if (key == "grad") noise.grad_deg = value;
    else if (key == "scale") noise.scale_rel = value;
    else if (key == "seed" && value >= 0 && value < 9.0e15 && value == std::floor(value)) noise.seed = static_cast<uint64_t>(value);
    else if (key == "seed") throw UsageError("noisy: seed= must be a whole number >= 0");
    else throw UsageError("noisy: unknown key '" + key + "' (keys: value, grad, scale, seed)");
  }
  noise.Check();
  return noise;
}

std::unique_ptr<Udf> MakeNoisyUdf(std::unique_ptr<Udf> inner, const UdfNoise& noise) {
  noise.Check();
  return std::make_unique<NoisyUdf>(std::move(inner), noise);
}

}  // namespace voroudf

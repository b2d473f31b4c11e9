#include "stages/sample-seeds/thin_sizing.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/rng.h"

namespace voroudf {

namespace {
// The spacing asked for where the part is thin, as a share of its thickness: a tube 2r across gets
// 2πr / (2r/3) ≈ 9 seeds around it, which build-gvd's dual closes (six leave it open in some draws).
constexpr double kThinSpacing = 1.0 / 3.0;
double ProbeLength(double h, int k) { return h * std::pow(2.0, -0.5 * k); }
}  // namespace

std::vector<double> ProbeThickness(const Udf& udf, const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                   double h) {
  // Lengths h·2^(−k/2): a probe flags a sheet D away along the normal when s lies in (D/1.9, D) (past the
  // medial point, before the far sheet), a range wider than the √2 between lengths, so no D in
  // (0.17 h, 1.9 h) falls between two probes. Longer probes would also see gaps between parts (a UDF has no
  // inside), such as the one between shape:sphere-ring's sphere and ring, and take seeds there.
  constexpr int kLengths = 8;
  const size_t n = points.size();
  std::vector<Vec3> probes(n * 2 * kLengths);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < kLengths; ++k)
      for (int side = 0; side < 2; ++side)
        probes[(i * kLengths + k) * 2 + side] = points[i] + (side ? -1.0 : 1.0) * ProbeLength(h, k) * normals[i];
  std::vector<double> d;
  std::vector<Vec3> g;
  udf.Evaluate(probes, d, g);
  std::vector<double> thickness(n, std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < n; ++i) {
    if (normals[i].squaredNorm() == 0.0) continue;
    for (int k = 0; k < kLengths; ++k) {
      const double s = ProbeLength(h, k);
      for (int side = 0; side < 2; ++side) {
        const size_t q = (i * kLengths + k) * 2 + side;
        const Vec3 out = (side ? -1.0 : 1.0) * normals[i];
        if (d[q] < 0.9 * s && g[q].dot(out) < -0.5) thickness[i] = 1.6 * s;
      }
    }
  }
  return thickness;
}

std::vector<double> ThinSeedWeights(const std::vector<double>& thickness, double h, double max_boost) {
  std::vector<double> weight(thickness.size(), 1.0);
  for (size_t i = 0; i < thickness.size(); ++i)
    if (std::isfinite(thickness[i])) weight[i] = std::clamp(std::pow(h / (kThinSpacing * thickness[i]), 2), 1.0, max_boost);
  return weight;
}

std::vector<size_t> ChooseWeighted(const std::vector<double>& weight, size_t count, uint64_t seed) {
  // Efraimidis & Spirakis (2006), "Weighted random sampling with a reservoir": the count largest keys
  // u^(1/w), compared as log(u)/w.
  std::vector<std::pair<double, size_t>> keys(weight.size());
  for (size_t i = 0; i < weight.size(); ++i) {
    Rng rng(seed ^ 0x7468696E5F736565ull, i);  // a stream of its own, apart from the draws
    keys[i] = {std::log(std::max(rng.Uniform(), 1e-300)) / weight[i], i};
  }
  const size_t take = std::min(count, keys.size());
  std::partial_sort(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(take), keys.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  std::vector<size_t> chosen(take);
  for (size_t k = 0; k < take; ++k) chosen[k] = keys[k].second;
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace voroudf

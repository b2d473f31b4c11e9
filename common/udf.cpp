#include "common/udf.h"

#include <algorithm>

namespace voroudf {

void Udf::Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  constexpr size_t kChunk = 256;
  const long chunks = static_cast<long>((count + kChunk - 1) / kChunk);
#pragma omp parallel for schedule(dynamic, 4)
  for (long c = 0; c < chunks; ++c) {
    const size_t begin = static_cast<size_t>(c) * kChunk;
    const size_t n = std::min(kChunk, count - begin);
    EvaluateChunk(points + begin, n, distance + begin, gradient + begin);
  }
}

void Udf::Evaluate(const std::vector<Vec3>& points, std::vector<double>& distance, std::vector<Vec3>& gradient) const {
  distance.resize(points.size());
  gradient.resize(points.size());
  Evaluate(points.data(), points.size(), distance.data(), gradient.data());
}

double Udf::Distance(const Vec3& p) const {
  Vec3 g;
  return Distance(p, &g);
}

double Udf::Distance(const Vec3& p, Vec3* gradient) const {
  double d = 0.0;
  EvaluateChunk(&p, 1, &d, gradient);
  return d;
}

}  // namespace voroudf

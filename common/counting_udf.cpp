#include "common/counting_udf.h"

#include <chrono>
#include <cstdio>

namespace voroudf {

namespace {

// Adds one call of `count` points that started at `start` to `usage`.
void Count(UdfUsage& usage, size_t count, std::chrono::steady_clock::time_point start) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
  usage.queries.fetch_add(count, std::memory_order_relaxed);
  usage.batches.fetch_add(1, std::memory_order_relaxed);
  usage.nanoseconds.fetch_add(static_cast<uint64_t>(ns), std::memory_order_relaxed);
}

// The three counters through `format` (two %llu, one %.3f).
std::string Format(const UdfUsage& usage, const char* format) {
  char line[160];
  std::snprintf(line, sizeof line, format, static_cast<unsigned long long>(usage.queries.load()),
                static_cast<unsigned long long>(usage.batches.load()), 1e-9 * static_cast<double>(usage.nanoseconds.load()));
  return line;
}

}  // namespace

std::string UdfUsage::Summary() const { return Format(*this, "%llu queries in %llu batches, %.3f s inside the UDF"); }

std::string UdfUsage::Tsv() const {
  return Format(*this, "udf_queries\tudf_batches\tudf_seconds\n%llu\t%llu\t%.3f\n");
}

CountingUdf::CountingUdf(std::unique_ptr<Udf> inner, std::shared_ptr<UdfUsage> usage)
    : inner_(std::move(inner)), usage_(std::move(usage)) {}

void CountingUdf::EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  const auto start = std::chrono::steady_clock::now();
  inner_->EvaluateChunk(points, count, distance, gradient);
  Count(*usage_, count, start);
}

void CountingUdf::Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  const auto start = std::chrono::steady_clock::now();
  inner_->Evaluate(points, count, distance, gradient);
  Count(*usage_, count, start);
}

}  // namespace voroudf

#pragma once
// The UDF queries a stage makes: every stage's source is wrapped so that it can report, at the end, how many
// points it asked for, in how many calls, and how long it waited (docs/conventions.md, "UDF usage"). For a
// learned UDF behind exec:, queries are the cost that matters.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "common/udf.h"

namespace voroudf {

/// Counters shared by a CountingUdf and whoever reports them. Thread-safe.
struct UdfUsage {
  std::atomic<uint64_t> queries{0};      ///< points evaluated
  std::atomic<uint64_t> batches{0};      ///< calls to Evaluate (one exec: round trip or more) or EvaluateChunk
  std::atomic<uint64_t> nanoseconds{0};  ///< time inside those calls, summed (concurrent calls add up)

  /// "Q queries in B batches, S s inside the UDF".
  std::string Summary() const;
  /// Two lines: the header "udf_queries\tudf_batches\tudf_seconds" and the values.
  std::string Tsv() const;
};

/// Forwards every call to `inner` and counts it in `usage`. Batches go to inner's own Evaluate, so a
/// source that sends a batch as large requests (exec:) still does.
class CountingUdf : public Udf {
 public:
  CountingUdf(std::unique_ptr<Udf> inner, std::shared_ptr<UdfUsage> usage);
  void EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  void Evaluate(const Vec3* points, size_t count, double* distance, Vec3* gradient) const override;
  using Udf::Evaluate;
  Box Domain() const override { return inner_->Domain(); }
  std::string Describe() const override { return inner_->Describe(); }

 private:
  std::unique_ptr<Udf> inner_;
  std::shared_ptr<UdfUsage> usage_;
};

}  // namespace voroudf

#pragma once
// `noisy:OPTIONS:SPEC`: any UDF with controlled errors, for measuring how the stages degrade on learned
// fields (docs/udf-sources.md, "Noisy"). The perturbation is a fixed function of the point and the
// noise seed — like a trained network, asking twice at one point gives the same answer — so results stay
// deterministic and independent of batching and threads.
#include <cstdint>
#include <memory>
#include <string>

#include "common/udf.h"

namespace voroudf {

/// What `noisy:` adds. Lengths are fractions of the inner source's domain diagonal, like every relative
/// length in voroudf.
struct UdfNoise {
  double value_rel = 0.0;   ///< value=: standard deviation of the distance error
  double grad_deg = 0.0;    ///< grad=: every non-zero gradient turned by exactly this angle (degrees, 0..90)
  double scale_rel = 0.02;  ///< scale=: correlation length of both errors (their lattice spacing)
  uint64_t seed = 0;        ///< seed=: which noise field

  /// Throws UsageError for values out of range.
  void Check() const;
};

/// Parses "value=1e-3,grad=15,scale=0.02,seed=0" (every key optional, any order). Throws UsageError naming
/// the bad item.
UdfNoise ParseUdfNoise(const std::string& options);

/// Wraps `inner`: with n(x) a smooth random field of zero mean and unit variance and t(x) a smooth random
/// unit direction (both from `noise.seed`, varying over `scale_rel` of the diagonal D),
///   d'(x) = |d(x) + value_rel * D * n(x)|,
///   g'(x) = cos(a) s g + sin(a) t_perp,  s = sign(d + value_rel D n), a = grad_deg, t_perp = t made normal to g.
/// Value and gradient errors are independent, so a study can vary each alone. Batches are forwarded whole.
std::unique_ptr<Udf> MakeNoisyUdf(std::unique_ptr<Udf> inner, const UdfNoise& noise);

}  // namespace voroudf

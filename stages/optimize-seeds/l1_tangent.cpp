#include "stages/optimize-seeds/l1_tangent.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace voroudf {

double L1TangentObjective(const L1TangentProblem& problem, const Vec3& y) {
  double sum = 0.0;
  for (size_t m = 0; m < problem.a.size(); ++m) sum += std::abs(problem.a[m].dot(y) - problem.b[m]);
  return sum + problem.gamma * y.squaredNorm();
}

namespace {

// Largest t in [0, 1] with c_kᵀ(t y) ≤ h_k for all k (y = 0 is strictly feasible).
double FeasibleScale(const L1TangentProblem& p, const Vec3& y) {
  double t = 1.0;
  for (size_t k = 0; k < p.c.size(); ++k) {
    const double cy = p.c[k].dot(y);
    if (cy > p.h[k]) t = std::min(t, p.h[k] / cy);
  }
  return t;
}

}  // namespace

L1TangentSolution SolveL1Tangent(const L1TangentProblem& p, const L1TangentOptions& options) {
  const size_t m_count = p.a.size();
  const size_t k_count = p.c.size();
  const double two_gamma = 2.0 * p.gamma;
  std::vector<double> u(m_count, 0.0), lambda(k_count, 0.0);
  Vec3 w = Vec3::Zero();  // Aᵀu + Cᵀλ, kept up to date incrementally

  L1TangentSolution best;
  best.primal = L1TangentObjective(p, Vec3::Zero());
  best.dual = -INFINITY;
  double dual_linear = 0.0;  // uᵀb + λᵀh, kept up to date too
  for (int sweep = 1; sweep <= options.max_sweeps; ++sweep) {
    for (size_t m = 0; m < m_count; ++m) {
      const double aa = p.a[m].squaredNorm();
      if (aa == 0.0) continue;
      // dD/du_m = −a_mᵀw/(2γ) − b_m; curvature −‖a_m‖²/(2γ): the exact 1-D maximiser, clipped.
      const double target = std::clamp(u[m] + options.relaxation * (-p.a[m].dot(w) - two_gamma * p.b[m]) / aa, -1.0, 1.0);
      const double step = target - u[m];
      if (step == 0.0) continue;
      u[m] = target;
      w += step * p.a[m];
      dual_linear += step * p.b[m];
    }
    for (size_t k = 0; k < k_count; ++k) {
      const double cc = p.c[k].squaredNorm();
      if (cc == 0.0) continue;
      const double target = std::max(0.0, lambda[k] + options.relaxation * (-p.c[k].dot(w) - two_gamma * p.h[k]) / cc);
      const double step = target - lambda[k];
      if (step == 0.0) continue;
      lambda[k] = target;
      w += step * p.c[k];
      dual_linear += step * p.h[k];
    }
    // Recompute the linear term exactly now and then so that rounding in the running sum cannot build up.
    if (sweep % 64 == 0) {
      dual_linear = 0.0;
      for (size_t m = 0; m < m_count; ++m) dual_linear += u[m] * p.b[m];
      for (size_t k = 0; k < k_count; ++k) dual_linear += lambda[k] * p.h[k];
    }
    const double dual = -w.squaredNorm() / (2.0 * two_gamma) - dual_linear;
    const Vec3 y_free = -w / two_gamma;
    const Vec3 y = FeasibleScale(p, y_free) * y_free;
    const double primal = L1TangentObjective(p, y);
    best.sweeps = sweep;
    best.dual = std::max(best.dual, dual);
    if (primal <= best.primal) {
      best.primal = primal;
      best.y = y;
    }
    if (best.primal - best.dual <= options.gap_tolerance) {
      best.converged = true;
      break;
    }
  }
  return best;
}

TangentRank ComputeTangentRank(const Vec3* normals, size_t count, double tau) {
  TangentRank result;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  for (size_t m = 0; m < count; ++m) ata.noalias() += normals[m] * normals[m].transpose();
  if (!(ata.trace() > 0.0)) return result;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(ata);
  // Eigen sorts eigenvalues increasingly; singular values are their square roots, wanted decreasing.
  for (int k = 0; k < 3; ++k) {
    result.singular_values[k] = std::sqrt(std::max(0.0, eig.eigenvalues()[2 - k]));
    result.v.col(k) = eig.eigenvectors().col(2 - k);
  }
  result.rank = 0;
  for (int k = 0; k < 3; ++k)
    if (result.singular_values[k] > tau * result.singular_values[0]) ++result.rank;
  return result;
}

}  // namespace voroudf

#include "stages/optimize-seeds/l1_tangent.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace voroudf {

void L1TangentProblem::AddTerm(const Vec3& a_m, double b_m, double tolerance) {
  if (w.size() < a.size()) w.resize(a.size(), 1.0);
  for (size_t k = 0; k < a.size(); ++k) {
    if (std::abs(b[k] - b_m) <= tolerance && (a[k] - a_m).lpNorm<Eigen::Infinity>() <= tolerance) {
      w[k] += 1.0;
      return;
    }
  }
  a.push_back(a_m);
  b.push_back(b_m);
  w.push_back(1.0);
}

namespace {

// w_m, the weight of term m (1 when the problem has no weights).
double Weight(const L1TangentProblem& p, size_t m) { return p.w.empty() ? 1.0 : p.w[m]; }

}  // namespace

double L1TangentObjective(const L1TangentProblem& problem, const Vec3& y) {
  double sum = 0.0;
  for (size_t m = 0; m < problem.a.size(); ++m)
    sum += Weight(problem, m) * std::abs(problem.a[m].dot(y) - problem.b[m]);
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

L1TangentSolution SolveL1TangentByCoordinateAscent(const L1TangentProblem& p, const L1TangentOptions& options) {
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
      const double bound = Weight(p, m);
      const double target = std::clamp(u[m] + options.relaxation * (-p.a[m].dot(w) - two_gamma * p.b[m]) / aa, -bound, bound);
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

double L1TangentDual(const L1TangentProblem& p, const std::vector<double>& u, const std::vector<double>& lambda) {
  Vec3 w = Vec3::Zero();
  double linear = 0.0;
  for (size_t m = 0; m < p.a.size(); ++m) {
    w += u[m] * p.a[m];
    linear += u[m] * p.b[m];
  }
  for (size_t k = 0; k < p.c.size(); ++k) {
    w += lambda[k] * p.c[k];
    linear += lambda[k] * p.h[k];
  }
  return -w.squaredNorm() / (4.0 * p.gamma) - linear;
}

// Cyclic coordinate ascent sweeps on D from (u, λ) (each coordinate's exact 1-D maximiser, clipped to its
// interval); D never decreases. Returns D at the end.
double AscendDual(const L1TangentProblem& p, std::vector<double>& u, std::vector<double>& lambda, int sweeps) {
  const double two_gamma = 2.0 * p.gamma;
  Vec3 w = Vec3::Zero();
  for (size_t m = 0; m < p.a.size(); ++m) w += u[m] * p.a[m];
  for (size_t k = 0; k < p.c.size(); ++k) w += lambda[k] * p.c[k];
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    for (size_t m = 0; m < p.a.size(); ++m) {
      const double bound = Weight(p, m);
      const double target = std::clamp(u[m] + (-p.a[m].dot(w) - two_gamma * p.b[m]) / p.a[m].squaredNorm(), -bound, bound);
      w += (target - u[m]) * p.a[m];
      u[m] = target;
    }
    for (size_t k = 0; k < p.c.size(); ++k) {
      const double target = std::max(0.0, lambda[k] + (-p.c[k].dot(w) - two_gamma * p.h[k]) / p.c[k].squaredNorm());
      w += (target - lambda[k]) * p.c[k];
      lambda[k] = target;
    }
  }
  return L1TangentDual(p, u, lambda);
}

namespace {

// The barrier function τ (Σ w_m t_m + γ‖y‖²) − Σ log s over the slacks s of the L1 problem's constraints;
// false where a slack is not positive.
bool BarrierValue(const L1TangentProblem& p, double tau, const Vec3& y, const std::vector<double>& t, double* value) {
  // Σ log s as the log of running products (flushed long before they could under- or overflow): the
  // line search evaluates this often, and std::log was 12 % of the stage's time (perf, fandisk 3k).
  double f = p.gamma * y.squaredNorm(), logs = 0.0, product = 1.0;
  auto take = [&](double slack) {
    product *= slack;
    if (product < 1e-150 || product > 1e150) {
      logs += std::log(product);
      product = 1.0;
    }
  };
  for (size_t m = 0; m < p.a.size(); ++m) {
    const double rm = p.a[m].dot(y) - p.b[m];
    const double sp = t[m] - rm, sm = t[m] + rm;
    if (!(sp > 0.0 && sm > 0.0)) return false;
    f += Weight(p, m) * t[m];
    take(sp);
    take(sm);
  }
  for (size_t k = 0; k < p.c.size(); ++k) {
    const double sk = p.h[k] - p.c[k].dot(y);
    if (!(sk > 0.0)) return false;
    take(sk);
  }
  logs += std::log(product);
  *value = tau * f - logs;
  return true;
}

// One damped Newton step on the barrier at τ from (y, t). Newton's system in (y, t) has a diagonal t-block,
// so eliminating t leaves a 3×3 system: O(M + K). False when the step is done: the Newton decrement (scale
// free) is below 1e-10, or rounding leaves no step that decreases the barrier.
bool NewtonStep(const L1TangentProblem& p, double tau, Vec3& y, std::vector<double>& t) {
  const size_t m_count = p.a.size(), k_count = p.c.size();
  Eigen::Matrix3d h = 2.0 * tau * p.gamma * Eigen::Matrix3d::Identity();
  Vec3 gy = 2.0 * tau * p.gamma * y;
  Vec3 rhs = Vec3::Zero();
  std::vector<double> gt(m_count), e(m_count), d(m_count), dt(m_count);  // gt: the gradient in t
  for (size_t m = 0; m < m_count; ++m) {
    const double rm = p.a[m].dot(y) - p.b[m];
    const double ip = 1.0 / (t[m] - rm), im = 1.0 / (t[m] + rm);
    gt[m] = tau * Weight(p, m) - ip - im;
    gy += (ip - im) * p.a[m];
    d[m] = ip * ip + im * im;
    e[m] = -ip * ip + im * im;
    // Schur complement of the t-block: (d − e²/d) a aᵀ = (4 ip² im² / d) a aᵀ.
    h += (d[m] - e[m] * e[m] / d[m]) * (p.a[m] * p.a[m].transpose());
    rhs += (e[m] / d[m]) * gt[m] * p.a[m];
  }
  for (size_t k = 0; k < k_count; ++k) {
    const double ik = 1.0 / (p.h[k] - p.c[k].dot(y));
    gy += ik * p.c[k];
    h += (ik * ik) * (p.c[k] * p.c[k].transpose());
  }
  const Vec3 dy = h.ldlt().solve(-gy + rhs);
  double decrement = -gy.dot(dy);
  for (size_t m = 0; m < m_count; ++m) {
    dt[m] = (-gt[m] - e[m] * p.a[m].dot(dy)) / d[m];
    decrement -= gt[m] * dt[m];
  }
  if (!(decrement > 1e-10)) return false;
  double f0;
  BarrierValue(p, tau, y, t, &f0);
  double step = 1.0;
  std::vector<double> t_new(m_count);
  for (int back = 0; back < 60; ++back, step *= 0.5) {
    const Vec3 y_new = y + step * dy;
    for (size_t m = 0; m < m_count; ++m) t_new[m] = t[m] + step * dt[m];
    double f1;
    if (BarrierValue(p, tau, y_new, t_new, &f1) && f1 <= f0 - 0.25 * step * decrement) {
      y = y_new;
      t.swap(t_new);
      return true;
    }
  }
  return false;
}

}  // namespace

L1TangentSolution SolveL1Tangent(const L1TangentProblem& p, const L1TangentOptions& options) {
  // Primal barrier method on  min Σ w_m t_m + γ‖y‖²  s.t.  −t_m ≤ a_mᵀy − b_m ≤ t_m,  c_kᵀy ≤ h_k, by
  // damped Newton steps (NewtonStep) along the central path. The central path's multipliers give a dual
  // point; the gap certifies the result.
  const size_t m_count = p.a.size(), k_count = p.c.size();
  L1TangentSolution best;
  best.primal = L1TangentObjective(p, Vec3::Zero());
  best.dual = 0.0;  // D(0, 0) = 0
  if (best.primal - best.dual <= options.gap_tolerance) {
    best.converged = true;
    return best;
  }
  const double barrier_terms = static_cast<double>(2 * m_count + k_count);
  Vec3 y = Vec3::Zero();
  std::vector<double> t(m_count);
  for (size_t m = 0; m < m_count; ++m) t[m] = std::abs(p.a[m].dot(y) - p.b[m]) + best.primal / static_cast<double>(m_count) + 1e-12;
  double tau = barrier_terms / best.primal;  // start where the barrier's gap bound equals P(0)
  std::vector<double> u(m_count), lambda(k_count);

  int steps = 0;
  for (int stage = 0; stage < 60 && steps < options.max_newton_steps; ++stage) {
    // Centre for this τ.
    for (int stage_steps = 0; steps < options.max_newton_steps && stage_steps < 50; ++steps, ++stage_steps)
      if (!NewtonStep(p, tau, y, t)) break;
    // Certificate from the central path's multipliers: u_m = z⁺ − z⁻, λ_k = 1/(τ s_k).
    for (size_t m = 0; m < m_count; ++m) {
      const double rm = p.a[m].dot(y) - p.b[m];
      u[m] = std::clamp(1.0 / (tau * (t[m] - rm)) - 1.0 / (tau * (t[m] + rm)), -Weight(p, m), Weight(p, m));
    }
    for (size_t k = 0; k < k_count; ++k) lambda[k] = 1.0 / (tau * (p.h[k] - p.c[k].dot(y)));
    const double primal = L1TangentObjective(p, y);
    // The multipliers are only as accurate as 1/(τ s) in floating point; a few ascent sweeps from them
    // (D only increases) sharpen the bound once the barrier has found the right active set.
    best.dual = std::max(best.dual, L1TangentDual(p, u, lambda));
    if (primal - best.dual > options.gap_tolerance) best.dual = std::max(best.dual, AscendDual(p, u, lambda, 3));
    if (primal <= best.primal) {
      best.primal = primal;
      best.y = y;
    }
    best.sweeps = steps;
    if (best.primal - best.dual <= options.gap_tolerance) {
      best.converged = true;
      break;
    }
    tau *= 20.0;
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

Vec3 StepAcrossCurve(const Vec3& y, const TangentRank& r, const Vec3* gradients, size_t count, int min_third,
                     double min_cos) {
  if (r.rank != 2) return y;
  const Vec3 t = r.v.col(2);
  int third = 0;
  for (size_t m = 0; m < count && third < min_third; ++m) {
    const double len2 = gradients[m].squaredNorm();
    if (len2 >= 0.25 && std::abs(gradients[m].dot(t)) >= min_cos * std::sqrt(len2)) ++third;
  }
  return third >= min_third ? y : Vec3(y - t.dot(y) * t);
}

double UnexplainedNormalSpread(const std::vector<TangentRank>& ranks) {
  std::vector<double> ratio;
  ratio.reserve(ranks.size());
  for (const TangentRank& r : ranks)
    if (r.rank > 0 && r.singular_values[0] > 0.0) ratio.push_back(r.singular_values[2] / r.singular_values[0]);
  if (ratio.empty()) return 0.0;
  auto mid = ratio.begin() + static_cast<std::ptrdiff_t>(ratio.size() / 2);
  std::nth_element(ratio.begin(), mid, ratio.end());
  return *mid;
}

void RecountRank(TangentRank& r, double tau, double spread) {
  if (r.rank == 0) return;
  const double threshold = std::sqrt(tau * tau + spread * spread) * r.singular_values[0];
  r.rank = 0;
  for (int k = 0; k < 3; ++k)
    if (r.singular_values[k] > threshold) ++r.rank;
}

double SecondPlaneShare(double tau) { return tau * tau / (1.0 + tau * tau); }

double BlindCreaseAngle(double tau) { return 2.0 * std::atan(tau); }

bool SeesTwoPlanes(const Vec3* normals, size_t count, const TangentRank& r, double min_angle, double max_angle,
                   double min_share, double min_contrast) {
  const size_t min_group = static_cast<size_t>(std::ceil(min_share * static_cast<double>(count)));
  if (count < 4 || min_group < 1 || 2 * min_group > count) return false;
  // Early out for most sheet cells. A share f of the normals turned by θ from the rest makes
  // (s₂² + s₃²)/s₁² ≥ μ₂/μ₁, μ = (1 ± √(1 − 4f(1−f)sin²θ))/2 the two-point spread (a normal is at least as far
  // from v₁ as its axis angle says, and spread within a group adds), and s₂ ≥ s₃: so a cell with
  // s₂²/s₁² below half that, at the smallest f and θ allowed, has no qualifying split.
  const double p = min_share * (1.0 - min_share) * std::pow(std::sin(min_angle), 2);
  const double root = std::sqrt(std::max(0.0, 1.0 - 4.0 * p));
  const double s1 = r.singular_values[0], s2 = r.singular_values[1];
  if (2.0 * s2 * s2 * (1.0 + root) < (1.0 - root) * s1 * s1) return false;
  // Axis angles in (−π/2, π/2] around the dominant direction v₁: a normal and its opposite are one plane.
  thread_local std::vector<double> phi;
  phi.clear();
  phi.reserve(count);
  for (size_t m = 0; m < count; ++m) {
    double a = normals[m].dot(r.v.col(0)), b = normals[m].dot(r.v.col(1));
    if (a < 0.0) a = -a, b = -b;
    if (a == 0.0 && b == 0.0) continue;
    phi.push_back(std::atan2(b, a));
  }
  const size_t n = phi.size();
  if (n < 2 * min_group) return false;
  std::sort(phi.begin(), phi.end());
  double sum = 0.0, sum_sq = 0.0;
  for (double x : phi) sum += x, sum_sq += x * x;
  // Prefix sums give each split's within-group sum of squares in O(1).
  double best_sse = std::numeric_limits<double>::infinity(), best_gap = 0.0, left = 0.0, left_sq = 0.0;
  for (size_t k = 1; k < n; ++k) {
    left += phi[k - 1], left_sq += phi[k - 1] * phi[k - 1];
    if (k < min_group || n - k < min_group) continue;
    const double nl = static_cast<double>(k), nr = static_cast<double>(n - k);
    const double right = sum - left;
    const double sse = (left_sq - left * left / nl) + (sum_sq - left_sq - right * right / nr);
    if (sse < best_sse) best_sse = sse, best_gap = right / nr - left / nl;
  }
  if (!std::isfinite(best_sse)) return false;
  const double spread = std::sqrt(std::max(0.0, best_sse) / static_cast<double>(n));
  return best_gap >= min_angle && best_gap < max_angle && best_gap >= min_contrast * spread;
}

}  // namespace voroudf

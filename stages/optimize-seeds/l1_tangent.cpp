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

// The primal-dual method's iterate: y, the term bounds t, and the multipliers of t − r ≥ 0 (zp), t + r ≥ 0
// (zm) and h − c·y ≥ 0 (lambda), r_m = a_mᵀy − b_m.
struct PrimalDual {
  Vec3 y = Vec3::Zero();
  std::vector<double> t, zp, zm, lambda;
};

// The slacks of the three kinds of inequality at x.
void Slacks(const L1TangentProblem& p, const PrimalDual& x, std::vector<double>& sp, std::vector<double>& sm,
            std::vector<double>& sc) {
  for (size_t m = 0; m < p.a.size(); ++m) {
    const double r = p.a[m].dot(x.y) - p.b[m];
    sp[m] = x.t[m] - r;
    sm[m] = x.t[m] + r;
  }
  for (size_t k = 0; k < p.c.size(); ++k) sc[k] = p.h[k] - p.c[k].dot(x.y);
}

// A Newton direction of the perturbed KKT system, the complementarity rows asking s·z to change by rp, rm, rc
// (s Δz + z Δs = r). The t-block and the multipliers are eliminated, which leaves a 3×3 system in Δy with the
// matrix `h` (the same for every right-hand side at one iterate).
struct Direction {
  Vec3 dy;
  std::vector<double> dt, dzp, dzm, dlambda;
};

class KktSystem {
 public:
  KktSystem(const L1TangentProblem& p, const PrimalDual& x, const std::vector<double>& sp, const std::vector<double>& sm,
            const std::vector<double>& sc)
      : p_(p), x_(x), sp_(sp), sm_(sm), sc_(sc), dp_(p.a.size()), dm_(p.a.size()), beta_(p.a.size()) {
    Eigen::Matrix3d h = 2.0 * p.gamma * Eigen::Matrix3d::Identity();
    for (size_t m = 0; m < p.a.size(); ++m) {
      const double dp = x.zp[m] / sp[m], dm = x.zm[m] / sm[m];
      dp_[m] = dp;
      dm_[m] = dm;
      h += (4.0 * dp * dm / (dp + dm)) * (p.a[m] * p.a[m].transpose());
    }
    for (size_t k = 0; k < p.c.size(); ++k) h += (x.lambda[k] / sc[k]) * (p.c[k] * p.c[k].transpose());
    // Stationarity in y: 2γ y + Σ (zp − zm) a + Σ λ c.
    residual_y_ = 2.0 * p.gamma * x.y;
    for (size_t m = 0; m < p.a.size(); ++m) residual_y_ += (x.zp[m] - x.zm[m]) * p.a[m];
    for (size_t k = 0; k < p.c.size(); ++k) residual_y_ += x.lambda[k] * p.c[k];
    ldlt_.compute(h);
  }

  void Solve(const std::vector<double>& rp, const std::vector<double>& rm, const std::vector<double>& rc,
             Direction& d) const {
    const size_t mc = p_.a.size(), kc = p_.c.size();
    d.dt.resize(mc);
    d.dzp.resize(mc);
    d.dzm.resize(mc);
    d.dlambda.resize(kc);
    Vec3 rhs = -residual_y_;
    for (size_t m = 0; m < mc; ++m) {
      const double dp = dp_[m], dm = dm_[m], s = dp + dm;
      const double ap = rp[m] / sp_[m], am = rm[m] / sm_[m];
      beta_[m] = ap + am - (Weight(p_, m) - x_.zp[m] - x_.zm[m]);  // stationarity in t: w − zp − zm
      rhs -= (ap - am - (dp - dm) * beta_[m] / s) * p_.a[m];
    }
    for (size_t k = 0; k < kc; ++k) rhs -= (rc[k] / sc_[k]) * p_.c[k];
    d.dy = ldlt_.solve(rhs);
    for (size_t m = 0; m < mc; ++m) {
      const double dp = dp_[m], dm = dm_[m];
      const double q = p_.a[m].dot(d.dy);
      d.dt[m] = (beta_[m] + (dp - dm) * q) / (dp + dm);
      d.dzp[m] = rp[m] / sp_[m] - dp * (d.dt[m] - q);
      d.dzm[m] = rm[m] / sm_[m] - dm * (d.dt[m] + q);
    }
    for (size_t k = 0; k < kc; ++k) d.dlambda[k] = (rc[k] + x_.lambda[k] * p_.c[k].dot(d.dy)) / sc_[k];
  }

  // The largest step in [0, 1] along d that keeps every slack and multiplier non-negative.
  double MaxStep(const Direction& d) const {
    double step = 1.0;
    auto limit = [&step](double value, double change) {
      if (change < 0.0) step = std::min(step, -value / change);
    };
    for (size_t m = 0; m < p_.a.size(); ++m) {
      const double q = p_.a[m].dot(d.dy);
      limit(sp_[m], d.dt[m] - q);
      limit(sm_[m], d.dt[m] + q);
      limit(x_.zp[m], d.dzp[m]);
      limit(x_.zm[m], d.dzm[m]);
    }
    for (size_t k = 0; k < p_.c.size(); ++k) {
      limit(sc_[k], -p_.c[k].dot(d.dy));
      limit(x_.lambda[k], d.dlambda[k]);
    }
    return step;
  }

 private:
  const L1TangentProblem& p_;
  const PrimalDual& x_;
  const std::vector<double>&sp_, &sm_, &sc_;
  std::vector<double> dp_, dm_;         // z⁺/s⁺ and z⁻/s⁻ at the iterate
  mutable std::vector<double> beta_;    // Solve's scratch: the t-row's right-hand side, reused by its second pass
  Vec3 residual_y_;
  Eigen::LDLT<Eigen::Matrix3d> ldlt_;
};

}  // namespace

L1TangentSolution SolveL1Tangent(const L1TangentProblem& p, const L1TangentOptions& options) {
  // Mehrotra's predictor-corrector primal-dual interior-point method (Nocedal & Wright, Numerical
  // Optimization, Sec. 16.6) on  min Σ w_m t_m + γ‖y‖²  s.t.  t_m − r_m ≥ 0, t_m + r_m ≥ 0, h_k − c_kᵀy ≥ 0.
  // The slacks are functions of (y, t), so the iterate stays strictly feasible; the multipliers give the
  // dual point u = zp − zm, λ whose gap certifies the result.
  const size_t mc = p.a.size(), kc = p.c.size();
  L1TangentSolution best;
  best.primal = L1TangentObjective(p, Vec3::Zero());
  best.dual = 0.0;  // D(0, 0) = 0
  if (best.primal - best.dual <= options.gap_tolerance) {
    best.converged = true;
    return best;
  }
  double total_weight = 0.0;
  for (size_t m = 0; m < mc; ++m) total_weight += Weight(p, m);
  const double theta = best.primal / total_weight;  // the mean |r_m| at y = 0: t starts that far above |r|
  PrimalDual x;
  x.t.resize(mc);
  x.zp.resize(mc);
  x.zm.resize(mc);
  x.lambda.resize(kc);
  std::vector<double> sp(mc), sm(mc), sc(kc);
  for (size_t m = 0; m < mc; ++m) {
    x.t[m] = std::abs(p.b[m]) + theta;
    x.zp[m] = x.zm[m] = 0.5 * Weight(p, m);  // stationarity in t holds from the start
  }
  Slacks(p, x, sp, sm, sc);
  double mu = 0.0;
  for (size_t m = 0; m < mc; ++m) mu += sp[m] * x.zp[m] + sm[m] * x.zm[m];
  mu /= static_cast<double>(2 * mc);
  for (size_t k = 0; k < kc; ++k) x.lambda[k] = mu / sc[k];
  const double pairs = static_cast<double>(2 * mc + kc);
  std::vector<double> rp(mc), rm(mc), rc(kc), u(mc), lambda(kc);
  Direction affine, step;
  for (int iteration = 1; iteration <= options.max_newton_steps; ++iteration) {
    const KktSystem kkt(p, x, sp, sm, sc);
    mu = 0.0;
    for (size_t m = 0; m < mc; ++m) mu += sp[m] * x.zp[m] + sm[m] * x.zm[m];
    for (size_t k = 0; k < kc; ++k) mu += sc[k] * x.lambda[k];
    mu /= pairs;
    // Predictor: the affine-scaling direction (s·z → 0).
    for (size_t m = 0; m < mc; ++m) rp[m] = -sp[m] * x.zp[m], rm[m] = -sm[m] * x.zm[m];
    for (size_t k = 0; k < kc; ++k) rc[k] = -sc[k] * x.lambda[k];
    kkt.Solve(rp, rm, rc, affine);
    const double a_aff = kkt.MaxStep(affine);
    double mu_aff = 0.0;
    for (size_t m = 0; m < mc; ++m) {
      const double q = p.a[m].dot(affine.dy);
      mu_aff += (sp[m] + a_aff * (affine.dt[m] - q)) * (x.zp[m] + a_aff * affine.dzp[m]) +
                (sm[m] + a_aff * (affine.dt[m] + q)) * (x.zm[m] + a_aff * affine.dzm[m]);
    }
    for (size_t k = 0; k < kc; ++k)
      mu_aff += (sc[k] - a_aff * p.c[k].dot(affine.dy)) * (x.lambda[k] + a_aff * affine.dlambda[k]);
    mu_aff /= pairs;
    const double sigma = std::pow(mu_aff / mu, 3);
    // Corrector: centring at σμ and the predictor's second-order term Δs·Δz.
    for (size_t m = 0; m < mc; ++m) {
      const double q = p.a[m].dot(affine.dy);
      rp[m] = sigma * mu - sp[m] * x.zp[m] - (affine.dt[m] - q) * affine.dzp[m];
      rm[m] = sigma * mu - sm[m] * x.zm[m] - (affine.dt[m] + q) * affine.dzm[m];
    }
    for (size_t k = 0; k < kc; ++k)
      rc[k] = sigma * mu - sc[k] * x.lambda[k] + p.c[k].dot(affine.dy) * affine.dlambda[k];
    kkt.Solve(rp, rm, rc, step);
    const double a = std::min(1.0, 0.99 * kkt.MaxStep(step));
    x.y += a * step.dy;
    for (size_t m = 0; m < mc; ++m) {
      x.t[m] += a * step.dt[m];
      x.zp[m] += a * step.dzp[m];
      x.zm[m] += a * step.dzm[m];
    }
    for (size_t k = 0; k < kc; ++k) x.lambda[k] += a * step.dlambda[k];
    Slacks(p, x, sp, sm, sc);
    bool feasible = true;
    for (size_t k = 0; k < kc; ++k) feasible = feasible && sc[k] > 0.0;
    best.sweeps = iteration;
    if (!feasible) break;  // rounding at a vanishing slack: keep the best point so far
    // Certificate: D(u, λ) ≤ P(y*) for any u in the box and λ ≥ 0.
    for (size_t m = 0; m < mc; ++m) u[m] = std::clamp(x.zp[m] - x.zm[m], -Weight(p, m), Weight(p, m));
    for (size_t k = 0; k < kc; ++k) lambda[k] = std::max(0.0, x.lambda[k]);
    const double primal = L1TangentObjective(p, x.y);
    best.dual = std::max(best.dual, L1TangentDual(p, u, lambda));
    // The multipliers are only as accurate as rounding lets the complementarity products be; a few ascent
    // sweeps from them (D only increases) sharpen the bound once the active set is found.
    if (primal - best.dual > options.gap_tolerance && primal - best.dual < 1e3 * options.gap_tolerance)
      best.dual = std::max(best.dual, AscendDual(p, u, lambda, 3));
    if (primal <= best.primal) {
      best.primal = primal;
      best.y = x.y;
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

bool NormalsMeetOnOneAxis(const Vec3* points, const double* distances, const Vec3* gradients, size_t count,
                          const TangentRank& r, double max_residual) {
  // Each line m, in the plane's coordinates: a_m · c = b_m, a_m the unit normal of the line (its direction
  // turned by 90°), b_m = a_m · f_m, f_m the foot point. Least squares for c: (Σ a aᵀ) c = Σ a b.
  thread_local std::vector<Eigen::Vector2d> foot, across;
  thread_local std::vector<double> radius;
  foot.clear(), across.clear();
  const Vec3 e1 = r.v.col(0), e2 = r.v.col(1);
  for (size_t m = 0; m < count; ++m) {
    const Eigen::Vector2d u(gradients[m].dot(e1), gradients[m].dot(e2));
    if (u.norm() < 0.5) continue;  // no direction in the plane (or no gradient)
    const Vec3 f = points[m] - distances[m] * gradients[m];
    foot.emplace_back(f.dot(e1), f.dot(e2));
    across.emplace_back(-u.y() / u.norm(), u.x() / u.norm());
  }
  const size_t n = foot.size();
  if (n < 8) return false;
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero(), mean = Eigen::Vector2d::Zero();
  for (size_t m = 0; m < n; ++m) {
    ata += across[m] * across[m].transpose();
    atb += across[m] * across[m].dot(foot[m]);
    mean += foot[m];
  }
  mean /= static_cast<double>(n);
  // Parallel lines (a flat sheet) have no centre: the smaller eigenvalue of Σ a aᵀ is near 0.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(ata);
  if (eig.eigenvalues()(0) < 1e-3 * static_cast<double>(n)) return false;
  const Eigen::Vector2d c = ata.ldlt().solve(atb);
  double residual2 = 0.0, spread2 = 0.0;
  radius.resize(n);
  for (size_t m = 0; m < n; ++m) {
    residual2 += std::pow(across[m].dot(c) - across[m].dot(foot[m]), 2);
    spread2 += (foot[m] - mean).squaredNorm();
    radius[m] = (foot[m] - c).norm();
  }
  const double residual = std::sqrt(residual2 / static_cast<double>(n)), spread = std::sqrt(spread2 / static_cast<double>(n));
  std::nth_element(radius.begin(), radius.begin() + static_cast<std::ptrdiff_t>(n / 2), radius.end());
  return spread > 0.0 && residual < max_residual * spread && radius[n / 2] >= 0.5 * spread;
}

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

#pragma once
// The constrained L1 tangent step of one seed (paper Sec. 3.1, Eq. "energy_l1_regularizer") and the rank /
// null space of its tangent-plane matrix A (paper Sec. 3.2, Eq. "particle_proj").
#include <Eigen/Core>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// One seed's L1 tangent problem, written in coordinates centred on the seed's current position x⁰ and
/// scaled by a length L (optimize-seeds uses the domain box diagonal):  y = (x − x⁰) / L.
///
///   minimise  P(y) = Σ_m |a_mᵀ y − b_m| + γ ‖y‖²   subject to  c_kᵀ y ≤ h_k  (all k)
///
/// For a sample p_m with UDF value d_m and gradient n_m: a_m = n_m, b_m = (n_mᵀ(p_m − x⁰) − d_m) / L, so
/// |a_mᵀy − b_m| = |n_mᵀ(p_m − x) − d_m| / L, the paper's Eq. (energy_l1) term. The constraints are the
/// cell's half-spaces; x⁰ must be strictly feasible (h_k > 0), which holds for a seed inside its own cell.
struct L1TangentProblem {
  std::vector<Vec3> a;      ///< sample gradients (unit vectors)
  std::vector<double> b;    ///< sample offsets (relative units)
  std::vector<Vec3> c;      ///< constraint normals (unit vectors)
  std::vector<double> h;    ///< constraint offsets (> 0, relative units)
  double gamma = 10.0;      ///< proximity weight γ (> 0)

  void Clear() { a.clear(); b.clear(); c.clear(); h.clear(); }
};

struct L1TangentOptions {
  /// Stop once the duality gap P(y) − D(u, λ) ≤ gap_tolerance. Since P is 2γ-strongly convex,
  /// ‖y − y*‖ ≤ sqrt(gap / γ): set gap_tolerance = γ·ε² for a position error of ε (relative units).
  double gap_tolerance = 1e-11;
  int max_sweeps = 2000;  ///< cyclic passes over the dual coordinates before giving up on the gap
  /// Projected successive over-relaxation factor ω ∈ (0, 2): each coordinate moves ω times its exact 1-D
  /// step (then clipped). ω = 1 is plain coordinate ascent; ω > 1 speeds it up on nearly parallel tangent
  /// planes (a faceted curved surface), and projected SOR on a box-constrained concave QP still converges
  /// for any ω in (0, 2) (Mangasarian 1977; Luo & Tseng 1992).
  double relaxation = 1.0;
};

struct L1TangentSolution {
  Vec3 y = Vec3::Zero();  ///< feasible minimiser (within the gap tolerance)
  double primal = 0.0;    ///< P(y)
  double dual = 0.0;      ///< D(u, λ) ≤ P(y*) ≤ P(y)
  int sweeps = 0;
  bool converged = false; ///< gap ≤ tolerance; if false, y is still feasible and P(y) ≤ P(0)
};

/// Solves the problem exactly up to a certified duality gap, by cyclic coordinate ascent on its dual
///   max_{u ∈ [−1,1]^M, λ ≥ 0}  D(u, λ) = −‖Aᵀu + Cᵀλ‖² / (4γ) − uᵀb − λᵀh,   y(u, λ) = −(Aᵀu + Cᵀλ) / (2γ)
/// (|r| = max_{|u|≤1} u r; the minimisation over y is closed-form because γ > 0). D is a concave quadratic
/// over a product of intervals, so every coordinate update is a closed-form 1-D maximisation clipped to
/// its interval, and cyclic coordinate ascent converges (Luo & Tseng 1992). The primal iterate y(u, λ) is
/// pulled back towards 0 (strictly feasible) until it satisfies every constraint; the gap between its
/// primal value and D certifies optimality. Falls back to y = 0 if that is better when not converged.
/// \pre gamma > 0; every h_k > 0; a_m and c_k unit (or zero: then ignored).
L1TangentSolution SolveL1Tangent(const L1TangentProblem& problem, const L1TangentOptions& options);

/// P(y) without the constraints (for tests and logs).
double L1TangentObjective(const L1TangentProblem& problem, const Vec3& y);

/// Rank and null space of the tangent-plane matrix A (rows n_mᵀ), paper Sec. 3.2: singular values
/// s_1 ≥ s_2 ≥ s_3 of A, rank = #{k : s_k > tau · s_1}, right singular vectors V by decreasing s_k;
/// the null space basis V₀ is the last (3 − rank) columns of V.
struct TangentRank {
  int rank = 0;                          ///< 0 if A is empty or zero
  Vec3 singular_values = Vec3::Zero();   ///< decreasing
  Eigen::Matrix3d v = Eigen::Matrix3d::Identity();  ///< right singular vectors as columns
};

/// Computed from AᵀA = Σ n_m n_mᵀ (3×3, whose eigenvalues are s_k²) so the cost is linear in M.
/// \pre 0 < tau < 1
TangentRank ComputeTangentRank(const Vec3* normals, size_t count, double tau);

}  // namespace voroudf

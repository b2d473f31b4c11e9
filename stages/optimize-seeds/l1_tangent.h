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
///   minimise  P(y) = Σ_m w_m |a_mᵀ y − b_m| + γ ‖y‖²   subject to  c_kᵀ y ≤ h_k  (all k)
///
/// For a sample p_m with UDF value d_m and gradient n_m: a_m = n_m, b_m = (n_mᵀ(p_m − x⁰) − d_m) / L, so
/// |a_mᵀy − b_m| = |n_mᵀ(p_m − x) − d_m| / L, the paper's Eq. (energy_l1) term. The constraints are the
/// cell's half-spaces; x⁰ must be strictly feasible (h_k > 0), which holds for a seed inside its own cell.
struct L1TangentProblem {
  std::vector<Vec3> a;      ///< sample gradients (unit vectors)
  std::vector<double> b;    ///< sample offsets (relative units)
  std::vector<double> w;    ///< weight of each term (> 0; empty: all 1): w_m |a_mᵀy − b_m|
  std::vector<Vec3> c;      ///< constraint normals (unit vectors)
  std::vector<double> h;    ///< constraint offsets (> 0, relative units)
  double gamma = 10.0;      ///< proximity weight γ (> 0)

  void Clear() { a.clear(); b.clear(); w.clear(); c.clear(); h.clear(); }

  /// Adds the term w·|aᵀy − b|, merged into an existing term with the same plane (a and b within
  /// `tolerance`): samples of one flat facet of a mesh all give the same tangent plane, and one dual
  /// coordinate per plane instead of one per sample makes each sweep cheaper.
  void AddTerm(const Vec3& a_m, double b_m, double tolerance = 1e-9);
};

struct L1TangentOptions {
  /// Stop once the duality gap P(y) − D(u, λ) ≤ gap_tolerance. Since P is 2γ-strongly convex,
  /// ‖y − y*‖ ≤ sqrt(gap / γ): set gap_tolerance = γ·ε² for a position error of ε (relative units).
  double gap_tolerance = 1e-11;
  int max_newton_steps = 200;  ///< interior-point iterations before giving up on the gap
  int max_sweeps = 2000;       ///< coordinate ascent: cyclic passes over the dual coordinates
  /// Coordinate ascent: projected successive over-relaxation factor ω ∈ (0, 2) (ω = 1: plain ascent);
  /// projected SOR on a box-constrained concave QP converges for any ω in (0, 2) (Mangasarian 1977).
  double relaxation = 1.0;
};

struct L1TangentSolution {
  Vec3 y = Vec3::Zero();  ///< feasible minimiser (within the gap tolerance)
  double primal = 0.0;    ///< P(y)
  double dual = 0.0;      ///< D(u, λ) ≤ P(y*) ≤ P(y)
  int sweeps = 0;         ///< interior-point iterations, or sweeps (coordinate ascent)
  bool converged = false; ///< gap ≤ tolerance; if false, y is still feasible and P(y) ≤ P(0)
};

/// The Lagrangian dual of the problem:
///   D(u, λ) = −‖Aᵀu + Cᵀλ‖² / (4γ) − uᵀb − λᵀh,   u_m ∈ [−w_m, w_m], λ ≥ 0,
/// whose minimiser in y is y(u, λ) = −(Aᵀu + Cᵀλ)/(2γ) (|r| = max_{|u|≤1} u r; closed form since γ > 0).
/// Every such (u, λ) gives a lower bound D ≤ min P: the certificate both solvers stop on.
double L1TangentDual(const L1TangentProblem& problem, const std::vector<double>& u, const std::vector<double>& lambda);

/// Solves the problem exactly up to a certified duality gap with Mehrotra's predictor-corrector primal-dual
/// interior-point method (Nocedal & Wright, Numerical Optimization, Sec. 16.6) on the smooth equivalent
/// min Σ w_m t_m + γ‖y‖²  s.t.  −t_m ≤ a_mᵀy − b_m ≤ t_m,  c_kᵀy ≤ h_k. The slacks are functions of (y, t), so
/// the iterate stays strictly feasible; eliminating the t-block and the multipliers reduces each Newton
/// system to 3×3 (one factorisation, two right-hand sides per iteration), so an iteration costs O(M + K).
/// The multipliers give a dual point u_m = z⁺_m − z⁻_m (clipped to [−w_m, w_m]), λ_k ≥ 0; the solver stops
/// when P(y) − D(u, λ) ≤ gap_tolerance. It returns the best feasible y seen, never worse than y = 0.
/// \pre gamma > 0; every h_k > 0; a_m and c_k unit vectors.
L1TangentSolution SolveL1Tangent(const L1TangentProblem& problem, const L1TangentOptions& options);

/// The same problem by cyclic coordinate ascent on D (each update a closed-form 1-D maximisation clipped
/// to its interval; converges for a concave quadratic over a box, Luo & Tseng 1992), with the primal
/// iterate y(u, λ) pulled back towards 0 until feasible for the gap. Simple and exact on orthogonal
/// planes, but slow on nearly parallel ones (curved or finely faceted surfaces); kept as an independent
/// cross-check of SolveL1Tangent in the tests.
L1TangentSolution SolveL1TangentByCoordinateAscent(const L1TangentProblem& problem, const L1TangentOptions& options);

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

/// The L1 step of a curve seed across its curve only (not in the paper; docs/optimize-seeds.md, "Curve
/// seeds step across their curve"). The step y of a seed whose cell has rank 2 loses its component along the
/// null direction t = r.v.col(2) (the curve's tangent), unless at least `min_third` of the cell's gradients
/// n have |n·t| ≥ min_cos·|n|: a third plane, a corner or a kink of the curve ahead, onto which the step must
/// stay free to go. Along a curve the L1 minimum is otherwise set by how the samples fall, not by the
/// surface (on a curved edge the tangent planes of the curved face meet the other face's near the samples'
/// median; on a field with value errors, where the error's plane families cross), and the steps of
/// neighbouring curve seeds meet there; spacing along a curve is the repulsion's work (it moves a curve
/// seed along t). min_cos = 0.3 (17.5° out of the curve's normal plane) lies above what gradient errors of
/// 15° give (sin 15° = 0.26) and below the kinks and corners of CAD curves.
/// \param gradients the cell's sample gradients (those shorter than 0.5 are skipped, as in the L1 terms)
/// Seeds of another rank get y back unchanged.
Vec3 StepAcrossCurve(const Vec3& y, const TangentRank& r, const Vec3* gradients, size_t count, int min_third = 1,
                     double min_cos = 0.3);

/// The spread of sample normals that no surface explains, ν: the median over cells of s₃/s₁. A sheet or a
/// crease leaves s₃ = 0 with exact gradients; gradient errors (a learned field's) add about the same ν to
/// every singular value below s₁, in every cell, so the median over a surface that is mostly sheets and
/// creases measures them. Cells with no usable sample are skipped; 0 if none is left.
double UnexplainedNormalSpread(const std::vector<TangentRank>& ranks);

/// Sets r.rank = #{k : s_k > sqrt(tau² + spread²) s₁}: s_k² - ν² s₁² > τ² s₁², the rank test of the paper
/// (Eq. particle_proj, threshold τ) applied to what remains once the unexplained spread is taken out.
/// spread = 0 is the paper's test.
void RecountRank(TangentRank& r, double tau, double spread);

/// The share of the samples that a second tangent plane turned by 90° needs for rank 2 at threshold τ:
/// shares f and 1 − f of two orthogonal planes give s₂/s₁ = sqrt(f / (1 − f)), so f = τ² / (1 + τ²).
double SecondPlaneShare(double tau);

/// The crease angle below which the singular-value test at τ never counts a second plane: two equally
/// sampled planes turned by θ give s₂/s₁ = tan(θ/2), the most any share gives, so θ < 2·atan(τ) (44° at 0.4).
double BlindCreaseAngle(double tau);

/// Crease test (not in the paper; docs/optimize-seeds.md, "Shallow creases"): whether the cell's normals
/// show two tangent planes turned from each other by an angle in [min_angle, max_angle) (radians), each
/// seen by at least `min_share` of the samples, rather than one curved sheet. It looks at the normals' axes
/// in the plane of the first two singular vectors: the split of their sorted angles into two groups with
/// the least within-group variance (1-D two-means, exact, each group at least min_share), which is a
/// crease when the groups' mean angles differ by an angle in the range and by ≥ `min_contrast` × the
/// within-group standard deviation. A uniform spread (a sheet curved by any angle) has contrast
/// sqrt(12) = 3.46; two planes with the samples of a convex crease's wedge between them have more than 9.
/// \param r the cell's TangentRank (v's first two columns are used)
/// \pre 0 < min_share ≤ 0.5
bool SeesTwoPlanes(const Vec3* normals, size_t count, const TangentRank& r, double min_angle, double max_angle,
                   double min_share, double min_contrast);

/// Curved-sheet test (not in the paper; docs/optimize-seeds.md, "Curved sheets"): whether the cell's normal
/// lines (through each sample's foot point x − d·n, along n) pass near one axis along the null direction
/// t = r.v.col(2), at a distance from it comparable to the foot points' spread — the samples of one sheet
/// curved round that axis: a tube, a rod or a fillet narrower than the cell. In the plane of v₁ and v₂ the
/// centre c minimises the squared distances from c to the lines; true when their RMS is below `max_residual`
/// × the foot points' RMS spread and the median distance from c to the foot points is at least half that
/// spread. A crease's face samples have parallel normal lines that no one point is near; the normal lines of
/// a convex edge's wedge samples meet on the edge, where their foot points lie.
/// \param r the cell's TangentRank (rank 2: v's third column is the axis)
bool NormalsMeetOnOneAxis(const Vec3* points, const double* distances, const Vec3* gradients, size_t count,
                          const TangentRank& r, double max_residual);

}  // namespace voroudf

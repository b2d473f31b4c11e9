#pragma once
// Feature-aware Gaussian repulsion (paper Sec. 3.2, Eqs. "particle" and "particle_proj"), minimised with
// Ceres' L-BFGS.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "common/types.h"

namespace voroudf {

/// Symmetric neighbour lists in CSR form: the neighbours of seed i are index[offset[i] .. offset[i+1]).
/// j ∈ N(i) ⇔ i ∈ N(j); no self pairs.
struct NeighbourLists {
  std::vector<size_t> offset;  ///< size N + 1
  std::vector<int> index;

  size_t size() const { return offset.empty() ? 0 : offset.size() - 1; }
  /// Builds symmetric lists from unordered pairs (i ≠ j, in any order, duplicates allowed); each list sorted.
  static NeighbourLists FromPairs(size_t n, std::vector<std::pair<int, int>> pairs);
};

/// Where a seed may move during repulsion: x = x̄ + σ · V₀ t with t ∈ R^dim (dim = 3 − rank; 0 fixes it).
struct MoveSpace {
  int dim = 0;
  Eigen::Matrix3d basis = Eigen::Matrix3d::Zero();  ///< first `dim` columns are the orthonormal V₀
};

/// E = Σ_i Σ_{j ∈ N(i)} exp(−‖x_j − x_i‖² / (2σ²)) (each unordered pair counted twice, as in the paper's
/// double sum); if `gradient` is not null it receives ∂E/∂x_i = Σ_j 2 exp(·) (x_j − x_i) / σ² per seed.
/// Each seed's terms are summed in neighbour order and seeds in index order: the result does not depend on
/// the thread count. \pre sigma > 0
double RepulsionEnergy(const std::vector<Vec3>& positions, const NeighbourLists& neighbours, double sigma,
                       std::vector<Vec3>* gradient);

struct RepulsionOptions {
  int max_iterations = 50;  ///< L-BFGS iterations (Ceres' default)
  /// Trust region: after the solve, a seed's displacement longer than max_step·σ is shortened to that
  /// length (along the same null-space direction). 0 disables it.
  double max_step = 0.0;
};

struct RepulsionResult {
  std::vector<Vec3> positions;       ///< after the solve and the trust-region clamp (not projected onto the zero set)
  size_t clamped = 0;                ///< seeds whose displacement was shortened
  double initial_energy = 0.0;
  double final_energy = 0.0;
  double initial_gradient_norm = 0.0; ///< ‖∂E/∂t‖ at t = 0, i.e. ‖(V₀V₀ᵀ g_i)_i‖ · σ
  int iterations = 0;
};

/// Minimises E over the seeds' null-space coordinates t_i (x_i = x̄_i + σ V₀,i t_i) with
/// ceres::GradientProblemSolver (L-BFGS, Wolfe line search). The exact gradient of the restricted problem
/// is σ V₀,iᵀ ∂E/∂x_i, i.e. the paper's projected force V₀V₀ᵀ g expressed in null-space coordinates, so the
/// line search sees a consistent function/gradient pair. Scaling t by σ keeps the problem well conditioned
/// whatever the seed spacing. The neighbour lists stay fixed during the solve (E is smooth in t). The
/// solve knows nothing of the surface's curvature or its edges: the clamp keeps seeds from sliding along
/// tangent planes across an edge or an open boundary before they are projected back.
/// \pre sigma > 0; positions, spaces and neighbours have the same size.
RepulsionResult MinimizeRepulsion(const std::vector<Vec3>& positions, const std::vector<MoveSpace>& spaces,
                                  const NeighbourLists& neighbours, double sigma, const RepulsionOptions& options);

}  // namespace voroudf

#include "stages/optimize-seeds/repulsion.h"

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include <algorithm>
#include <cmath>

namespace voroudf {

NeighbourLists NeighbourLists::FromPairs(size_t n, std::vector<std::pair<int, int>> pairs) {
  std::vector<std::pair<int, int>> directed;
  directed.reserve(2 * pairs.size());
  for (const auto& [i, j] : pairs) {
    if (i == j) continue;
    directed.emplace_back(i, j);
    directed.emplace_back(j, i);
  }
  std::sort(directed.begin(), directed.end());
  directed.erase(std::unique(directed.begin(), directed.end()), directed.end());
  NeighbourLists lists;
  lists.offset.assign(n + 1, 0);
  lists.index.reserve(directed.size());
  for (const auto& [i, j] : directed) {
    ++lists.offset[static_cast<size_t>(i) + 1];
    lists.index.push_back(j);
  }
  for (size_t i = 0; i < n; ++i) lists.offset[i + 1] += lists.offset[i];
  return lists;
}

double RepulsionEnergy(const std::vector<Vec3>& positions, const NeighbourLists& neighbours, double sigma,
                       std::vector<Vec3>* gradient) {
  const long n = static_cast<long>(positions.size());
  const double inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  const double inv_sigma2 = 1.0 / (sigma * sigma);
  std::vector<double> per_seed(static_cast<size_t>(n), 0.0);
  if (gradient) gradient->assign(static_cast<size_t>(n), Vec3::Zero());
  // Called many times per L-BFGS iteration: threads pay off from a few thousand pairs per call (2,500 seeds
  // give ~20 k; a fork and join costs microseconds, the pairs a fraction of a millisecond).
#pragma omp parallel for schedule(static) if (neighbours.index.size() > 4000)
  for (long i = 0; i < n; ++i) {
    double e = 0.0;
    Vec3 g = Vec3::Zero();
    for (size_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k) {
      const Vec3 diff = positions[static_cast<size_t>(neighbours.index[k])] - positions[i];
      const double kernel = std::exp(-diff.squaredNorm() * inv_two_sigma2);
      e += kernel;
      g += (2.0 * kernel * inv_sigma2) * diff;
    }
    per_seed[i] = e;
    if (gradient) (*gradient)[i] = g;
  }
  double total = 0.0;
  for (double e : per_seed) total += e;
  return total;
}

namespace {

class RestrictedRepulsion : public ceres::FirstOrderFunction {
 public:
  RestrictedRepulsion(const std::vector<Vec3>& base, const std::vector<MoveSpace>& spaces,
                      const NeighbourLists& neighbours, double sigma)
      : base_(base), spaces_(spaces), neighbours_(neighbours), sigma_(sigma), offset_(base.size() + 1, 0) {
    for (size_t i = 0; i < base.size(); ++i) offset_[i + 1] = offset_[i] + static_cast<size_t>(spaces[i].dim);
  }

  int NumParameters() const override { return static_cast<int>(offset_.back()); }

  std::vector<Vec3> Positions(const double* t) const {
    std::vector<Vec3> x(base_);
    for (size_t i = 0; i < base_.size(); ++i)
      for (int d = 0; d < spaces_[i].dim; ++d) x[i] += (sigma_ * t[offset_[i] + d]) * spaces_[i].basis.col(d);
    return x;
  }

  bool Evaluate(const double* t, double* cost, double* gradient) const override {
    const std::vector<Vec3> x = Positions(t);
    std::vector<Vec3> g;
    *cost = RepulsionEnergy(x, neighbours_, sigma_, gradient ? &g : nullptr);
    if (!std::isfinite(*cost)) return false;
    if (gradient) {
      for (size_t i = 0; i < base_.size(); ++i)
        for (int d = 0; d < spaces_[i].dim; ++d) gradient[offset_[i] + d] = sigma_ * spaces_[i].basis.col(d).dot(g[i]);
    }
    return true;
  }

 private:
  const std::vector<Vec3>& base_;
  const std::vector<MoveSpace>& spaces_;
  const NeighbourLists& neighbours_;
  double sigma_;
  std::vector<size_t> offset_;
};

}  // namespace

RepulsionResult MinimizeRepulsion(const std::vector<Vec3>& positions, const std::vector<MoveSpace>& spaces,
                                  const NeighbourLists& neighbours, double sigma, const RepulsionOptions& options) {
  RepulsionResult result;
  // GradientProblem takes ownership of the function; keep a raw pointer for Positions().
  auto* function = new RestrictedRepulsion(positions, spaces, neighbours, sigma);
  const ceres::GradientProblem problem(function);
  std::vector<double> t(static_cast<size_t>(function->NumParameters()), 0.0);
  std::vector<double> gradient(t.size());
  function->Evaluate(t.data(), &result.initial_energy, gradient.data());
  double norm2 = 0.0;
  for (double v : gradient) norm2 += v * v;
  result.initial_gradient_norm = std::sqrt(norm2);
  result.final_energy = result.initial_energy;
  result.positions = positions;
  if (t.empty() || result.initial_gradient_norm == 0.0) return result;

  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  solver_options.line_search_type = ceres::WOLFE;  // L-BFGS needs the Wolfe conditions
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(solver_options, problem, t.data(), &summary);
  result.positions = function->Positions(t.data());
  if (options.max_step > 0.0) {
    const double limit = options.max_step * sigma;
    for (size_t i = 0; i < positions.size(); ++i) {
      const Vec3 step = result.positions[i] - positions[i];
      const double length = step.norm();
      if (length <= limit) continue;
      result.positions[i] = positions[i] + (limit / length) * step;
      ++result.clamped;
    }
  }
  result.final_energy = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  return result;
}

}  // namespace voroudf

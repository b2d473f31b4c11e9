#pragma once
// Samples inside the seeds' Voronoi cells (paper Sec. 3.1: "M points sampled within its Voronoi cell Ω_i"),
// their UDF values and gradients, and the cells' bounding half-spaces.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/monitor.h"
#include "common/udf.h"
#include "stages/optimize-seeds/sample_pool.h"
#include "stages/optimize-seeds/seed_index.h"

namespace voroudf {

struct CellSamplingOptions {
  int samples_per_cell = 100;    ///< M
  int radius_knn = 6;            ///< k: the cell is bounded by a ball of radius factor × (distance to the k-th nearest seed)
  double radius_factor = 0.5;    ///< as OptimizeSeedsOptions::cell_radius_factor (the stage default)
  int max_draws_per_sample = 100; ///< rejection budget: at most M × this draws (in the ball's bounding cube) per cell
  /// Two-stage sampling (0: off): a cell whose first `early_samples` samples already have rank 1 at
  /// `early_rank_threshold` (one tangent plane, clearly: s₂ ≤ that × s₁) keeps only those; the others get
  /// all M. The samples are a prefix of the same random draw, so a cell that needs M gets the same M.
  int early_samples = 0;
  double early_rank_threshold = 0.2;
  /// Optional, per seed: only cells marked here may stop at their early samples (null: every cell).
  const std::vector<char>* early_allowed = nullptr;
  /// Optional: take each cell's samples from this pool (its M lowest-mark points in the cell, whose UDF
  /// values the pool keeps across calls) instead of fresh rejection draws from (rng_seed, round).
  SamplePool* pool = nullptr;
};

/// Per seed i: the bounding radius R_i, the seeds within 2 R_i (the only ones whose bisector planes can cut
/// the ball B(x_i, R_i): a seed farther than 2R cannot be nearer than x_i to any point of the ball), and the
/// accepted samples with their UDF value and gradient.
struct CellSamples {
  std::vector<double> radius;
  std::vector<size_t> neighbour_offset;  ///< CSR over seeds, neighbours nearest first, self excluded
  std::vector<int> neighbour;
  std::vector<size_t> sample_offset;     ///< samples of seed i: [sample_offset[i], sample_offset[i+1])
  std::vector<Vec3> point;
  std::vector<double> distance;
  std::vector<Vec3> gradient;
  uint64_t draws = 0;                    ///< candidate points drawn in the bounding cubes in this call
  uint64_t drawn_samples = 0;            ///< of which accepted (acceptance = drawn_samples / draws)
  size_t short_cells = 0;                ///< redrawn cells that got fewer than M samples within the budget
  size_t redrawn = 0;                    ///< cells sampled in this call (the others were kept)
  size_t early_cells = 0;                ///< of which kept their early samples only (early_samples)
  size_t reused = 0;                     ///< samples of redrawn cells whose UDF value the pool already had
  std::vector<double> pool_mark;         ///< with a pool: per cell, the mark of its M-th sample (0: fewer)
  std::vector<char> early_kept;          ///< per cell: 1 if it has its early samples only
};

/// Memory SampleVoronoiCells keeps from call to call: the candidates' arrays and a spent result whose
/// arrays are filled again. At 50k seeds a call's samples take half a gigabyte; allocated afresh at every
/// call, each of their pages was first cleared by the kernel (a fifth of optimize-seeds' time at 50k seeds).
struct CellSamplingBuffers {
  std::vector<Vec3> candidate, candidate_gradient;  ///< M slots per cell
  std::vector<double> candidate_distance;
  CellSamples spare;  ///< a result no longer needed (its contents are not read)
};

/// Draws up to M points uniformly in Ω_i ∩ B(x_i, R_i) for every seed by rejection from the ball's bounding cube (exact
/// nearest-seed test against the seeds within 2 R_i, found with PCL's kd-tree), then evaluates the UDF at
/// all of them in one batch. Seed i draws from the counter-based stream (rng_seed, round · N + i), so the
/// result does not depend on the thread count. With options.pool the M points are the cell's M lowest-mark
/// points of the pool instead (also uniform in the cell, sample_pool.h), and the UDF is asked only at
/// those it has not seen. \pre seeds.size() ≥ 2, index built over `seeds`.
///
/// Incremental use: given the previous call's result and seed positions, a cell is kept as it was (same
/// radius, neighbours, samples and UDF values) when no seed within its influence radius (2R_i, and the
/// distance of its k-th nearest seed) moved, before or after the move — such a cell is exactly the same
/// set, so redrawing it would only change the random draw. Early on, when σ is small and few seeds
/// move, this saves most of the UDF evaluations. Seeds appended at the end, or removed from it, since the
/// previous call count as moved (removals elsewhere: CarryCells first). A cell that kept only its early samples is redrawn when this call wants
/// every cell whole (early_samples = 0). `buffers` (optional) only saves allocations: the result is the same.
CellSamples SampleVoronoiCells(const Udf& udf, const std::vector<Vec3>& seeds, const SeedIndex& index,
                               const CellSamplingOptions& options, uint64_t rng_seed, uint64_t round,
                               const CellSamples* previous = nullptr, const std::vector<Vec3>* previous_seeds = nullptr,
                               CellSamplingBuffers* buffers = nullptr);

/// For SampleVoronoiCells' incremental use after seeds were removed from anywhere in the list (which shifts
/// the indices of all later ones): re-indexes `previous` and `previous_seeds` to `seeds`. Seed i takes the
/// cell of the previous seed at exactly its position, its neighbours re-indexed, when all of that cell's
/// neighbours are still there and no previous seed within its influence radius has gone or moved. Any other
/// seed gets no cell (radius 0), so its cell is redrawn; a seed with no previous seed at its position also
/// gets a NaN previous position, so it counts as moved (the cells it cuts are redrawn too). Invariant: a
/// carried cell is exactly the set it was. \pre previous's cells belong to previous_seeds. `spare`
/// (optional): a spent result whose memory the carried cells take; it gets the previous cells' memory.
void CarryCells(const std::vector<Vec3>& seeds, const CellSamplingOptions& options, CellSamples& previous,
                std::vector<Vec3>& previous_seeds, CellSamples* spare = nullptr);

}  // namespace voroudf

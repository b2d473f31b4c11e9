// optimize-seeds: moves seeds onto sharp and non-manifold features and spreads them evenly (docs/optimize-seeds.md).
#include <cstdio>
#include <filesystem>

#include "common/cli.h"
#include "common/errors.h"
#include "common/projection.h"
#include "stages/optimize-seeds/optimize_seeds.h"

int main(int argc, char** argv) {
  voroudf::OptimizeSeedsOptions o;
  std::string udf_spec, input, output, trace_dir;
  bool ascii = false;

  voroudf::StageCli cli("optimize-seeds",
                        "Paper Alg. 1: constrained L1 tangent steps in Voronoi cells and feature-aware repulsion "
                        "(L-BFGS); writes the optimised seeds with their UDF value, gradient and rank.");
  cli.AddUdf(&udf_spec);
  cli.AddInput(&input, "input seeds PLY (seeds0.ply)");
  cli.AddOutput(&output, "output seeds PLY (seeds.ply)");
  cli.AddSeed(&o.seed);
  cli.AddAscii(&ascii);
  auto& app = cli.app();
  app.add_option("--trace", trace_dir, "directory for the seeds after every outer iteration (iter-NNN.ply)");
  cli.MarkNonSemantic("--trace");  // debugging output only: not part of the provenance
  app.add_option("-m,--samples-per-cell", o.samples_per_cell, "M: samples per Voronoi cell");
  app.add_option("--early-samples", o.early_samples, "a cell whose first N samples clearly show one plane keeps those N (0: all get M)");
  app.add_option("--cell-samples", o.cell_samples, "pool: a cell's samples come from one point set kept for the run, with their UDF values; fresh: new draws every round (the paper)");
  app.add_option("--pool-layers", o.pool_layers, "with --cell-samples pool: independent point sets the rounds take in turn");
  app.add_option("--repulsion-cells", o.repulsion_cells, "every: each repulsion round draws the cells again (the paper); first: only an outer iteration's first, later rounds keep its ranks");
  app.add_option("--gamma", o.gamma, "proximity weight of the L1 step (lengths relative to the diagonal)");
  app.add_option("--delta", o.delta, "inner loop stops when the projected gradient changes by less than this");
  app.add_option("--max-outer-iters", o.max_outer_iters, "cap on outer iterations (L1 step + repulsion)");
  app.add_option("--max-inner-iters", o.max_inner_iters, "cap on repulsion rounds per outer iteration");
  app.add_option("--lbfgs-max-iters", o.lbfgs_max_iters, "L-BFGS iterations per repulsion round (few: on fixed tangent planes the energy has no minimum, and a long run ends at --max-step for every seed)");
  app.add_option("--rank-threshold", o.rank_threshold, "rank(A) counts singular values above this fraction of the largest");
  app.add_option("--crease-angle-deg", o.crease_angle_deg, "a sheet cell whose normals show two planes this many degrees apart (below 2 atan(--rank-threshold)) is a crease (0: off)");
  app.add_option("--sample-planes", o.sample_planes, "gradient: a cell sample's tangent plane is its gradient's (the paper); fit: fitted to the surface points the cell's samples point at (gradient errors); auto: fit when the gradients are off those planes by more than 8 deg and more than the value errors explain");
  app.add_option("--rank-noise", o.rank_noise, "take the normal spread no surface explains (gradient errors) out of the rank test");
  app.add_option("--curved-sheets", o.curved_sheets, "a rank-2 cell whose normal lines meet on one axis is a sheet curved within it (a tube or rod narrower than a cell; use with sample-seeds --thin-boost)");
  app.add_option("--cell-knn", o.cell_knn, "cells are bounded by a ball sized by the distance to this nearest seed");
  app.add_option("--cell-radius-factor", o.cell_radius_factor, "ball radius / distance to the --cell-knn-th seed");
  app.add_option("--sigma-max-spacing", o.sigma_max_spacing, "kernel width at most this x mean seed spacing (0: no cap)");
  app.add_option("--sigma-min-spacing", o.sigma_min_spacing, "kernel width at least this x mean seed spacing (0: the paper's minimum distance alone)");
  app.add_option("--feature-clearance", o.feature_clearance, "thin feature seeds to this x mean spacing and keep sheet seeds that far from them (0: none)");
  app.add_option("--curve-separation", o.curve_separation, "curve seeds this x mean spacing or more apart across their tangents, on a chord off the tangents' bisector, are on two curves: kept and chained apart (0: never)");
  app.add_option("--feature-steps", o.feature_steps, "L1 steps of the feature seeds alone after the outer loop");
  app.add_option("--feature-gap-max", o.feature_gap_max, "add a seed between two consecutive seeds of a feature chain farther apart than this x mean spacing, and extend chain ends along their curve (0: never)");
  app.add_option("--feature-chord-tol", o.feature_chord_tol, "add a seed where a feature curve leaves the chord between two of its seeds by more than this x mean spacing (0: never)");
  app.add_option("--max-step", o.max_step, "a repulsion round moves a seed at most this many kernel widths (0: no limit)");
  app.add_option("--repulsion-cutoff", o.repulsion_cutoff, "seeds repel within this many kernel widths");
  app.add_option("--l1-tol-rel", o.l1_tol_rel, "L1 step position accuracy (certified by the duality gap), relative");
  app.add_option("--l1-curve-step", o.l1_curve_step, "free: a curve seed's L1 step moves it in every direction (the paper); across: only across its curve unless its cell sees a corner; auto: across on a field with a floor (value errors), free on an exact one");
  app.add_option("--l1-max-steps", o.l1_max_steps, "iterations of the L1 step's interior-point solver");
  app.add_option("--move-tol", o.move_tol, "an inner loop moving no seed farther than this many kernel widths ends it");
  app.add_option("--outer-tol", o.outer_tol, "outer loop ends when the spacing CV improves by less than this, relatively");
  app.add_option("--proj-tol-rel", o.proj_tol_rel, "projection tolerance on d, relative to the diagonal");
  app.add_option("--proj-max-iters", o.proj_max_iters, "projection steps before a move is undone");
  app.add_option("--proj-floor-rel", o.proj_floor_rel, voroudf::kProjFloorRelHelp);
  app.add_option("--proj-twin-factor", o.proj_twin_factor, voroudf::kProjTwinFactorHelp);

  return cli.Run(argc, argv, [&] { o.Check(); }, [&](voroudf::Monitor& monitor) {
    const auto udf = cli.OpenUdf(monitor);
    const voroudf::SeedCloud seeds0 = voroudf::ReadSeeds(input);
    std::error_code ec;
    if (!trace_dir.empty() && !std::filesystem::create_directories(trace_dir, ec) && ec)
      throw voroudf::OutputError(trace_dir, "cannot create the trace directory: " + ec.message());
    const auto trace = [&](const voroudf::OuterIterationReport& report, const voroudf::SeedCloud& seeds) {
      char name[32];
      std::snprintf(name, sizeof name, "/iter-%03d.ply", report.iteration);
      voroudf::WriteSeeds(trace_dir + name, seeds, cli.provenance(), ascii);
    };
    const voroudf::SeedCloud seeds = voroudf::OptimizeSeeds(*udf, seeds0, o, monitor,
                                                            trace_dir.empty() ? nullptr : std::function(trace));
    voroudf::WriteSeeds(output, seeds, cli.provenance(), ascii);
    monitor.Info("wrote " + std::to_string(seeds.size()) + " seeds to " + output);
  });
}

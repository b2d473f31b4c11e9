// build-gvd: the dual of the approximate geodesic Voronoi diagram of the seeds (docs/build-gvd.md).
#include "common/cli.h"
#include "common/errors.h"
#include "common/projection.h"
#include "formats/mesh_io.h"
#include "stages/build-gvd/build_gvd.h"

int main(int argc, char** argv) {
  voroudf::BuildGvdOptions options;
  std::string udf_spec, input, output, labels;
  bool ascii = false, graph = false;

  voroudf::StageCli cli("build-gvd",
                        "Labels dense zero-set samples with their geodesically nearest seed (Dijkstra over a pruned "
                        "kNN graph) and writes the dual triangles of that Voronoi diagram: the thick mesh.");
  cli.AddUdf(&udf_spec);
  cli.AddInput(&input, "input seeds PLY (seeds.ply)");
  cli.AddOutput(&output, "output thick mesh PLY, vertices = the seeds (thick.ply)");
  cli.AddExtraOutput("--labels", &labels, "also write the labelled samples (labels PLY)");
  cli.AddSeed(&options.seed);
  cli.AddAscii(&ascii);
  auto& app = cli.app();
  app.add_flag("--graph", graph, "with --labels: also write the pruned kNN graph as an edge element");
  app.add_option("--samples-per-seed", options.samples_per_seed, "dense samples drawn per sheet seed");
  app.add_option("--curve-sample-weight", options.curve_sample_weight,
                 "ball samples of a curve or corner seed (rank 2, 3) / a sheet seed's of the same ball radius");
  app.add_option("--space-fraction", options.space_fraction, "fraction of dense samples drawn in the whole box");
  app.add_option("--curve-samples", options.curve_samples,
                 "tangent: curve and corner seeds' ball samples drawn again in the tangent plane where they landed "
                 "(even density up to where sheets cross); ball: as they land")
      ->check(CLI::IsMember({"tangent", "ball"}));
  app.add_option("--ball-shares", options.ball_shares,
                 "area: ball samples shared out by ball area (even density on the surface); seed: as many per seed "
                 "(a density that follows the seeds', with sample-seeds --thin-boost)")
      ->check(CLI::IsMember({"area", "seed"}));
  app.add_option("--ball-scale", options.ball_scale, "ball radius around a seed / distance to its 6th-nearest seed");
  app.add_option("--knn", options.knn, "neighbours per sample in the kNN graph");
  app.add_option("--eps-udf-rel", options.eps_udf_rel, "prune edges with midpoint UDF above this x diagonal");
  app.add_option("--eps-grad", options.eps_grad, "prune edges with |cos(edge, gradient)| above this at an end");
  app.add_option("--eps-grad-both", options.eps_grad_both,
                 "prune edges with |cos(edge, gradient)| above this at both ends (across a thin wall; 1: off)");
  app.add_option("--eps-grad-wall", options.eps_grad_wall,
                 "prune edges with |cos(edge, gradient)| above this at both ends whose gradients are parallel within "
                 "30 degrees (from a sheet to the parallel one beside it; 1: off)");
  app.add_option("--dual", options.dual,
                 "delaunay: the witnessed triples that are locally Delaunay (one triangulation per junction); "
                 "paper: every witnessed triple (the paper's thick dual)")
      ->check(CLI::IsMember({"delaunay", "paper"}));
  app.add_option("--region-flatness", options.region_flatness,
                 "with --dual delaunay: a region flatter than this (least / largest spread) is a sheet");
  app.add_option("--chart-angle", options.chart_angle_deg,
                 "with --dual delaunay: seeds whose normals agree within this angle (deg) share a chart");
  app.add_option("--chain-links", options.chain_links,
                 "with --dual delaunay: drop the triangles that jump a seed of a feature chain or cut across it "
                 "where sheets cross (true/false)");
  app.add_option("--proj-tol-rel", options.proj_tol_rel, "projection tolerance on d, relative to the diagonal");
  app.add_option("--proj-max-iters", options.proj_max_iters, "projection steps before a sample is dropped");
  app.add_option("--proj-floor-rel", options.proj_floor_rel, voroudf::kProjFloorRelHelp);
  app.add_option("--proj-twin-factor", options.proj_twin_factor, voroudf::kProjTwinFactorHelp);

  return cli.Run(argc, argv, [&] { options.Check(); }, [&](voroudf::Monitor& monitor) {
    const auto udf = cli.OpenUdf(monitor);
    const voroudf::SeedCloud seeds = voroudf::ReadSeeds(input);
    if (seeds.size() == 0) throw voroudf::InputError(input, "the seeds file has no seeds");
    const voroudf::GvdResult gvd = voroudf::BuildGvd(*udf, seeds, options, graph && !labels.empty(), monitor);
    voroudf::WriteMeshPly(output, gvd.thick, cli.provenance(), ascii);
    monitor.Info("wrote " + std::to_string(gvd.thick.faces.size()) + " faces to " + output);
    if (!labels.empty()) {
      voroudf::WriteLabels(labels, gvd.samples, cli.provenance(), ascii);
      monitor.Info("wrote " + std::to_string(gvd.samples.size()) + " labelled samples to " + labels);
    }
  });
}

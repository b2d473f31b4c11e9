// sample-seeds: N seeds near the UDF's zero set, projected onto it and spread farthest apart (docs/sample-seeds.md).
#include "common/cli.h"
#include "common/projection.h"
#include "stages/sample-seeds/sample_seeds.h"

int main(int argc, char** argv) {
  voroudf::SampleSeedsOptions options;
  std::string udf_spec, output;
  bool ascii = false;

  voroudf::StageCli cli("sample-seeds",
                        "Draws points uniformly in the UDF's domain box (within a band around the surface), projects each onto "
                        "the zero set with x <- x - d(x) n(x) and writes --count of them, chosen farthest apart, as a seeds PLY.");
  cli.AddUdf(&udf_spec);
  cli.AddOutput(&output, "output seeds PLY (seeds0.ply)");
  cli.AddSeed(&options.seed);
  cli.AddAscii(&ascii);
  auto& app = cli.app();
  app.add_option("-n,--count", options.count, "number of points drawn (inside the band) before projection");
  app.add_option("--band-rel", options.band_rel,
                 "keep only draws with d < band x diagonal (0: whole box); spreads seeds by area, not onto edges");
  app.add_option("--dedup-rel", options.dedup_rel, "drop seeds closer than this x diagonal to an earlier one");
  app.add_option("--proj-tol-rel", options.proj_tol_rel,
                 "projection tolerance on d, relative to the domain box diagonal");
  app.add_option("--proj-max-iters", options.proj_max_iters, "projection steps before a seed is dropped");
  app.add_option("--thin-boost", options.thin_boost, "up to this many times the seeds where the part is thinner than two spacings, about nine round a tube (1: uniform)");
  app.add_option("--spread-pool", options.spread_pool,
                 "draw this many times --count points and keep the --count farthest apart (1: uniform draws, the paper)");
  app.add_option("--proj-floor-rel", options.proj_floor_rel, voroudf::kProjFloorRelHelp);
  app.add_option("--proj-twin-factor", options.proj_twin_factor, voroudf::kProjTwinFactorHelp);

  return cli.Run(argc, argv, [&] { options.Check(); }, [&](voroudf::Monitor& monitor) {
    const auto udf = cli.OpenUdf(monitor);
    const voroudf::SeedCloud seeds = voroudf::SampleSeeds(*udf, options, monitor);
    voroudf::WriteSeeds(output, seeds, cli.provenance(), ascii);
    monitor.Info("wrote " + std::to_string(seeds.size()) + " seeds to " + output);
  });
}

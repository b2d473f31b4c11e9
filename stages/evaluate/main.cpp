// evaluate: the paper's metrics of a mesh against a reference mesh, as JSON (docs/evaluate.md).
#include <chrono>
#include <cstdio>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/errors.h"
#include "formats/mesh_io.h"
#include "stages/evaluate/evaluate.h"

int main(int argc, char** argv) {
  voroudf::EvaluateOptions options;
  std::string input, reference, output, feature_misses;
  bool timings = false;

  voroudf::StageCli cli("evaluate",
                        "Computes CD, HD, ECD, TQ, TD and NM-CD of a mesh against a reference mesh in the "
                        "reference's normalised frame, sampled (the paper's protocol) and exact (samples to the "
                        "other mesh's triangles); prints one line of JSON, or writes it to -o.");
  cli.AddInput(&input, "mesh under test (.ply, .obj, .off or .stl)");
  cli.AddExtraInput("--reference", &reference, "reference mesh (.ply, .obj, .off or .stl; - for a PLY on stdin)")->required();
  cli.AddExtraOutput("-o,--output", &output, "write the JSON here (atomically) instead of stdout");
  cli.AddExtraOutput("--feature-misses", &feature_misses,
                     "also write the reference's sharp-edge samples that no mesh edge comes within the feature "
                     "tolerance of (the untraced features), as an edges PLY without edges, in the reference's frame");
  cli.AddSeed(&options.seed);
  auto& app = cli.app();
  app.add_option("--samples", options.samples, "area-uniform surface samples per mesh (CD, HD, ECD)");
  app.add_option("--nm-samples", options.nm_samples, "samples per mesh along its non-manifold edges (NM-CD)");
  app.add_option("--edge-samples", options.edge_samples, "samples per mesh along its sharp edges (exact ECD)");
  app.add_option("--feature-angle", options.feature_angle_deg,
                 "feature recall: edges whose dihedral departs from flat by more than this (degrees)");
  app.add_option("--ref-nm-curves", options.ref_nm_curves,
                 "the reference's non-manifold curves for NM-CD and spurious_nonmanifold_edges: union (its edges "
                 "of 3+ faces and where its triangles cross or touch: the UDF's branching) or edges (3+ faces only)")
      ->capture_default_str();
  app.add_flag("--floor", options.floor,
               "also the sampled CD/HD/ECD of the reference against itself (keys *_floor_*): their sampling floor");
  // Off by default: wall-clock time would make the output bytes differ from run to run.
  app.add_flag("--timings", timings, "add the wall-clock seconds to the JSON (key \"seconds\")");

  return cli.Run(argc, argv, [&] { options.Check(); }, [&](voroudf::Monitor& monitor) {
    const auto start = std::chrono::steady_clock::now();
    const voroudf::TriangleMesh mesh = voroudf::ReadMesh(input);
    const voroudf::TriangleMesh ref = voroudf::ReadMesh(reference);
    monitor.Info("mesh: " + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.faces.size()) +
                 " faces; reference: " + std::to_string(ref.vertices.size()) + " vertices, " +
                 std::to_string(ref.faces.size()) + " faces");
    const voroudf::Metrics metrics = voroudf::Evaluate(mesh, ref, options, monitor);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string json = voroudf::MetricsJson(metrics, options, input, reference, timings ? seconds : -1.0);
    if (output.empty()) {
      if (std::fwrite(json.data(), 1, json.size(), stdout) != json.size() || std::fflush(stdout) != 0)
        throw voroudf::OutputError("stdout", "cannot write");
    } else {
      voroudf::WriteFileAtomically(output, json);
    }
    if (!feature_misses.empty()) {
      // Back from the normalised frame to the reference's own coordinates, to be seen over it in a viewer.
      voroudf::EdgeSet misses;
      for (const voroudf::Vec3& p : metrics.features.missed)
        misses.vertices.push_back(p / metrics.frame.scale + metrics.frame.center);
      voroudf::WriteEdgesPly(feature_misses, misses, cli.provenance());
      monitor.Info("wrote " + std::to_string(misses.vertices.size()) + " untraced feature samples to " + feature_misses);
    }
    monitor.Info("done in " + std::to_string(seconds) + " s");
  });
}

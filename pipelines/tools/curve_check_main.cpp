// curve-check: how a mesh of a built-in shape keeps its non-manifold curves and its Euler characteristic,
// as one JSON line (pipelines/nonmanifold-sweep.sh).
#include <cstdio>

#include "common/cli.h"
#include "common/shapes.h"
#include "formats/mesh_io.h"
#include "pipelines/tools/curve_check.h"

int main(int argc, char** argv) {
  std::string shape, input;
  double tol = 1e-3, max_gap = 0;
  voroudf::StageCli cli("curve-check", "Checks a mesh of shape:NAME against the shape's known non-manifold curves "
                                       "and Euler characteristic; prints one JSON line.");
  cli.AddInput(&input, "mesh PLY");
  cli.app().add_option("--shape", shape, "built-in shape the mesh was made of")->required();
  cli.app().add_option("--tol", tol, "a non-manifold edge farther than this from the curves is off them");
  cli.app().add_option("--max-gap", max_gap, "longest uncovered stretch of the curves (0: 3 x mean edge length)");
  return cli.Run(argc, argv, [] {}, [&](voroudf::Monitor&) {
    const voroudf::BranchingCheck c =
        voroudf::CheckBranchingCurves(voroudf::ReadMesh(input), voroudf::KnownTopology(shape), tol, max_gap);
    std::printf("{\"shape\": \"%s\", \"pass\": %s, \"euler\": %lld, \"expected_euler\": %lld, \"nonmanifold_edges\": %zu, "
                "\"off_curve\": %zu, \"max_offset\": %.6g, \"longest_gap\": %.6g, \"mean_edge\": %.6g, "
                "\"boundary_edges\": %zu}\n",
                shape.c_str(), c.pass ? "true" : "false", c.euler, c.expected_euler, c.nonmanifold_edges, c.off_curve,
                c.max_offset, c.longest_gap, c.mean_edge, c.boundary_edges);
  });
}

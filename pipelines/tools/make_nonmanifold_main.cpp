// make-nonmanifold: one synthetic non-manifold benchmark shape from a closed CAD mesh (paper Sec. 4.1).
// Writes OUT (a voroudf mesh) and OUT.json with the parameters and the counts, so the set is reproducible.
#include <cstdio>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/mesh_topology.h"
#include "formats/mesh_io.h"
#include "pipelines/tools/synthetic_nonmanifold.h"

int main(int argc, char** argv) {
  voroudf::OverlapOptions options;
  std::string input, output;
  std::vector<double> normal{options.plane_normal.x(), options.plane_normal.y(), options.plane_normal.z()};
  voroudf::StageCli cli("make-nonmanifold", "Cuts a closed mesh with a plane, shifts one part into the other by a "
                                            "narrow band and merges them: the crossings become non-manifold edges.");
  cli.AddInput(&input, "closed triangle mesh (.ply .obj .off .stl)");
  cli.AddOutput(&output, "merged non-manifold mesh (.ply); parameters are written to OUTPUT.json");
  cli.app().add_option("--normal", normal, "cut plane normal")->expected(3);
  cli.app().add_option("--offset-rel", options.plane_offset_rel, "plane offset from the bbox centre, x diagonal");
  cli.app().add_option("--overlap-rel", options.overlap_rel, "shift of one part into the other, x diagonal");
  return cli.Run(argc, argv, [&] {
    options.plane_normal = voroudf::Vec3(normal[0], normal[1], normal[2]);
    options.Check();
  }, [&](voroudf::Monitor& monitor) {
    const voroudf::TriangleMesh merged = voroudf::MakeOverlapNonManifold(voroudf::ReadMesh(input), options, input);
    const voroudf::TopologyStats s = voroudf::ComputeTopology(merged);
    voroudf::WriteMeshPly(output, merged, cli.provenance());
    char json[512];
    std::snprintf(json, sizeof json,
                  "{\"source\": \"%s\", \"normal\": [%.6f, %.6f, %.6f], \"offset_rel\": %g, \"overlap_rel\": %g, "
                  "\"vertices\": %zu, \"faces\": %zu, \"nonmanifold_edges\": %zu, \"euler\": %lld}\n",
                  input.c_str(), normal[0], normal[1], normal[2], options.plane_offset_rel, options.overlap_rel,
                  s.num_vertices, s.num_faces, s.nonmanifold_edges, s.euler);
    voroudf::WriteFileAtomically(output + ".json", json);
    monitor.Info("wrote " + output + ": " + std::to_string(s.num_faces) + " faces, " +
                 std::to_string(s.nonmanifold_edges) + " non-manifold edges");
  });
}

// thin-mesh: thins the thick dual mesh of build-gvd into the final surface mesh (docs/thin-mesh.md).
#include "common/cli.h"
#include "formats/mesh_io.h"
#include "stages/thin-mesh/thin_mesh.h"

int main(int argc, char** argv) {
  voroudf::ThinMeshOptions options;
  std::string udf_spec, input, output, nm_edges;
  bool ascii = false;

  voroudf::StageCli cli("thin-mesh",
                        "Removes face pairs from the closed tetrahedra of a dual mesh (the pair on a manifold edge "
                        "whose centroids have the highest UDF), then small components, then closes the gaps of "
                        "junctions the dual missed; keeps non-manifold edges.");
  cli.AddUdf(&udf_spec);
  cli.AddInput(&input, "input thick mesh PLY (thick.ply from build-gvd)");
  cli.AddOutput(&output, "output mesh PLY (mesh.ply)");
  cli.AddExtraOutput("--nm-edges", &nm_edges, "also write the non-manifold edges (3+ faces) as an edges PLY");
  cli.AddAscii(&ascii);
  auto& app = cli.app();
  app.add_option("--min-component-faces", options.min_component_faces,
                 "components with fewer faces are removed (unless that opens a hole)");
  app.add_option("--degenerate-quality", options.degenerate_quality,
                 "faces with triangle quality below this are dropped as degenerate (0: only zero area)");
  app.add_option("--thinning", options.thinning,
                 "paper: the paper's two steps only; close-holes: then close the junction gaps the dual left and "
                 "collapse the flaps that leaves dangling")
      ->check(CLI::IsMember({"paper", "close-holes"}));
  app.add_option("--layer-angle", options.layer_angle_deg,
                 "a small component without a free edge is removed only if it lies within this angle (deg) of "
                 "faces that stay (a second layer); 180: always, as the paper");
  app.add_option("--overlap-angle", options.overlap_angle_deg,
                 "a face added to close a gap must not lie within this angle (deg) of a face on its edges");
  app.add_option("--rim-flaps", options.rim_flaps,
                 "remove the faces hanging from a free edge across a non-manifold edge where the edges they leave "
                 "open lie on a rim (true/false; not with --thinning paper)");
  app.add_option("--fold-flaps", options.fold_flaps,
                 "remove the faces hanging from a free edge folded over another face of a non-manifold edge "
                 "(within --overlap-angle), then close the holes again (true/false; not with --thinning paper)");
  app.add_option("--shell-rings", options.shell_rings,
                 "open the closed shells the paper's steps leave (bubbles no face pair can thin) that lie within "
                 "this many edges of one of their faces, at a face off the surface (0: off; not with --thinning paper)");
  app.add_option("--relax-iters", options.relax.iterations,
                 "then even the triangles out: steps moving each vertex inside a smooth patch toward its "
                 "neighbours' centroid along the surface (0: off, the paper's mesh: vertices are the seeds)");
  app.add_option("--relax-step", options.relax.step, "share of the way to the centroid taken per step");
  app.add_option("--relax-feature-angle", options.relax.feature_angle_deg,
                 "vertices on an edge whose faces' normals differ by more than this (deg) stay, as on rims "
                 "and non-manifold edges");
  app.add_option("--split-feature-chords", options.chords.enabled,
                 "before relaxing, split each sharp edge that cuts across a curved feature (the point where its "
                 "two sheets' tangent planes meet lies over 10 % of its length off it) at that point (true/false)");

  return cli.Run(argc, argv, [&] { options.Check(); }, [&](voroudf::Monitor& monitor) {
    const auto udf = cli.OpenUdf(monitor);
    const voroudf::TriangleMesh thick = voroudf::ReadMeshPly(input);
    const voroudf::TriangleMesh mesh = voroudf::ThinMesh(*udf, thick, options, monitor);
    voroudf::WriteMeshPly(output, mesh, cli.provenance(), ascii);
    monitor.Info("wrote " + std::to_string(mesh.faces.size()) + " faces to " + output);
    if (!nm_edges.empty()) {
      const voroudf::EdgeSet edges = voroudf::NonManifoldEdges(mesh);
      voroudf::WriteEdgesPly(nm_edges, edges, cli.provenance(), ascii);
      monitor.Info("wrote " + std::to_string(edges.edges.size()) + " non-manifold edges to " + nm_edges);
    }
  });
}

// udf-grid: samples any UDF source on a regular grid and writes it as a .npy with its box sidecar — the form
// learned UDFs are exported in — so that `--udf GRID.npy` stands in for a learned field in experiments
// (pipelines/noise-study). Distances only: the grid source then takes gradients from its interpolant.
#include <cstdio>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/errors.h"
#include "common/grid_udf.h"

int main(int argc, char** argv) {
  std::string spec, output;
  int resolution = 64;
  voroudf::StageCli cli("udf-grid", "Samples a UDF at RES^3 nodes of its domain box (first and last node on the box "
                                    "faces) into OUTPUT.npy (float32) and OUTPUT.json ({\"box\": ...}).");
  cli.AddUdf(&spec);
  cli.AddOutput(&output, "grid (.npy); its box is written to the same path with .json");
  cli.app().add_option("--resolution", resolution, "nodes per axis, 2..1024")->capture_default_str();
  return cli.Run(argc, argv, [&] {
    if (resolution < 2 || resolution > 1024) throw voroudf::UsageError("--resolution must be in [2, 1024]");
    if (output.size() < 5 || output.substr(output.size() - 4) != ".npy")
      throw voroudf::UsageError("-o must name a .npy file");
  }, [&](voroudf::Monitor& monitor) {
    const auto udf = cli.OpenUdf(monitor);
    const voroudf::Box box = udf->Domain();
    const size_t n = static_cast<size_t>(resolution);
    std::vector<voroudf::Vec3> nodes(n * n * n);
    const voroudf::Vec3 h = box.Extent() / static_cast<double>(n - 1);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        for (size_t k = 0; k < n; ++k)
          nodes[(i * n + j) * n + k] = box.min + voroudf::Vec3(i * h.x(), j * h.y(), k * h.z());
    std::vector<double> distance;
    std::vector<voroudf::Vec3> gradient;
    udf->Evaluate(nodes, distance, gradient);
    const std::vector<float> values(distance.begin(), distance.end());
    char json[256];
    std::snprintf(json, sizeof json, "{\"box\": [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g]]}\n", box.min.x(),
                  box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z());
    voroudf::WriteNpyFloat32(output, {n, n, n}, values);
    voroudf::WriteFileAtomically(output.substr(0, output.size() - 4) + ".json", json);
    monitor.Info("wrote " + output + " (" + std::to_string(n) + "^3, box " + voroudf::FormatBox(box) + ")");
  });
}

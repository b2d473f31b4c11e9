// bench-udf: UDF queries per second per source, one thread and all threads (not a test; run by
// pipelines/bench.sh). Mesh sources are timed on near-surface points (area-uniform surface samples jittered
// by up to 1 % of the domain diagonal per coordinate: the pipeline's workload) and on points uniform in the
// domain box, against CGAL's AABB_tree on the same points as the reference (speed and the largest
// disagreement in distance). A grid sampled from the first mesh and the exec: reference server complete
// the table.
//
// Each figure is the best of three rounds (see Rate).
//
// Usage: bench-udf [--points N] [--seconds S] [--server COMMAND] MESH...
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "common/exec_udf.h"
#include "common/grid_udf.h"
#include "common/mesh_udf.h"
#include "common/rng.h"

namespace {

using namespace voroudf;
using Clock = std::chrono::steady_clock;

using K = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

// Queries per second of `pass` (one pass over `n` queries): the best of three rounds of at least
// min_seconds / 3 each, so that other processes on a shared machine disturb the figure less.
double Rate(size_t n, double min_seconds, const std::function<void()>& pass) {
  pass();  // warm-up (page faults, caches, a server's first import)
  double best = 0.0;
  for (int round = 0; round < 3; ++round) {
    size_t done = 0;
    const auto start = Clock::now();
    do {
      pass();
      done += n;
    } while (Seconds(start) < min_seconds / 3);
    best = std::max(best, static_cast<double>(done) / Seconds(start));
  }
  return best;
}

std::vector<Vec3> NearSurface(const TriangleMesh& m, const Box& domain, size_t n, uint64_t seed) {
  std::vector<double> cumulative(m.faces.size());
  double total = 0.0;
  for (size_t f = 0; f < m.faces.size(); ++f) {
    const Tri& t = m.faces[f];
    total += 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
    cumulative[f] = total;
  }
  const double jitter = 0.01 * domain.Diagonal();
  std::vector<Vec3> pts(n);
  for (size_t i = 0; i < n; ++i) {
    Rng rng(seed, i);
    const size_t f = std::min(m.faces.size() - 1,
                              static_cast<size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), rng.Uniform() * total) -
                                                  cumulative.begin()));
    double u = rng.Uniform(), v = rng.Uniform();
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const Tri& t = m.faces[f];
    const Vec3 on = m.vertices[t[0]] + u * (m.vertices[t[1]] - m.vertices[t[0]]) + v * (m.vertices[t[2]] - m.vertices[t[0]]);
    pts[i] = on + jitter * Vec3(rng.Uniform(-1, 1), rng.Uniform(-1, 1), rng.Uniform(-1, 1));
  }
  return pts;
}

std::vector<Vec3> Uniform(const Box& b, size_t n, uint64_t seed) {
  std::vector<Vec3> pts(n);
  for (size_t i = 0; i < n; ++i) {
    Rng rng(seed, i);
    pts[i] = Vec3(rng.Uniform(b.min.x(), b.max.x()), rng.Uniform(b.min.y(), b.max.y()), rng.Uniform(b.min.z(), b.max.z()));
  }
  return pts;
}

struct Row {
  std::string source, points;
  int threads;
  double rate;
  std::string note;
};

void Print(const std::vector<Row>& rows) {
  std::printf("| source | query points | threads | queries/s | queries/s/thread | note |\n|---|---|---:|---:|---:|---|\n");
  for (const Row& r : rows)
    std::printf("| %s | %s | %d | %.3g M | %.3g M | %s |\n", r.source.c_str(), r.points.c_str(), r.threads, r.rate / 1e6,
                r.rate / 1e6 / r.threads, r.note.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  size_t n = 200000;
  double seconds = 1.5;
  std::string server = std::string("/usr/bin/python3 ") + VOROUDF_SOURCE_DIR + "/pipelines/udf_server_sphere.py";
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--points" && i + 1 < argc) n = std::strtoul(argv[++i], nullptr, 10);
    else if (a == "--seconds" && i + 1 < argc) seconds = std::strtod(argv[++i], nullptr);
    else if (a == "--server" && i + 1 < argc) server = argv[++i];
    else if (a.rfind("--", 0) == 0 || n == 0 || !(seconds > 0)) {
      std::fprintf(stderr, "usage: bench-udf [--points N] [--seconds S] [--server COMMAND] MESH...\n");
      return 2;
    } else meshes.push_back(a);
  }
  if (meshes.empty()) {
    std::fprintf(stderr, "usage: bench-udf [--points N] [--seconds S] [--server COMMAND] MESH...\n");
    return 2;
  }
  const int all = omp_get_max_threads();
  std::vector<Row> rows;
  std::vector<double> d(n);
  std::vector<Vec3> g(n);
  std::unique_ptr<MeshUdf> first;
  try {
    for (const std::string& path : meshes) {
      auto t0 = Clock::now();
      auto udf = MeshUdf::Open(path);
      const double bvh_s = Seconds(t0);
      const std::string name = path.substr(path.find_last_of('/') + 1) + " (" + std::to_string(udf->mesh().faces.size()) + " f)";
      std::fprintf(stderr, "%s: %s\n", name.c_str(), udf->Describe().c_str());

      CgalTriangles tris;
      for (const Tri& t : udf->mesh().faces) {
        auto P = [&](int k) { const Vec3& v = udf->mesh().vertices[t[k]]; return K::Point_3(v.x(), v.y(), v.z()); };
        tris.emplace_back(P(0), P(1), P(2));
      }
      t0 = Clock::now();
      CgalTree tree(tris.begin(), tris.end());
      tree.accelerate_distance_queries();
      tree.build();
      const double cgal_s = Seconds(t0);
      char note[160];
      std::snprintf(note, sizeof note, "read + BVH build %.3f s (CGAL tree %.3f s)", bvh_s, cgal_s);

      const std::pair<std::string, std::vector<Vec3>> sets[] = {
          {"near surface (±1 % diag)", NearSurface(udf->mesh(), udf->Domain(), n, 1)},
          {"uniform in domain", Uniform(udf->Domain(), n, 2)}};
      for (const auto& set : sets) {
        // Named, not structured, bindings: clang 14 (the TSan build) cannot capture those in a lambda.
        const std::string& label = set.first;
        const std::vector<Vec3>& pts = set.second;
        // Agreement with CGAL (exact closest point in double as well).
        double worst = 0.0;
        udf->Evaluate(pts.data(), n, d.data(), g.data());
        for (size_t i = 0; i < n; i += 7) {
          const K::Point_3 q(pts[i].x(), pts[i].y(), pts[i].z());
          worst = std::max(worst, std::abs(std::sqrt(tree.squared_distance(q)) - d[i]));
        }
        // EvaluateChunk: the points in the given (random) order; Evaluate: the batch API every stage uses,
        // which visits large batches in Morton order.
        const double chunk = Rate(n, seconds, [&] { udf->EvaluateChunk(pts.data(), n, d.data(), g.data()); });
        rows.push_back({"mesh " + name, label, 1, chunk, std::string("EvaluateChunk, input order; ") + note});
        omp_set_num_threads(1);
        const double one = Rate(n, seconds, [&] { udf->Evaluate(pts.data(), n, d.data(), g.data()); });
        omp_set_num_threads(all);
        rows.push_back({"mesh " + name, label, 1, one, "Evaluate (Morton-ordered batch)"});
        const double many = Rate(n, seconds, [&] { udf->Evaluate(pts.data(), n, d.data(), g.data()); });
        rows.push_back({"mesh " + name, label, all, many, "Evaluate (Morton-ordered batch)"});
        std::vector<double> cd(n);
        const double cgal_one = Rate(n, seconds, [&] {
          for (size_t i = 0; i < n; ++i) {
            const auto hit = tree.closest_point_and_primitive(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()));
            cd[i] = CGAL::squared_distance(hit.first, K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()));
          }
        });
        char cgal_note[96];
        std::snprintf(cgal_note, sizeof cgal_note, "reference; max |d - d_CGAL| = %.1e", worst);
        rows.push_back({"CGAL AABB_tree " + name, label, 1, cgal_one, cgal_note});
        const double cgal_many = Rate(n, seconds, [&] {
#pragma omp parallel for schedule(dynamic, 256)
          for (long i = 0; i < static_cast<long>(n); ++i) {
            const auto hit = tree.closest_point_and_primitive(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()));
            cd[i] = CGAL::squared_distance(hit.first, K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()));
          }
        });
        rows.push_back({"CGAL AABB_tree " + name, label, all, cgal_many, ""});
        Print({rows.end() - 5, rows.end()});
      }
      if (!first) first = std::move(udf);
    }

    // Grid: 128^3 samples of the first mesh's UDF, queried on the same kind of near-surface points.
    {
      const size_t res = 128;
      const Box box = first->Domain();
      std::vector<Vec3> nodes(res * res * res);
      for (size_t i = 0; i < res; ++i)
        for (size_t j = 0; j < res; ++j)
          for (size_t k = 0; k < res; ++k)
            nodes[(i * res + j) * res + k] = box.min + box.Extent().cwiseProduct(Vec3(i, j, k) / double(res - 1));
      std::vector<double> nd;
      std::vector<Vec3> ng;
      first->Evaluate(nodes, nd, ng);
      const GridUdf grid(std::vector<float>(nd.begin(), nd.end()), {res, res, res}, box, {}, "grid");
      const std::vector<Vec3> pts = NearSurface(first->mesh(), box, n, 3);
      const double one = Rate(n, seconds, [&] { grid.EvaluateChunk(pts.data(), n, d.data(), g.data()); });
      rows.push_back({"grid 128^3 of the first mesh", "near surface (±1 % diag)", 1, one, "tricubic of d^2 + Hessian normal near 0"});
      const double many = Rate(n, seconds, [&] { grid.Evaluate(pts.data(), n, d.data(), g.data()); });
      rows.push_back({"grid 128^3 of the first mesh", "near surface (±1 % diag)", all, many, ""});
      Print({rows.end() - 2, rows.end()});
    }

    // exec: the reference Python server (float32 over pipes, numpy on the server's side).
    {
      ExecUdf exec(server, {});
      const std::vector<Vec3> pts = Uniform(exec.Domain(), n, 4);
      const double rate = Rate(n, seconds, [&] { exec.Evaluate(pts.data(), n, d.data(), g.data()); });
      rows.push_back({"exec: " + exec.server_name(), "uniform in domain", 1, rate, "65536 points per request"});
      Print({rows.end() - 1, rows.end()});
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench-udf: error: %s\n", e.what());
    return 3;
  }
  std::printf("\n## bench-udf summary (%zu points per set, %d threads available)\n\n", n, all);
  Print(rows);
  return 0;
}

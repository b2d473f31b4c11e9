#include "common/shapes.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "common/errors.h"
#include "common/triangle_bvh.h"

namespace voroudf {
namespace {

// Below this length a direction is undefined; the shapes are unit-sized so an absolute value is right.
constexpr double kTiny = 1e-12;

// Any unit vector orthogonal to n (deterministic).
Vec3 AnyOrthogonal(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(a).normalized();
}

class Sphere : public Primitive {
 public:
  Sphere(const Vec3& c, double r) : c_(c), r_(r) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const Vec3 v = p - c_;
    const double len = v.norm();
    *normal = len > kTiny ? Vec3(v / len) : Vec3::UnitZ();
    return c_ + r_ * *normal;
  }

 private:
  Vec3 c_;
  double r_;
};

class Hemisphere : public Primitive {
 public:
  Hemisphere(const Vec3& c, double r, const Vec3& axis) : c_(c), r_(r), axis_(axis.normalized()) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const Vec3 v = p - c_;
    const double h = v.dot(axis_);
    const double len = v.norm();
    if (h >= 0.0) {
      *normal = len > kTiny ? Vec3(v / len) : axis_;
    } else {
      // Below the cut plane the closest point is on the rim, in the direction of v's in-plane part
      // (maximising a linear function over a spherical cap whose pole is not in it).
      const Vec3 in_plane = v - h * axis_;
      const double l = in_plane.norm();
      *normal = l > kTiny ? Vec3(in_plane / l) : AnyOrthogonal(axis_);
    }
    return c_ + r_ * *normal;
  }

 private:
  Vec3 c_;
  double r_;
  Vec3 axis_;
};

class Disc : public Primitive {
 public:
  Disc(const Vec3& c, const Vec3& n, double r) : c_(c), n_(n.normalized()), r_(r) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const Vec3 v = p - c_;
    Vec3 in_plane = v - v.dot(n_) * n_;
    const double l = in_plane.norm();
    if (l > r_) in_plane *= r_ / l;
    *normal = n_;
    return c_ + in_plane;
  }

 private:
  Vec3 c_, n_;
  double r_;
};

class Rectangle : public Primitive {
 public:
  Rectangle(const Vec3& c, const Vec3& u, const Vec3& v, double hu, double hv)
      : c_(c), u_(u.normalized()), v_(v.normalized()), n_(u_.cross(v_).normalized()), hu_(hu), hv_(hv) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const Vec3 w = p - c_;
    const double a = std::clamp(w.dot(u_), -hu_, hu_);
    const double b = std::clamp(w.dot(v_), -hv_, hv_);
    *normal = n_;
    return c_ + a * u_ + b * v_;
  }

 private:
  Vec3 c_, u_, v_, n_;
  double hu_, hv_;
};

class CubeSurface : public Primitive {
 public:
  explicit CubeSurface(double h) : h_(h) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    // The face whose plane is nearest to p: largest |p_k| (first on ties).
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(p[i]) > std::abs(p[k])) k = i;
    const double s = p[k] < 0.0 ? -1.0 : 1.0;
    *normal = s * Vec3::Unit(k);
    Vec3 c;
    if ((p.array().abs() <= h_).all()) {
      c = p;  // inside: push the dominant coordinate onto its face
      c[k] = s * h_;
    } else {
      c = p.cwiseMax(-h_).cwiseMin(h_);
    }
    return c;
  }

 private:
  double h_;
};

class Torus : public Primitive {
 public:
  Torus(double R, double r) : R_(R), r_(r) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const double rho = std::hypot(p.x(), p.y());
    const Vec3 radial = rho > kTiny ? Vec3(p.x() / rho, p.y() / rho, 0.0) : Vec3::UnitX();
    const Vec3 m = R_ * radial;  // nearest point of the core circle
    const Vec3 v = p - m;
    const double l = v.norm();
    *normal = l > kTiny ? Vec3(v / l) : radial;
    return m + r_ * *normal;
  }

 private:
  double R_, r_;
};

// A closed polyhedron given by its triangles: the closest point over them (TriangleBvh, which keeps its own
// packed copy of the triangles), the normal of the closest triangle.
class Polyhedron : public Primitive {
 public:
  explicit Polyhedron(const TriangleMesh& mesh) : bvh_(mesh.vertices, mesh.faces) {}
  Vec3 ClosestPoint(const Vec3& p, Vec3* normal) const override {
    const TriangleBvh::Hit hit = bvh_.Closest(p);
    *normal = bvh_.FaceNormal(hit.face);
    return hit.point;
  }

 private:
  TriangleBvh bvh_;
};

// The prism over a simple polygon (counter-clockwise, star-shaped from its first vertex, so a fan from
// it triangulates it) between z = -half_height and z = +half_height, faces oriented outwards.
TriangleMesh PrismMesh(const std::vector<Eigen::Vector2d>& polygon, double half_height) {
  TriangleMesh m;
  const int n = static_cast<int>(polygon.size());
  for (double z : {-half_height, half_height})
    for (const auto& q : polygon) m.vertices.emplace_back(q.x(), q.y(), z);
  for (int i = 1; i + 1 < n; ++i) {
    m.faces.push_back({0, i + 1, i});          // bottom, facing -z
    m.faces.push_back({n, n + i, n + i + 1});  // top, facing +z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.faces.push_back({i, j, n + j});
    m.faces.push_back({i, n + j, n + i});
  }
  return m;
}

// shape:feature-prism's cross-section: an L whose upright ends in a 20° spike at (-0.5, 0.5), with the
// outer corner (0.5, -0.5) chamfered by 0.06. Its prism has a concave edge (at D), a 0.085 chamfer face
// whose two short top and bottom edges join close corners, and two sharp edges meeting at 20° (at F).
std::vector<Eigen::Vector2d> FeaturePrismPolygon() {
  const double spike = 20.0 * M_PI / 180.0;
  return {{-0.5, -0.5}, {0.44, -0.5}, {0.5, -0.44}, {0.5, -0.1},
          {-0.5 + 0.6 * std::tan(spike), -0.1},  // D: the concave corner
          {-0.5, 0.5}};                           // F: the 20° spike
}

}  // namespace

std::unique_ptr<Primitive> MakeSphere(const Vec3& c, double r) { return std::make_unique<Sphere>(c, r); }
std::unique_ptr<Primitive> MakeHemisphere(const Vec3& c, double r, const Vec3& axis) {
  return std::make_unique<Hemisphere>(c, r, axis);
}
std::unique_ptr<Primitive> MakeDisc(const Vec3& c, const Vec3& n, double r) { return std::make_unique<Disc>(c, n, r); }
std::unique_ptr<Primitive> MakeRectangle(const Vec3& c, const Vec3& u, const Vec3& v, double hu, double hv) {
  return std::make_unique<Rectangle>(c, u, v, hu, hv);
}
std::unique_ptr<Primitive> MakeCubeSurface(double h) { return std::make_unique<CubeSurface>(h); }
std::unique_ptr<Primitive> MakeTorus(double R, double r) { return std::make_unique<Torus>(R, r); }

AnalyticUdf::AnalyticUdf(std::string name, std::string description, Box domain,
                         std::vector<std::unique_ptr<Primitive>> parts)
    : name_(std::move(name)), description_(std::move(description)), domain_(domain), parts_(std::move(parts)) {}

void AnalyticUdf::EvaluateChunk(const Vec3* points, size_t count, double* distance, Vec3* gradient) const {
  for (size_t i = 0; i < count; ++i) {
    const Vec3& p = points[i];
    double best = INFINITY;
    Vec3 best_c = p, best_n = Vec3::UnitZ();
    for (const auto& part : parts_) {
      Vec3 n;
      const Vec3 c = part->ClosestPoint(p, &n);
      const double d = (p - c).norm();
      if (d < best) {
        best = d;
        best_c = c;
        best_n = n;
      }
    }
    distance[i] = best;
    gradient[i] = best > kTiny ? Vec3((p - best_c) / best) : best_n;
  }
}

std::string AnalyticUdf::Describe() const { return "shape:" + name_ + " (" + description_ + ")"; }

namespace {

// shape:fold's turn: below the 2·atan(0.4) = 43.6° at which optimize-seeds' rank test starts to see a crease.
constexpr double kFoldAngle = 35.0 * M_PI / 180.0;

struct ShapeEntry {
  const char* name;
  const char* description;
  std::function<std::vector<std::unique_ptr<Primitive>>()> build;
};

template <typename... P>
std::vector<std::unique_ptr<Primitive>> Parts(P&&... p) {
  std::vector<std::unique_ptr<Primitive>> v;
  (v.push_back(std::forward<P>(p)), ...);
  return v;
}

const std::vector<ShapeEntry>& Shapes() {
  const Vec3 o = Vec3::Zero(), x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  static const std::vector<ShapeEntry> shapes = {
      {"sphere", "sphere of radius 0.5 at the origin", [=] { return Parts(MakeSphere(o, 0.5)); }},
      {"cube", "surface of the cube [-0.5,0.5]^3: 12 sharp edges, 8 corners",
       [=] { return Parts(MakeCubeSurface(0.5)); }},
      {"feature-prism", "prism |z|<=0.3 over an L with a 20 degree spike and a chamfered corner: a concave edge, "
                        "short edges between close corners, sharp edges meeting at 20 degrees",
       [=] { return Parts(std::make_unique<Polyhedron>(ShapeMesh("feature-prism"))); }},
      {"disc", "open disc of radius 0.5 in the plane z=0", [=] { return Parts(MakeDisc(o, z, 0.5)); }},
      {"hemisphere", "open upper hemisphere (z>=0) of the sphere of radius 0.5",
       [=] { return Parts(MakeHemisphere(o, 0.5, z)); }},
      {"crossing-planes", "squares [-0.5,0.5]^2 in z=0 and x=0 crossing along the y axis (non-manifold line)",
       [=] { return Parts(MakeRectangle(o, x, y, 0.5, 0.5), MakeRectangle(o, y, z, 0.5, 0.5)); }},
      {"sphere-disc", "sphere of radius 0.5 with the disc z=0 inside it (non-manifold equator)",
       [=] { return Parts(MakeSphere(o, 0.5), MakeDisc(o, z, 0.5)); }},
      {"three-discs", "discs of radius 0.5 in the planes x=0, y=0, z=0 (non-manifold axes)",
       [=] { return Parts(MakeDisc(o, z, 0.5), MakeDisc(o, x, 0.5), MakeDisc(o, y, 0.5)); }},
      {"torus", "torus around z, radii 0.35 and 0.15 (genus 1)", [=] { return Parts(MakeTorus(0.35, 0.15)); }},
      {"sphere-ring", "sphere of radius 0.35 inside a thin ring: torus around z, radii 0.48 and 0.03 (thin part)",
       [=] { return Parts(MakeSphere(o, 0.35), MakeTorus(0.48, 0.03)); }},
      {"fold", "open sheet folded along the y axis by 35 degrees: [-0.5,0]x[-0.5,0.5] in z=0 and its mirror turned up (shallow crease)",
       [=] {
         const Vec3 up(std::cos(kFoldAngle), 0.0, std::sin(kFoldAngle));  // the second half's direction away from the fold
         return Parts(MakeRectangle(Vec3(-0.25, 0, 0), x, y, 0.25, 0.5), MakeRectangle(0.25 * up, up, y, 0.25, 0.5));
       }},
  };
  return shapes;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> ShapeCatalog() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& s : Shapes()) out.emplace_back(s.name, s.description);
  return out;
}

std::unique_ptr<AnalyticUdf> MakeShape(const std::string& name) {
  // Every shape lies in [-0.5,0.5]^3; one common domain keeps relative lengths comparable across shapes.
  const Box domain{Vec3::Constant(-0.6), Vec3::Constant(0.6)};
  std::string known;
  for (const auto& s : Shapes()) {
    if (name == s.name) return std::make_unique<AnalyticUdf>(s.name, s.description, domain, s.build());
    known += std::string(known.empty() ? "" : ", ") + s.name;
  }
  throw InputError("shape:" + name, "unknown built-in shape (known: " + known + ")");
}

namespace {

std::vector<Vec3> Segment(const Vec3& a, const Vec3& b) {
  std::vector<Vec3> line;
  const int n = 1000;
  for (int i = 0; i <= n; ++i) line.push_back(a + (b - a) * (static_cast<double>(i) / n));
  return line;
}

}  // namespace

TriangleMesh ShapeMesh(const std::string& name) {
  if (name == "feature-prism") return PrismMesh(FeaturePrismPolygon(), 0.3);
  if (name == "cube") return PrismMesh({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}}, 0.5);
  throw InputError("shape:" + name, "not a polyhedron (shapes with a triangle mesh: cube, feature-prism)");
}

ShapeTopology KnownTopology(const std::string& name) {
  ShapeTopology t;
  // chi of a union = sum of the parts' chi - sum over pairwise intersections + the triple one.
  if (name == "sphere" || name == "cube" || name == "feature-prism") t.euler = 2;
  else if (name == "disc" || name == "hemisphere" || name == "fold") t.euler = 1;
  else if (name == "torus") t.euler = 0;
  else if (name == "sphere-ring") t.euler = 2 + 0;  // two components: a sphere and a torus
  else if (name == "crossing-planes") {
    t.euler = 1 + 1 - 1;  // two squares, one common segment
    t.branching_curves = {Segment(Vec3(0, -0.5, 0), Vec3(0, 0.5, 0))};
  } else if (name == "sphere-disc") {
    t.euler = 2 + 1 - 0;  // sphere and disc glued along a circle (chi 0)
    std::vector<Vec3> circle;
    for (int i = 0; i <= 4000; ++i) {
      const double a = 2 * M_PI * i / 4000;
      circle.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0);
    }
    t.branching_curves = {circle};
  } else if (name == "three-discs") {
    t.euler = 3 - 3 + 1;  // three discs, three common diameters, one common centre
    t.branching_curves = {Segment(Vec3(-0.5, 0, 0), Vec3(0.5, 0, 0)), Segment(Vec3(0, -0.5, 0), Vec3(0, 0.5, 0)),
                          Segment(Vec3(0, 0, -0.5), Vec3(0, 0, 0.5))};
  } else {
    throw InputError("shape:" + name, "no known topology");
  }
  return t;
}

}  // namespace voroudf

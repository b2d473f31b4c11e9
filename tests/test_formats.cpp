// Formats: round trips, files from other tools, and every kind of bad file refused with a clear error.
#include <gtest/gtest.h>

#include <functional>

#include <cmath>
#include <cstring>

#include "common/errors.h"
#include "common/rng.h"
#include "formats/labels_io.h"
#include "formats/mesh_io.h"
#include "formats/ply.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::ReadBytes;
using test::TempDir;
using test::WriteBytes;

SeedCloud RandomSeeds(size_t n) {
  SeedCloud s;
  s.Resize(n);
  Rng rng(7, 0);
  for (size_t i = 0; i < n; ++i) {
    // Values representable in float32, so that a round trip must be exact.
    for (int k = 0; k < 3; ++k) {
      s.position[i][k] = static_cast<float>(rng.Uniform(-1, 1));
      s.normal[i][k] = static_cast<float>(rng.Uniform(-1, 1));
    }
    s.udf[i] = static_cast<float>(rng.Uniform(0, 1e-3));
    s.rank[i] = static_cast<uint8_t>(rng.Below(4));
  }
  return s;
}

TriangleMesh NonManifoldMesh() {
  // Three triangles on the edge (0,1), plus one more: an edge of valence 3.
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5f, 1, 0), Vec3(0.5f, -1, 0), Vec3(0.5f, 0, 1), Vec3(2, 2, 2)};
  m.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {2, 4, 5}};
  return m;
}

Provenance TestProvenance() { return Provenance{"test", "--count 3", "shape:sphere"}; }

void ExpectInputError(const std::function<void()>& f, const std::string& expected_fragment) {
  try {
    f();
    FAIL() << "no error; expected one mentioning '" << expected_fragment << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected_fragment), std::string::npos) << e.what();
    EXPECT_EQ(e.exit_code(), kExitBadInput);
  }
}

class RoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(RoundTrip, SeedsAreBitExact) {
  const bool ascii = GetParam();
  TempDir dir;
  const SeedCloud seeds = RandomSeeds(200);
  WriteSeeds(dir / "a.ply", seeds, TestProvenance(), ascii);
  const SeedCloud back = ReadSeeds(dir / "a.ply");
  ASSERT_EQ(back.size(), seeds.size());
  for (size_t i = 0; i < seeds.size(); ++i) {
    EXPECT_EQ(back.position[i], seeds.position[i]);
    EXPECT_EQ(back.normal[i], seeds.normal[i]);
    EXPECT_EQ(back.udf[i], seeds.udf[i]);
    EXPECT_EQ(back.rank[i], seeds.rank[i]);
  }
  WriteSeeds(dir / "b.ply", back, TestProvenance(), ascii);
  EXPECT_EQ(ReadBytes(dir / "a.ply"), ReadBytes(dir / "b.ply"));
  const std::string head = ReadBytes(dir / "a.ply").substr(0, 200);
  EXPECT_NE(head.find(ascii ? "format ascii 1.0" : "format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(head.find("comment voroudf seeds 1"), std::string::npos);
  EXPECT_NE(head.find("comment stage test"), std::string::npos);
  EXPECT_NE(head.find("comment udf shape:sphere"), std::string::npos);
}

TEST_P(RoundTrip, NonManifoldMeshKeepsItsFaces) {
  const bool ascii = GetParam();
  TempDir dir;
  const TriangleMesh m = NonManifoldMesh();
  WriteMeshPly(dir / "m.ply", m, TestProvenance(), ascii);
  const TriangleMesh back = ReadMeshPly(dir / "m.ply");
  EXPECT_EQ(back.vertices, m.vertices);
  EXPECT_EQ(back.faces, m.faces);
  WriteMeshPly(dir / "m2.ply", back, TestProvenance(), ascii);
  EXPECT_EQ(ReadBytes(dir / "m.ply"), ReadBytes(dir / "m2.ply"));
}

TEST_P(RoundTrip, LabelsWithGraph) {
  const bool ascii = GetParam();
  TempDir dir;
  LabeledSamples s;
  s.position = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  s.label = {0, -1, 2};
  s.dist = {0.0, 0.25, 0.5};
  s.edges = {{{0, 1}}, {{1, 2}}};
  WriteLabels(dir / "l.ply", s, TestProvenance(), ascii);
  const LabeledSamples back = ReadLabels(dir / "l.ply");
  EXPECT_EQ(back.position, s.position);
  EXPECT_EQ(back.label, s.label);
  EXPECT_EQ(back.dist, (std::vector<double>{0.0, -1.0, 0.5})) << "an unreached sample's distance is written as -1";
  EXPECT_EQ(back.edges, s.edges);
  s.dist[1] = INFINITY;  // what the sweep leaves on an unreached sample: still a readable file
  WriteLabels(dir / "l.ply", s, TestProvenance(), ascii);
  EXPECT_EQ(ReadLabels(dir / "l.ply").dist[1], -1.0);
}

INSTANTIATE_TEST_SUITE_P(BinaryAndAscii, RoundTrip, ::testing::Values(false, true));

TEST(ForeignFiles, DoubleCoordinatesExtraPropertiesAndOtherOrder) {
  TempDir dir;
  // Binary little-endian, double x y z, an extra property before and after, no voroudf comment.
  std::string body;
  auto put = [&](const void* p, size_t n) { body.append(static_cast<const char*>(p), n); };
  const double pts[2][3] = {{0.1, 0.2, 0.3}, {-1.5, 2.25, 1e-9}};
  for (const auto& p : pts) {
    const int32_t id = 42;
    put(&id, 4);
    put(p, 24);
    const float confidence = 0.5f;
    put(&confidence, 4);
  }
  WriteBytes(dir / "s.ply",
             "ply\nformat binary_little_endian 1.0\ncomment from another tool\nelement vertex 2\n"
             "property int id\nproperty double x\nproperty double y\nproperty double z\nproperty float confidence\n"
             "end_header\n" + body);
  const SeedCloud s = ReadSeeds(dir / "s.ply");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.position[0], Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(s.position[1], Vec3(-1.5, 2.25, 1e-9));
  EXPECT_FALSE(s.has_field);
  EXPECT_EQ(s.rank[0], kRankUnknown);
}

TEST(ForeignFiles, CrlfAsciiMeshWithQuadAndVertexIndexName) {
  TempDir dir;
  WriteBytes(dir / "q.ply",
             "ply\r\nformat ascii 1.0\r\nelement vertex 4\r\nproperty float x\r\nproperty float y\r\n"
             "property float z\r\nproperty uchar red\r\nelement face 1\r\nproperty list uchar uint vertex_index\r\n"
             "end_header\r\n0 0 0 255\r\n1 0 0 0\r\n1 1 0 0\r\n0 1 0 0\r\n4 0 1 2 3\r\n");
  const TriangleMesh m = ReadMeshPly(dir / "q.ply");
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices[2], Vec3(1, 1, 0));
  ASSERT_EQ(m.faces.size(), 2u);  // the quad as a fan
  EXPECT_EQ(m.faces[0], (Tri{0, 1, 2}));
  EXPECT_EQ(m.faces[1], (Tri{0, 2, 3}));
}

TEST(ForeignFiles, BigEndianBinary) {
  TempDir dir;
  std::string body;
  const float v[3] = {1.5f, -2.0f, 0.25f};
  for (float f : v) {
    unsigned char b[4];
    std::memcpy(b, &f, 4);
    for (int k = 3; k >= 0; --k) body.push_back(static_cast<char>(b[k]));
  }
  WriteBytes(dir / "be.ply", "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
                             "property float y\nproperty float z\nend_header\n" + body);
  EXPECT_EQ(ReadSeeds(dir / "be.ply").position[0], Vec3(1.5, -2.0, 0.25));
}

TEST(ForeignFiles, ObjOffAndStl) {
  TempDir dir;
  WriteBytes(dir / "t.obj", "# comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
                            "f 1/1/1 2/1/1 3/1/1\nf -4//1 -3//1 -1//1\n");
  const TriangleMesh obj = ReadMesh(dir / "t.obj");
  EXPECT_EQ(obj.vertices.size(), 4u);
  ASSERT_EQ(obj.faces.size(), 2u);
  EXPECT_EQ(obj.faces[1], (Tri{0, 1, 3}));

  WriteBytes(dir / "t.off", "OFF\n# tetrahedron\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                            "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3 255 0 0\n");
  const TriangleMesh off = ReadMesh(dir / "t.off");
  EXPECT_EQ(off.vertices.size(), 4u);
  EXPECT_EQ(off.faces.size(), 4u);

  // STL: every triangle repeats its corners; reading must weld them back to 4 vertices.
  const float corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int tris[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::string bin(80, ' ');
  const uint32_t n = 4;
  bin.append(reinterpret_cast<const char*>(&n), 4);
  std::string ascii = "solid t\n";
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 0};
    bin.append(reinterpret_cast<const char*>(normal), 12);
    ascii += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      bin.append(reinterpret_cast<const char*>(corners[t[k]]), 12);
      ascii += "   vertex " + std::to_string(corners[t[k]][0]) + " " + std::to_string(corners[t[k]][1]) + " " +
               std::to_string(corners[t[k]][2]) + "\n";
    }
    bin.append(2, '\0');
    ascii += "  endloop\n endfacet\n";
  }
  ascii += "endsolid t\n";
  WriteBytes(dir / "b.stl", bin);
  WriteBytes(dir / "a.STL", ascii);
  for (const char* f : {"b.stl", "a.STL"}) {
    const TriangleMesh stl = ReadMesh(dir / f);
    EXPECT_EQ(stl.vertices.size(), 4u) << f;
    EXPECT_EQ(stl.faces.size(), 4u) << f;
  }
}

class BadFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteSeeds(dir_ / "good.ply", RandomSeeds(50), TestProvenance());
    good_ = ReadBytes(dir_ / "good.ply");
  }
  std::string Path(const std::string& name) { return dir_ / name; }
  TempDir dir_;
  std::string good_;
};

TEST_F(BadFiles, TruncatedBinary) {
  WriteBytes(Path("t.ply"), good_.substr(0, good_.size() - 7));
  ExpectInputError([&] { ReadSeeds(Path("t.ply")); }, "truncated");
}

TEST_F(BadFiles, TruncatedAscii) {
  WriteSeeds(Path("a.ply"), RandomSeeds(10), TestProvenance(), true);
  const std::string a = ReadBytes(Path("a.ply"));
  WriteBytes(Path("t.ply"), a.substr(0, a.size() - 30));
  ExpectInputError([&] { ReadSeeds(Path("t.ply")); }, "truncated");
}

TEST_F(BadFiles, TruncatedHeader) {
  WriteBytes(Path("t.ply"), good_.substr(0, 40));
  ExpectInputError([&] { ReadSeeds(Path("t.ply")); }, "end_header");
}

TEST_F(BadFiles, WrongMagic) {
  WriteBytes(Path("m.ply"), "plx" + good_.substr(3));
  ExpectInputError([&] { ReadSeeds(Path("m.ply")); }, "not a PLY file");
}

TEST_F(BadFiles, FutureVersion) {
  std::string s = good_;
  s.replace(s.find("voroudf seeds 1"), 15, "voroudf seeds 9");
  WriteBytes(Path("v.ply"), s);
  ExpectInputError([&] { ReadSeeds(Path("v.ply")); }, "newer");
}

TEST_F(BadFiles, NaNCoordinate) {
  WriteBytes(Path("n.ply"), "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                            "property float z\nend_header\n0 0 0\n1 nan 0\n");
  ExpectInputError([&] { ReadSeeds(Path("n.ply")); }, "item 1 property 'y' is not finite");
}

TEST(FiniteOutput, EveryWriterRefusesNonFiniteOrUnrepresentableValuesAndWritesNothing) {
  TempDir dir;
  auto expect_refused = [&](const std::function<void(const std::string&)>& write, const char* what) {
    try {
      write(dir / "out.ply");
      ADD_FAILURE() << what << ": written";
    } catch (const NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("nothing written"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(test::Exists(dir / "out.ply")) << what;
    EXPECT_EQ(dir.List().size(), 0u) << what << ": no temporary file left";
  };
  for (double bad : {std::nan(""), double(INFINITY), -double(INFINITY), 1e300}) {
    SeedCloud seeds = RandomSeeds(4);
    seeds.position[2].x() = bad;
    expect_refused([&](const std::string& p) { WriteSeeds(p, seeds, TestProvenance()); }, "seed position");
    seeds = RandomSeeds(4);
    seeds.udf[1] = bad;
    expect_refused([&](const std::string& p) { WriteSeeds(p, seeds, TestProvenance(), true); }, "seed udf");
    TriangleMesh mesh = NonManifoldMesh();
    mesh.vertices[0].z() = bad;
    expect_refused([&](const std::string& p) { WriteMeshPly(p, mesh, TestProvenance()); }, "mesh vertex");
    LabeledSamples labels;
    labels.position = {Vec3(0, 0, 0), Vec3(bad, 0, 0)};
    labels.label = {0, 0};
    labels.dist = {0, 0};
    expect_refused([&](const std::string& p) { WriteLabels(p, labels, TestProvenance()); }, "label position");
  }
}

TEST(Header, CommentsEscapeControlCharactersSoTheHeaderStaysWhole) {
  TempDir dir;
  const Provenance provenance{"test", "--x 1", "shape:sphere\nelement vertex 99\rend_header\x01"};
  WriteSeeds(dir / "s.ply", RandomSeeds(3), provenance);
  const SeedCloud back = ReadSeeds(dir / "s.ply");
  EXPECT_EQ(back.size(), 3u);
  const std::string bytes = test::ReadBytes(dir / "s.ply");
  EXPECT_NE(bytes.find("comment udf shape:sphere\\x0aelement vertex 99\\x0dend_header\\x01\n"), std::string::npos)
      << bytes.substr(0, 300);
}

TEST_F(BadFiles, FaceIndexOutOfRange) {
  TriangleMesh m = NonManifoldMesh();
  m.faces[2][1] = 6;
  WriteMeshPly(Path("f.ply"), m, TestProvenance());
  ExpectInputError([&] { ReadMeshPly(Path("f.ply")); }, "out of range");
}

TEST_F(BadFiles, MeshGivenAsSeeds) {
  WriteMeshPly(Path("mesh.ply"), NonManifoldMesh(), TestProvenance());
  ExpectInputError([&] { ReadSeeds(Path("mesh.ply")); }, "is a voroudf mesh file, expected a seeds file");
  // The same mesh from another tool (no voroudf comment) is recognised by its faces.
  std::string s = ReadBytes(Path("mesh.ply"));
  s.replace(s.find("comment voroudf mesh 1"), 22, "comment other tool 11");
  WriteBytes(Path("foreign.ply"), s);
  ExpectInputError([&] { ReadSeeds(Path("foreign.ply")); }, "is a mesh");
}

TEST_F(BadFiles, SeedsGivenAsMesh) {
  ExpectInputError([&] { ReadMeshPly(Path("good.ply")); }, "is a voroudf seeds file, expected a mesh file");
}

TEST_F(BadFiles, MissingFileAndBadList) {
  ExpectInputError([&] { ReadSeeds(Path("absent.ply")); }, "cannot open");
  WriteBytes(Path("l.ply"), "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
  ExpectInputError([&] { ReadMeshPly(Path("l.ply")); }, "at least 3 vertices");
  WriteBytes(Path("x.ply"), "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                            "property float z\nend_header\n0 zero 0\n");
  ExpectInputError([&] { ReadSeeds(Path("x.ply")); }, "'zero' is not a number");
}

TEST(AtomicWrite, FailureLeavesNothingAndSuccessReplaces) {
  TempDir dir;
  EXPECT_THROW(WriteSeeds(dir / "missing/sub/s.ply", RandomSeeds(3), TestProvenance()), OutputError);
  EXPECT_TRUE(dir.List().empty());
  WriteSeeds(dir / "s.ply", RandomSeeds(3), TestProvenance());
  WriteSeeds(dir / "s.ply", RandomSeeds(9), TestProvenance());
  EXPECT_EQ(ReadSeeds(dir / "s.ply").size(), 9u);
  EXPECT_EQ(dir.List(), std::vector<std::string>{"s.ply"});  // no temporary file left behind
}

}  // namespace
}  // namespace voroudf

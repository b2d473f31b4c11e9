// exec: UDF sources (common/exec_udf.h, docs/exec-protocol.md): the Python reference server against
// shape:sphere, concurrent queries, and fake servers that exit early, write garbage, answer the wrong count
// or never answer, each of which must end in exit code 3 within the timeout, never a hang.
#include <gtest/gtest.h>
#include <omp.h>
#include <signal.h>

#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <cmath>
#include <thread>

#include "common/errors.h"
#include "common/exec_udf.h"
#include "common/rng.h"
#include "common/shapes.h"
#include "common/udf_spec.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::RunProgram;
using test::TempDir;
using Clock = std::chrono::steady_clock;

const std::string kServer = std::string("/usr/bin/python3 ") + VOROUDF_SOURCE_DIR + "/pipelines/udf_server_sphere.py";

// The handshake of a fake server in Python (struct only), followed by `body`.
std::string FakeServer(const std::string& body) {
  return "import struct, sys, time\n"
         "out = sys.stdout.buffer\n"
         "name = b'fake'\n"
         "out.write(b'VUDF' + struct.pack('<I6fI', 1, -1, -1, -1, 1, 1, 1, len(name)) + name)\n"
         "out.flush()\n" + body;
}

double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

TEST(ExecUdf, ReferenceServerMatchesTheBuiltInSphere) {
  ExecUdfOptions o;
  o.max_batch = 1000;  // several requests per Evaluate
  const ExecUdf udf(kServer, o);
  EXPECT_EQ(udf.server_name(), "udf_server_sphere.py (sphere r=0.5)");
  EXPECT_NEAR(udf.Domain().min.x(), -0.6, 1e-7);
  EXPECT_NEAR(udf.Domain().max.z(), 0.6, 1e-7);
  const auto sphere = MakeShape("sphere");
  Rng rng(3, 3);
  std::vector<Vec3> pts(5000);
  for (Vec3& p : pts) p = Vec3(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6)).cast<float>().cast<double>();
  std::vector<double> d, de;
  std::vector<Vec3> g, ge;
  udf.Evaluate(pts, d, g);
  sphere->Evaluate(pts, de, ge);
  for (size_t i = 0; i < pts.size(); ++i) {
    ASSERT_NEAR(d[i], de[i], 2e-7) << i;
    ASSERT_LT((g[i] - ge[i]).norm(), 1e-6) << i;
  }
}

TEST(ExecUdf, ConcurrentChunksFromManyThreadsAreSerialisedCorrectly) {
  const ExecUdf udf(kServer, {});
  const auto sphere = MakeShape("sphere");
  const int n = 4000;
  std::vector<Vec3> pts(n);
  Rng rng(4, 4);
  for (Vec3& p : pts) p = Vec3(rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6), rng.Uniform(-0.6, 0.6)).cast<float>().cast<double>();
  std::vector<double> d(n);
  std::vector<Vec3> g(n);
#pragma omp parallel for num_threads(4) schedule(dynamic, 1)
  for (int c = 0; c < n; c += 37) udf.EvaluateChunk(&pts[c], std::min(37, n - c), &d[c], &g[c]);
  for (int i = 0; i < n; ++i) ASSERT_NEAR(d[i], sphere->Distance(pts[i]), 2e-7) << i;
}

TEST(ExecUdf, NormalizeWrapsAnExecSource) {
  UdfSourceOptions o;
  o.normalize = true;
  const auto udf = OpenUdf("exec:" + kServer, o);  // box [-0.6,0.6]^3 -> [-0.5,0.5]^3, sphere radius 0.5/1.2
  EXPECT_NEAR(udf->Domain().max.x(), 0.5, 1e-6);
  EXPECT_NEAR(udf->Distance(Vec3(0.0, 0.0, 0.0)), 0.5 / 1.2, 1e-6);
  EXPECT_NE(udf->Describe().find("--udf-normalize"), std::string::npos);
}

class FakeServers : public ::testing::Test {
 protected:
  std::string Script(const std::string& name, const std::string& body) {
    test::WriteBytes(dir_ / name, body);
    return "/usr/bin/python3 " + dir_ / name;
  }
  // Runs the library on a fake server: it must throw InputError naming `expect` within `limit_s` seconds.
  void ExpectInputError(const std::string& command, const std::string& expect, double timeout_s = 1.0,
                        double limit_s = 6.0) {
    const auto start = Clock::now();
    try {
      ExecUdfOptions o;
      o.timeout_s = timeout_s;
      ExecUdf udf(command, o);
      std::vector<Vec3> pts(10, Vec3(0.1, 0.2, 0.3));
      std::vector<double> d;
      std::vector<Vec3> g;
      udf.Evaluate(pts, d, g);
      ADD_FAILURE() << command << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
    EXPECT_LT(Seconds(start), limit_s) << command;
  }
  TempDir dir_;
};

TEST_F(FakeServers, EveryMisbehaviourIsAnInputErrorWithinTheTimeout) {
  ExpectInputError(Script("early.py", FakeServer("sys.stdin.buffer.read(4)\nsys.exit(7)\n")), "exited with status 7");
  ExpectInputError(Script("garbage.py", "import sys\nsys.stdout.write('hello, I am not a UDF server at all\\n' * 3)\n"
                                        "sys.stdout.flush()\ntime = __import__('time')\ntime.sleep(30)\n"),
                   "expected the magic 'VUDF'");
  ExpectInputError(Script("silent.py", FakeServer("time.sleep(60)\n")), "--udf-timeout");
  ExpectInputError(Script("nohandshake.py", "import time\ntime.sleep(60)\n"), "handshake");
  ExpectInputError(Script("count.py", FakeServer(
                       "n = struct.unpack('<I', sys.stdin.buffer.read(4))[0]\nsys.stdin.buffer.read(12 * n)\n"
                       "out.write(struct.pack('<I', n + 1) + bytes(16 * (n + 1)))\nout.flush()\ntime.sleep(60)\n")),
                   "wrong count");
  ExpectInputError(Script("short.py", FakeServer(
                       "n = struct.unpack('<I', sys.stdin.buffer.read(4))[0]\nsys.stdin.buffer.read(12 * n)\n"
                       "out.write(struct.pack('<I', n) + bytes(8 * n))\nout.flush()\ntime.sleep(60)\n")),
                   "--udf-timeout");
  ExpectInputError(Script("nan.py", FakeServer(
                       "n = struct.unpack('<I', sys.stdin.buffer.read(4))[0]\nsys.stdin.buffer.read(12 * n)\n"
                       "out.write(struct.pack('<I', n) + struct.pack('<f', float('nan')) * (4 * n))\nout.flush()\n"
                       "time.sleep(60)\n")),
                   "non-finite");
  ExpectInputError(Script("version.py", "import struct, sys\nsys.stdout.buffer.write(b'VUDF' + struct.pack('<I', 9) + bytes(40))\n"
                                        "sys.stdout.flush()\n"),
                   "version 9");
  // Closes its stdin and stays: our write gets EPIPE (SIGPIPE must not kill the program).
  // (stdin closed before the handshake, so it is closed by the time we write)
  ExpectInputError("exec " + Script("closed.py", "import os\nos.close(0)\n" + FakeServer("time.sleep(60)\n")),
                   "closed its stdin");
  ExpectInputError("/nonexistent/udf-server", "exited with status 127");
  ExpectInputError("", "no command");
}

TEST_F(FakeServers, AStalledServerIsKilledAndReaped) {
  const std::string cmd = Script("pid.py", FakeServer("open(sys.argv[1], 'w').write(str(__import__('os').getpid()))\n"
                                                      "time.sleep(60)\n")) + " " + dir_ / "pid";
  ExecUdfOptions o;
  o.timeout_s = 0.5;
  {
    ExecUdf udf(cmd, o);
    EXPECT_THROW(udf.Distance(Vec3::Zero()), InputError);
    // After an error every further query fails at once with the same error.
    const auto start = Clock::now();
    EXPECT_THROW(udf.Distance(Vec3::Zero()), InputError);
    EXPECT_LT(Seconds(start), 0.1);
  }
  const pid_t pid = std::stoi(test::ReadBytes(dir_ / "pid"));
  bool gone = false;
  for (int i = 0; i < 200 && !gone; ++i) {
    gone = kill(pid, 0) != 0;
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(gone) << "the server process " << pid << " is still there";
}

// Queries from inside an OpenMP region, as a stage's own parallel loop would make them.
void QueryFromParallelRegion(const std::string& command) {
  ExecUdf udf(command, {});
  std::vector<Vec3> p(64, Vec3::Zero()), g(64);
  std::vector<double> d(64);
#pragma omp parallel for num_threads(2)
  for (int c = 0; c < 64; c += 8) udf.EvaluateChunk(&p[c], 8, &d[c], &g[c]);
  std::exit(0);
}

TEST_F(FakeServers, AFailureInsideAParallelRegionEndsTheProcessWithExitThree) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string cmd = Script("early.py", FakeServer("sys.stdin.buffer.read(4)\nsys.exit(5)\n"));
  EXPECT_EXIT(QueryFromParallelRegion(cmd), ::testing::ExitedWithCode(3), "error: exec:.*exited with status 5");
}

TEST_F(FakeServers, SampleSeedsEndsWithExitThreeWithinTheTimeoutAndNoOutput) {
  const std::string cases[] = {
      Script("early.py", FakeServer("sys.stdin.buffer.read(4)\nsys.exit(1)\n")),
      Script("garbage.py", "import sys\nsys.stdout.write('garbage' * 100)\nsys.stdout.flush()\n"),
      Script("silent.py", FakeServer("time.sleep(60)\n")),
  };
  for (const std::string& server : cases) {
    const auto start = Clock::now();
    const auto r = RunProgram("sample-seeds", {"--udf", "exec:" + server, "--udf-timeout", "1", "--count", "100", "-o",
                                               dir_ / "seeds.ply"});
    EXPECT_EQ(r.exit_code, 3) << server << "\n" << r.err;
    EXPECT_LT(Seconds(start), 8.0) << server;
    EXPECT_FALSE(test::Exists(dir_ / "seeds.ply"));
    // One line: "sample-seeds: error: exec:...: ...".
    EXPECT_NE(r.err.find("sample-seeds: error: exec:"), std::string::npos) << r.err;
  }
}

// A server that ignores SIGTERM and forks a child that does too; both write their pids to `pid_file`.
std::string StubbornServer(const std::string& body) {
  return FakeServer("import os, signal\n"
                    "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
                    "child = os.fork()\n"
                    "if child == 0:\n"
                    "    time.sleep(600)\n"
                    "    os._exit(0)\n"
                    "open(sys.argv[1] + '.tmp', 'w').write('%d %d' % (os.getpid(), child))\n"
                    "os.rename(sys.argv[1] + '.tmp', sys.argv[1])\n" + body);
}

// Alive and not a zombie (a zombie is gone for every purpose but its process table entry).
bool Alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto paren = line.rfind(')');
  return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] != 'Z';
}

std::vector<pid_t> WaitForPids(const std::string& pid_file) {
  for (int i = 0; i < 1000 && !test::Exists(pid_file); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::istringstream in(test::ReadBytes(pid_file));
  pid_t a = 0, b = 0;
  in >> a >> b;
  return {a, b};
}

bool AllGoneWithin(const std::vector<pid_t>& pids, double seconds) {
  const auto start = Clock::now();
  while (Seconds(start) < seconds) {
    bool any = false;
    for (pid_t p : pids) any = any || Alive(p);
    if (!any) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST_F(FakeServers, AServerThatIgnoresSigtermAndForksIsEndedWithItsChild) {
  // The first ignores both EOF and SIGTERM: only SIGKILL to its whole group ends it. The second exits at
  // EOF, as it should, but leaves its child behind: the group is ended although the server is gone.
  for (const char* body : {"time.sleep(600)\n", "sys.stdin.buffer.read()\nsys.exit(0)\n"}) {
    const std::string pid_file = dir_ / (std::string("pids") + (body[0] == 't' ? "1" : "2"));
    const std::string cmd = Script("stubborn.py", StubbornServer(body)) + " " + pid_file;
    std::vector<pid_t> pids;
    {
      ExecUdf udf(cmd, {});
      pids = WaitForPids(pid_file);
      ASSERT_GT(pids[0], 0);
      ASSERT_GT(pids[1], 0);
      EXPECT_TRUE(Alive(pids[0]) && Alive(pids[1]));
    }
    EXPECT_TRUE(AllGoneWithin(pids, 1.0)) << body << ": server " << pids[0] << " or its child " << pids[1]
                                          << " is still running";
  }
}

TEST_F(FakeServers, ASignalToTheStageEndsTheServersGroup) {
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
    const std::string pid_file = dir_ / ("pids" + std::to_string(sig));
    const std::string server = Script("stubborn.py", StubbornServer("time.sleep(600)\n")) + " " + pid_file;
    const pid_t stage = fork();
    ASSERT_GE(stage, 0);
    if (stage == 0) {
      const std::string exe = std::string(VOROUDF_BIN_DIR) + "/sample-seeds";
      execl(exe.c_str(), "sample-seeds", "--udf", ("exec:" + server).c_str(), "--count", "100", "-q", "-o",
            (dir_ / "s.ply").c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    const std::vector<pid_t> pids = WaitForPids(pid_file);
    ASSERT_GT(pids[1], 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the stage now waits for an answer
    kill(stage, sig);
    int status = 0;
    waitpid(stage, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << status;
    EXPECT_TRUE(AllGoneWithin(pids, 1.0)) << "signal " << sig << ": server or child still running";
    EXPECT_FALSE(test::Exists(dir_ / "s.ply"));
  }
  EXPECT_EQ(test::ReadBytes(dir_ / "stubborn.py").empty(), false);
}

TEST_F(FakeServers, AnErrorInsideTheStageEndsTheServersGroup) {
  // The server answers garbage to the first request; it and its child must not outlive the stage.
  const std::string server = Script("garbage_stubborn.py", StubbornServer("n = struct.unpack('<I', sys.stdin.buffer.read(4))[0]\n"
                                                                          "sys.stdin.buffer.read(12 * n)\n"
                                                                          "sys.stdout.buffer.write(b'x' * 64)\n"
                                                                          "sys.stdout.flush()\n"
                                                                          "time.sleep(600)\n")) +
                             " " + dir_ / "gpids";
  const auto r = RunProgram("sample-seeds", {"--udf", "exec:" + server, "--count", "100", "-o", dir_ / "s.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_TRUE(AllGoneWithin(WaitForPids(dir_ / "gpids"), 1.0));
}

TEST(ExecUdfExe, ReferenceServerGivesTheSameSeedsAsTheBuiltInSphere) {
  TempDir dir;
  const auto a = RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "1000", "--seed", "8", "-o", dir / "a.ply"});
  const auto b = RunProgram("sample-seeds", {"--udf", "exec:" + kServer, "--count", "1000", "--seed", "8", "-o", dir / "b.ply"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_NE(b.err.find("server 'udf_server_sphere.py (sphere r=0.5)'"), std::string::npos) << b.err;
  const SeedCloud sa = ReadSeeds(dir / "a.ply"), sb = ReadSeeds(dir / "b.ply");
  ASSERT_EQ(sa.size(), sb.size());
  for (size_t i = 0; i < sa.size(); ++i) {
    // float32 on the wire (points, distances) and the float32 box of the handshake: ~1e-7.
    ASSERT_LT((sa.position[i] - sb.position[i]).norm(), 1e-5) << i;
    // On the surface the normal may come out either way round (docs/udf-sources.md).
    ASSERT_GT(std::abs(sa.normal[i].dot(sb.normal[i])), 1.0 - 1e-6) << i;
  }
}

}  // namespace
}  // namespace voroudf

namespace voroudf {
namespace {

// A stage's UDF usage (--udf-stats, common/counting_udf.h) is what the source was asked: the points a
// server received, in at most as many batches as it got requests (a batch may be sent as several).
TEST_F(FakeServers, UdfStatsCountThePointsTheServerReceived) {
  const std::string counts = dir_ / "counts.txt";
  const std::string server = Script("counting.py", FakeServer(
      "import math\n"
      "points = requests = 0\n"
      "while len(head := sys.stdin.buffer.read(4)) == 4:\n"
      "    n = struct.unpack('<I', head)[0]\n"
      "    x = struct.unpack('<%df' % (3 * n), sys.stdin.buffer.read(12 * n))\n"
      "    points += n\n"
      "    requests += 1\n"
      "    d, g = [], []\n"
      "    for i in range(n):\n"
      "        p = x[3 * i:3 * i + 3]\n"
      "        r = math.sqrt(sum(c * c for c in p)) or 1.0\n"
      "        d.append(abs(r - 0.5))\n"
      "        s = 1.0 if r >= 0.5 else -1.0\n"
      "        g += [s * c / r for c in p]\n"
      "    out.write(struct.pack('<I', n) + struct.pack('<%df' % n, *d) + struct.pack('<%df' % (3 * n), *g))\n"
      "    out.flush()\n"
      "open(sys.argv[1], 'w').write('%d %d' % (points, requests))\n")) + " " + counts;
  const std::string stats = dir_ / "stats.tsv", seeds = dir_ / "seeds0.ply";
  const auto r = RunProgram("sample-seeds",
                            {"--udf", "exec:" + server, "--count", "200", "-o", seeds, "--udf-stats", stats});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream c(counts), s(stats);
  uint64_t points = 0, requests = 0, queries = 0, batches = 0;
  double seconds = -1;
  std::string header;
  ASSERT_TRUE(c >> points >> requests);
  ASSERT_TRUE(std::getline(s, header));
  EXPECT_EQ(header, "udf_queries\tudf_batches\tudf_seconds");
  ASSERT_TRUE(s >> queries >> batches >> seconds);
  EXPECT_GT(points, 200u);
  EXPECT_EQ(queries, points);
  EXPECT_GE(batches, 1u);
  EXPECT_LE(batches, requests);
  EXPECT_GT(seconds, 0.0);
  EXPECT_NE(r.err.find("UDF usage: " + std::to_string(queries) + " queries in " + std::to_string(batches) + " batches"),
            std::string::npos) << r.err;
}

}  // namespace
}  // namespace voroudf

namespace voroudf {
namespace {

// unix: sources: the same protocol over a Unix-domain socket to a server that is already running.
class UnixServers : public ::testing::Test {
 protected:
  // Starts `/usr/bin/python3 SCRIPT SOCKET` and waits for the socket to appear.
  void Start(const std::string& script_body) {
    test::WriteBytes(dir_ / "server.py", script_body);
    socket_ = dir_ / "udf.sock";
    pid_ = fork();
    ASSERT_GE(pid_, 0);
    if (pid_ == 0) {
      execl("/usr/bin/python3", "python3", (dir_ / "server.py").c_str(), socket_.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    for (int i = 0; i < 500 && !test::Exists(socket_ + ".ready"); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(test::Exists(socket_ + ".ready")) << "the test server did not start";
  }
  void TearDown() override {
    if (pid_ > 0) kill(pid_, SIGKILL), waitpid(pid_, nullptr, 0);
  }
  // A one-connection server in Python: binds the socket, accepts once, then the handshake and `body`
  // with `inp` and `out` on the connection (as FakeServer's stdin and stdout).
  static std::string OneShot(const std::string& body, bool hello = true) {
    return "import socket, struct, sys, time\n"
           "s = socket.socket(socket.AF_UNIX)\n"
           "s.bind(sys.argv[1])\n"
           "s.listen(4)\n"
           "open(sys.argv[1] + '.ready', 'w').close()\n"
           "conn, _ = s.accept()\n"
           "inp, out = conn.makefile('rb'), conn.makefile('wb')\n" +
           std::string(hello ? "out.write(b'VUDF' + struct.pack('<I6fI', 1, -1, -1, -1, 1, 1, 1, 4) + b'fake')\n"
                               "out.flush()\n"
                             : "") +
           body;
  }
  void ExpectInputError(const std::string& expect, double timeout_s = 1.0) {
    const auto start = Clock::now();
    try {
      ExecUdfOptions o;
      o.timeout_s = timeout_s;
      ExecUdf udf(ExecUdf::UnixSocket{socket_}, o);
      std::vector<Vec3> pts(10, Vec3(0.1, 0.2, 0.3));
      std::vector<double> d;
      std::vector<Vec3> g;
      udf.Evaluate(pts, d, g);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("unix:" + socket_), std::string::npos) << e.what();
    }
    EXPECT_LT(Seconds(start), timeout_s + 3.0);
  }
  TempDir dir_;
  std::string socket_;
  pid_t pid_ = -1;
};

// One server process serves two stages in turn, and each gets what an exec: server gives.
TEST_F(UnixServers, OneServerServesSeveralStagesLikeAnExecServer) {
  // The reference server, marked ready once it takes a connection (the probe's is a client that leaves).
  Start("import runpy, socket, sys, threading, time\n"
        "path = sys.argv[1]\n"
        "def ready():\n"
        "    while True:\n"
        "        try:\n"
        "            c = socket.socket(socket.AF_UNIX)\n"
        "            c.connect(path)\n"
        "            c.close()\n"
        "            break\n"
        "        except OSError:\n"
        "            time.sleep(0.01)\n"
        "    open(path + '.ready', 'w').close()\n"
        "threading.Thread(target=ready, daemon=True).start()\n"
        "sys.argv = ['udf_server_sphere.py', '--unix', path]\n"
        "runpy.run_path('" VOROUDF_SOURCE_DIR "/pipelines/udf_server_sphere.py', run_name='__main__')\n");
  const std::string unix_seeds = dir_ / "u.ply", exec_seeds = dir_ / "e.ply", unix_opt = dir_ / "uo.ply";
  auto r = RunProgram("sample-seeds", {"--udf", "unix:" + socket_, "--count", "300", "-o", unix_seeds});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunProgram("optimize-seeds", {"--udf", "unix:" + socket_, "-i", unix_seeds, "-o", unix_opt, "--max-outer-iters", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunProgram("sample-seeds", {"--udf", "exec:" + kServer, "--count", "300", "-o", exec_seeds});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const SeedCloud a = ReadSeeds(unix_seeds), b = ReadSeeds(exec_seeds);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.position[i], b.position[i]);
  EXPECT_GT(ReadSeeds(unix_opt).size(), 200u);
}

TEST_F(UnixServers, EveryMisbehaviourIsAnInputErrorWithinTheTimeout) {
  socket_ = dir_ / "nobody.sock";
  ExpectInputError("cannot connect");
  const std::string out = dir_ / "s.ply";
  const auto r = RunProgram("sample-seeds", {"--udf", "unix:" + socket_, "--count", "100", "-o", out});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("is the server running?"), std::string::npos) << r.err;
  EXPECT_FALSE(test::Exists(out));
  Start(OneShot("inp.close()\nout.close()\nconn.close()\ntime.sleep(60)\n", false));
  ExpectInputError("closed the connection");
}

TEST_F(UnixServers, AServerThatNeverAnswersTimesOut) {
  Start(OneShot("time.sleep(60)\n", false));
  ExpectInputError("--udf-timeout");
}

TEST_F(UnixServers, GarbageAndAWrongCountAreInputErrors) {
  Start(OneShot("inp.read(4)\nout.write(struct.pack('<I', 3) + b'x' * 100)\nout.flush()\ntime.sleep(60)\n"));
  ExpectInputError("answered 3 values to a request of 10");
}

TEST_F(UnixServers, ABadHandshakeIsAnInputError) {
  Start(OneShot("out.write(b'HTTP/1.1 200 OK' + b' ' * 40)\nout.flush()\ntime.sleep(60)\n", false));
  ExpectInputError("VUDF");
}

TEST_F(UnixServers, AServerThatDiesMidRequestIsAnInputError) {
  Start(OneShot("inp.read(4)\nsys.exit(0)\n"));
  ExpectInputError("closed the connection");
}

}  // namespace
}  // namespace voroudf

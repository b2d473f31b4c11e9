// What a hostile but fair user can do around the stages (docs/conventions.md): outputs that are special
// files, symlinks or several at once, streams through a shell pipeline, bounded readers, option values
// that do not fit, non-finite results. Each class of defect has a test here, on the library and on the
// real executables.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <thread>

#include "common/atomic_file.h"
#include "common/cleanup.h"
#include "common/errors.h"
#include "common/input_file.h"
#include "formats/mesh_io.h"
#include "formats/seeds_io.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

using test::Exists;
using test::ReadBytes;
using test::RunProgram;
using test::TempDir;
using test::WriteBytes;

const char* const kPrograms[] = {"sample-seeds", "optimize-seeds", "build-gvd", "thin-mesh", "evaluate"};

bool IsSymlink(const std::string& path) {
  struct stat st;
  return lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

// The last line of a stage's stderr: its one error line.
std::string LastLine(const std::string& err) {
  std::string s = err;
  while (!s.empty() && s.back() == '\n') s.pop_back();
  const auto nl = s.rfind('\n');
  return nl == std::string::npos ? s : s.substr(nl + 1);
}

// Runs `script` with bash, the build's bin directory as $B; returns the exit status.
int Bash(const std::string& script) {
  const std::string cmd = "B='" + std::string(VOROUDF_BIN_DIR) + "' bash -c '" + script + "'";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// ---- output semantics (common/atomic_file) ----

TEST(OutputTargets, EachKindOfPathIsWrittenAsDocumented) {
  TempDir dir;
  EXPECT_EQ(ResolveOutput(dir / "new.ply").kind, OutputKind::kReplace);
  WriteBytes(dir / "old.ply", "x");
  EXPECT_EQ(ResolveOutput(dir / "old.ply").kind, OutputKind::kReplace);
  const OutputTarget null = ResolveOutput("/dev/null");
  EXPECT_EQ(null.kind, OutputKind::kStream);
  EXPECT_TRUE(null.shareable);
  for (const char* s : {"-", "/dev/stdout"}) {
    EXPECT_EQ(ResolveOutput(s).kind, OutputKind::kStream) << s;
    EXPECT_EQ(ResolveOutput(s).fd, 1) << s;
  }
  EXPECT_EQ(ResolveOutput("/dev/stderr").fd, 2);
  ASSERT_EQ(mkfifo((dir / "fifo").c_str(), 0600), 0);
  EXPECT_EQ(ResolveOutput(dir / "fifo").kind, OutputKind::kStream);
  ASSERT_EQ(symlink("old.ply", (dir / "link").c_str()), 0);
  const OutputTarget link = ResolveOutput(dir / "link");
  EXPECT_EQ(link.kind, OutputKind::kReplace);
  EXPECT_EQ(link.path.substr(link.path.rfind('/')), "/old.ply");
  EXPECT_THROW(ResolveOutput(dir.path()), OutputError);
  EXPECT_THROW(ResolveOutput(dir / "missing/x.ply"), OutputError);
  ASSERT_EQ(symlink("loop2", (dir / "loop1").c_str()), 0);
  ASSERT_EQ(symlink("loop1", (dir / "loop2").c_str()), 0);
  EXPECT_THROW(ResolveOutput(dir / "loop1"), OutputError);
}

TEST(OutputTargets, ASymlinkKeepsBeingALinkAndItsTargetIsReplaced) {
  TempDir dir;
  ASSERT_EQ(mkdir((dir / "real").c_str(), 0755), 0);
  WriteBytes(dir / "real/seeds.ply", "old");
  chmod((dir / "real/seeds.ply").c_str(), 0640);
  ASSERT_EQ(symlink("real/seeds.ply", (dir / "seeds.ply").c_str()), 0);
  WriteFileAtomically(dir / "seeds.ply", "new bytes");
  EXPECT_TRUE(IsSymlink(dir / "seeds.ply"));
  EXPECT_EQ(ReadBytes(dir / "real/seeds.ply"), "new bytes");
  struct stat st;
  ASSERT_EQ(stat((dir / "real/seeds.ply").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u) << "the replaced file keeps its mode";
  // A dangling link: its target is created.
  ASSERT_EQ(symlink("real/later.ply", (dir / "later.ply").c_str()), 0);
  WriteFileAtomically(dir / "later.ply", "made");
  EXPECT_TRUE(IsSymlink(dir / "later.ply"));
  EXPECT_EQ(ReadBytes(dir / "real/later.ply"), "made");
}

TEST(OutputTargets, AFifoIsWrittenThroughNotReplaced) {
  TempDir dir;
  const std::string fifo = dir / "fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = ReadBytes(fifo); });
  WriteFileAtomically(fifo, "through the pipe");
  reader.join();
  EXPECT_EQ(got, "through the pipe");
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

TEST(OutputSets, AllOrNothing) {
  TempDir dir;
  WriteBytes(dir / "a.ply", "old a");
  {
    OutputSet set;
    set.Add(dir / "a.ply");
    set.Add(dir / "b.ply");
    EXPECT_EQ(dir.List().size(), 3u) << "the temporary files exist before any work";
    set.Write(dir / "a.ply", "new a");
    EXPECT_THROW(set.Commit(), Error) << "b was never written";
  }
  EXPECT_EQ(ReadBytes(dir / "a.ply"), "old a") << "nothing published";
  EXPECT_EQ(dir.List(), std::vector<std::string>{"a.ply"}) << "no temporary file left";
  {
    OutputSet set;
    set.Add(dir / "a.ply");
    set.Add(dir / "b.ply");
    set.Write(dir / "a.ply", "new a");
    set.Write(dir / "b.ply", "new b");
  }  // abandoned without Commit, as when the stage throws after writing
  EXPECT_EQ(ReadBytes(dir / "a.ply"), "old a");
  EXPECT_FALSE(Exists(dir / "b.ply"));
  OutputSet set;
  set.Add(dir / "a.ply");
  set.Add(dir / "b.ply");
  set.Write(dir / "b.ply", "new b");
  set.Write(dir / "a.ply", "new a");
  set.Commit();
  EXPECT_EQ(ReadBytes(dir / "a.ply"), "new a");
  EXPECT_EQ(ReadBytes(dir / "b.ply"), "new b");
  EXPECT_EQ(dir.List().size(), 2u);
}

// A signal that lands while a temporary file is being created and registered, or while a set is being
// published, is acted on only when that step is done: here raised inside the step, from another thread as
// the kernel may pick any thread, in a child that has the stages' handlers installed.
TEST(OutputSets, ASignalInsideCreationOrPublicationWaitsForTheStepToFinish) {
  for (const bool commit : {false, true}) {
    TempDir dir;
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      InstallCleanupHandlers();
      OutputSet set;
      set.Add(dir / "a.ply");
      set.Add(dir / "b.ply");
      set.Write(dir / "a.ply", "a");
      set.Write(dir / "b.ply", "b");
      {
        DeferCleanupSignals step;
        std::thread([] { kill(getpid(), SIGTERM); }).join();
        // Still running: the handler has returned; mark that, then end the step (the signal acts there).
        WriteBytes(dir / "ran-on.txt", "");
        if (commit) set.Commit();
      }
      _exit(0);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << status;
    const std::vector<std::string> expected =
        commit ? std::vector<std::string>{"a.ply", "b.ply", "ran-on.txt"} : std::vector<std::string>{"ran-on.txt"};
    std::vector<std::string> names = dir.List();
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, expected) << (commit ? "published together" : "both temporaries removed");
  }
}

TEST(OutputSets, TheSameFileTwiceIsAUsageErrorWhateverItsSpelling) {
  TempDir dir;
  ASSERT_EQ(mkdir((dir / "sub").c_str(), 0755), 0);
  ASSERT_EQ(symlink("x.ply", (dir / "alias.ply").c_str()), 0);
  const std::vector<std::pair<std::string, std::string>> same = {
      {dir / "x.ply", dir / "x.ply"}, {dir / "x.ply", dir / "sub/../x.ply"}, {dir / "x.ply", dir / "alias.ply"},
      {"-", "/dev/stdout"}};
  for (const auto& [a, b] : same) {
    OutputSet set;
    set.Add(a);
    EXPECT_THROW(set.Add(b), UsageError) << a << " " << b;
  }
  OutputSet devices;
  devices.Add("/dev/null");
  EXPECT_NO_THROW(devices.Add("/dev/null")) << "a character device may take several outputs";
  EXPECT_TRUE(dir.List().size() == 2u);
}

TEST(OutputSets, APlaceNoFileCanBeCreatedFailsWhenAddedNotAtTheEnd) {
  OutputSet set;
  EXPECT_THROW(set.Add("/proc/voroudf-test-output.ply"), OutputError) << "not even root creates files in /proc";
  EXPECT_THROW(set.Add("/dev/null/x.ply"), OutputError);
}

// ---- inputs (common/input_file) ----

TEST(Inputs, DirectoriesStreamsAndDeclaredCountsAreBounded) {
  TempDir dir;
  try {
    ReadSeeds(dir.path());
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.path() + ": is a directory"), std::string::npos) << e.what();
  }
  // /dev/zero is refused from its first bytes, not after filling memory.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(ReadSeeds("/dev/zero"), InputError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  // Declared counts the file cannot hold: refused before anything is reserved.
  WriteBytes(dir / "huge.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n0 0 0\n");
  EXPECT_THROW(ReadSeeds(dir / "huge.ply"), InputError);
  WriteBytes(dir / "huge.off", "OFF\n1000000000 1000000000 0\n0 0 0\n");
  EXPECT_THROW(ReadMesh(dir / "huge.off"), InputError);
  WriteBytes(dir / "huge_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1e300 0 1 2\n");
  EXPECT_THROW(ReadMesh(dir / "huge_face.off"), InputError);
  WriteBytes(dir / "bad.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\n");
  try {
    ReadMesh(dir / "bad.stl");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 5: 'zero' is not a number"), std::string::npos) << e.what();
  }
}

// ---- the executables ----

TEST(Executables, SpecialOutputsAreWrittenThroughNotReplaced) {
  TempDir dir;
  const auto r = RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "300", "-o", "/dev/null"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  struct stat st;
  ASSERT_EQ(stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null is still a character device";
  const auto out = RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "300", "-o", "-"});
  ASSERT_EQ(out.exit_code, 0) << out.err;
  WriteBytes(dir / "from_stdout.ply", out.out);
  EXPECT_GT(ReadSeeds(dir / "from_stdout.ply").size(), 200u) << "stdout carries a whole seeds file";
  EXPECT_EQ(out.err.find("ply\nformat"), std::string::npos) << "nothing but logs on stderr";
}

TEST(Executables, ShellPipelineThroughStdinAndStdout) {
  TempDir dir;
  const std::string chain =
      "set -o pipefail; $B/sample-seeds --udf shape:sphere --count 600 -q -o - | "
      "$B/optimize-seeds --udf shape:sphere -i - -o - -q --max-outer-iters 1 | "
      "$B/build-gvd --udf shape:sphere -i - -o - -q | "
      "$B/thin-mesh --udf shape:sphere -i - -o " + dir / "mesh.ply" + " -q && "
      "$B/evaluate -i " + dir / "mesh.ply" + " --reference - -q --samples 5000 < " + dir / "mesh.ply" +
      " > " + dir / "m.json";
  ASSERT_EQ(Bash(chain), 0);
  const TriangleMesh mesh = ReadMesh(dir / "mesh.ply");
  EXPECT_GT(mesh.faces.size(), 800u);
  EXPECT_NE(ReadBytes(dir / "m.json").find("\"td\": 0,"), std::string::npos) << ReadBytes(dir / "m.json");
  // The same chain through files gives the same bytes.
  const std::string files =
      "$B/sample-seeds --udf shape:sphere --count 600 -q -o " + dir / "s0.ply" + " && "
      "$B/optimize-seeds --udf shape:sphere -i " + dir / "s0.ply" + " -o " + dir / "s.ply" + " -q --max-outer-iters 1 && "
      "$B/build-gvd --udf shape:sphere -i " + dir / "s.ply" + " -o " + dir / "t.ply" + " -q && "
      "$B/thin-mesh --udf shape:sphere -i " + dir / "t.ply" + " -o " + dir / "mesh2.ply" + " -q";
  ASSERT_EQ(Bash(files), 0);
  EXPECT_EQ(ReadBytes(dir / "mesh.ply"), ReadBytes(dir / "mesh2.ply"));
}

TEST(Executables, TwoOutputsArePublishedTogetherOrNotAtAll) {
  TempDir dir;
  ASSERT_EQ(RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "400", "-q", "-o", dir / "s.ply"}).exit_code, 0);
  // The second output cannot be created: the stage fails before the work, and leaves no first output.
  const auto start = std::chrono::steady_clock::now();
  const auto r = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir / "s.ply", "-o", dir / "thick.ply",
                                          "--labels", dir / "no/such/dir/labels.ply"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_NE(LastLine(r.err).find("labels.ply: directory"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(dir / "thick.ply"));
  // The same file for both: a usage error.
  for (const auto& [program, flag] : {std::pair{"build-gvd", "--labels"}, std::pair{"thin-mesh", "--nm-edges"}}) {
    const auto same = RunProgram(program, {"--udf", "shape:sphere", "-i", dir / "s.ply", "-o", dir / "x.ply", flag,
                                           dir / "./x.ply"});
    EXPECT_EQ(same.exit_code, 2) << program << same.err;
    EXPECT_NE(LastLine(same.err).find("name the same output file"), std::string::npos) << same.err;
  }
  EXPECT_EQ(dir.List(), std::vector<std::string>{"s.ply"});
  // A full disk on the second output (/dev/full takes no byte): the first is not published either.
  const auto full = RunProgram("build-gvd", {"--udf", "shape:sphere", "-i", dir / "s.ply", "-o", dir / "thick.ply",
                                             "--labels", "/dev/full"});
  EXPECT_EQ(full.exit_code, 1) << full.err;
  EXPECT_NE(LastLine(full.err).find("/dev/full: write failed"), std::string::npos) << full.err;
  EXPECT_EQ(dir.List(), std::vector<std::string>{"s.ply"});
}

TEST(Executables, ASignalWhileWritingLeavesNeitherOutput) {
  TempDir dir;
  ASSERT_EQ(RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "3000", "-q", "-o", dir / "s.ply"}).exit_code, 0);
  // build-gvd at 3k seeds runs for a while; SIGTERM it as soon as its temporary files exist.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string exe = std::string(VOROUDF_BIN_DIR) + "/build-gvd";
    execl(exe.c_str(), "build-gvd", "--udf", "shape:sphere", "-i", (dir / "s.ply").c_str(), "-o",
          (dir / "thick.ply").c_str(), "--labels", (dir / "labels.ply").c_str(), "-q", "--threads", "1",
          "--samples-per-seed", "2000", static_cast<char*>(nullptr));
    _exit(127);
  }
  for (int i = 0; i < 400 && dir.List().size() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(dir.List().size(), 3u) << "both temporary files exist while the stage works";
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  EXPECT_EQ(dir.List(), std::vector<std::string>{"s.ply"});
}

TEST(Executables, NumericOptionsOutsideTheirRangeAreOneReadableLineAndExitTwo) {
  TempDir dir;
  struct Case {
    std::vector<std::string> args;
    const char* message;
  };
  const std::string out = dir / "s.ply";
  const std::vector<Case> cases = {
      {{"--count", "-5"}, "'-5' is not a non-negative integer"},
      {{"--count", "1e3"}, "'1e3' is not a non-negative integer"},
      {{"--seed", "99999999999999999999999"}, "is out of range"},
      {{"--seed", "-1"}, "'-1' is not a non-negative integer"},
      {{"--threads", "100000"}, "--threads must be in [0, 1024]"},
      {{"--threads", "-1"}, "--threads must be in [0, 1024]"},
      {{"--udf-timeout", "nan"}, "'nan' is not a finite number"},
      {{"--udf-timeout", "1e19"}, "--udf-timeout must be in (0, 1e6]"},
      {{"--udf-timeout", "-1"}, "--udf-timeout must be in (0, 1e6]"},
      {{"--band-rel", "1e400"}, "'1e400' is not a finite number"},
      {{"--udf-box", "0,0,0,1,1,1"}, "--udf-box applies to a .npy grid source only"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = {"--udf", "shape:sphere", "--count", "300", "-o", out};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const auto r = RunProgram("sample-seeds", args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << " " << c.args[1] << ": " << r.err;
    EXPECT_NE(LastLine(r.err).find(c.message), std::string::npos) << r.err;
    EXPECT_LT(LastLine(r.err).size(), 200u) << "no 300-digit numbers: " << r.err;
    EXPECT_FALSE(Exists(out));
  }
  // "0100" is a hundred, not octal 64 (a few drawn points may not reach the surface).
  ASSERT_EQ(RunProgram("sample-seeds", {"--udf", "shape:sphere", "--count", "0100", "-o", out}).exit_code, 0);
  EXPECT_LE(ReadSeeds(out).size(), 100u);
  EXPECT_GT(ReadSeeds(out).size(), 80u);
  // --threads on every program (the files need not exist: options are checked first).
  for (const char* program : kPrograms) {
    std::vector<std::string> args = {"-i", dir / "in.ply", "--threads", "100000"};
    if (std::string(program) == "evaluate") args.insert(args.end(), {"--reference", dir / "ref.ply"});
    else args.insert(args.end(), {"--udf", "shape:sphere", "-o", dir / "o.ply"});
    if (std::string(program) == "sample-seeds") args.erase(args.begin(), args.begin() + 2);
    const auto r = RunProgram(program, args);
    EXPECT_EQ(r.exit_code, 2) << program << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << program << ": " << r.err;
    EXPECT_NE(r.err.find("--threads must be in [0, 1024]"), std::string::npos) << program << ": " << r.err;
  }
}

TEST(Executables, BadInputsExitThreeNamingTheFile) {
  TempDir dir;
  WriteBytes(dir / "huge.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                               "property float y\nproperty float z\nend_header\n0 0 0\n");
  for (const std::string& input : {std::string("/dev/zero"), dir / "huge.ply", dir.path()}) {
    const auto r = RunProgram("optimize-seeds", {"--udf", "shape:sphere", "-i", input, "-o", dir / "out.ply"});
    EXPECT_EQ(r.exit_code, 3) << input << r.err;
    EXPECT_NE(LastLine(r.err).find(input + ": "), std::string::npos) << r.err;
    EXPECT_FALSE(Exists(dir / "out.ply"));
  }
  const auto r = RunProgram("evaluate", {"-i", "-", "--reference", "-"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
}

TEST(Executables, AGridBoxThatOverflowsIsBadInputNotInfiniteSeeds) {
  TempDir dir;
  // A 2x2x2 float32 grid with a sidecar box of +-1e300 (finite numbers, infinite diagonal).
  std::string npy("\x93NUMPY\x01\x00", 8);
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }";
  header.append(64 - (10 + header.size() + 1) % 64, ' ');
  header += '\n';
  npy += static_cast<char>(header.size());
  npy += '\0';
  npy += header;
  const float values[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  npy.append(reinterpret_cast<const char*>(values), sizeof values);
  WriteBytes(dir / "g.npy", npy);
  WriteBytes(dir / "g.json", "{\"box\": [[-1e300, -1e300, -1e300], [1e300, 1e300, 1e300]]}");
  const auto r = RunProgram("sample-seeds", {"--udf", dir / "g.npy", "--count", "100", "-o", dir / "s.ply"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(LastLine(r.err).find("g.json"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(dir / "s.ply"));
}

TEST(Executables, ANewlineInTheUdfPathKeepsEveryHeaderWhole) {
  TempDir dir;
  const std::string obj = dir / "two\nlines.obj";
  WriteBytes(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const auto r = RunProgram("sample-seeds", {"--udf", obj, "--count", "200", "-q", "-o", dir / "s.ply"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(ReadSeeds(dir / "s.ply").size(), 100u);
  EXPECT_NE(ReadBytes(dir / "s.ply").find("two\\x0alines.obj\n"), std::string::npos);
}

// ---- the second start with huge pages (common/huge_pages.h) ----

bool KernelAsksForMadvise() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(in, line) && line.find("[madvise]") != std::string::npos;
}

// An exec: source that writes its environment's GLIBC_TUNABLES and VOROUDF_SAVED_GLIBC_TUNABLES lines to
// `file`, then fails the handshake (sample-seeds then exits 3, which is not what is tested).
int RunWithEnvProbe(const std::string& env, const std::string& file) {
  const std::string probe = "env | grep -E \\\"^(GLIBC_TUNABLES|VOROUDF_SAVED_GLIBC_TUNABLES)=\\\" > " + file;
  return Bash(env + " \"$B/sample-seeds\" --udf \"exec:" + probe + "; exit 1\" -o " + file + ".ply -q 2>/dev/null");
}

TEST(HugePages, ChildProcessesSeeTheCallersEnvironment) {
  TempDir dir;
  EXPECT_EQ(RunWithEnvProbe("GLIBC_TUNABLES=glibc.malloc.check=0", dir / "set.txt"), kExitBadInput);
  EXPECT_EQ(ReadBytes(dir / "set.txt"), "GLIBC_TUNABLES=glibc.malloc.check=0\n");
  EXPECT_EQ(RunWithEnvProbe("env -u GLIBC_TUNABLES", dir / "unset.txt"), kExitBadInput);
  EXPECT_EQ(ReadBytes(dir / "unset.txt"), "");
}

TEST(HugePages, TheStageStartsAgainWithTheTunableAndWritesTheSameBytes) {
  if (!KernelAsksForMadvise()) GTEST_SKIP() << "transparent huge pages are not 'madvise' here: nothing to start again";
  TempDir dir;
  const std::string log = dir / "log.txt";
  ASSERT_EQ(Bash("\"$B/sample-seeds\" --udf shape:torus --count 300 -o " + dir / "seeds.ply -q && "
                 "env -u GLIBC_TUNABLES \"$B/build-gvd\" --udf shape:torus -i " + dir / "seeds.ply -o " +
                 dir / "on.ply -v 2> " + log +
                 " && VOROUDF_HUGE_PAGES=0 \"$B/build-gvd\" --udf shape:torus -i " + dir / "seeds.ply -o " +
                 dir / "off.ply -v 2> " + dir / "off.txt"), 0);
  EXPECT_NE(ReadBytes(log).find("heap in transparent huge pages"), std::string::npos);
  EXPECT_EQ(ReadBytes(dir / "off.txt").find("heap in transparent huge pages"), std::string::npos);
  EXPECT_EQ(ReadBytes(dir / "on.ply"), ReadBytes(dir / "off.ply"));
}

}  // namespace
}  // namespace voroudf

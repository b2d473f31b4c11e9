// The fuzz harnesses (tests/fuzz/harnesses.h) over their committed seed corpus and over every input a
// fuzzer ever crashed on (tests/fuzz/regressions/<harness>/), so what was fixed stays fixed. A harness
// aborts on anything but a result or a voroudf::Error; here that ends the test.
#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/fuzz/harnesses.h"
#include "tests/support/test_support.h"

namespace voroudf {
namespace {

std::vector<std::string> FilesIn(const std::string& dir) {
  std::vector<std::string> files;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d))
      if (e->d_name[0] != '.') files.push_back(dir + "/" + e->d_name);
    closedir(d);
  }
  std::sort(files.begin(), files.end());
  return files;
}

void RunAll(const std::string& harness, void (*body)(const uint8_t*, size_t), size_t min_corpus) {
  const std::string root = std::string(VOROUDF_SOURCE_DIR) + "/tests/fuzz/";
  const std::vector<std::string> corpus = FilesIn(root + "corpus/" + harness);
  EXPECT_GE(corpus.size(), min_corpus) << "the seed corpus of " << harness;
  std::vector<std::string> inputs = corpus;
  for (const std::string& f : FilesIn(root + "regressions/" + harness)) inputs.push_back(f);
  for (const std::string& f : inputs) {
    SCOPED_TRACE(f);
    const std::string bytes = test::ReadBytes(f);
    body(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
}

TEST(FuzzRegressions, Ply) { RunAll("ply", fuzz::Ply, 4); }
TEST(FuzzRegressions, MeshText) { RunAll("mesh_text", fuzz::MeshText, 4); }
TEST(FuzzRegressions, Npy) { RunAll("npy", fuzz::Npy, 2); }
TEST(FuzzRegressions, ExecProtocol) { RunAll("exec_protocol", fuzz::ExecProtocol, 2); }

}  // namespace
}  // namespace voroudf

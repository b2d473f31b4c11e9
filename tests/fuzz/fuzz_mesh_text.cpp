// libFuzzer entry point: voroudf::fuzz::MeshText (tests/fuzz/harnesses.h). Run by pipelines/fuzz.sh.
#include "tests/fuzz/harnesses.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  voroudf::fuzz::MeshText(data, size);
  return 0;
}

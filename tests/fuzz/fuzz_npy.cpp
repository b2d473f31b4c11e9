// libFuzzer entry point: voroudf::fuzz::Npy (tests/fuzz/harnesses.h). Run by pipelines/fuzz.sh.
#include "tests/fuzz/harnesses.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  voroudf::fuzz::Npy(data, size);
  return 0;
}

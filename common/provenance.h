#pragma once
// Where a file came from; written as PLY header comments by every writer.
#include <string>

namespace voroudf {

struct Provenance {
  std::string stage;    ///< producing program, e.g. "sample-seeds"
  std::string options;  ///< its effective options that change the result, e.g. "--count 1000 --seed 0"
  std::string udf;      ///< the --udf SPEC, if the stage read one
};

}  // namespace voroudf

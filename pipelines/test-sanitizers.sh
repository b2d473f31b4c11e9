#!/usr/bin/env bash
# The test suite under sanitizers, in its own build folder.
#
# Usage: pipelines/test-sanitizers.sh [asan|tsan] [CTEST_ARGS ...]
#   asan (default): AddressSanitizer + UndefinedBehaviorSanitizer (GCC), errors fatal, in build-asan/; every test.
#   tsan: ThreadSanitizer (clang, with LLVM's OpenMP runtime and its Archer tool, so that OpenMP's own
#         synchronisation is understood), in build-tsan/; the tests of the threaded stages by default.
# Installs what is missing itself (the project's packages through setup.sh; clang and libomp for tsan).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
KIND=${1:-asan}
[ $# -gt 0 ] && shift
bash "$ROOT/pipelines/setup.sh"

case "$KIND" in
  asan)
    B="$ROOT/build-asan"
    cmake -S "$ROOT" -B "$B" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVOROUDF_SANITIZE=address,undefined \
      ${VOROUDF_CMAKE_ARGS:-} > /dev/null
    export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
    ;;
  tsan)
    missing=()
    for p in clang libomp-14-dev; do
      dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if ((${#missing[@]})); then
      SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
      $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
    fi
    B="$ROOT/build-tsan"
    cmake -S "$ROOT" -B "$B" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
      -DVOROUDF_SANITIZE=thread > /dev/null
    # Archer asks for ignore_noninstrumented_modules: the OpenMP runtime itself is not instrumented.
    export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ignore_noninstrumented_modules=1"
    export OMP_TOOL_LIBRARIES=/usr/lib/llvm-14/lib/libarcher.so
    (($#)) || set -- -R "SampleSeeds|OptimizeSeeds|BuildGvd|Evaluate|ExecUdf|Chain"
    ;;
  *) echo "usage: $0 [asan|tsan] [CTEST_ARGS ...]" >&2; exit 2 ;;
esac
cmake --build "$B" -j"$(nproc)" >&2
ctest --test-dir "$B" --output-on-failure -j"$(nproc)" --timeout 3000 "$@"

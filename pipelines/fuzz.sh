#!/usr/bin/env bash
# Fuzzes the readers with libFuzzer (tests/fuzz/harnesses.h): the PLY reader and the seeds/labels/mesh
# readers on top of it, the OBJ/OFF/STL readers, the .npy + JSON sidecar reader and the exec: protocol client.
#
# Usage: pipelines/fuzz.sh SECONDS [HARNESS ...]     (default: all four, two at a time)
#   Installs clang, its runtime and libomp when missing (Debian packages), builds with
#   -DVOROUDF_FUZZ=ON in build-fuzz/ (ASan + UBSan), runs each harness for SECONDS from a copy of its
#   committed seed corpus (tests/fuzz/corpus/<harness>), and prints executions and crashes per harness.
#   A crashing input is kept in build-fuzz/findings/<harness>/; once fixed, commit it under
#   tests/fuzz/regressions/<harness>/ so that test_fuzz_regressions runs it in the ordinary suite.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SECONDS_EACH=${1:?usage: pipelines/fuzz.sh SECONDS [HARNESS ...]}
shift
HARNESSES=("$@")
((${#HARNESSES[@]})) || HARNESSES=(ply mesh_text npy exec_protocol)

bash "$ROOT/pipelines/setup.sh"  # the project's own dependencies (and a normal build)
missing=()
for p in clang libclang-rt-14-dev libomp-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

B="$ROOT/build-fuzz"
cmake -S "$ROOT" -B "$B" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DVOROUDF_FUZZ=ON > /dev/null
cmake --build "$B" -j"$(nproc)" --target "${HARNESSES[@]/#/fuzz_}" >&2

run_one() {
  local h=$1 work="$B/work/$1" findings="$B/findings/$1"
  rm -rf "$work"; mkdir -p "$work" "$findings"
  cp "$ROOT/tests/fuzz/corpus/$h"/* "$work/"
  # -rss_limit_mb and -malloc_limit_mb make an unbounded allocation a finding, not a stuck machine.
  "$B/bin/fuzz_$h" "$work" -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$findings/" > "$B/work/$h.log" 2>&1 || true
  local execs crashes
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$B/work/$h.log" | grep -o '[0-9]*$' || echo "?")
  crashes=$(find "$findings" -type f | wc -l)
  printf '| %s | %s s | %s | %s | %s |\n' "$h" "$SECONDS_EACH" "$execs" "$(ls "$work" | wc -l)" "$crashes"
}

echo "| harness | time | executions | corpus after | crashing inputs |"
echo "|---|---|---|---|---|"
# Two at a time on two cores; each harness is single-threaded.
for ((i = 0; i < ${#HARNESSES[@]}; i += 2)); do
  run_one "${HARNESSES[i]}" &
  if ((i + 1 < ${#HARNESSES[@]})); then run_one "${HARNESSES[i + 1]}" & fi
  wait
done
echo "logs: $B/work/*.log; crashing inputs: $B/findings/" >&2

#!/usr/bin/env bash
# Builds and runs the benchmark programs (tests/bench/), each printing a Markdown table on stdout, then the
# per-stage timings of the mesh chain (pipelines/bench-stages.sh).
#
# Usage: pipelines/bench.sh [BUILD_DIR]        (default: build/ in the checkout)
#   DATA=DIR           folder of the shared meshes (default: ../shared/data beside the checkout)
#   VOROUDF_LOCK=FILE  run the build and each benchmark under `flock FILE` (shared machines)
# Add a benchmark: one line in BENCHES below, "TARGET ARGUMENTS..." (arguments are split on spaces).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
data=${DATA:-$root/../shared/data}

BENCHES=(
  "bench-udf $data/cad/cgal_fandisk.off $data/classic/cgal_armadillo.off"
)

locked() { if [ -n "${VOROUDF_LOCK:-}" ]; then flock "$VOROUDF_LOCK" "$@"; else "$@"; fi; }

targets=()
for line in "${BENCHES[@]}"; do targets+=("${line%% *}"); done
[ -f "$build/CMakeCache.txt" ] || cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >&2
locked cmake --build "$build" -j"$(nproc)" --target "${targets[@]}" sample-seeds optimize-seeds build-gvd thin-mesh >&2

status=0
for line in "${BENCHES[@]}"; do
  read -r -a words <<< "$line"
  echo "## ${words[0]} (${words[*]:1})"
  echo
  locked "$build/bin/${words[0]}" "${words[@]:1}" || { echo "${words[0]} failed" >&2; status=1; }
  echo
done
echo "## bench-stages (the mesh chain, per stage)"
echo
locked env DATA="$data" "$root/pipelines/bench-stages.sh" "$build/bin" || { echo "bench-stages failed" >&2; status=1; }
exit $status

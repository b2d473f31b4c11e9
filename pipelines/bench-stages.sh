#!/usr/bin/env bash
# Per-stage wall time of the mesh chain (sample-seeds -> optimize-seeds -> build-gvd -> thin-mesh), the
# median of REPS runs, and the output size, on shape:cube and cgal_fandisk.off at COUNT seeds. Target of
# build-gvd + thin-mesh (issue 5): under 5 s for 3k seeds on the 2-core CI machine. Prints a Markdown table.
#
# Usage: pipelines/bench-stages.sh [BIN_DIR]      (default: build/bin in the checkout)
#   DATA=DIR      folder of the shared meshes (default: ../shared/data beside the checkout; fandisk is
#                 skipped when it is missing)
#   COUNT=N       seeds (3000)    REPS=N   runs per input (3)    THREADS=N   --threads of every stage (0)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/bin}
data=${DATA:-$root/../shared/data}
count=${COUNT:-3000}
reps=${REPS:-3}
threads=${THREADS:-0}
for p in sample-seeds optimize-seeds build-gvd thin-mesh; do
  [ -x "$bin/$p" ] || { echo "bench-stages: $bin/$p is not built" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs a command quietly and prints its wall time in seconds.
timed() {
  local t0 t1
  t0=$(date +%s.%N)
  "$@" -q
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f\n", b - a }'
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
# Vertex and face counts from a PLY header.
counts() { awk '/^element vertex/ { v = $3 } /^element face/ { f = $3 } /^end_header/ { print v, f; exit }' "$1"; }

inputs=("shape:cube")
[ -f "$data/cad/cgal_fandisk.off" ] && inputs+=("$data/cad/cgal_fandisk.off")

echo "| input | seeds | runs | s sample-seeds | s optimize-seeds | s build-gvd | s thin-mesh | s build-gvd + thin-mesh | #v | #f |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for udf in "${inputs[@]}"; do
  : > "$work/times"
  for ((r = 1; r <= reps; ++r)); do
    common=(--udf "$udf" --threads "$threads")
    s1=$(timed "$bin/sample-seeds" "${common[@]}" --count "$count" --seed 1 -o "$work/seeds0.ply")
    s2=$(timed "$bin/optimize-seeds" "${common[@]}" -i "$work/seeds0.ply" -o "$work/seeds.ply")
    s3=$(timed "$bin/build-gvd" "${common[@]}" -i "$work/seeds.ply" -o "$work/thick.ply")
    s4=$(timed "$bin/thin-mesh" "${common[@]}" -i "$work/thick.ply" -o "$work/mesh.ply")
    echo "$s1 $s2 $s3 $s4" >> "$work/times"
  done
  cols=()
  for c in 1 2 3 4; do cols+=("$(awk -v c=$c '{ print $c }' "$work/times" | median)"); done
  gvd_thin=$(awk '{ print $3 + $4 }' "$work/times" | median)
  read -r nv nf < <(counts "$work/mesh.ply")
  echo "| $(basename "$udf") | $count | $reps | ${cols[0]} | ${cols[1]} | ${cols[2]} | ${cols[3]} | $gvd_thin | $nv | $nf |"
done

#!/usr/bin/env bash
# Per-stage cost of the mesh chain (sample-seeds -> optimize-seeds -> build-gvd -> thin-mesh): wall time,
# CPU time (user + system), UDF queries and peak memory of every stage and of the whole chain, medians of
# REPS runs (queries are the same in every run). Inputs: shape:sphere, the same sphere through the numpy
# reference server behind exec: and behind unix: (what a learned UDF pays for the protocol), shape:cube, and
# cgal_fandisk.off. Prints a Markdown table.
#
# Usage: pipelines/bench-stages.sh [BIN_DIR]      (default: build/bin in the checkout)
#   DATA=DIR      folder of the shared meshes (default: ../shared/data beside the checkout; fandisk is
#                 skipped when it is missing)
#   COUNT=N       seeds (2500), or several: COUNT="1000 2500 10000 50000" (scaling)
#   INPUTS="A;B"  UDF sources to run, separated by ';' (default: the five above)
#   REPS=N   runs per input (3)    THREADS=N   --threads of every stage (0: all cores); several, e.g.
#                 THREADS="1 2": the runs alternate between them (so that all see the same machine) and a
#                 column gives each one's speed-up over the first (median wall time of the first / of this)
#   OPTIMIZE_ARGS="..."  extra options of optimize-seeds, e.g. "--cell-samples fresh" (the paper's sampling)
#   SAMPLE_ARGS="..."    extra options of sample-seeds, e.g. "--spread-pool 1" (the paper's uniform start)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${1:-$root/build/bin}
data=${DATA:-$root/../shared/data}
count=${COUNT:-2500}
reps=${REPS:-3}
read -r -a thread_counts <<< "${THREADS:-0}"
read -r -a optimize_args <<< "${OPTIMIZE_ARGS:-}"
read -r -a sample_args <<< "${SAMPLE_ARGS:-}"
for p in sample-seeds optimize-seeds build-gvd thin-mesh; do
  [ -x "$bin/$p" ] || { echo "bench-stages: $bin/$p is not built" >&2; exit 2; }
done
work=$(mktemp -d)
server_pid=""
trap '[ -n "$server_pid" ] && kill "$server_pid" 2> /dev/null; rm -rf "$work"' EXIT

# Runs a stage quietly; appends "wall cpu peak_kb queries" to the file $1.
timed() {
  local out=$1; shift
  /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@" -q --udf-stats "$work/stats"
  local q
  q=$(sed -n 2p "$work/stats" | cut -f1)
  awk -v q="$q" '{ printf "%.3f %.3f %d %s\n", $1, $2 + $3, $4, q }' "$work/time" >> "$out"
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
col() { awk -v c="$2" '{ print $c }' "$1" | median; }

/usr/bin/python3 "$root/pipelines/udf_server_sphere.py" --unix "$work/sphere.sock" &
server_pid=$!
for _ in $(seq 100); do [ -S "$work/sphere.sock" ] && break; sleep 0.05; done
inputs=("shape:sphere" "exec:/usr/bin/python3 $root/pipelines/udf_server_sphere.py" "unix:$work/sphere.sock" "shape:cube")
[ -f "$data/cad/cgal_fandisk.off" ] && inputs+=("$data/cad/cgal_fandisk.off")
[ -n "${INPUTS:-}" ] && IFS=';' read -r -a inputs <<< "$INPUTS"
read -r -a counts <<< "$count"

echo "| input | seeds | threads | stage | s wall | s CPU | UDF queries | peak MB | speed-up |"
echo "|---|---|---|---|---|---|---|---|---|"
for udf in "${inputs[@]}"; do
 for count in "${counts[@]}"; do
  stages=(sample-seeds optimize-seeds build-gvd thin-mesh)
  for t in "${thread_counts[@]}"; do
    mkdir -p "$work/t$t"
    for s in "${stages[@]}" total; do : > "$work/t$t/$s"; done
  done
  for ((r = 1; r <= reps; ++r)); do
   for t in "${thread_counts[@]}"; do
    out="$work/t$t"
    common=(--udf "$udf" --threads "$t")
    timed "$out/sample-seeds" "$bin/sample-seeds" "${common[@]}" "${sample_args[@]}" --count "$count" --seed 1 -o "$work/seeds0.ply"
    timed "$out/optimize-seeds" "$bin/optimize-seeds" "${common[@]}" "${optimize_args[@]}" -i "$work/seeds0.ply" -o "$work/seeds.ply"
    timed "$out/build-gvd" "$bin/build-gvd" "${common[@]}" -i "$work/seeds.ply" -o "$work/thick.ply"
    timed "$out/thin-mesh" "$bin/thin-mesh" "${common[@]}" -i "$work/thick.ply" -o "$work/mesh.ply"
    # The run's total: sums of wall, CPU and queries, the largest peak.
    paste -d' ' "$out/sample-seeds" "$out/optimize-seeds" "$out/build-gvd" "$out/thin-mesh" | tail -1 |
      awk '{ w = c = q = 0; m = 0; for (i = 0; i < 4; ++i) { w += $(4*i+1); c += $(4*i+2); if ($(4*i+3) > m) m = $(4*i+3); q += $(4*i+4) }
             printf "%.3f %.3f %d %d\n", w, c, m, q }' >> "$out/total"
   done
  done
  name=$(basename "${udf%% *}")
  [[ "$udf" == exec:* ]] && name="exec: numpy sphere server"
  [[ "$udf" == unix:* ]] && name="unix: numpy sphere server"
  first="$work/t${thread_counts[0]}"
  for t in "${thread_counts[@]}"; do
    for s in "${stages[@]}" total; do
      wall=$(col "$work/t$t/$s" 1)
      speedup=$(awk -v a="$(col "$first/$s" 1)" -v b="$wall" 'BEGIN { if (b > 0) printf "%.2f", a / b; else print "-" }')
      printf "| %s | %s | %s | %s | %s | %s | %s | %.0f | %s |\n" "$name" "$count" "$t" "$s" "$wall" \
        "$(col "$work/t$t/$s" 2)" "$(col "$work/t$t/$s" 4)" "$(col "$work/t$t/$s" 3 | awk '{ print $1 / 1024 }')" "$speedup"
    done
  done
 done
done
echo
echo "--threads ${thread_counts[*]} (0: all cores), medians of $reps runs (this machine: $(nproc) cores)."

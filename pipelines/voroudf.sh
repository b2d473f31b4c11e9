#!/usr/bin/env bash
# The whole chain for one shape: sample-seeds -> optimize-seeds -> build-gvd -> thin-mesh [-> evaluate].
# Every intermediate file is kept in DIR so each stage can be opened in a viewer; DIR/timings.tsv has, per
# stage, its wall seconds and the UDF queries it made, in how many batches, and the seconds inside the UDF
# ("-" for a swapped-in program, which is not asked for them).
#
# Usage: pipelines/voroudf.sh --udf SPEC -o DIR [--count N] [--seed S] [--threads T] [--reference MESH]
#            [--sample-seeds "ARGS"] [--optimize-seeds "ARGS"] [--build-gvd "ARGS"] [--thin-mesh "ARGS"]
#            [--evaluate "ARGS"] [--from STAGE] [--fast]
#   --STAGE "ARGS"  extra options for that stage (split on spaces), e.g. --optimize-seeds "--gamma 5"
#   --fast          0.65-0.7x the time and UDF queries, rougher meshes: optimize-seeds gets
#                   --samples-per-cell 60 --repulsion-cells first, build-gvd --samples-per-seed 100
#                   --curve-sample-weight 1
#                   (docs/performance.md, "A faster chain"); those options cannot be given again
#   --from STAGE    start at this stage (optimize-seeds, build-gvd or thin-mesh), with the earlier stages'
#                   files already in DIR: to try one stage's options or program on the same input
#   --reference     also run evaluate against this mesh -> DIR/metrics.json
# Swap a stage for your own program with VOROUDF_<STAGE>=command (e.g. VOROUDF_OPTIMIZE_SEEDS=my-opt):
# it is called with the same options and files.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${VOROUDF_BIN:-$ROOT/build/bin}
SAMPLE_SEEDS=${VOROUDF_SAMPLE_SEEDS:-$BIN/sample-seeds}
OPTIMIZE_SEEDS=${VOROUDF_OPTIMIZE_SEEDS:-$BIN/optimize-seeds}
BUILD_GVD=${VOROUDF_BUILD_GVD:-$BIN/build-gvd}
THIN_MESH=${VOROUDF_THIN_MESH:-$BIN/thin-mesh}
EVALUATE=${VOROUDF_EVALUATE:-$BIN/evaluate}

usage() { sed -n '7,18p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit "${1:-2}"; }
UDF="" OUT="" COUNT=3000 SEED=0 THREADS=0 REF="" FROM=sample-seeds FAST=0
A_SAMPLE="" A_OPT="" A_GVD="" A_THIN="" A_EVAL=""
while (($#)); do
  case "$1" in
    --udf) UDF=$2; shift 2 ;;
    -o|--output) OUT=$2; shift 2 ;;
    --count) COUNT=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --threads) THREADS=$2; shift 2 ;;
    --reference) REF=$2; shift 2 ;;
    --sample-seeds) A_SAMPLE=$2; shift 2 ;;
    --optimize-seeds) A_OPT=$2; shift 2 ;;
    --build-gvd) A_GVD=$2; shift 2 ;;
    --thin-mesh) A_THIN=$2; shift 2 ;;
    --evaluate) A_EVAL=$2; shift 2 ;;
    --from) FROM=$2; shift 2 ;;
    --fast) FAST=1; shift ;;
    -h|--help) usage 0 ;;
    *) echo "$0: unknown option '$1'" >&2; usage ;;
  esac
done
[ -n "$UDF" ] && [ -n "$OUT" ] || usage
# The fast setting: fewer samples per cell, the cells drawn once per outer iteration, a sparser graph.
if [ "$FAST" = 1 ]; then
  A_OPT="--samples-per-cell 60 --repulsion-cells first $A_OPT"
  A_GVD="--samples-per-seed 100 --curve-sample-weight 1 $A_GVD"
fi
# The stages in order, and the file each reads from DIR.
STAGES=(sample-seeds optimize-seeds build-gvd thin-mesh)
declare -A INPUT=([optimize-seeds]=seeds0.ply [build-gvd]=seeds.ply [thin-mesh]=thick.ply)
first=-1
for i in "${!STAGES[@]}"; do [ "${STAGES[$i]}" = "$FROM" ] && first=$i; done
[ "$first" -ge 0 ] || { echo "$0: --from: unknown stage '$FROM' (sample-seeds, optimize-seeds, build-gvd or thin-mesh)" >&2; exit 2; }
if [ "$first" -gt 0 ] && [ ! -s "$OUT/${INPUT[$FROM]}" ]; then
  echo "$0: --from $FROM needs $OUT/${INPUT[$FROM]} (the earlier stages' output)" >&2
  exit 2
fi
from() { for i in "${!STAGES[@]}"; do [ "${STAGES[$i]}" = "$1" ] && [ "$i" -ge "$first" ] && return 0; done; return 1; }
mkdir -p "$OUT"
printf 'stage\tseconds\tudf_queries\tudf_batches\tudf_seconds\n' > "$OUT/timings.tsv"

# Echoes the command, runs it, appends its row to timings.tsv. Our own programs (the command is
# $BIN/STAGE) also get --udf-stats, whose numbers go into the row.
run() {
  local stage=$1; shift
  local stats="$OUT/.udf-stats-$stage.tsv" extra=()
  [ "$1" = "$BIN/$stage" ] && [ "$stage" != evaluate ] && extra=(--udf-stats "$stats")
  echo "+ $* ${extra[*]}" >&2
  local t0 t1 queries=- batches=- inside=-
  t0=$(date +%s.%N)
  "$@" "${extra[@]}"
  t1=$(date +%s.%N)
  if [ -s "$stats" ]; then
    read -r queries batches inside < <(sed -n 2p "$stats")
    rm -f "$stats"
  fi
  awk -v s="$stage" -v a="$t0" -v b="$t1" -v q="$queries" -v n="$batches" -v u="$inside" \
    'BEGIN { printf "%s\t%.3f\t%s\t%s\t%s\n", s, b - a, q, n, u }' >> "$OUT/timings.tsv"
}

# shellcheck disable=SC2086  # the per-stage ARGS are meant to be split
from sample-seeds && run sample-seeds $SAMPLE_SEEDS --udf "$UDF" --count "$COUNT" --seed "$SEED" --threads "$THREADS" \
  -o "$OUT/seeds0.ply" $A_SAMPLE
# shellcheck disable=SC2086
from optimize-seeds && run optimize-seeds $OPTIMIZE_SEEDS --udf "$UDF" --seed "$SEED" --threads "$THREADS" \
  -i "$OUT/seeds0.ply" -o "$OUT/seeds.ply" $A_OPT
# shellcheck disable=SC2086
from build-gvd && run build-gvd $BUILD_GVD --udf "$UDF" --seed "$SEED" --threads "$THREADS" \
  -i "$OUT/seeds.ply" -o "$OUT/thick.ply" --labels "$OUT/labels.ply" $A_GVD
# shellcheck disable=SC2086
run thin-mesh $THIN_MESH --udf "$UDF" --threads "$THREADS" \
  -i "$OUT/thick.ply" -o "$OUT/mesh.ply" --nm-edges "$OUT/nm-edges.ply" $A_THIN
if [ -n "$REF" ]; then
  # shellcheck disable=SC2086
  run evaluate $EVALUATE -i "$OUT/mesh.ply" --reference "$REF" --threads "$THREADS" -o "$OUT/metrics.json" $A_EVAL
fi
echo "mesh: $OUT/mesh.ply (non-manifold edges: $OUT/nm-edges.ply; Voronoi labels: $OUT/labels.ply)" >&2

#!/usr/bin/env bash
# The whole chain for one shape (sample-seeds -> optimize-seeds -> build-gvd -> thin-mesh); every intermediate
# file is kept in DIR so each stage can be inspected.
# Usage: pipelines/voroudf.sh --udf SPEC -o DIR [--count N] [--seed S] [--threads T]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${VOROUDF_BIN:-$ROOT/build/bin}

usage() { echo "usage: $0 --udf SPEC -o DIR [--count N] [--seed S] [--threads T]" >&2; exit 2; }
UDF="" OUT="" COUNT=3000 SEED=0 THREADS=0
while (($#)); do
  case "$1" in
    --udf) UDF=$2; shift 2 ;;
    -o|--output) OUT=$2; shift 2 ;;
    --count) COUNT=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --threads) THREADS=$2; shift 2 ;;
    -h|--help) usage ;;
    *) echo "$0: unknown option '$1'" >&2; usage ;;
  esac
done
[ -n "$UDF" ] && [ -n "$OUT" ] || usage
mkdir -p "$OUT"

run() { echo "+ $*" >&2; "$@"; }
run "$BIN/sample-seeds" --udf "$UDF" --count "$COUNT" --seed "$SEED" --threads "$THREADS" -o "$OUT/seeds0.ply"
if [ -x "$BIN/optimize-seeds" ]; then
  run "$BIN/optimize-seeds" --udf "$UDF" --seed "$SEED" --threads "$THREADS" -i "$OUT/seeds0.ply" -o "$OUT/seeds.ply"
else
  echo "$0: warning: $BIN/optimize-seeds not found; meshing the unoptimised seeds" >&2
  cp "$OUT/seeds0.ply" "$OUT/seeds.ply"
fi
run "$BIN/build-gvd" --udf "$UDF" --seed "$SEED" --threads "$THREADS" -i "$OUT/seeds.ply" -o "$OUT/thick.ply" \
  --labels "$OUT/labels.ply"
run "$BIN/thin-mesh" --udf "$UDF" --threads "$THREADS" -i "$OUT/thick.ply" -o "$OUT/mesh.ply" \
  --nm-edges "$OUT/nm-edges.ply"
echo "mesh: $OUT/mesh.ply (non-manifold edges: $OUT/nm-edges.ply; Voronoi labels: $OUT/labels.ply)" >&2

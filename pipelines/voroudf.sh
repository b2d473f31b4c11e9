#!/usr/bin/env bash
# The whole chain for one shape; every intermediate file is kept in DIR so each stage can be inspected.
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

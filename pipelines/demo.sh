#!/usr/bin/env bash
# Quick start, first command: install what is missing, build, and run the chain on a built-in shape.
# Usage: bash pipelines/demo.sh [SHAPE] [OUTDIR]   (defaults: cube, ./voroudf-demo/SHAPE)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SHAPE=${1:-cube}
OUT=${2:-voroudf-demo/$SHAPE}
bash "$ROOT/pipelines/setup.sh"
bash "$ROOT/pipelines/voroudf.sh" --udf "shape:$SHAPE" -o "$OUT"
echo "demo: files of every stage are in $OUT/"
ls -l "$OUT"

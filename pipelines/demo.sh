#!/usr/bin/env bash
# Quick start, first command: install what is missing, build, and run the chain on a built-in shape.
# Usage: bash pipelines/demo.sh [SHAPE] [OUTDIR]   (defaults: cube, ./voroudf-demo/SHAPE)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SHAPE=${1:-cube}
OUT=${2:-voroudf-demo/$SHAPE}
bash "$ROOT/pipelines/setup.sh"
bash "$ROOT/pipelines/voroudf.sh" --udf "shape:$SHAPE" -o "$OUT"
/usr/bin/python3 "$ROOT/pipelines/render.py" "$OUT/mesh.ply" -o "$OUT/mesh.png" 2> /dev/null ||
  echo "demo: no picture (pipelines/render.py failed)" >&2
echo "demo: files of every stage are in $OUT/"
ls -l "$OUT"
if [ -s "$OUT/mesh.png" ]; then echo "demo: picture of the mesh (non-manifold edges red, boundary blue): $OUT/mesh.png"; fi

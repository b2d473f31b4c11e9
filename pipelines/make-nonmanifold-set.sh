#!/usr/bin/env bash
# Builds the synthetic non-manifold benchmark set (paper Sec. 4.1) from ten closed CAD meshes:
# each is cut by a fixed oblique plane, one part is shifted into the other by 2 % of the diagonal, and the
# two are corefined and merged (pipelines/tools/synthetic_nonmanifold.h). Parameters go to NAME.ply.json.
# Usage: pipelines/make-nonmanifold-set.sh OUTDIR [CAD_DIR]   (CAD_DIR default: ../shared/data/cad)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${VOROUDF_BIN:-$ROOT/build/bin}
OUT=${1:?usage: $0 OUTDIR [CAD_DIR]}
CAD=${2:-$ROOT/../shared/data/cad}
# Closed, non-self-intersecting models whose cut gives crossings (checked: all ten succeed).
MODELS=(abc_00000003_forgescan.stl abc_00000005_forgescan.stl abc_00000007_forgescan.stl
        abc_00000009_forgescan.stl cgal_anchor.off cgal_fandisk.off cgal_joint.off cgal_pinion.off
        cgal_rotor.off cgal_spool.off)
mkdir -p "$OUT"
for m in "${MODELS[@]}"; do
  name=${m%.*}
  [ -s "$OUT/$name.ply" ] && continue
  "$BIN/make-nonmanifold" -q -i "$CAD/$m" -o "$OUT/$name.ply" --overlap-rel 0.02
done
echo "non-manifold set: ${#MODELS[@]} meshes in $OUT" >&2

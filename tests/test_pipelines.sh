#!/usr/bin/env bash
# End-to-end tests of the chained executables through the three drivers: pipelines/voroudf.sh,
# Makefile.example and pipelines/Snakefile. Usage: test_pipelines.sh BIN_DIR {voroudf-sh|make|snakemake|benchmark|noise-study|feature-misses}
set -euo pipefail
BIN=$(cd "$1" && pwd)
WHAT=$2
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
export VOROUDF_BIN=$BIN

case "$WHAT" in
  voroudf-sh)
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/a" --count 500 --seed 3 2> "$TMP/log"
    for f in seeds0.ply seeds.ply thick.ply labels.ply mesh.ply nm-edges.ply timings.tsv; do
      [ -s "$TMP/a/$f" ] || fail "voroudf.sh did not write $f"
    done
    [ "$(cut -f1 "$TMP/a/timings.tsv" | tr '\n' ' ')" = "stage sample-seeds optimize-seeds build-gvd thin-mesh " ] ||
      fail "timings.tsv: $(cat "$TMP/a/timings.tsv")"
    # Every stage made UDF queries, in at least one batch, and says so (not "-", which is for swapped stages).
    awk -F'\t' 'NR > 1 && !($3 > 0 && $4 > 0 && $4 <= $3 && $5 >= 0) { exit 1 }' "$TMP/a/timings.tsv" ||
      fail "timings.tsv lacks the UDF queries: $(cat "$TMP/a/timings.tsv")"
    grep -q "UDF usage: [0-9]* queries in [0-9]* batches" "$TMP/log" || fail "stages do not log their UDF usage"
    ! ls "$TMP/a"/.udf-stats-* > /dev/null 2>&1 || fail "the --udf-stats files were left behind"
    grep -q "^+ .*optimize-seeds --udf shape:sphere" "$TMP/log" || fail "commands are not echoed"
    # The same inputs, options and seed give the same bytes through the whole chain.
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/b" --count 500 --seed 3 2> /dev/null
    cmp -s "$TMP/a/mesh.ply" "$TMP/b/mesh.ply" || fail "the chain is not deterministic"
    # A stage swapped for another program (here: one that keeps the seeds as they are).
    printf '#!/bin/sh\nwhile [ $# -gt 0 ]; do case "$1" in -i) in=$2; shift;; -o) out=$2; shift;; esac; shift; done\ncp "$in" "$out"\n' > "$TMP/keep-seeds"
    chmod +x "$TMP/keep-seeds"
    VOROUDF_OPTIMIZE_SEEDS="$TMP/keep-seeds" bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/c" \
      --count 300 2> /dev/null
    cmp -s "$TMP/c/seeds0.ply" "$TMP/c/seeds.ply" || fail "the swapped stage was not used"
    [ "$(awk -F'\t' '$1 == "optimize-seeds" { print $3 }' "$TMP/c/timings.tsv")" = "-" ] ||
      fail "a swapped stage should have no UDF counts: $(cat "$TMP/c/timings.tsv")"
    [ -s "$TMP/c/mesh.ply" ] || fail "no mesh after swapping a stage"
    # --from: the chain from a later stage on the earlier stages' files gives the same mesh; without those
    # files it stops with exit 2 and names the file.
    mkdir -p "$TMP/e"
    cp "$TMP/a/seeds.ply" "$TMP/e/"
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/e" --count 500 --seed 3 --from build-gvd 2> /dev/null
    cmp -s "$TMP/a/mesh.ply" "$TMP/e/mesh.ply" || fail "--from build-gvd gave another mesh"
    [ "$(cut -f1 "$TMP/e/timings.tsv" | tr '\n' ' ')" = "stage build-gvd thin-mesh " ] ||
      fail "--from build-gvd ran other stages: $(cat "$TMP/e/timings.tsv")"
    set +e
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/f" --from thin-mesh 2> "$TMP/err"
    rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q "thick.ply" "$TMP/err" || fail "--from without its input: exit $rc, $(cat "$TMP/err")"
    # A failing stage stops the chain with its exit code.
    set +e
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:nope -o "$TMP/d" 2> /dev/null
    rc=$?
    set -e
    [ "$rc" = 3 ] || fail "a bad --udf should end the chain with exit 3, got $rc"
    [ ! -e "$TMP/d/seeds0.ply" ] || fail "a failed stage left a file"
    # --fast: the stages run with the fast setting (each file's header records its options) and fewer UDF
    # queries than the default chain on the same input; an option of the setting given again is refused.
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/g" --count 500 --seed 3 --fast 2> /dev/null
    grep -a -m1 "^comment options" "$TMP/g/seeds.ply" | grep -q -- "--samples-per-cell 60 .*--repulsion-cells first" ||
      fail "--fast: optimize-seeds ran without the fast setting"
    grep -a -m1 "^comment options" "$TMP/g/thick.ply" | grep -q -- "--samples-per-seed 100" ||
      fail "--fast: build-gvd ran without the fast setting"
    queries() { awk -F'\t' 'NR > 1 { q += $3 } END { print q }' "$1/timings.tsv"; }
    [ "$(queries "$TMP/g")" -lt "$(queries "$TMP/a")" ] ||
      fail "--fast asked no fewer UDF queries: $(queries "$TMP/g") against $(queries "$TMP/a")"
    set +e
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/h" --count 300 --fast \
      --build-gvd "--samples-per-seed 150" 2> "$TMP/err"
    rc=$?
    set -e
    [ "$rc" = 2 ] && grep -q -- "--samples-per-seed" "$TMP/err" || fail "--fast with its option again: exit $rc"
    ;;
  make)
    make -s -f "$ROOT/Makefile.example" -C "$TMP" -j2 VOROUDF_BIN="$BIN" SHAPES="sphere disc" COUNT=400 OUT=out \
      > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "make failed"; }
    for s in sphere disc; do [ -s "$TMP/out/$s/mesh.ply" ] || fail "make did not build $s"; done
    # A folder of reference meshes: the chain plus evaluate for each.
    mkdir -p "$TMP/data"
    cp "$TMP/out/sphere/mesh.ply" "$TMP/data/ball.ply"
    make -s -f "$ROOT/Makefile.example" -C "$TMP" -j2 VOROUDF_BIN="$BIN" DATA=data COUNT=400 OUT=meshes \
      > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "make over a folder failed"; }
    grep -q '"cd_x1e3"' "$TMP/meshes/ball/metrics.json" || fail "no metrics for the folder's mesh"
    ;;
  snakemake)
    command -v snakemake > /dev/null || fail "snakemake is not installed (pipelines/setup.sh installs it)"
    (cd "$TMP" && snakemake -s "$ROOT/pipelines/Snakefile" --cores 2 --quiet \
      --config shapes=sphere,torus out=snake count=400 bin="$BIN" > "$TMP/log" 2>&1) ||
      { cat "$TMP/log"; fail "snakemake failed"; }
    for s in sphere torus; do [ -s "$TMP/snake/$s/mesh.ply" ] || fail "snakemake did not build $s"; done
    ;;
  benchmark)
    # A folder with one good mesh and one broken file: two rows, the broken one with its error, and a table.
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/s" --count 300 2> /dev/null
    mkdir -p "$TMP/data/cad"
    cp "$TMP/s/mesh.ply" "$TMP/data/cad/ball.ply"
    printf 'OFF\n3 1 0\n0 0 0\n1 0\n' > "$TMP/data/cad/broken.off"
    "$ROOT/pipelines/benchmark" --sets cad --data "$TMP/data" --out "$TMP/bench" --bin "$BIN" -j 2 --count 300 \
      > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "the benchmark driver failed"; }
    grep -q '^| cad | 2 | 1 |' "$TMP/bench/results.md" || { cat "$TMP/bench/results.md"; fail "no table row"; }
    grep -q '^cad,ball,' "$TMP/bench/results.csv" || fail "no CSV row for the good mesh"
    grep -q '| CD | CD floor | CD exact |' "$TMP/bench/results.md" || fail "no sampled/floor/exact columns"
    grep -q '^- cad: ball [0-9.]* (ref->mesh' "$TMP/bench/results.md" || fail "no largest-exact-HD list"
    /usr/bin/python3 -c "import csv,sys; r=[r for r in csv.DictReader(open(sys.argv[1])) if r['shape']=='ball'][0]; \
      sys.exit(0 if 0 < float(r['cd_exact_x1e3']) < float(r['cd_x1e3']) and float(r['cd_floor_x1e3']) > 0 else 1)" \
      "$TMP/bench/results.csv" || fail "exact CD not between 0 and the sampled CD, or no floor"
    grep -q '^cad,broken,.*exit 3' "$TMP/bench/results.csv" || { cat "$TMP/bench/results.csv"; fail "no error row"; }
    # --reuse --from thin-mesh: the same meshes from the first run's thick duals, only thin-mesh timed.
    "$ROOT/pipelines/benchmark" --sets cad --data "$TMP/data" --out "$TMP/bench2" --bin "$BIN" -j 2 --count 300 \
      --reuse "$TMP/bench" --from thin-mesh > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "benchmark --reuse failed"; }
    cmp -s "$TMP/bench/runs/cad/ball/mesh.ply" "$TMP/bench2/runs/cad/ball/mesh.ply" || fail "--reuse gave another mesh"
    [ "$(cut -f1 "$TMP/bench2/runs/cad/ball/timings.tsv" | tr '\n' ' ')" = "stage thin-mesh " ] ||
      fail "--reuse --from thin-mesh ran other stages"
    ;;
  feature-misses)
    # The cube meshed twice: as is (feature seeds on its edges), and with a rank test that sees no feature
    # (every seed rank 1). The classes' shares add up to 1 - recall, and without feature seeds every miss
    # is "no-seed".
    printf 'OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n' > "$TMP/cube.off"
    bash "$ROOT/pipelines/voroudf.sh" --udf "$TMP/cube.off" --reference "$TMP/cube.off" -o "$TMP/cube" \
      --count 600 2> /dev/null
    bash "$ROOT/pipelines/voroudf.sh" --udf "$TMP/cube.off" --reference "$TMP/cube.off" -o "$TMP/flat" \
      --count 600 --optimize-seeds "--rank-threshold 0.99 --crease-angle-deg 0" 2> /dev/null
    "$ROOT/pipelines/feature-misses" --bin "$BIN" "$TMP/cube" "$TMP/flat" > "$TMP/table" 2> "$TMP/log" ||
      { cat "$TMP/log"; fail "feature-misses failed"; }
    /usr/bin/python3 - "$TMP/table" <<'PY' || { cat "$TMP/table"; fail "feature-misses: wrong shares"; }
import sys
rows = {l.split("|")[1].strip(): [float(x) for x in l.split("|")[2:7]] for l in open(sys.argv[1])
        if l.startswith("| cube") or l.startswith("| flat")}
for name, (recall, chord, across, one_side, no_seed) in rows.items():
    assert abs(chord + across + one_side + no_seed - (1 - recall)) < 0.002, name
flat = rows["flat"]
assert rows["cube"][0] > 0.95 and flat[0] < 0.9 and flat[4] > 0.99 * (1 - flat[0]), rows
PY
    # The rank it classes by is the seeds file's rank property, found by name: the cube's seeds have rank-3
    # corners and rank-2 edge seeds, the flat run's none.
    /usr/bin/python3 - "$ROOT/pipelines/feature-misses" "$TMP/cube/seeds.ply" "$TMP/flat/seeds.ply" <<'PY' ||
import sys, importlib.machinery, importlib.util
loader = importlib.machinery.SourceFileLoader("feature_misses", sys.argv[1])
fm = importlib.util.module_from_spec(importlib.util.spec_from_loader("feature_misses", loader))
loader.exec_module(fm)
_, cube = fm.seed_ranks(sys.argv[2])
_, flat = fm.seed_ranks(sys.argv[3])
assert (cube == 3).sum() >= 8 and (cube == 2).sum() > 0 and set(cube) <= {1, 2, 3}, sorted(set(cube))
assert (flat >= 2).sum() == 0, sorted(set(flat))
PY
      fail "feature-misses: the seeds' ranks are not read from their rank property"
    ;;
  noise-study)
    # One ball at three noise levels and as a grid: a row each, none failed, and at a value error of 1e-3
    # the mesh keeps its vertices (projection to a floor; without it about half the seeds were dropped).
    bash "$ROOT/pipelines/voroudf.sh" --udf shape:sphere -o "$TMP/s" --count 300 2> /dev/null
    mkdir -p "$TMP/data/cad"
    cp "$TMP/s/mesh.ply" "$TMP/data/cad/ball.ply"
    "$ROOT/pipelines/noise-study" --sets cad:1 --data "$TMP/data" --out "$TMP/study" --bin "$BIN" -j 2 --count 400 \
      --levels clean,v1e-3,g15,grid --grid-resolution 32 > "$TMP/log" 2>&1 || { cat "$TMP/log"; fail "noise-study failed"; }
    for level in clean v1e-3 g15 grid; do
      grep -q "^| $level | 1 | 0 |" "$TMP/study/study.md" || { cat "$TMP/study/study.md"; fail "no row for $level"; }
    done
    /usr/bin/python3 -c "import csv,sys; r={r['level']: r for r in csv.DictReader(open(sys.argv[1]))}; \
      sys.exit(0 if float(r['v1e-3']['vertices']) >= 0.9 * float(r['clean']['vertices']) else 1)" \
      "$TMP/study/study.csv" || { cat "$TMP/study/study.md"; fail "the noisy run lost vertices"; }
    ;;
  *) fail "unknown test '$WHAT'" ;;
esac
echo "ok: $WHAT"

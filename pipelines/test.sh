#!/usr/bin/env bash
# Quick start, second command: install what is missing, build, run every test through ctest.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$ROOT/pipelines/setup.sh"
ctest --test-dir "$ROOT/build" --output-on-failure -j"$(nproc)" --timeout 900

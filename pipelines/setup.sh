#!/usr/bin/env bash
# Installs the Debian packages voroudf needs (only those missing; --no-install-recommends; sudo when not
# root) and builds it in build/ (Release). Sourced or run by demo.sh and test.sh.
# Extra CMake arguments: VOROUDF_CMAKE_ARGS="-DVOROUDF_WERROR=ON" (CI sets this).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

PACKAGES=(
  build-essential cmake              # compiler, make, cmake
  libeigen3-dev libcli11-dev libgtest-dev
  libceres-dev                       # L-BFGS (optimize-seeds)
  libflann-dev                       # kd-trees: kNN graphs (build-gvd), seed neighbours (optimize-seeds)
  libopenmesh-dev libcgal-dev        # manifold mesh work, exact predicates
  python3-numpy snakemake            # exec: reference server, Python package, Snakefile
  python3-vtk9 xvfb xauth            # pictures (pipelines/render.py: VTK under a virtual X server)
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
  echo "voroudf setup: installing ${missing[*]}" >&2
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# `import voroudf` from Debian's python3 without PYTHONPATH (README, docs/python.md): a path file in the user's
# site-packages that points at python/, as `pip install -e` would write (PEP 668 keeps pip off Debian's own
# python). Said when written; delete the file to undo.
site=$(/usr/bin/python3 -m site --user-site 2> /dev/null || true)
if [ -n "$site" ] && mkdir -p "$site" 2> /dev/null && [ "$(cat "$site/voroudf.pth" 2> /dev/null)" != "$ROOT/python" ]; then
  echo "$ROOT/python" > "$site/voroudf.pth" &&
    echo "voroudf setup: python3 can 'import voroudf' from this clone ($site/voroudf.pth)" >&2
fi

# shellcheck disable=SC2086  # VOROUDF_CMAKE_ARGS is a list of arguments
cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release ${VOROUDF_CMAKE_ARGS:-} >&2
cmake --build "$ROOT/build" -j"$(nproc)" >&2

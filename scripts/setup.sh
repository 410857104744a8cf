#!/usr/bin/env bash
# Installs the Debian packages polydg needs to build, test and check its output.
# Idempotent: when every package is already present it only runs dpkg-query and exits.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libcgal-dev libeigen3-dev libpugixml-dev zlib1g-dev libassimp-dev
  libopenvdb-dev libboost-iostreams-dev
  libsuitesparse-dev libopenblas0-pthread libopenblas-pthread-dev
  libtbb-dev libjemalloc-dev libcli11-dev nlohmann-json3-dev libtet1.5-dev
  libgtest-dev libgmock-dev libbenchmark-dev libspectra-dev clang-format universal-ctags
  python3-vtk9 python3-meshio python3-numpy assimp-testmodels
  pybind11-dev python3-pybind11 python3-dev python3-pytest python3-dask python3-distributed
  openfoam  # polydg export's tests and bench: checkMesh, foamToVTK, postProcess, snappyHexMesh
  xvfb xauth  # scripts/render_images.py: Debian's VTK 9.1 renders only through an X server
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "setup: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null

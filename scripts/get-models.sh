#!/usr/bin/env bash
# Fetches the real models the benchmarks use beyond the bundled testdata/, from Debian's
# packages (the project does not ship them): the Stanford bunny as a closed 75,408-triangle
# surface (bunny00.off of CGAL's data, package libcgal-demo), tetgen and Gmsh (HXT), the
# reference meshers `polydg bench --suite meshing` times polydg against, and OpenFOAM (snappyHexMesh and
# checkMesh, package openfoam; scripts/setup.sh installs it too), the peer of `polydg bench
# --suite openfoam`.
# Usage: scripts/get-models.sh [DIR]   (default build/share/polydg/models, where polydg bench
# looks for them; `polydg bench --data DIR` reads DIR/models instead).
set -euo pipefail
cd "$(dirname "$0")/.."
dest=${1:-build/share/polydg/models}
mkdir -p "$dest"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
tools=()
command -v tetgen >/dev/null 2>&1 || tools+=(tetgen)
command -v gmsh >/dev/null 2>&1 || tools+=(gmsh)
command -v snappyHexMesh >/dev/null 2>&1 || tools+=(openfoam)
if ((${#tools[@]})); then
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${tools[@]}" >/dev/null
fi
if [[ ! -f "$dest/bunny.off" ]]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  (cd "$work" && { apt-get download libcgal-demo >/dev/null 2>&1 ||
    { $SUDO apt-get update -qq && apt-get download libcgal-demo >/dev/null; }; })
  dpkg -x "$work"/libcgal-demo_*.deb "$work/x"
  tar -xzf "$work/x/usr/share/doc/libcgal-dev/data.tar.gz" -C "$work" data/meshes/bunny00.off
  mv "$work/data/meshes/bunny00.off" "$dest/bunny.off.tmp"
  mv "$dest/bunny.off.tmp" "$dest/bunny.off"
fi
echo "models in $dest: $(ls "$dest" | tr '\n' ' ')"

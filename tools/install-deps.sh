#!/bin/sh
# Install the Debian packages cohfrac needs, if any are missing (idempotent).
# Needs root or sudo only when something is missing.
set -eu
PKGS="gcc g++ make cmake pkg-config libbullet-dev libbullet-extras-dev libccd-dev libfcl-dev
      libhdf5-dev libcmocka-dev liblua5.4-dev tetgen gmsh glmark2-data python3 python3-h5py
      python3-numpy python3-scipy python3-matplotlib ffmpeg libtinygltf-dev nlohmann-json3-dev
      blender python3-meshio paraview python3-paraview xvfb
      clang libomp-dev libassimp-dev libmeshoptimizer-dev libcgal-dev
      libopenmpi-dev openmpi-bin metis"
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "cohfrac: installing missing Debian packages:$missing"
if [ "$(id -u)" -eq 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "cohfrac: need root or sudo to install:$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $missing

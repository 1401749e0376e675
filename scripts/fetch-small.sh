#!/bin/sh
# Fetches the `small` scene (see docs/scenes.md, "Small"): link 6 of the
# Franka Emika Panda robot arm's visual meshes, from the PyPI wheel of
# pybullet 3.2.7 (103 MB to download, 2.3 MB kept), into $1, else
# $XDG_DATA_HOME/mrsl/franka-panda (default ~/.local/share/mrsl/franka-panda),
# where mrslc and the tests find it. Keeps link6.obj, its material library
# and texture, and the model's Apache-2.0 LICENSE.txt. Needs pip and python3
# (for its zipfile module); no root, nothing is installed.
set -eu
version=3.2.7
wheel="pybullet-$version-cp311-cp311-manylinux_2_17_x86_64.manylinux2014_x86_64.whl"
sha256=5d858abf7c12a21ef3ed351cf81dac1b5e486ec25c9ab59bfc84beb89034edff
dest="${1:-${XDG_DATA_HOME:-$HOME/.local/share}/mrsl/franka-panda}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
python3 -m pip download --no-deps --only-binary=:all: --python-version 3.11 --implementation cp \
    --abi cp311 --platform manylinux2014_x86_64 "pybullet==$version" -d . -q
echo "$sha256  $wheel" | sha256sum -c -
panda=pybullet_data/franka_panda
visual="$panda/meshes/visual"
python3 - "$wheel" "$visual/link6.obj" "$visual/link6.mtl" "$visual/colors.png" "$panda/LICENSE.txt" <<'PY'
import sys, zipfile
with zipfile.ZipFile(sys.argv[1]) as wheel:
    for name in sys.argv[2:]:
        wheel.extract(name, ".")
PY
mkdir -p "$dest"
cp "$visual/link6.obj" "$visual/link6.mtl" "$visual/colors.png" "$panda/LICENSE.txt" "$dest/"
echo "$dest/link6.obj"

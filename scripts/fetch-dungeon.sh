#!/bin/sh
# Fetches the textured `dungeon` scene (see docs/scenes.md, "Dungeon"): the
# level of the Castle Game Engine's third-person navigation example, from
# Debian's castle-game-engine-doc package (about 260 MB to download, 41 MB
# kept), into $1, else $XDG_DATA_HOME/mrsl/castle-dungeon (default
# ~/.local/share/mrsl/castle-dungeon), where mrslc and the tests find it.
# Needs apt-get and dpkg-deb (Debian or Ubuntu); no root.
set -eu
dest="${1:-${XDG_DATA_HOME:-$HOME/.local/share}/mrsl/castle-dungeon}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
apt-get download castle-game-engine-doc
dpkg-deb -x castle-game-engine-doc_*.deb pkg
doc=pkg/usr/share/doc/castle-game-engine-doc
level="$doc/examples/third_person_navigation/data/level"
mkdir -p "$dest/textures"
cp "$level/level-dungeon.gltf" "$level/level-dungeon.bin" "$dest/"
cp "$level"/textures/* "$dest/textures/"
# The package's licence statement travels with the files.
cp "$doc/copyright" "$dest/debian-copyright"
echo "$dest/level-dungeon.gltf"

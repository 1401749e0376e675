#!/bin/sh
# Fetches the `outdoor` scene (see docs/scenes.md, "Outdoor"): the "forza"
# road course of the racing game TORCS, from Debian's torcs-data package
# (version 1.3.7+dfsg-5, 333 MB to download, 20 MB kept), into $1,
# else $XDG_DATA_HOME/mrsl/torcs-forza (default
# ~/.local/share/mrsl/torcs-forza), where mrslc and the tests find it.
# Only the track's model (forza.acc), its textures and its readme (the
# credits and the Free Art License statement) are kept, with the package's
# copyright file. Needs apt-get and dpkg-deb (Debian or Ubuntu); no root.
set -eu
version=1.3.7+dfsg-5
dest="${1:-${XDG_DATA_HOME:-$HOME/.local/share}/mrsl/torcs-forza}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
apt-get download "torcs-data=$version"
track=./usr/share/games/torcs/tracks/road/forza
copyright=./usr/share/doc/torcs-data/copyright
dpkg-deb --fsys-tarfile "torcs-data_${version}_all.deb" | tar -x "$track" "$copyright"
mkdir -p "$dest"
cp "$track/forza.acc" "$track"/*.png "$track/readme.txt" "$dest/"
# The package's licence statement travels with the files.
cp "$copyright" "$dest/debian-copyright"
echo "$dest/forza.acc"

#!/bin/sh
# The GPU run in one command: every mode at its defaults over Sponza and the
# scene suite at 1920x1080 and 3840x2160 on the machine's preferred adapter
# (a discrete GPU over an integrated one or a software driver), paired with
# the reference; writes OUTDIR/suite.md and OUTDIR/suite.json.
#
#   scripts/gpu-bench.sh OUTDIR [mrslc bench options...]
#
# Options after OUTDIR replace the default sizes when they name a --size,
# and are passed on to `mrslc bench --suite` (--scene, --runs, a program).
# Builds mrslc in release first, unless $MRSLC names a binary to use (a
# machine that cannot reach crates.io runs a binary built elsewhere).
# Scenes whose files are missing are listed as not measured, not fatal:
# fetch them first (scripts/fetch-*.sh; docs/scenes.md) or point
# MRSL_SPONZA, MRSL_DUNGEON, ... at them.
set -eu
if [ $# -lt 1 ]; then
    echo "usage: scripts/gpu-bench.sh OUTDIR [mrslc bench options...]" >&2
    exit 2
fi
out="$1"
shift
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ -z "${MRSLC:-}" ]; then
    cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p mrslc
    MRSLC="${CARGO_TARGET_DIR:-$root/target}/release/mrslc"
fi
sizes="--size 1920x1080 --size 3840x2160"
for arg in "$@"; do
    case "$arg" in --size | --size=*) sizes="" ;; esac
done
# shellcheck disable=SC2086 # $sizes is two options or none
exec "$MRSLC" bench --suite --out "$out" $sizes "$@"

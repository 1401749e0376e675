#!/bin/sh
# What a better refinement criterion could give the workload at most: coarse
# 4x4 and the hierarchical mode over each scene, at their defaults, with the
# workload's predicates disabled (its keys and the background rule still
# refine), and with nothing refined at all (no predicates, no keys; the
# hierarchical mode's variance test off too). Each is a plain
# `mrslc render examples/sponza_lights.mrsl --compare` (3 pairs with the
# reference per render), the variants interleaved round by round; writes
# OUTDIR/bounds.md (speed per round, its median, MSSIM, the share of the
# coarse work evaluated) and OUTDIR/renders/.
#
#   scripts/workload-bounds.sh OUTDIR [--scene S]... [--size WxH] [--rounds N]
#
# Defaults: the scenes sponza, outdoor and small, 1920x1080, 3 rounds.
# Builds mrslc in release first, unless $MRSLC names a binary to use.
# docs/eval/evaluation.md ("What refinement could give") reads its figures.
set -eu
usage="usage: scripts/workload-bounds.sh OUTDIR [--scene S]... [--size WxH] [--rounds N]"
if [ $# -lt 1 ]; then
    echo "$usage" >&2
    exit 2
fi
out="$1"
shift
scenes=""
size="1920x1080"
rounds=3
while [ $# -gt 0 ]; do
    case "$1" in
    --scene) scenes="$scenes $2" ;;
    --size) size="$2" ;;
    --rounds) rounds="$2" ;;
    *)
        echo "$usage" >&2
        exit 2
        ;;
    esac
    shift 2
done
[ -n "$scenes" ] || scenes="sponza outdoor small"
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ -z "${MRSLC:-}" ]; then
    cargo build --release --quiet --manifest-path "$root/Cargo.toml" -p mrslc
    MRSLC="${CARGO_TARGET_DIR:-$root/target}/release/mrslc"
fi
mkdir -p "$out/renders"
program="$root/examples/sponza_lights.mrsl"
# The same program without its discontinuity keys: the annotations go, the
# channels stay (the background rule is not a key and stays).
keyless="$out/sponza_lights_without_keys.mrsl"
sed -E 's/^@(surface_)?key\([^)]*\) +//' "$program" >"$keyless"
if cmp -s "$program" "$keyless"; then
    echo "workload-bounds: $program declares no key to remove" >&2
    exit 1
fi
# Every predicate of the workload made unreachable (docs/eval/evaluation.md names them).
off="--set light_tolerance=1e9 --set shadow_tolerance=1e9 --set blocker_edge=1e9"
raw="$out/renders/runs.txt"
: >"$raw"
device=""
round=1
while [ "$round" -le "$rounds" ]; do
    for scene in $scenes; do
        for mode in coarse4x4 hierarchical; do
            similarity=""
            [ "$mode" = hierarchical ] && similarity="--similarity 1e9"
            for variant in defaults predicates-off nothing-refined; do
                case $variant in
                defaults) args="$program" ;;
                predicates-off) args="$program $off $similarity" ;;
                nothing-refined) args="$keyless $off $similarity" ;;
                esac
                echo "workload-bounds: round $round/$rounds, $scene, $mode, $variant" >&2
                # shellcheck disable=SC2086 # $args is the program and its options
                said=$("$MRSLC" render $args --scene "$scene" --mode "$mode" --size "$size" --compare \
                    --out "$out/renders" 2>&1) || {
                    echo "$said" >&2
                    exit 1
                }
                speed=$(echo "$said" | sed -n "s/.*, \([0-9.]*\)x the reference's speed.*/\1/p")
                mssim=$(echo "$said" | sed -n 's/.* MSSIM \([0-9.]*\),.*/\1/p')
                coarse=$(echo "$said" | sed -n 's/.*(\([0-9.]*\)% of its coarse effects).*/\1/p')
                if [ -z "$speed" ] || [ -z "$mssim" ] || [ -z "$coarse" ]; then
                    echo "workload-bounds: no speed, MSSIM or coarse share in:" >&2
                    echo "$said" >&2
                    exit 1
                fi
                echo "$scene $mode $variant $round $speed $mssim $coarse" >>"$raw"
                [ -n "$device" ] || device=$(echo "$said" | sed -n 's/.*; device: \(.*\) ([0-9]* ms)$/\1/p' | head -n 1)
            done
        done
    done
    round=$((round + 1))
done
# One row per scene, mode and variant: the rounds' speeds and their median.
{
    echo "# The workload with less refinement ($size, $rounds rounds)"
    echo
    echo "\`mrslc render --compare\` per round (each the median of 3 pairs with the reference);"
    echo "device: $device"
    echo
    echo "| scene | mode | variant | speed per round | median | MSSIM | coarse work evaluated |"
    echo "|---|---|---|---|---:|---:|---:|"
    awk '
        { key = $1 " " $2 " " $3; if (!(key in n)) order[++keys] = key
          n[key]++; speed[key, n[key]] = $5; mssim[key] = $6; coarse[key] = $7 }
        END {
            for (i = 1; i <= keys; i++) {
                key = order[i]; m = n[key]; list = ""
                for (j = 1; j <= m; j++) { s[j] = speed[key, j]; list = list (j > 1 ? ", " : "") s[j] "x" }
                for (a = 1; a <= m; a++) for (b = a + 1; b <= m; b++) if (s[b] + 0 < s[a] + 0) { t = s[a]; s[a] = s[b]; s[b] = t }
                median = (m % 2) ? s[(m + 1) / 2] : (s[m / 2] + s[m / 2 + 1]) / 2
                split(key, k, " ")
                printf "| %s | %s | %s | %s | %.2fx | %s | %s%% |\n", k[1], k[2], k[3], list, median, mssim[key], coarse[key]
            }
        }' "$raw"
} >"$out/bounds.md"
echo "wrote $out/bounds.md" >&2

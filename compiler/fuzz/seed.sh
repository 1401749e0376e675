#!/bin/sh
# Fills corpus/{lex,parse,check,compile} with the seed corpus: every program
# of compiler/tests/data/ok, compiler/tests/data/err and examples/*.mrsl.
# The corpus directories are not committed (see .gitignore); run this once
# before `cargo +nightly fuzz run TARGET`. Usage: compiler/fuzz/seed.sh
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
for target in lex parse check compile; do
    mkdir -p "$here/corpus/$target"
    n=0
    for f in "$root"/compiler/tests/data/ok/*.mrsl "$root"/compiler/tests/data/err/*.mrsl "$root"/examples/*.mrsl; do
        cp "$f" "$here/corpus/$target/seed_$(basename "$(dirname "$f")")_$(basename "$f")"
        n=$((n + 1))
    done
done
echo "copied $n seed programs into each of corpus/{lex,parse,check,compile}"

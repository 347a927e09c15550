#!/usr/bin/env bash
# The ABI check (docs/development.md, "The ABI"): libabigail's abidw describes the built
# libplume.so's public face (the functions include/plume/ declares, the types they reach) and
# abidiff compares it with the committed baseline abi/libplume.abi.
#   scripts/abi-check.sh BUILD           fails on a change that breaks a program built against the
#                                        baseline (a function removed, a parameter or a struct it
#                                        reaches changed; the inside of an opaque handle is not
#                                        the ABI) under the same soname, and on a baseline of
#                                        another soname; added functions pass
#   scripts/abi-check.sh BUILD --update  writes the baseline from BUILD's library (after a soname
#                                        bump, or after a reviewed compatible change)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:?usage: scripts/abi-check.sh BUILD [--update]}
baseline=abi/libplume.abi
for tool in abidw abidiff; do
    command -v "$tool" >/dev/null || { echo "abi-check: $tool not found: apt-get install abigail-tools" >&2; exit 2; }
done
lib=$(readlink -f "$build/libplume.so")
[ -f "$lib" ] || { echo "abi-check: no $build/libplume.so: run make first" >&2; exit 2; }
current="$build/abi/libplume.abi"
mkdir -p "$build/abi"
abidw --headers-dir include/plume --drop-private-types --drop-undefined-syms --exported-interfaces-only \
    --no-show-locs --no-corpus-path --out-file "$current" "$lib"
soname_of() { sed -n "1s/.* soname='\([^']*\)'.*/\1/p" "$1"; }
if [ "${2:-}" = "--update" ]; then
    cp "$current" "$baseline"
    echo "abi-check: $baseline now describes $(soname_of "$baseline") ($(grep -c '<elf-symbol' "$baseline") functions)"
    exit 0
fi
[ -f "$baseline" ] || { echo "abi-check: no $baseline: write it with scripts/abi-check.sh $build --update" >&2; exit 1; }
have=$(soname_of "$baseline") now=$(soname_of "$current")
if [ "$have" != "$now" ]; then
    echo "abi-check: the baseline describes $have but the library is $now: after a soname bump, write the" >&2
    echo "           baseline anew (scripts/abi-check.sh $build --update) and commit it with the bump" >&2
    exit 1
fi
# the opaque handles (typedef struct plume_x plume_x; in include/plume/, defined inside the library):
# a program never sees their layout, so a change in it is not an ABI change
suppr="$build/abi/opaque.suppr"
grep -oh 'typedef struct plume_[a-z0-9_]* plume_[a-z0-9_]*;' include/plume/*.h | awk '{print $3}' | sort -u |
    while read -r name; do printf '[suppress_type]\n  type_kind = struct\n  name = %s\n\n' "$name"; done >"$suppr"
# the structs that grow (their first member is `size_t size`, docs/development.md): members appended
# at their end are compatible, the library reading only the bytes a program's size says it has
awk '/^typedef struct \{/ { open = 1; first = 1; next }
     open && first && NF { grows = ($0 ~ /^ *size_t size;/); first = 0 }
     open && /^\} plume_[a-z0-9_]*;/ { if (grows) { sub(/;.*/, "", $2); print $2 } open = 0 }' include/plume/*.h |
    sort -u | while read -r name; do
        printf '[suppress_type]\n  type_kind = struct\n  name = %s\n  has_data_member_inserted_at = end\n\n' "$name"
    done >>"$suppr"
set +e
abidiff --no-added-syms --suppressions "$suppr" "$baseline" "$current" >"$build/abi/abidiff.txt" 2>&1
rc=$?
set -e
# abidiff's exit code is a bit field: 1 error, 2 usage, 4 an ABI change, 8 an incompatible one. Added
# functions are not reported (--no-added-syms), so any change left removes or alters what an
# existing program uses: a struct that grew, a parameter that changed, a function that went
if [ $((rc & 3)) -ne 0 ]; then
    cat "$build/abi/abidiff.txt" >&2
    echo "abi-check: abidiff failed (exit $rc)" >&2
    exit 2
fi
if [ $((rc & 12)) -ne 0 ]; then
    cat "$build/abi/abidiff.txt" >&2
    echo "abi-check: the change above breaks programs built against $have. Either undo it, or bump" >&2
    echo "           VERSION_MAJOR (Makefile and include/plume/base.h) and write the baseline anew" >&2
    echo "           (scripts/abi-check.sh $build --update)" >&2
    exit 1
fi
# abidiff exits 4 when functions were added: that is the answer here, not a failure
added=$({ abidiff --suppressions "$suppr" "$baseline" "$current" 2>/dev/null || true; } | sed -n 's/.* \([0-9]*\) Added function.*/\1/p' | head -n 1)
echo "abi-check: $now keeps the ABI of $baseline ($(grep -c '<elf-symbol' "$baseline") functions; ${added:-0} added)"

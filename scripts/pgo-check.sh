#!/usr/bin/env bash
# Whether pgo/uavex.profdata still reaches the optimized builds in target/release.
#
# A profile is matched to functions by symbol name, and the names change, all at once and
# silently, with anything in cargo's metadata hash (Cargo.lock, the rustc version, features,
# profile settings): the build then compiles as if there were no profile. This looks up the map
# update's `integrate_scan`, the hottest function of a mission, in `uavex` and in the decision
# benchmark, and tells whether the profile holds that name.
#
# usage: cargo build --release && cargo bench --no-run && scripts/pgo-check.sh
# Needs llvm-profdata 19 or later, as scripts/pgo-train.sh. Exit status 1 if a build is missed.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pgo-profdata.sh
hot='_ZN13uavex_systems7mapping9integrate14integrate_scan17h[0-9a-f]*E'
trained=$("$profdata" show --all-functions pgo/uavex.profdata | grep -o "$hot" | sort -u)
status=0
for binary in target/release/uavex target/release/deps/decision-*; do
    case $binary in *.d) continue ;; esac
    [ -x "$binary" ] || continue
    name=$(nm "$binary" | grep -o "$hot" | sort -u | head -1)
    if [ -z "$name" ]; then
        echo "pgo-check: $binary has no integrate_scan symbol (stripped?)" >&2
        status=1
    elif grep -qx "$name" <<< "$trained"; then
        echo "reached: $binary"
    else
        echo "MISSED:  $binary ($name is not in the profile: remake it with scripts/pgo-train.sh)"
        status=1
    fi
done
exit $status

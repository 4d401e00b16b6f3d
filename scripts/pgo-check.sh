#!/usr/bin/env bash
# Whether pgo/uavex.profdata still reaches the optimized builds in target/release.
#
# A profile is matched to functions by symbol name, and the names change, all at once and
# silently, with anything in cargo's metadata hash (Cargo.lock, the rustc version, features,
# profile settings): the build then compiles as if there were no profile. This looks up the map
# update's `integrate` (behind `integrate_scan`), the hottest function of a mission, in `uavex`
# and in the decision benchmark, and tells whether the profile holds that name; and whether the
# map update's walk calls any `core::array` function out of line (see the loop's last check).
#
# usage: cargo build --release && cargo bench --no-run && scripts/pgo-check.sh
# Needs llvm-profdata 19 or later, as scripts/pgo-train.sh. Exit status 1 if a build is missed.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pgo-profdata.sh
hot='_ZN13uavex_systems7mapping9integrate9integrate17h[0-9a-f]*E'
trained=$("$profdata" show --all-functions pgo/uavex.profdata | grep -o "$hot" | sort -u)
status=0
for binary in target/release/uavex target/release/deps/decision-*; do
    case $binary in *.d) continue ;; esac
    [ -x "$binary" ] || continue
    name=$(nm "$binary" | grep -o "$hot" | sort -u | head -1)
    if [ -z "$name" ]; then
        echo "pgo-check: $binary has no mapping::integrate::integrate symbol (stripped?)" >&2
        status=1
    elif grep -qx "$name" <<< "$trained"; then
        echo "reached: $binary"
    else
        echo "MISSED:  $binary ($name is not in the profile: remake it with scripts/pgo-train.sh)"
        status=1
    fi
    # The function the map update's walk is inlined into (the one holding most of the lines
    # of mapping/walk.rs) must not call a `core::array` function: an `array::map` left out
    # of line there (`try_map`) spilled the walk's registers and cost the map update 13 %
    # (mapping/axes.rs).
    walk=$(objdump -d --no-show-raw-insn -C -l "$binary" 2>/dev/null \
        | awk '/^[0-9a-f]+ </ { fn = $0 } /mapping\/walk\.rs:/ { print fn }' \
        | sort | uniq -c | sort -rn | head -1 | sed 's/^ *[0-9]* //')
    calls=$(objdump -d --no-show-raw-insn -C "$binary" \
        | awk -v walk="$walk" '$0 == walk { inside = 1; next } /^[0-9a-f]+ </ { inside = 0 }
            inside && /call.*<core::array::/' | wc -l)
    if [ "$calls" -gt 0 ]; then
        echo "OUT OF LINE: $binary: the map update calls core::array functions $calls times ($walk)"
        status=1
    fi
done
exit $status

#!/usr/bin/env bash
# Timing of two builds on this 2-core machine, N rounds; prints each run's wall time, then the
# minimum and median of each build.
#
# Paired (the default): OLD and NEW run at the same time, one pinned to each core (cores
# swapped every other round). Both runs of a round see the same machine: on a shared VM whose
# speed drifts by 30 % within an hour, alternating runs mix speeds; paired runs do not. (Both
# share the L3 and the memory bus, which slows memory-bound work in both alike.)
#
# `--alternate`: OLD then NEW, one after the other, both on core 1. For a VM whose two cores
# run at different speeds at the same time (the Intel Xeon VM of 2026-12-06: up to 20 % apart
# within a round), where pairing compares the cores more than the builds; compare the minimums.
#
# usage: scripts/ab-pair.sh [--alternate] OLD NEW N ARGS...   e.g.
#   scripts/ab-pair.sh /tmp/uavex-old target/release/uavex 4 run scenarios/eaae_pillars.toml --out
# The last argument gets a per-binary output folder appended (/tmp/ab-pair-old, -new).
set -euo pipefail
alternate=false
if [ "${1:-}" = --alternate ]; then
    alternate=true
    shift
fi
old=$1 new=$2 rounds=$3
shift 3
: > /tmp/ab-pair-times

# Runs build `label` (old or new) on `core` with the remaining arguments, and prints its time.
run() {
    local label=$1 core=$2 binary
    shift 2
    if [ "$label" = old ]; then binary=$old; else binary=$new; fi
    rm -rf "/tmp/ab-pair-$label"
    if ! /usr/bin/time -f %e -o "/tmp/ab-pair-$label.time" taskset -c "$core" "$binary" "$@" \
        "/tmp/ab-pair-$label" > /dev/null 2> "/tmp/ab-pair-$label.err"; then
        echo "round $round $label failed: see /tmp/ab-pair-$label.err" >&2
        return
    fi
    echo "round $round $label $(tail -1 "/tmp/ab-pair-$label.time") s" | tee -a /tmp/ab-pair-times
}

for round in $(seq 1 "$rounds"); do
    if $alternate; then
        run old 1 "$@"
        run new 1 "$@"
    else
        if (( round % 2 )); then cores=(1 0); else cores=(0 1); fi
        run old "${cores[0]}" "$@" &
        run new "${cores[1]}" "$@" &
        wait
    fi
done
for label in old new; do
    awk -v label="$label" '$3 == label { print $4 }' /tmp/ab-pair-times | sort -n \
        | awk -v label="$label" '{ t[NR] = $1 }
            END { if (NR == 0) { printf "%s: no run finished\n", label; exit }
                  m = (NR % 2) ? t[(NR + 1) / 2] : (t[NR / 2] + t[NR / 2 + 1]) / 2;
                  printf "%s: min %.2f s, median %.2f s over %d runs\n", label, t[1], m, NR }'
done

#!/usr/bin/env bash
# Paired timing of two builds on this 2-core machine: runs OLD and NEW at the same time, one
# pinned to each core (cores swapped every other round), N rounds, and prints each run's wall
# time. Both runs of a round see the same machine: on a shared VM whose speed drifts by 30 %
# within an hour, alternating runs mix speeds; paired runs do not. (Both share the L3 and the
# memory bus, which slows memory-bound work in both alike.)
#
# usage: scripts/ab-pair.sh OLD NEW N ARGS...   e.g.
#   scripts/ab-pair.sh /tmp/uavex-old target/release/uavex 4 run scenarios/eaae_pillars.toml --out
# The last argument gets a per-binary output folder appended (/tmp/ab-pair-old, -new).
set -euo pipefail
old=$1 new=$2 rounds=$3
shift 3
for round in $(seq 1 "$rounds"); do
    if (( round % 2 )); then cores=(1 0); else cores=(0 1); fi
    rm -rf /tmp/ab-pair-old /tmp/ab-pair-new
    (/usr/bin/time -f "round $round old %e s" taskset -c "${cores[0]}" "$old" "$@" /tmp/ab-pair-old \
        > /dev/null 2> /tmp/ab-pair-old.err; tail -1 /tmp/ab-pair-old.err) &
    (/usr/bin/time -f "round $round new %e s" taskset -c "${cores[1]}" "$new" "$@" /tmp/ab-pair-new \
        > /dev/null 2> /tmp/ab-pair-new.err; tail -1 /tmp/ab-pair-new.err) &
    wait
done

#!/usr/bin/env bash
# Deterministic counts for the replayed decisions of the decision bench: instructions, and
# cache misses of a simulated 1 MB last-level cache (the size of this project's VM's L2), by
# function. On a shared VM whose speed drifts by 10-30 % within minutes and that has no
# hardware counters, these tell two builds apart where timings cannot (a change of 2 % in
# the path search is invisible in paired timings, plain in these counts).
#
# usage: scripts/callgrind-decisions.sh BENCH_BINARY OUT_FILE [SEED]   e.g.
#   cargo bench --no-run --locked
#   scripts/callgrind-decisions.sh target/release/deps/decision-<hash> /tmp/cg-new.out 4
#   callgrind_annotate --inclusive=yes --show=Ir,D1mr,DLmr /tmp/cg-new.out | head -40
#
# The mission the bench flies first runs uninstrumented (about a minute under valgrind): the
# bench pauses before its replay (`DECISION_PAUSE_S`), and this script switches the
# instrumentation on then. The replay runs each decision once (`DECISION_REPEATS=1`): some
# 4 minutes for seed 4. Needs valgrind (Debian: `apt-get install valgrind`).
set -euo pipefail
bench=$1 out=$2 seed=${3:-4}
log="$out.log"
DECISION_SEEDS=$seed DECISION_REPEATS=1 DECISION_PAUSE_S=2 \
    valgrind --tool=callgrind --cache-sim=yes --LL=1048576,8,64 --instr-atstart=no \
    --callgrind-out-file="$out" "$bench" > "$log" 2>&1 &
pid=$!
# One seed: a second one's mission would fly instrumented (an hour), as the instrumentation
# stays on once switched on.
until grep -q "replay in" "$log" 2>/dev/null; do
    if ! kill -0 "$pid" 2>/dev/null; then
        echo "the bench ended before its replay; see $log" >&2
        exit 1
    fi
    sleep 0.2
done
callgrind_control -i on "$pid" > /dev/null
wait "$pid"
grep -E "I +refs|LL misses" "$log"
echo "profile in $out (callgrind_annotate $out)"

#!/usr/bin/env bash
# Makes pgo/uavex.profdata, the profile-guided optimization data every optimized build uses
# (scripts/rustc-pgo): builds uavex instrumented, runs the training workload, merges the counts.
#
# Needs llvm-profdata of LLVM 19 or later (Debian: `apt-get install llvm-19`; LLVM 19 reads the
# raw profiles of rustc's LLVM 22, and rustc reads its merged ones). About 14 minutes on the
# project's 2-core machine. Afterwards `cargo clean`: cargo does not see the profile change.
#
# Two builds are trained: `cargo build --release` (the `uavex` program) and `cargo bench` (the
# benchmarks). A profile is matched to functions by their symbol names, and the two builds name
# every function of the workspace differently (the benchmarks' dev-dependencies change the
# features of shared dependencies, hence every crate's metadata hash): a profile of one build
# leaves the other unoptimized, silently. `cargo bench --no-run` builds `uavex` too, with the
# benchmarks' names; the workload runs once with each program, into one profile. The names
# also change with Cargo.lock, the rustc version and dependencies' features: remake the profile
# after any of these (scripts/pgo-check.sh tells whether it still reaches both builds).
#
# The workload: pgo/training.toml (the EAAE scenes x strategies, EAAE also with every cluster
# evaluated, on seed 6, which no benchmark uses), then one run of every other shipped scenario
# (the scenario files under scenarios/ that are not sweep plans),
# so that no system is left out of the profile (code never run in training is laid out as
# cold). Two runs of the script give profiles of the same functions, 99.9 % alike in edge counts
# (the sweep's two jobs interleave differently).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/pgo-profdata.sh
work=target/pgo-train
rm -rf "$work/runs" "$work/bin"
mkdir -p "$work/bin"
instrumented() {
    UAVEX_PGO=off RUSTFLAGS="-Cprofile-generate=$PWD/$work/raw" "$@" --locked --target-dir "$work/build"
}
instrumented cargo build --release
cp "$work/build/release/uavex" "$work/bin/uavex-release"
instrumented cargo bench --no-run
cp "$work/build/release/uavex" "$work/bin/uavex-bench"
# The build's own instrumented programs (build scripts, procedural macros) wrote profiles too.
rm -rf "$work/raw"
for build in release bench; do
    uavex=$work/bin/uavex-$build
    runs=$work/runs/$build
    "$uavex" sweep pgo/training.toml --out "$runs/sweep" --jobs 2
    # Every other shipped scenario, once: not the sweep plans, nor the scenes the training plan
    # ran (their own seed, 1, is the benchmarks').
    for scenario in scenarios/*.toml scenarios/examples/*.toml; do
        case $scenario in
        scenarios/eaae_pillars.toml | scenarios/eaae_simple.toml) continue ;;
        esac
        grep -q '^\[\[scenario\]\]' "$scenario" && continue
        "$uavex" run "$scenario" --out "$runs/$(basename "$scenario" .toml)" > /dev/null
    done
done
"$profdata" merge --sparse -o pgo/uavex.profdata "$work"/raw/*.profraw
ls -l pgo/uavex.profdata

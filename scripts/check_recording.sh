#!/usr/bin/env bash
# Opt-in check (not CI) that the real rerun viewer reads uavex's recordings: records 30 s of
# the shipped Pillars exploration and runs `rerun rrd verify` (every column deserialised with
# rerun's own reflection, footer and manifest checked) and `rerun rrd stats` on it.
#
# Needs the viewer's CLI at the version of the SDK crates uavex writes with:
#   pip install "rerun-sdk==0.36.*"
# Then open the file with `rerun OUT/pillars.rrd`.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/record_check}
mkdir -p "$out"
# The scene without its 600 s limit: 30 s is a handful of decisions.
sed 's/^time_limit_s = .*/time_limit_s = 30.0/' scenarios/eaae_pillars.toml > "$out/pillars_30s.toml"
cargo run --release --features record -- \
    run "$out/pillars_30s.toml" --out "$out" --record "$out/pillars.rrd"
rerun rrd verify "$out/pillars.rrd"
rerun rrd stats "$out/pillars.rrd"

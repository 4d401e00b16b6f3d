#!/usr/bin/env bash
# Checks uavex's OctoMap .bt files against the real OctoMap library: installs liboctomap-dev
# when missing (Debian/Ubuntu, needs root or sudo), builds the checker, and runs the ignored
# integration test engine/tests/octomap_bt.rs with it.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"

if [ ! -f /usr/include/octomap/OcTree.h ]; then
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  $sudo_cmd apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y liboctomap-dev g++
fi

out="${CARGO_TARGET_DIR:-$root/target}/octomap-checker"
mkdir -p "$out"
g++ -std=c++17 -O2 -Wall -Wextra -o "$out/check_bt" "$here/check_bt.cpp" -loctomap -loctomath
echo "built $out/check_bt"

cd "$root"
UAVEX_OCTOMAP_CHECKER="$out/check_bt" cargo test -p uavex-engine --test octomap_bt -- --ignored --nocapture

# Sourced by the PGO scripts (pgo-train.sh, pgo-check.sh): sets `profdata` to an llvm-profdata
# of LLVM 19 or later, which reads the raw profiles of rustc's LLVM 22 (Debian: `apt-get
# install llvm-19`; `LLVM_PROFDATA` overrides), or exits 2 saying so.
profdata=${LLVM_PROFDATA:-$(command -v llvm-profdata-19 || command -v llvm-profdata || true)}
if [ -z "$profdata" ]; then
    echo "$(basename "$0"): no llvm-profdata (19 or later) found; apt-get install llvm-19, or set LLVM_PROFDATA" >&2
    exit 2
fi

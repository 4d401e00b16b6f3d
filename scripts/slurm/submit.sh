#!/usr/bin/env bash
# Submits a sweep as a Slurm job array of N shards and a merge job that runs after it.
#
#   scripts/slurm/submit.sh PLAN OUT N [extra sbatch options...]
#
# Prints the two job ids. Results: OUT/shard-1..N while it runs, OUT/merged at the end
# (runs.csv, runs.parquet, summary.csv, summary.md, plots/). Set UAVEX to the uavex binary if
# it is not on the PATH of the compute nodes.
set -euo pipefail

if [ $# -lt 3 ]; then
    echo "usage: $0 PLAN OUT N [sbatch options...]" >&2
    exit 2
fi
plan=$(realpath "$1")
out=$(realpath -m "$2")
count=$3
shift 3
here=$(dirname "$(realpath "$0")")
mkdir -p "${out}"

array=$(sbatch --parsable --array="1-${count}" --chdir="${out}" \
    --export="ALL,PLAN=${plan},OUT=${out}" "$@" "${here}/sweep_array.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterany:${array}" --chdir="${out}" \
    --export="ALL,OUT=${out}" "$@" "${here}/merge.sbatch")
echo "array job ${array} (${count} shards), merge job ${merge}"

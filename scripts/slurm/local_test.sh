#!/usr/bin/env bash
# Opt-in end-to-end test of the Slurm scripts on this machine: installs a single-node Slurm
# from Debian (slurm-wlm, munge), starts munged, slurmctld and slurmd, runs a small sweep as a
# 4-task job array plus the merge job (submit.sh), and checks that the merged results equal an
# unsharded sweep of the same plan run directly.
#
#   sudo scripts/slurm/local_test.sh --yes          # installs packages, starts daemons
#   sudo scripts/slurm/local_test.sh --yes --stop   # ... and stops the daemons afterwards
#
# It changes the machine (packages, /etc/slurm/slurm.conf, daemons), so it runs only with
# --yes, as root, on Debian or Ubuntu. Not part of CI.
set -euo pipefail

yes=0
stop=0
for arg in "$@"; do
    case "${arg}" in
        --yes) yes=1 ;;
        --stop) stop=1 ;;
        *) echo "unknown option ${arg}" >&2; exit 2 ;;
    esac
done
if [ "${yes}" -ne 1 ]; then
    sed -n '2,12p' "$0"
    echo "refusing to change this machine without --yes" >&2
    exit 2
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "run as root (it installs packages and starts daemons)" >&2
    exit 2
fi

here=$(dirname "$(realpath "$0")")
repo=$(realpath "${here}/../..")
host=$(hostname -s)
cpus=$(nproc)

echo "== installing slurm-wlm and munge"
export DEBIAN_FRONTEND=noninteractive
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge >/dev/null
fi

echo "== starting munged"
if [ ! -s /etc/munge/munge.key ]; then
    mungekey --create --force
fi
chown munge:munge /etc/munge/munge.key
chmod 400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
if ! munge -n >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged
    sleep 1
fi
munge -n | unmunge >/dev/null

echo "== configuring a single-node cluster on ${host} (${cpus} CPUs)"
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<CONF
# Written by uavex scripts/slurm/local_test.sh: one node, no cgroups, no accounting.
ClusterName=uavex-local
SlurmctldHost=${host}
AuthType=auth/munge
SlurmUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=${host} CPUs=${cpus} State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF

echo "== starting slurmctld and slurmd"
if ! scontrol ping 2>/dev/null | grep -q UP; then
    slurmctld
fi
if ! pgrep -x slurmd >/dev/null; then
    slurmd
fi
for _ in $(seq 1 30); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE 'idle|mix|alloc'; then
        break
    fi
    sleep 1
done
sinfo

echo "== building uavex"
(cd "${repo}" && cargo build --release --quiet)
uavex="${repo}/target/release/uavex"

work=$(mktemp -d /tmp/uavex-slurm.XXXXXX)
echo "== a sweep of 8 short runs in ${work}"
# The sweep tests' room (tests/sweep_common.rs): runs of a fraction of a second with every
# source of randomness a run has.
cp "${repo}/tests/fixtures/sweep_room.toml" "${work}/room.toml"
cat > "${work}/plan.toml" <<'TOML'
name = "slurm_local_test"
seeds = 4
[[scenario]]
file = "room.toml"
[grid]
"uav.0.behaviour.speed" = [1.0, 2.0]
TOML

echo "== submitting a 4-task array and its merge"
ids=$(UAVEX="${uavex}" "${here}/submit.sh" "${work}/plan.toml" "${work}/out" 4 --cpus-per-task=1)
echo "${ids}"
merge_id=$(echo "${ids}" | sed -E 's/.*merge job ([0-9]+).*/\1/')
for _ in $(seq 1 300); do
    if ! squeue -h -j "${merge_id}" 2>/dev/null | grep -q .; then
        break
    fi
    sleep 1
done
cat "${work}/out"/uavex-merge-*.out

echo "== the same plan unsharded, for comparison"
"${uavex}" sweep "${work}/plan.toml" --out "${work}/direct" --jobs 2 >/dev/null

status=0
for file in summary.csv summary.md; do
    if cmp -s "${work}/out/merged/${file}" "${work}/direct/${file}"; then
        echo "ok: merged ${file} equals the unsharded sweep's"
    else
        echo "FAILED: merged ${file} differs from the unsharded sweep's" >&2
        status=1
    fi
done
strip_wall_time() {
    python3 -c 'import csv,sys
rows = list(csv.reader(open(sys.argv[1])))
at = rows[0].index("wall_time_s")
for r in rows: del r[at]; print(",".join(r))' "$1"
}
if [ "$(strip_wall_time "${work}/out/merged/runs.csv")" = "$(strip_wall_time "${work}/direct/runs.csv")" ]; then
    echo "ok: merged runs.csv equals the unsharded sweep's (but for wall times)"
else
    echo "FAILED: merged runs.csv differs" >&2
    status=1
fi
runs=$(find "${work}/out/merged/runs" -name summary.json | wc -l)
echo "merged runs: ${runs} (plan: 8)"
[ "${runs}" -eq 8 ] || status=1

if [ "${stop}" -eq 1 ]; then
    echo "== stopping the daemons"
    scontrol shutdown || true
    if [ -s /run/munge/munged.pid ]; then
        kill "$(cat /run/munge/munged.pid)" || true
    fi
fi
exit "${status}"

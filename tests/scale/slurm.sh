#!/usr/bin/env bash
# Runs the Slurm recipe of docs/scale.md (docs/scale/mocap-clean.sbatch) on
# a real one-node Slurm on this machine: Debian's slurm-wlm and munge
# (installed when missing), a slurm.conf of this host in a scratch folder,
# munged, slurmctld and slurmd started and stopped by this script. The job
# cleans the two sample takes with the shipped model through
# `sbatch --wait`; the outputs must equal mocap.clean's in one process.
#
#   bash tests/scale/slurm.sh        (as root; after tests/python/run.sh,
#                                     whose venv has mocap and Ray)
# Not part of tests/run.sh: it starts system daemons.
set -euo pipefail
cd "$(dirname "$0")/../.."
root="$(pwd)"
venv="$(cd "${CARGO_TARGET_DIR:-target}/py-venv" && pwd)"
[ -x "$venv/bin/ray" ] || { echo "no Ray in $venv: run tests/python/run.sh first" >&2; exit 1; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get install -y -q slurm-wlm munge >/dev/null
fi

work="$(mktemp -d /tmp/mslurm.XXXXXX)"
chmod 755 "$work"  # munged runs as the munge user
host="$(hostname -s)"
conf="$work/slurm.conf"
cat > "$conf" <<CONF
ClusterName=mocap-check
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SlurmctldPort=$((20000 + RANDOM % 10000))
SlurmdPort=$((30000 + RANDOM % 10000))
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
mkdir -p "$work/state" "$work/spool" "$work/in" "$work/out"
export SLURM_CONF="$conf"

cleanup() {
    [ -f "$work/slurmd.pid" ] && kill "$(cat "$work/slurmd.pid")" 2>/dev/null || true
    [ -f "$work/slurmctld.pid" ] && kill "$(cat "$work/slurmctld.pid")" 2>/dev/null || true
    [ -n "${munge_pid:-}" ] && kill "$munge_pid" 2>/dev/null || true
    "$venv/bin/ray" stop --force >/dev/null 2>&1 || true
    rm -rf "$work"
}
trap cleanup EXIT

# munge, with a socket of its own.
mkdir -p "$work/munge"
chown munge:munge "$work/munge" 2>/dev/null || true
runuser -u munge -- /usr/sbin/munged --socket="$work/munge/socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" --seed-file="$work/munge/seed"
munge_pid="$(cat "$work/munge/munged.pid")"
echo "AuthInfo=socket=$work/munge/socket" >> "$conf"

/usr/sbin/slurmctld -f "$conf"
/usr/sbin/slurmd -f "$conf"
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -q idle && break
    sleep 1
done
sinfo

cp samples/*.bvh "$work/in/"
sbatch --wait --nodes=1 --cpus-per-task="$(nproc)" --time=00:10:00 --output="$work/job.out" \
    --export="ALL,VENV=$venv,ARCHIVE=$work/in,OUT=$work/out" docs/scale/mocap-clean.sbatch \
    || { cat "$work/job.out"; exit 1; }
cat "$work/job.out"
"$venv/bin/python" - "$work" <<'PY'
import json, sys
from pathlib import Path
import mocap
work = Path(sys.argv[1])
lines = [json.loads(l) for l in (work / "out" / "manifest.jsonl").read_text().splitlines()]
takes = sorted((work / "in").glob("*.bvh"))
assert len(lines) == len(takes) and all(r["status"] == "done" for r in lines), lines
for take in takes:
    ours = (work / "out" / take.name).read_bytes()
    mocap.clean(mocap.read(take)).write(work / "ref.bvh")
    assert ours == (work / "ref.bvh").read_bytes(), take
print(f"slurm: {len(takes)} takes cleaned by the sbatch recipe, equal to mocap.clean")
PY

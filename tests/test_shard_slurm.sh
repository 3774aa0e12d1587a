#!/usr/bin/env bash
# scripts/bake-slurm on a real one-node Slurm: installs Debian's slurm-wlm
# and munge if missing, starts munged, slurmctld and slurmd from a
# configuration in a temporary folder (own ports, sockets and state),
# submits the shard array and the dependent merge job, compares the merged
# file with the whole bake byte for byte, then stops the daemons it started
# by their pids. Skips (77) when not root or when Slurm cannot be had.
# Usage: test_shard_slurm.sh VDSH_BAKE VDSH_MERGE SCRIPTS_DIR
set -u
bake=$1 merge=$2 scripts=$3
[[ $(id -u) -eq 0 ]] || { echo "SKIP: needs root to start slurmctld and slurmd"; exit 77; }
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  for try in 1 2 3 4 5 6; do # apt's lock may be busy
    apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null 2>&1 && break
    sleep 20
  done
fi
for p in munged slurmctld slurmd sbatch squeue; do
  command -v $p >/dev/null || { echo "SKIP: no $p (slurm-wlm, munge)"; exit 77; }
done
tmp=$(mktemp -d /tmp/vdsh-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for i in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail=0
# Ports of our own (other test runs may start their own Slurm beside us).
base=$((20000 + RANDOM % 20000))
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/munge" "$tmp/run"
chmod 700 "$tmp/munge"
key=$tmp/munge/munge.key
dd if=/dev/urandom of="$key" bs=1 count=1024 status=none
chmod 400 "$key"
node=vdshnode
cat > "$tmp/slurm.conf" <<CONF
ClusterName=vdshtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$base
SlurmdPort=$((base + 1))
SrunPortRange=$((base + 2))-$((base + 40))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/run/slurmctld.pid
SlurmdPidFile=$tmp/run/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
NodeName=$node NodeAddr=127.0.0.1 NodeHostname=$(hostname -s) CPUs=$(nproc) State=UNKNOWN
PartitionName=vdsh Nodes=$node Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF
export SLURM_CONF=$tmp/slurm.conf
munged -F --force --key-file="$key" --socket="$tmp/munge/munge.socket" \
  --pid-file="$tmp/run/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge/seed" &
pids+=($!)
slurmctld -D -c -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N $node -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
dump() { for f in "$tmp"/*.log "$tmp"/*.out; do echo "== $f" >&2; tail -20 "$f" >&2; done; }
up=0
for i in $(seq 150); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then up=1; break; fi
  sleep 0.2
done
[[ $up -eq 1 ]] || { echo "FAIL: the one-node Slurm did not come up" >&2; dump; exit 1; }

tiny=(builtin:room --max-edge 1.5 --rays 32 --cube-size 8)
"$bake" "${tiny[@]}" -q -o "$tmp/whole.vdsh" || { echo "FAIL: whole bake" >&2; exit 1; }
export VDSH_BAKE=$bake VDSH_MERGE=$merge
job=$("$scripts/bake-slurm" 4 "$tmp/scene.vdsh" --cpus-per-task=1 -- "${tiny[@]}" --threads 1) ||
  { echo "FAIL: bake-slurm" >&2; dump; exit 1; }
done_=0
for i in $(seq 600); do
  state=$(scontrol show job "$job" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2)
  case $state in COMPLETED) done_=1; break ;; FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY) break ;; esac
  sleep 0.2
done
if [[ $done_ -ne 1 ]]; then
  echo "FAIL: merge job $job ended as '${state:-unknown}'" >&2; squeue >&2; cat "$tmp"/scene.slurm-*.log >&2; dump; fail=1
fi
cmp "$tmp/scene.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: Slurm merge differs from the whole bake" >&2; fail=1; }
for k in 09-12 13-16 17-20 21-24; do
  cmp "$tmp/scene.sh$k.exr" "$tmp/whole.sh$k.exr" || { echo "FAIL: cubemap $k" >&2; fail=1; }
done
ls "$tmp"/scene.part-* >/dev/null 2>&1 && { echo "FAIL: parts left behind" >&2; fail=1; }
# Each shard's log keeps its progress (the recipe no longer passes -q).
for f in "$tmp"/scene.slurm-*_*.log; do
  grep -q '^vdsh-bake: 100.0%' "$f" || { echo "FAIL: no progress in $f" >&2; cat "$f" >&2; fail=1; }
done
exit $fail

#!/usr/bin/env bash
# scripts/bake-slurm on a real one-node Slurm: installs Debian's slurm-wlm
# and munge if missing, starts munged, slurmctld and slurmd from a
# configuration in a temporary folder (own ports, sockets and state),
# submits the shard array and the dependent merge job, compares the merged
# file with the whole bake byte for byte, then stops the daemons it started
# by their pids. Skips (77) when not root or when Slurm cannot be had.
# Issue 26: the usage text is the header comment only (no code line); bad
# bake arguments are refused before anything is submitted (vdsh-bake's
# message, its exit status, no job queued); a shard that fails after
# submission gets the merge job cancelled, not left pending forever; the
# output's name has a space, a quote and a '%' (the logs beside it); more shards than receivers and
# OUT in a missing folder are refused before anything is submitted;
# --report R.json among the bake's arguments: each shard writes R.part-I.json;
# stale reports (more shards, parts baked again) removed, stale parts refused;
# a relative mesh and VDSH_BAKE work when the job starts elsewhere (--chdir).
# Usage: test_shard_slurm.sh VDSH_BAKE VDSH_MERGE SCRIPTS_DIR
set -u
bake=$1 merge=$2 scripts=$3
. "$(dirname "$0")/lib.sh"
# The usage text (needs no Slurm).
check_recipe_usage bake-slurm
# Without sbatch on PATH: said, exit 1, nothing run (was bash's "sbatch:
# command not found", 127, after vdsh-bake's check).
nos=$(mktemp -d /tmp/vdsh-nosbatch.XXXXXX)
for t in bash dirname; do ln -s "$(command -v $t)" "$nos/$t"; done
msg=$(cd "$nos" && PATH=$nos VDSH_BAKE=$bake VDSH_MERGE=$merge "$nos/bash" "$scripts/bake-slurm" 2 "$nos/x.vdsh" -- builtin:room 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"no sbatch"* ]] || { echo "FAIL: without sbatch: exit $rc: $msg" >&2; fail=1; }
ls "$nos"/x* >/dev/null 2>&1 && { echo "FAIL: without sbatch: files written" >&2; fail=1; }
# vdsh-bake's own output or shard among its arguments: refused, exit 2 (a
# user's -o was silently overridden by the script's).
for a in "-o $nos/y.vdsh" "--output=$nos/y.vdsh" "-o$nos/y.vdsh" "--shard 1/2" "--out $nos/y.vdsh" "--sha 1/2"; do
  msg=$(VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-slurm" 2 "$nos/x.vdsh" -- builtin:room $a 2>&1)
  rc=$?
  [[ $rc -eq 2 && $msg == *"among vdsh-bake's arguments"* ]] || { echo "FAIL: '$a': exit $rc: $msg" >&2; fail=1; }
done
ls "$nos"/[xy]* >/dev/null 2>&1 && { echo "FAIL: -o among the arguments: files written" >&2; fail=1; }
# More shards than receivers: refused by the check, nothing submitted (an
# sbatch of our own records any call). vdsh-bake --export-obj exited 0
# before the shard was checked against the receivers, so every shard
# failed on the cluster.
printf '#!/bin/sh\necho "$@" >> "%s/sbatch.calls"\necho 1\n' "$nos" > "$nos/sbatch"
chmod +x "$nos/sbatch"
msg=$(PATH=$nos:$PATH VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-slurm" 100000 "$nos/x.vdsh" -- builtin:room --max-edge 1.5 2>&1)
rc=$?
[[ $rc -ne 0 && $msg == *"needs shard < count <= the"* && ! -e $nos/sbatch.calls ]] ||
  { echo "FAIL: 100000 shards of a small bake: exit $rc, sbatch called: $(cat "$nos/sbatch.calls" 2>/dev/null | head -c 200): $msg" >&2; fail=1; }
# OUT in a folder that does not exist: refused, nothing submitted (its
# absolute path was made as "/x.vdsh", the parts and the merge queued to
# write in the root folder, exit 0).
msg=$(PATH=$nos:$PATH VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-slurm" 2 "$nos/nodir/x.vdsh" -- builtin:room --max-edge 1.5 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"no folder '$nos/nodir'"* && ! -e $nos/sbatch.calls ]] ||
  { echo "FAIL: OUT in a missing folder: exit $rc, sbatch called: $(cat "$nos/sbatch.calls" 2>/dev/null | head -c 300): $msg" >&2; fail=1; }
# --report among vdsh-bake's arguments: each shard writes its own report,
# named like its part (every shard wrote the same file, the last one won;
# the check before submitting wrote it too). An sbatch of our own keeps the
# shard array's command, run here as shard 1.
mkdir -p "$nos/rep"
printf '#!/bin/sh\nwhile [ $# -gt 0 ]; do [ "$1" = --wrap ] && printf "%%s\\n" "$2" >> "%s/wraps"; shift; done\necho 7\n' \
  "$nos/rep" > "$nos/rep/sbatch"
chmod +x "$nos/rep/sbatch"
# Reports left by an earlier run with more shards (r.part-2.json, -5) and
# one of a part that is not there (r.part-0.json: shard 0 bakes again)
# are removed at submission; r.part-1.json, whose part is there, is kept.
for i in 0 1 2 5; do echo "{\"stale\": $i}" >"$nos/rep/r.part-$i.json"; done
: >"$nos/rep/r.part-1.vdsh"
(cd "$nos/rep" && PATH=$nos/rep:$PATH VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-slurm" 2 r.vdsh -- \
  builtin:room --max-edge 1.5 --rays 32 --cube-size 8 --report r.json >/dev/null 2>&1) ||
  { echo "FAIL: bake-slurm with --report" >&2; fail=1; }
[[ -e $nos/rep/r.json ]] && { echo "FAIL: --report: r.json written before any shard ran" >&2; fail=1; }
for i in 0 2 5; do
  [[ -e $nos/rep/r.part-$i.json ]] && { echo "FAIL: --report: the stale r.part-$i.json kept" >&2; fail=1; }
done
[[ -e $nos/rep/r.part-1.json ]] || { echo "FAIL: --report: r.part-1.json of a part there removed" >&2; fail=1; }
rm -f "$nos/rep/r.part-1.vdsh" "$nos/rep/r.part-1.json"
# A part of an earlier run with more shards: refused, naming it, nothing
# submitted (merged parts 0-1 and left part 2 behind for ever).
: >"$nos/rep/s.part-2.vdsh"
mv "$nos/rep/wraps" "$nos/rep/wraps.keep"
msg=$(cd "$nos/rep" && PATH=$nos/rep:$PATH VDSH_BAKE=$bake VDSH_MERGE=$merge "$scripts/bake-slurm" 2 s.vdsh -- \
  builtin:room --max-edge 1.5 --rays 32 --cube-size 8 2>&1)
rc=$?
[[ $rc -eq 1 && $msg == *"s.part-2.vdsh' is a part of a bake with more than 2 shards"* && ! -e $nos/rep/wraps ]] ||
  { echo "FAIL: a part of a run with more shards: exit $rc, submitted: $(cat "$nos/rep/wraps" 2>/dev/null): $msg" >&2; fail=1; }
mv "$nos/rep/wraps.keep" "$nos/rep/wraps"
(cd / && SLURM_ARRAY_TASK_ID=1 sh -c "$(head -n 1 "$nos/rep/wraps" 2>/dev/null)" >/dev/null 2>&1) ||
  { echo "FAIL: --report: shard 1's command failed: $(head -n 1 "$nos/rep/wraps" 2>/dev/null)" >&2; fail=1; }
[[ -e $nos/rep/r.part-1.vdsh && ! -e $nos/rep/r.json ]] && grep -q '"seconds"' "$nos/rep/r.part-1.json" 2>/dev/null ||
  { echo "FAIL: --report: shard 1 wrote no r.part-1.json (or wrote r.json): $(ls "$nos/rep")" >&2; fail=1; }
# Relative paths (a mesh, VDSH_BAKE) given from the caller's folder: the
# shard's command runs them from there wherever the job starts (sbatch
# --chdir=/ among the options; the job run here from /): they were looked
# up in the job's folder ("no such file").
mkdir -p "$nos/rel/bin"
cp "$(dirname "$0")/data/room_box.obj" "$nos/rel/m.obj"
ln -s "$bake" "$nos/rel/bin/vdsh-bake"
printf '#!/bin/sh\nwhile [ $# -gt 0 ]; do [ "$1" = --wrap ] && printf "%%s\\n" "$2" >> "%s/wraps"; shift; done\necho 8\n' \
  "$nos/rel" > "$nos/rel/sbatch"
chmod +x "$nos/rel/sbatch"
(cd "$nos/rel" && PATH=$nos/rel:$PATH VDSH_BAKE=bin/vdsh-bake VDSH_MERGE=$merge "$scripts/bake-slurm" 2 r.vdsh --chdir=/ -- \
  m.obj --max-edge 1.5 --rays 32 --cube-size 8 >/dev/null 2>&1) ||
  { echo "FAIL: bake-slurm with a relative mesh and VDSH_BAKE" >&2; fail=1; }
(cd / && SLURM_ARRAY_TASK_ID=0 sh -c "$(head -n 1 "$nos/rel/wraps" 2>/dev/null)" >"$nos/rel/out.txt" 2>&1) ||
  { echo "FAIL: relative paths: shard 0's command failed from /: $(head -c 300 "$nos/rel/out.txt")" >&2; fail=1; }
[[ -e $nos/rel/r.part-0.vdsh ]] || { echo "FAIL: relative paths: no r.part-0.vdsh" >&2; fail=1; }
rm -rf "$nos"
skip() { [[ $fail -eq 0 ]] || exit 1; echo "SKIP: $1"; exit 77; }
[[ $(id -u) -eq 0 ]] || skip "needs root to start slurmctld and slurmd"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  for try in 1 2 3 4 5 6; do # apt's lock may be busy
    apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null 2>&1 && break
    sleep 20
  done
fi
for p in munged slurmctld slurmd sbatch squeue; do
  command -v $p >/dev/null || skip "no $p (slurm-wlm, munge)"
done
tmp=$(mktemp -d /tmp/vdsh-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  [[ -n ${SLURM_CONF:-} ]] && scancel --user=root --quiet 2>/dev/null
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for i in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
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
# The state a job ends in (or the last seen after ~120 s).
final_state() {
  local state=
  for i in $(seq 600); do
    state=$(scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2)
    case $state in COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY) break ;; esac
    sleep 0.2
  done
  echo "${state:-unknown}"
}
queued() { squeue -h -o %i 2>/dev/null | wc -l; }
# A name with a space and a quote.
name="$tmp/it's a 100%x scene" # '%x' is a pattern of sbatch --output: the logs went elsewhere
job=$("$scripts/bake-slurm" 4 "$name.vdsh" --cpus-per-task=1 -- "${tiny[@]}" --threads 1) ||
  { echo "FAIL: bake-slurm" >&2; dump; exit 1; }
state=$(final_state "$job")
if [[ $state != COMPLETED ]]; then
  echo "FAIL: merge job $job ended as '$state'" >&2; squeue >&2; cat "$name".slurm-*.log >&2; dump; fail=1
fi
cmp "$name.vdsh" "$tmp/whole.vdsh" || { echo "FAIL: Slurm merge differs from the whole bake" >&2; fail=1; }
for k in 09-12 13-16 17-20 21-24; do
  cmp "$name.sh$k.exr" "$tmp/whole.sh$k.exr" || { echo "FAIL: cubemap $k" >&2; fail=1; }
done
ls "$name".part-* >/dev/null 2>&1 && { echo "FAIL: parts left behind" >&2; fail=1; }
# Each shard's log keeps its progress (the recipe no longer passes -q).
for f in "$name".slurm-*_*.log; do
  grep -q '^vdsh-bake: 100.0%' "$f" || { echo "FAIL: no progress in $f" >&2; cat "$f" >&2; fail=1; }
done

# Bad bake arguments: refused before submitting, with vdsh-bake's message
# and exit status (2: usage); nothing queued.
before=$(queued)
if out=$("$scripts/bake-slurm" 4 "$tmp/bad.vdsh" -- "${tiny[@]}" --rays 0 2>"$tmp/bad.err"); then
  echo "FAIL: bake-slurm submitted a bake with --rays 0 (job $out)" >&2; fail=1
else
  rc=$?
  [[ $rc -eq 2 ]] || { echo "FAIL: bad arguments: exit $rc, not vdsh-bake's 2" >&2; fail=1; }
  grep -q -- "--rays takes" "$tmp/bad.err" || { echo "FAIL: no vdsh-bake message:" >&2; cat "$tmp/bad.err" >&2; fail=1; }
fi
[[ $(queued) -eq $before ]] || { echo "FAIL: jobs queued for bad arguments:" >&2; squeue >&2; fail=1; }
# A missing mesh: the same.
"$scripts/bake-slurm" 4 "$tmp/bad.vdsh" -- "$tmp/no such mesh.obj" 2>"$tmp/bad.err" >/dev/null &&
  { echo "FAIL: bake-slurm submitted a bake of a missing mesh" >&2; fail=1; }
[[ $(queued) -eq $before ]] || { echo "FAIL: jobs queued for a missing mesh:" >&2; squeue >&2; fail=1; }

# A shard that fails after submission (shard 1 of 4, through a wrapper that
# passes the check): the merge job is cancelled, not left pending.
cat > "$tmp/flaky-bake" <<WRAP
#!/bin/sh
for a in "\$@"; do [ "\$a" = 1/4 ] && { echo "flaky-bake: shard 1 fails" >&2; exit 1; }; done
exec "$bake" "\$@"
WRAP
chmod +x "$tmp/flaky-bake"
job=$(VDSH_BAKE=$tmp/flaky-bake "$scripts/bake-slurm" 4 "$tmp/flaky.vdsh" --cpus-per-task=1 -- "${tiny[@]}" --threads 1) ||
  { echo "FAIL: bake-slurm (flaky shard)" >&2; fail=1; }
if [[ -n $job ]]; then
  state=$(final_state "$job")
  [[ $state == CANCELLED ]] ||
    { echo "FAIL: merge job $job after a failed shard: '$state', not CANCELLED" >&2; squeue >&2; fail=1; }
  [[ -e $tmp/flaky.vdsh ]] && { echo "FAIL: merged despite a failed shard" >&2; fail=1; }
  for i in $(seq 600); do [[ $(queued) -eq 0 ]] && break; sleep 0.2; done
  # The shards that succeeded keep their parts, for the resubmission.
  for i in 0 2 3; do
    [[ -e $tmp/flaky.part-$i.vdsh ]] || { echo "FAIL: part $i of the failed bake removed" >&2; fail=1; }
  done
fi
exit $fail

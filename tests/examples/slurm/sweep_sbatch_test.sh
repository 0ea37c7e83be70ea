#!/bin/bash
# examples/slurm/sweep.sbatch and merge.sbatch on a real single-node Slurm (issue #28): this
# test stands up munged, slurmctld and slurmd from Debian's slurm-wlm and munge with a
# generated configuration in a temporary folder (its own munge key and socket, unprivileged
# ports, no cgroups: proctrack/linuxproc, task/none), submits the sweep as a job array with
# `sbatch --wait`, merges the parts with the merge script, and checks the result is byte for
# byte the sweep run in one process. Every daemon it started is stopped however it ends.
#
# Exit 0 pass, 1 fail, 77 not run (ctest SKIP_RETURN_CODE): the packages are not installed, or
# the daemons cannot start on this machine — the reason and the daemons' logs are printed.
#
# usage: sweep_sbatch_test.sh RDYN_BINARY SOURCE_DIR
set -uo pipefail

rdyn=$1
src=$2
skip() { echo "SKIP: $*"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }

for tool in mungekey munged munge slurmctld slurmd sbatch sinfo squeue scancel; do
  command -v "$tool" >/dev/null || skip "$tool is not installed (apt-get install slurm-wlm munge)"
done

work=$(mktemp -d "${TMPDIR:-/tmp}/rdyn_slurm_XXXXXX") || fail "no temporary folder"
chmod 711 "$work"  # the jobs' user reaches the munge socket through it
export SLURM_CONF=$work/slurm.conf
unset SLURM_JOB_ID SLURM_ARRAY_JOB_ID  # when ctest itself runs inside a Slurm job
pids=()

logs() {
  for f in "$work"/munged.log "$work"/slurmctld.log "$work"/slurmd.log; do
    [ -s "$f" ] && { echo "--- $f (last 15 lines)"; tail -n 15 "$f"; }
  done
}

# Stops what this test started: the jobs first (bounded wait), then slurmd, slurmctld and
# munged by the process ids it recorded, then removes the folder.
cleanup() {
  local status=$?
  trap - EXIT INT TERM
  if [ ${#pids[@]} -gt 0 ]; then
    scancel --full --quiet --user="$(id -un)" 2>/dev/null
    for _ in $(seq 50); do
      [ -z "$(squeue -h 2>/dev/null)" ] && break
      sleep 0.2
    done
    for ((k = ${#pids[@]} - 1; k >= 0; k--)); do kill "${pids[k]}" 2>/dev/null; done
    for pid in "${pids[@]}"; do
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null
    done
  fi
  if [ -f "$work/munged.pid" ]; then
    munged_pid=$(cat "$work/munged.pid")
    kill "$munged_pid" 2>/dev/null
    for _ in $(seq 50); do kill -0 "$munged_pid" 2>/dev/null || break; sleep 0.1; done
  fi
  [ $status -ne 0 ] && [ $status -ne 77 ] && logs
  rm -rf "$work"
  exit $status
}
trap cleanup EXIT
trap 'exit 1' INT TERM

# A free TCP port on 127.0.0.1 from 20000–29999 (nothing answers a connection to it).
free_port() {
  local port
  for _ in $(seq 50); do
    port=$((20000 + RANDOM % 10000))
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null && [ "$port" != "${1:-}" ]; then
      echo "$port"
      return 0
    fi
  done
  return 1
}
ctld_port=$(free_port) || skip "no free TCP port in 20000-29999"
d_port=$(free_port "$ctld_port") || skip "no free TCP port in 20000-29999"

# munge: a key of our own, a socket in the folder.
mungekey -c -k "$work/munge.key" >/dev/null 2>&1 || skip "mungekey cannot create a key"
chmod 400 "$work/munge.key"
munged -f --socket="$work/munge.sock" --key-file="$work/munge.key" --log-file="$work/munged.log" \
  --pid-file="$work/munged.pid" --seed-file="$work/munged.seed" ||
  { logs; skip "munged does not start (log above)"; }
munge -S "$work/munge.sock" -n >/dev/null 2>&1 || { logs; skip "munged started but does not answer on its socket"; }

host=$(uname -n)
host=${host%%.*}
user=$(id -un)
cpus=$(nproc)
mkdir -p "$work/ctld" "$work/d" "$work/parts" "$work/logs"
cat >"$SLURM_CONF" <<CONF
ClusterName=rdyntest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge.sock
StateSaveLocation=$work/ctld
SlurmdSpoolDir=$work/d
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=rdyntest Nodes=$host Default=YES MaxTime=30 State=UP
CONF

# The daemons in the foreground of background processes, so their ids are ours to stop.
slurmctld -D -i >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D >"$work/slurmd.out" 2>&1 &
pids+=($!)
ready=
for _ in $(seq 150); do  # up to 30 s for the node to register
  for pid in "${pids[@]}"; do
    kill -0 "$pid" 2>/dev/null || { cat "$work"/slurm*.out; logs; skip "a Slurm daemon exited at start (output above)"; }
  done
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null)
  [ "$state" = idle ] && { ready=1; break; }
  sleep 0.2
done
[ -n "$ready" ] || { logs; skip "the node did not become idle in 30 s (state '${state:-none}')"; }
echo "Slurm up on $host: slurmctld port $ctld_port, slurmd port $d_port, $cpus CPUs"

# The sweep: three heights (each a new mechanism) by two powers, in one process...
axes=(bicycle --vary bicycle_leg.subject.height_m=1.6:1.9:3 --vary bicycle_leg.resistance.power_W=100:150:2)
"$rdyn" sweep "${axes[@]}" --threads 2 --out "$work/whole.csv" || fail "the one-process sweep failed"

# ...and as a job array of four tasks (one of them runs cases 6-6: none), then the merge job.
# Every wait is bounded (30 s for the node, then 300 + 120 + 120 s of jobs, each job --time=5
# min), so the script ends, and its trap stops the daemons, before ctest's 900 s timeout would
# kill it without its trap.
export RDYN=$rdyn
cd "$work" || fail "cd $work"
timeout 300 sbatch --wait --array=0-3 --cpus-per-task=1 --time=5 --output="$work/logs/sweep-%A_%a.log" \
  "$src/examples/slurm/sweep.sbatch" "$work/parts" "${axes[@]}" ||
  { cat "$work"/logs/*.log; fail "the sweep array failed"; }
timeout 120 sbatch --wait --time=5 --output="$work/logs/merge.log" "$src/examples/slurm/merge.sbatch" "$work/parts" ||
  { cat "$work"/logs/*.log; fail "the merge job failed"; }
cat "$work"/logs/*.log
cmp "$work/whole.csv" "$work/parts/sweep.csv" ||
  { diff "$work/whole.csv" "$work/parts/sweep.csv"; fail "the merged array differs from the one-process sweep"; }

# Resubmitted, every task finds its part complete and skips it.
timeout 120 sbatch --wait --array=0-3 --cpus-per-task=1 --time=5 --output="$work/logs/again-%A_%a.log" \
  "$src/examples/slurm/sweep.sbatch" "$work/parts" "${axes[@]}" || fail "the resubmitted array failed"
skipped=$(cat "$work"/logs/again-*.log | grep -c "already complete: skipped")
[ "$skipped" = 4 ] || { cat "$work"/logs/again-*.log; fail "$skipped of 4 resubmitted tasks skipped their part"; }
echo "PASS: the merged Slurm array equals the one-process sweep ($(($(wc -l <"$work/whole.csv") - 2)) cases)"

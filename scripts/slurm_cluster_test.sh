#!/usr/bin/env bash
# End-to-end test of cluster/slurm_build.sbatch on a real, one-node Slurm cluster on
# localhost (called by tests/tests/slurm_cluster.rs; runs alone as well):
#
#   bash scripts/slurm_cluster_test.sh [BIN_DIR]      # BIN_DIR holds rh-pipeline [target/release]
#
# 1. starts munged (a generated key), slurmctld and slurmd from a generated slurm.conf;
#    every state, spool, log, pid and socket file lives in one temp dir, the ports are free
#    ones on 127.0.0.1;
# 2. submits the project's own cluster/slurm_build.sbatch, unchanged, as a 4-task job array
#    of a label-only build (RH_N scenes), cancels task 0 (`scancel`) once it has finished
#    some but not all of its scene groups, lets the other tasks finish, resubmits task 0
#    and checks that it says it resumed;
# 3. runs `rh-pipeline merge` and checks the merged dataset equals a single
#    `rh-pipeline build` of the same scenes byte for byte (every file).
#
# Jobs, daemons and the temp dir are removed at the end, also on failure or interrupt.
# Needs root (SlurmUser=root, as in a CI container) and Debian's slurm-wlm and munge,
# which scripts/setup.sh installs. Where they are missing or a daemon cannot start, it
# fails (exit 1) saying why and what to install; it never skips.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
bin_dir="$(cd "${1:-$repo/target/release}" && pwd)"
N="${RH_SLURM_TEST_N:-1200}"         # scenes; each of the 4 tasks builds a quarter
SEED="${RH_SLURM_TEST_SEED:-7}"
WAIT_S="${RH_SLURM_TEST_WAIT_S:-240}" # bound on every wait

fail() {
  echo "slurm e2e: FAILED: $*" >&2
  exit 1
}
cannot_run() {
  echo "slurm e2e: cannot run a Slurm cluster on this machine: $*" >&2
  echo "slurm e2e: install Debian's slurm-wlm and munge (bash scripts/setup.sh does: apt-get install slurm-wlm munge) and run as root" >&2
  exit 1
}

for cmd in munged mungekey slurmctld slurmd sbatch squeue scancel scontrol sinfo python3; do
  command -v "$cmd" >/dev/null || cannot_run "'$cmd' is not installed (PATH=$PATH)"
done
[ "$(id -u)" -eq 0 ] || cannot_run "it must run as root (slurmd starts jobs as their submitting user and the generated slurm.conf has SlurmUser=root); running as $(id -un)"
[ -x "$bin_dir/rh-pipeline" ] || fail "$bin_dir/rh-pipeline is not built (cargo build --release --bins)"

T="$(mktemp -d /tmp/rh-slurm.XXXXXX)"
chmod 755 "$T"
export SLURM_CONF="$T/slurm.conf"
pids=()
cleanup() {
  local rc=$?
  set +e
  if [ -f "$SLURM_CONF" ] && [ -n "${ctld_pid:-}" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    # Jobs first (their processes belong to slurmd's step daemons), bounded.
    local ids
    ids="$(squeue -h -o %A 2>/dev/null | sort -u)"
    if [ -n "$ids" ]; then
      # shellcheck disable=SC2086
      scancel $ids 2>/dev/null
      for _ in $(seq 1 100); do
        [ -z "$(squeue -h 2>/dev/null)" ] && break
        sleep 0.2
      done
    fi
  fi
  if [ "$rc" -ne 0 ]; then
    for f in "$T"/log/*.log "$T"/work/logs/*.out; do
      [ -f "$f" ] && { echo "---- $f (last lines)" >&2; tail -n 15 "$f" >&2; }
    done
  fi
  # Daemons by the PIDs this script started: TERM, then KILL after 10 s.
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
    kill -9 "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  rm -rf "$T"
  echo "slurm e2e: daemons stopped (pids ${pids[*]:-none}), removed $T"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
echo "slurm e2e: temp dir $T"

# Waits until `$@` succeeds, at most WAIT_S seconds; fails with $what.
wait_for() {
  local what="$1"
  shift
  local deadline=$((SECONDS + WAIT_S))
  until "$@"; do
    [ $SECONDS -lt $deadline ] || fail "timed out after ${WAIT_S}s waiting for $what"
    sleep 0.2
  done
}
alive() { kill -0 "$1" 2>/dev/null || cannot_run "$2 exited at start-up; its log: $(tail -n 5 "$3" 2>/dev/null)"; }

mkdir -p "$T/state" "$T/spool" "$T/log" "$T/work/logs"

# --- munge, with a key of its own ---------------------------------------------------------
mungekey --create --keyfile="$T/munge.key" >/dev/null
munged --foreground --force --key-file="$T/munge.key" --socket="$T/munge.sock" \
  --pid-file="$T/munged.pid" --log-file="$T/log/munged.log" --seed-file="$T/munged.seed" \
  >/dev/null 2>&1 &
pids+=($!)
munge_pid=$!
wait_for "munged's socket" test -S "$T/munge.sock"
alive "$munge_pid" munged "$T/log/munged.log"

# --- slurm.conf: free ports on 127.0.0.1, everything under $T ------------------------------
read -r ctld_port slurmd_port < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])')
cat >"$SLURM_CONF" <<EOF
ClusterName=rhtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge.sock
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
KillWait=5
MinJobAge=600
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=2048 State=UNKNOWN
PartitionName=rh Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" >"$T/log/slurmctld.stdout" 2>&1 &
pids+=($!)
ctld_pid=$!
slurmd -D -N localhost -f "$SLURM_CONF" >"$T/log/slurmd.stdout" 2>&1 &
pids+=($!)
slurmd_pid=$!
node_idle() {
  alive "$ctld_pid" slurmctld "$T/log/slurmctld.log"
  alive "$slurmd_pid" slurmd "$T/log/slurmd.log"
  [ "$(sinfo -h -N -o %T 2>/dev/null)" = idle ]
}
wait_for "the node to come up idle (sinfo)" node_idle
echo "slurm e2e: cluster up: slurmctld :$ctld_port, slurmd :$slurmd_port, $(nproc) CPUs"

# --- the job array, as the project documents it --------------------------------------------
cd "$T/work"
export RH_N="$N" RH_SEED="$SEED" RH_SHARDS=4 RH_SHARD_DIR="$T/work/shards"
export RH_PIPELINE="$bin_dir/rh-pipeline" RH_BUILD_ARGS="--no-render"
# Only the resources are scaled down to this machine (the file asks for 8 CPUs and 8 GB).
submit() { sbatch --parsable --array="$1" --cpus-per-task=1 --mem=256M --time=10:00 "$repo/cluster/slurm_build.sbatch"; }
job="$(submit 0-3)"
echo "slurm e2e: submitted array job $job (tasks 0-3, $N scenes, seed $SEED)"

# Task 0 is cancelled once it has finished 3 of its scene groups.
records0() { [ "$(find "$RH_SHARD_DIR/0/.rh-build/groups" -name '*.parquet' 2>/dev/null | wc -l)" -ge 3 ]; }
task0_started_or_over() {
  records0 || [ -f "$RH_SHARD_DIR/0/README.md" ] || [ -z "$(squeue -h -j "${job}_0" 2>/dev/null)" ]
}
wait_for "task 0 to finish 3 scene groups" task0_started_or_over
records0 || fail "task ${job}_0 ended before writing 3 scene groups; log: $(cat "logs/build-${job}_0.out" 2>/dev/null)"
scancel "${job}_0"
task_gone() { [ -z "$(squeue -h -j "$1" 2>/dev/null)" ]; }
wait_for "task ${job}_0 to leave the queue after scancel" task_gone "${job}_0"
done_groups="$(find "$RH_SHARD_DIR/0/.rh-build/groups" -name '*.parquet' | wc -l)"
[ -d "$RH_SHARD_DIR/0/.rh-build" ] && [ ! -f "$RH_SHARD_DIR/0/README.md" ] \
  || fail "task 0 finished before scancel reached it; raise RH_SLURM_TEST_N (now $N) so it runs longer"
echo "slurm e2e: cancelled task ${job}_0 mid-way ($done_groups of $((N / 16)) scene groups done)"

wait_for "array job $job to finish" task_gone "$job"
state() { scontrol -o show job "$1" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p'; }
[ "$(state "${job}_0")" = CANCELLED ] || fail "task ${job}_0 is $(state "${job}_0"), expected CANCELLED"
for i in 1 2 3; do
  [ "$(state "${job}_$i")" = COMPLETED ] || fail "task ${job}_$i is $(state "${job}_$i"), expected COMPLETED; log: $(tail -n 5 "logs/build-${job}_$i.out")"
done

# --- resubmit the cancelled task: it resumes -----------------------------------------------
job2="$(submit 0)"
wait_for "resubmitted task ${job2}_0 to finish" task_gone "$job2"
[ "$(state "${job2}_0")" = COMPLETED ] || fail "resubmitted task ${job2}_0 is $(state "${job2}_0"); log: $(tail -n 5 "logs/build-${job2}_0.out")"
grep -q "^resumed $done_groups groups" "logs/build-${job2}_0.out" \
  || fail "resubmitted task ${job2}_0 did not say it resumed $done_groups groups; its log: $(cat "logs/build-${job2}_0.out")"
echo "slurm e2e: resubmitted task 0 as ${job2}_0: $(grep '^resumed' "logs/build-${job2}_0.out")"

# --- merge and compare with a single build -------------------------------------------------
"$RH_PIPELINE" merge "$T/merged" "$RH_SHARD_DIR"/0 "$RH_SHARD_DIR"/1 "$RH_SHARD_DIR"/2 "$RH_SHARD_DIR"/3 --json >"$T/merge.json"
"$RH_PIPELINE" build --n "$N" --seed "$SEED" --no-render --quiet --out "$T/single" >/dev/null
diff -r "$T/single" "$T/merged" >"$T/diff.txt" 2>&1 \
  || fail "the merged dataset differs from a single build: $(head -n 20 "$T/diff.txt")"
files="$(find "$T/single" -type f | wc -l)"
[ "$files" -gt "$N" ] || fail "the single build has only $files files for $N scenes"
echo "slurm e2e: ok: merge of 4 Slurm shards (one cancelled and resumed) equals a single build, $files files byte for byte"

#!/usr/bin/env bash
# make test-slurm: `mpmlab slurm` against a real one-node Slurm cluster.
#
#   scripts/test-slurm.sh MPMLAB_BIN PYTHON
#
# Installs Debian's slurmctld, slurmd, slurm-client and munge when missing, then starts
# munged, slurmctld and slurmd in the foreground as children of this script, with every file
# (configuration, munge key and socket, state, spool, logs) in a temporary directory and
# ports picked free on 127.0.0.1: no systemd, nothing under /etc touched, no accounting
# (proctrack/linuxproc, task/none). Then:
#   1. all of tests/matrices/*.yaml on one machine (`mpmlab run`), and the same files as an
#      array of 3 shards (`mpmlab slurm --shards 3 --wait`) into another directory; after
#      `mpmlab report` on both, scripts/compare_results.py checks every dataset and attribute
#      of every run file bit for bit (except the wall_seconds attribute) and the reports
#      byte for byte (summary.csv except its wall_seconds column);
#   2. a shard rerun by hand (`mpmlab run --shard 2/3`) writes nothing;
#   3. the failure path: one run file made unwritable, so the shard that owns it fails, must
#      make `mpmlab slurm --wait` exit non-zero, and `mpmlab report` must list the run as
#      missing.
# The trap cancels what is left in the queue and stops exactly the daemons started here, by
# their PIDs, whether the test passes or fails; the temporary directory is kept on failure.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
source scripts/lib.sh

[ $# -eq 2 ] || die "usage: scripts/test-slurm.sh MPMLAB_BIN PYTHON"
BIN=$(realpath "$1")
PY=$2
[ -x "$BIN" ] || die "$BIN: not an executable (make build first)"
"$PY" -c 'import h5py' || die "$PY has no h5py (make deps-python first)"
SHARDS=3
MATRICES=(tests/matrices/*.yaml)
started=$SECONDS

missing=()
for cmd in munged mungekey slurmctld slurmd sbatch squeue scancel; do
  command -v "$cmd" >/dev/null 2>&1 || missing+=("$cmd")
done
if [ ${#missing[@]} -gt 0 ]; then
  apt_install slurmctld slurmd slurm-client munge
fi
echo "slurm: $(slurmctld -V), $(munged -V 2>&1 | head -n 1)"

work=$(mktemp -d "${TMPDIR:-/tmp}/mpmlab-slurm.XXXXXX")
# munged wants its socket directory, and the directories above it, searchable by everyone.
chmod 755 "$work"
mkdir -p "$work"/{munge,state,spool,log}
chmod 755 "$work/munge"
export SLURM_CONF="$work/slurm.conf"

names=()
pids=()

# stop NAME PID: TERM, then KILL after 15 s; only this PID, a child of this script.
stop() {
  local name=$1 pid=$2 i
  kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < 150; i++)); do
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  if kill -0 "$pid" 2>/dev/null; then
    echo "  $name (pid $pid) did not stop on TERM; killing it"
    kill -KILL "$pid" 2>/dev/null || true
  fi
  wait "$pid" 2>/dev/null || true
  echo "  stopped $name (pid $pid)"
}

cleanup() {
  local rc=$? i jobs
  set +e
  trap - EXIT INT TERM
  if [ ${#pids[@]} -ge 2 ]; then
    jobs=$(squeue -h -o %A 2>/dev/null | sort -u)
    if [ -n "$jobs" ]; then
      echo "  cancelling jobs left in the queue: $jobs"
      # shellcheck disable=SC2086
      scancel $jobs
      for ((i = 0; i < 100; i++)); do
        [ -z "$(squeue -h 2>/dev/null)" ] && break
        sleep 0.2
      done
    fi
  fi
  step "stopping the daemons started by this test"
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    stop "${names[i]}" "${pids[i]}"
  done
  if [ $rc -ne 0 ]; then
    for log in "$work"/log/*.log "$work"/log/*.out "$work"/*/slurm/*.out; do
      [ -f "$log" ] || continue
      echo "---- $log (last lines)"
      tail -n 15 "$log"
    done
    echo "test-slurm FAILED after $((SECONDS - started)) s; files kept in $work"
  else
    rm -rf "$work"
    echo "test-slurm passed in $((SECONDS - started)) s"
  fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# start NAME COMMAND...: in the background, recorded for cleanup.
start() {
  local name=$1
  shift
  "$@" >"$work/log/$name.out" 2>&1 &
  names+=("$name")
  pids+=($!)
  echo "  started $name (pid $!)"
}

# await WHAT SECONDS COMMAND...: until COMMAND succeeds; fails if a daemon has died.
await() {
  local what=$1 limit=$2 i j
  shift 2
  for ((i = 0; i < limit * 5; i++)); do
    "$@" >/dev/null 2>&1 && return 0
    for ((j = 0; j < ${#pids[@]}; j++)); do
      kill -0 "${pids[j]}" 2>/dev/null || die "${names[j]} exited while waiting for $what"
    done
    sleep 0.2
  done
  die "no $what after $limit s"
}

node_idle() { [ "$(sinfo -h -n "$host" -o %T)" = idle ]; }

host=$(hostname -s)
read -r ctld_port slurmd_port < <("$PY" -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks:
    s.bind(("127.0.0.1", 0))
print(*(s.getsockname()[1] for s in socks))')

step "one-node cluster in $work (node $host, $(nproc) CPUs, ports $ctld_port and $slurmd_port)"
mungekey --create --keyfile="$work/munge/munge.key"
start munged munged --foreground --key-file="$work/munge/munge.key" \
  --socket="$work/munge/munge.socket" --pid-file="$work/munge/munged.pid" \
  --log-file="$work/log/munged.log" --seed-file="$work/munge/munged.seed"
await munged 10 munge -n -S "$work/munge/munge.socket"

cat >"$SLURM_CONF" <<EOF
ClusterName=mpmlab-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
# sbatch --wait polls with growing pauses while they stay under MinJobAge / 2: 2 s, then 8 s.
MinJobAge=10
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
start slurmctld slurmctld -D -f "$SLURM_CONF"
await slurmctld 30 scontrol ping
start slurmd slurmd -D -f "$SLURM_CONF" -N "$host"
await "idle node $host" 60 node_idle
sinfo

single=$work/single
sharded=$work/sharded
step "single machine: mpmlab run --out $single (${#MATRICES[@]} files)"
"$BIN" run --out "$single" "${MATRICES[@]}"

step "cluster: mpmlab slurm --shards $SHARDS --wait --out $sharded"
t0=$SECONDS
job=$(timeout 300 "$BIN" slurm "${MATRICES[@]}" --out "$sharded" --shards "$SHARDS" \
  --partition debug --time 00:10:00 --cpus-per-task 1 --wait)
echo "array job $job ended after $((SECONDS - t0)) s"
for ((k = 1; k <= SHARDS; k++)); do
  log=$(echo "$sharded"/slurm/*-"${job}_$k".out)
  [ -f "$log" ] || die "no log of task $k: $log"
  grep -q "^shard $k/$SHARDS: " "$log" || die "task $k did not run shard $k/$SHARDS (see $log)"
  grep "^shard $k/$SHARDS: " "$log"
done

for f in "${MATRICES[@]}"; do
  name=$(basename "$f" .yaml)
  "$BIN" report "$single/$name" 2>/dev/null
  "$BIN" report "$sharded/$name" 2>/dev/null
done
step "compare the merged shards with the single-machine run"
"$PY" scripts/compare_results.py "$single" "$sharded"

step "a shard run again skips its complete runs"
copies=()
for f in "${MATRICES[@]}"; do copies+=("$sharded/$(basename "$f" .yaml)/experiment.yaml"); done
rerun=$("$BIN" run --shard "2/$SHARDS" --out "$sharded" "${copies[@]}" 2>&1)
if grep -v ' 0 runs written' <<<"$rerun" | grep -q 'runs written'; then
  echo "$rerun"
  die "rerunning shard 2/$SHARDS wrote runs again"
fi

step "failure path: a shard that fails makes mpmlab slurm --wait exit non-zero"
failing=$work/failing
file=tests/matrices/ci_mms1d.yaml
blocked=$("$BIN" expand "$file" | awk 'NR == 1 { print $1 }')
# A directory where the run file goes: renaming the finished run onto it fails.
mkdir -p "$failing/ci_mms1d/runs/$blocked.h5/blocker"
if timeout 300 "$BIN" slurm "$file" --out "$failing" --shards "$SHARDS" --force --wait \
  >"$work/failing.out" 2>&1; then
  cat "$work/failing.out"
  die "mpmlab slurm --wait exited 0 although the shard with $blocked failed"
fi
cat "$work/failing.out"
grep -q 'a task failed' "$work/failing.out" || die "no 'a task failed' in the output above"
grep -Eq "^shard [0-9]+/$SHARDS: FAILED" "$work/failing.out" || die "the failed shard is not named above"
rm -r "$failing/ci_mms1d/runs/$blocked.h5"
"$BIN" report "$failing/ci_mms1d" 2>"$work/report.err" || true
cat "$work/report.err"
grep -qx "missing run: $blocked" "$work/report.err" || die "report does not list $blocked as missing"
[ "$(grep -c '^missing run: ' "$work/report.err")" -eq 1 ] ||
  die "report lists other runs as missing than $blocked"

#!/usr/bin/env bash
# The Slurm example of docs/sweeps.md, scripts/slurm/needle_sweep.sbatch, run as written on a single-node Slurm
# started here on localhost (munged, slurmctld and slurmd from Debian's munge and slurm-wlm, their files in a
# temporary folder), against the same sweep on worker processes: the same deflections bit for bit.
# Skipped (exit 77) where the daemons are missing or cannot start (not root, no slurm-wlm).
#   tests/sweeps/slurm_array_test.sh NEEDLE_BINARY SOURCE_DIR
set -uo pipefail
needle="$1"
source_dir="$2"
skip() { echo "slurm_array_test: skipped: $*"; exit 77; }
for tool in munged slurmctld slurmd sbatch sinfo scontrol; do command -v "$tool" > /dev/null || skip "no $tool (apt-get install slurm-wlm munge)"; done
[ "$(id -u)" = 0 ] || skip "slurmd must run as root to start jobs"
[ "$(dirname "$(readlink -f "$needle")")" = "$(readlink -f "$source_dir/build/apps")" ] ||
  skip "the example takes needle from the checkout's build/apps; this one is $needle"

t="$(mktemp -d /tmp/needle_slurm.XXXXXX)"
chmod 700 "$t"
cleanup() {
  [ -f "$t/slurmd.pid" ] && kill "$(cat "$t/slurmd.pid")" 2> /dev/null
  [ -f "$t/slurmctld.pid" ] && kill "$(cat "$t/slurmctld.pid")" 2> /dev/null
  [ -f "$t/munged.pid" ] && kill "$(cat "$t/munged.pid")" 2> /dev/null
  sleep 1
  rm -rf "$t"
}
trap cleanup EXIT
fail() {
  echo "slurm_array_test: FAILED: $*" >&2
  for log in "$t"/*.log "$t"/*.out; do [ -f "$log" ] && { echo "--- $log" >&2; tail -n 20 "$log" >&2; }; done
  exit 1
}

# munge: its own key, socket and files.
mkdir -p "$t/munge" && chmod 700 "$t/munge"
dd if=/dev/urandom of="$t/munge/munge.key" bs=1024 count=1 status=none && chmod 400 "$t/munge/munge.key"
munged --force --key-file="$t/munge/munge.key" --socket="$t/munge/munge.socket" --pid-file="$t/munged.pid" \
  --log-file="$t/munged.log" --seed-file="$t/munge/munge.seed" || skip "munged does not start (see $t/munged.log)"

# Two free ports for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c 'import socket
ports = []
for _ in range(2):
    s = socket.socket(); s.bind(("127.0.0.1", 0)); ports.append(s.getsockname()[1]); s.close()
print(*ports)')
host="$(hostname -s)"
cpus="$(nproc)"
mkdir -p "$t/state" "$t/spool"
cat > "$t/slurm.conf" << EOF
ClusterName=needletest
SlurmctldHost=$host
SlurmUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
AuthInfo=socket=$t/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$t/state
SlurmdSpoolDir=$t/spool
SlurmctldPidFile=$t/slurmctld.pid
SlurmdPidFile=$t/slurmd.pid
SlurmctldLogFile=$t/slurmctld.log
SlurmdLogFile=$t/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$t/slurm.conf"
slurmctld -f "$SLURM_CONF" || skip "slurmctld does not start"
slurmd -f "$SLURM_CONF" || skip "slurmd does not start"
for _ in $(seq 60); do
  state="$(sinfo -h -o %T 2> /dev/null | head -1)"
  [ "$state" = idle ] && break
  sleep 0.5
done
[ "$state" = idle ] || skip "the node did not come up (state '$state'; $t/slurmd.log)"

# The tiny sweep of tests/sweeps/test_sweeps.cpp: two d_a (and one that cannot be ground) times two frictions.
cp "$source_dir/tests/data/sweeps/tiny/scene.json" "$source_dir/tests/data/sweeps/tiny/sweep.json" "$t/" || fail "no tests/data/sweeps/tiny"
n="$("$needle" sweep "$t/sweep.json" --count)" || fail "needle sweep --count"
[ "$n" = 6 ] || fail "the tiny sweep has $n cases, not 6"

# The docs' commands, from the checkout, the sweep and its folder given as the script's header says; the tasks' output
# into the temporary folder instead of the checkout; one CPU a task (this node may have two).
cd "$source_dir" || fail "no $source_dir"
export SWEEP="$t/sweep.json" OUT="$t/sweeps/array"
job="$(sbatch --parsable --array=0-$((n - 1)) --cpus-per-task=1 --output="$t/task-%A_%a.out" scripts/slurm/needle_sweep.sbatch)" ||
  fail "sbatch of the array"
timeout 600 sbatch --wait --dependency=afterany:"$job" --output="$t/collect-%j.out" scripts/slurm/needle_sweep.sbatch > /dev/null ||
  fail "the collecting job (or a task) failed"
[ -f "$OUT/sweep.json" ] || fail "no table in $OUT"
for k in $(seq 0 $((n - 1))); do
  [ -f "$t/task-${job}_$k.out" ] || fail "task $k wrote no output file"
done

"$needle" sweep "$SWEEP" --out "$t/sweeps/jobs" --jobs 2 --quiet > "$t/jobs.out" 2>&1 || fail "needle sweep --jobs 2"
python3 - "$OUT/sweep.json" "$t/sweeps/jobs/sweep.json" << 'EOF' || fail "the array's table differs from --jobs'"
import json, sys
def deflections(path):
    table = json.load(open(path))
    return {c["name"]: c["deflection_mm"] for c in table["cases"] if c["status"] == "finished"}, table["counts"]
(array, counts_a), (jobs, counts_j) = deflections(sys.argv[1]), deflections(sys.argv[2])
print("array:", counts_a, "jobs:", counts_j)
assert counts_a["finished"] == 4 and counts_a["infeasible"] == 2, counts_a
assert array == jobs, (array, jobs)  # bit for bit: the same doubles
print("slurm_array_test: the array's 4 deflections equal the workers' bit for bit:", array)
EOF
echo "slurm_array_test: passed"

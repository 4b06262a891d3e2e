#!/usr/bin/env bash
# soak sweep --slurm through a real single-node Slurm: munged, slurmctld and slurmd (Debian's munge,
# slurmctld, slurmd, slurm-client) configured for this host in a temporary folder, a 4-variant sweep
# submitted as a job array, waited for, collected, and everything stopped afterwards.
#
#   tests/slurm/slurm_sweep_test.sh SOAK_BINARY
#
# Exit 0 when the four variants ran through Slurm to a summary that says so, 1 when something that
# started failed, 77 (ctest's "skipped") with the reason when Slurm cannot start here: not root, a
# package missing, or a daemon that does not come up (its log's end is printed).
set -uo pipefail
soak="$(realpath "${1:?usage: $0 SOAK_BINARY}")"

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAILED: $*"; exit 1; }

[ "$(id -u)" -eq 0 ] || skip "slurmd and slurmctld run as root here, and this is uid $(id -u)"
for tool in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$tool" > /dev/null || skip "$tool is not installed (Debian's munge, slurmctld, slurmd, slurm-client: scripts/setup.sh)"
done

work="$(mktemp -d /tmp/soak_slurm_test.XXXXXX)"
host="$(hostname -s)"
export SLURM_CONF="$work/slurm.conf"
stop_all() {
  scancel --quiet --full --user=root 2> /dev/null
  for pid in "$work"/slurmd.pid "$work"/slurmctld.pid "$work"/munge/munged.pid; do
    [ -f "$pid" ] && kill "$(cat "$pid")" 2> /dev/null
  done
  sleep 1
  rm -rf "$work"
}
trap stop_all EXIT

# munge with its own key and socket, so the host's munge (if any) is left alone
mkdir -p "$work/munge" "$work/spool" "$work/state"
head -c 1024 /dev/urandom > "$work/munge/munge.key"
chmod 600 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/socket" --pid-file="$work/munge/munged.pid" \
  --log-file="$work/munge/munged.log" --seed-file="$work/munge/seed" ||
  skip "munged did not start: $(tail -n 3 "$work/munge/munged.log" 2> /dev/null)"

# ports away from the defaults (6817/6818), so a cluster of the host's own is not disturbed
cat > "$SLURM_CONF" << EOF
ClusterName=soaktest
SlurmctldHost=$host
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=soaktest Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -c || skip "slurmctld did not start: $(tail -n 5 "$work/slurmctld.log" 2> /dev/null)"
slurmd || skip "slurmd did not start: $(tail -n 5 "$work/slurmd.log" 2> /dev/null)"
for _ in $(seq 60); do
  sinfo --noheader --states=idle 2> /dev/null | grep -q soaktest && break
  sleep 0.5
done
sinfo --noheader --states=idle 2> /dev/null | grep -q soaktest ||
  skip "the node did not become idle within 30 s: $(sinfo 2>&1 | tail -n 2); $(tail -n 5 "$work/slurmd.log")"

# the sweep: a small pinned cloth under a small block, 2 x 2 variants of 10 frames (0.2 s: the block lands)
cat > "$work/tiny.json" << 'EOF'
{"name": "tiny",
 "solver": {"dt": 0.01, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
 "output": {"frames": 10, "stepsPerFrame": 2},
 "cloth": [{"name": "sheet", "mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.2, 0.2],
            "resolution": [10, 10], "axisU": [1, 0, 0], "axisV": [0, 0, 1]}, "pin": {"corners": [0, 1, 2, 3]}}],
 "emitters": [{"name": "cube", "type": "block", "min": [-0.04, 0.54, -0.04], "max": [0.04, 0.62, 0.04]}],
 "wetting": {}}
EOF
cat > "$work/sweep.json" << 'EOF'
{"scene": "tiny.json", "axes": {"solver.substeps": [1, 2], "wetting.absorption.rate": [0.05, 0.2]}}
EOF
out="$work/out"
"$soak" sweep "$work/sweep.json" -o "$out" --slurm --time 5 --cpus-per-task 1 | tee "$work/submit.txt" ||
  fail "soak sweep --slurm failed"
job="$(sed -n 's/.*submitted job \([0-9]*\),.*/\1/p' "$work/submit.txt")"
[ -n "$job" ] || fail "no job id in: $(cat "$work/submit.txt")"
for _ in $(seq 240); do
  [ -z "$(squeue --noheader --jobs="$job" 2> /dev/null)" ] && break
  sleep 0.5
done
# a job that never left the queue says the node cannot run jobs here (not soak's fault); one that
# started and did not end is a failure
if [ -n "$(squeue --noheader --jobs="$job" --states=PENDING 2> /dev/null)" ] && ! ls "$out"/slurm-"$job"_*.out > /dev/null 2>&1; then
  skip "job $job never started within 120 s: $(squeue --jobs="$job" 2>&1 | tail -n 2); $(tail -n 5 "$work/slurmd.log")"
fi
[ -z "$(squeue --noheader --jobs="$job" 2> /dev/null)" ] || fail "job $job still running after 120 s: $(squeue)"
ls "$out"/slurm-"$job"_*.out > /dev/null 2>&1 || fail "the array tasks wrote no Slurm output"
"$soak" sweep "$work/sweep.json" -o "$out" --collect --no-contact-sheet || fail "soak sweep --collect: not every variant complete
$(cat "$out"/summary.csv; cat "$out"/slurm-*.out "$out"/v*.log 2> /dev/null)"
/usr/bin/python3 - "$out/summary.json" << 'EOF' || fail "the summary is not what the sweep ran"
import json, sys
s = json.load(open(sys.argv[1]))
v = s["variants"]
assert len(v) == 4, len(v)
assert all(x["status"] == "complete" and x["framesWritten"] == 11 for x in v), v
assert [x["params"]["solver.substeps"] for x in v] == [1, 1, 2, 2], v
assert all(x["heldWaterKg"] > 0 for x in v), v  # the block landed on the cloth and soaked in
# more absorption holds more water, at either substep count
assert v[1]["heldWaterKg"] > v[0]["heldWaterKg"] and v[3]["heldWaterKg"] > v[2]["heldWaterKg"], v
EOF
# --wait: one frame more for every variant (so all four run again), submitted, waited for, summarised
timeout 120 "$soak" sweep "$work/sweep.json" -o "$out" --slurm --wait --frames 11 --no-contact-sheet |
  tee "$work/wait.txt" || fail "soak sweep --slurm --wait did not end with every variant complete"
grep -q "waiting for it" "$work/wait.txt" && grep -q "4 complete, 0 failed" "$work/wait.txt" ||
  fail "soak sweep --slurm --wait said: $(cat "$work/wait.txt")"
grep -q '"framesWritten": 12' "$out/v003/run.json" || fail "v003 was not run to frame 11: $(cat "$out/v003/run.json")"
echo "soak sweep ran 4 variants through Slurm job $job, and again with --wait"

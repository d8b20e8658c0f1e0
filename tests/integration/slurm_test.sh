#!/usr/bin/env bash
# Caliper on a real Slurm cluster (Debian's slurm-wlm and munge) made of network namespaces on
# this machine (support/slurm.sh): slurmctld on hosta (the login node), a slurmd on hostb and on
# hostc (2 CPUs each). Everything is submitted as a user would, with `launch/caliper slurm`:
#  1. a 20-run batch over both nodes over TLS (certificates made with `launch/caliper certs` in a
#     PKI directory all hosts see); hostc (its slurmd and its Caliper processes) is killed
#     mid-run: the job still finishes every run, each once and bit-identical to a single-host
#     run, and the summary lists the retries; `slurm status` shows progress while it runs;
#  2. a second batch cancelled with scancel: within seconds no Caliper process is left on any
#     host and no naming service (no names) outlives it; the finished runs are kept and the
#     summary marks the others interrupted;
#  3. the same sweep as a job array of 4 tasks with one task cancelled on purpose: the merge job
#     reports what is missing, `launch/caliper slurm rerun` runs only that, and the merged runs/
#     equal the single-host results byte for byte;
#  4. a calibration over both nodes in plain GIOP (--insecure, which warns).
# Needs root (namespaces, daemons); without it, or without Slurm, skipped (exit 77) with the reason.
set -uo pipefail
TAG=sl$$
# shellcheck source=support/netns.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/netns.sh"
# shellcheck source=support/slurm.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/slurm.sh"
unset CALIPER_INSECURE CALIPER_TLS_IDENTITY CALIPER_LISTEN CALIPER_NAMESERVICE CALIPER_SOCKET_DIR
PKI=$WORK/pki
SHARED=$WORK/shared  # "the shared filesystem": every namespace sees the same files
BUILD=$(dirname "$BIN")

netns_require
slurm_require
command -v openssl >/dev/null || { echo "FAIL: no openssl command (launch/deps.txt lists it)"; exit 1; }
netns_hosts
T0=$SECONDS
slurm_cluster
echo "Slurm cluster up in $((SECONDS - T0)) s: $(slurm_a sinfo -h -N -o '%N %t' | xargs)"
mkdir -p "$SHARED"

# launch/caliper as the user on the login node (hosta)
caliper() { slurm_a env CALIPER_NO_BUILD=1 CALIPER_BUILD_DIR="$BUILD" CALIPER_PKI="$PKI" \
  HOME="$WORK/home" bash "$SRC/launch/caliper" "$@"; }
mkdir -p "$WORK/home"

{ c() { bash "$SRC/launch/caliper" certs "$@" --dir "$PKI"; }
  c ca && c host hostb && c host hostc && c user root; } >"$WORK/certs.out" 2>&1 ||
  { cat "$WORK/certs.out"; echo "FAIL: launch/caliper certs"; exit 1; }

# ---------------------------------------------------------------- the experiments
cat >"$SHARED/sweep.json" <<JSON
{"name": "arm", "scene": "$SRC/models/ecce_arm.dae", "duration_s": 12, "every_n_steps": 20,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
 "commands": [[0, "elbow_flexor", 6], [6, "elbow_flexor", 0], [6, "elbow_extensor", 4]],
 "sweep": {"ecce_arm.forearm.mass": [0.30, 0.31, 0.32, 0.33, 0.34, 0.35, 0.36, 0.37, 0.38, 0.39,
                                      0.40, 0.41, 0.42, 0.43, 0.44, 0.45, 0.46, 0.47, 0.48, 0.49]}}
JSON
cat >"$SHARED/runs.json" <<JSON
{"scene": "$SRC/models/ecce_arm.dae", "duration_s": 1, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position"],
 "commands": [[0, "elbow_flexor", 6], [0.5, "elbow_flexor", 1], [0.5, "elbow_extensor", 5]]}
JSON
sed 's/"commands"/"set": {"ecce_arm.forearm.mass": 1.3}, "commands"/' "$SHARED/runs.json" >"$SHARED/truth.json"
cat >"$SHARED/cal.json" <<JSON
{"experiments": "runs.json", "measured": {"runs": "truth/runs/truth.csv"},
 "parameters": [{"id": "ecce_arm.forearm.mass", "lower": 0.5, "upper": 2, "scale": "log"}],
 "optimiser": {"generations": 3, "population": 5, "sigma0": 0.2}, "seed": 3}
JSON
# the single-host reference: a local session of two Models on hosta
in_ns a env BIN="$BIN" SRC="$SRC" WORK="$WORK" bash -c '
  source "$SRC/launch/local_models.sh"
  mkdir -p "$WORK/ref-session"
  local_models_start "$WORK/ref-session" 2
  "$BIN/caliper-ctl" batch "$WORK/shared/sweep.json" --out "$WORK/reference" >"$WORK/reference.out" 2>&1
  rc=$?
  # a "measured" recording for the calibration job: the arm with a heavier forearm
  "$BIN/caliper-ctl" batch "$WORK/shared/truth.json" --out "$WORK/shared/truth" >/dev/null 2>&1 || rc=1
  local_models_stop
  exit $rc' || { cat "$WORK/reference.out"; echo "FAIL: the single-host batch"; exit 1; }
echo "reference: $(grep ' runs done' "$WORK/reference.out" | tail -1)"

same_as_reference() {  # DIR: prints how many runs equal the reference byte for byte
  local n=0 f
  for f in "$WORK/reference/runs/"*.csv; do
    cmp -s "$f" "$1/runs/$(basename "$f")" && n=$((n + 1))
  done
  echo "$n"
}
caliper_processes() {  # every Caliper process (and naming service) in the host namespaces
  local n p
  for n in a b c; do
    for p in $(ip netns pids "$TAG-$n" 2>/dev/null); do
      ps -o comm=,pid=,ppid=,etimes=,args= -p "$p" 2>/dev/null | grep -E '^(caliper-|omniNames)' |
        cut -c1-200 | sed "s/^/host$n: /"
    done
  done
}

# ---------------------------------------------------------------- 1. a batch, a node lost mid-run
OUT1=$SHARED/job1
job=$(caliper slurm batch "$SHARED/sweep.json" --out "$OUT1" --nodes 2 --models-per-node 2 \
  --no-requeue 2>"$WORK/submit1.err" | tail -1)
[[ "$job" =~ ^[0-9]+$ ]] || { cat "$WORK/submit1.err"; echo "FAIL: slurm batch did not submit"; exit 1; }
pass "submitted job $job: $(grep -o 'job [0-9]*: .*' "$WORK/submit1.err" | head -1)"
# kill hostc once both hosts' Models are busy and some runs are done
killed=
for _ in $(seq 1 600); do
  done_runs=$(grep -o '"runs_done": "[0-9]*"' "$OUT1/status.json" 2>/dev/null | grep -o '[0-9]*')
  busy_c=$(in_ns c pgrep -c caliper-model 2>/dev/null || echo 0)
  if [ "${done_runs:-0}" -ge 3 ] && [ "$busy_c" -ge 2 ]; then
    st=$(caliper slurm status "$job" 2>&1)
    slurm_kill_node c
    killed=$done_runs
    break
  fi
  slurm_a squeue -h -j "$job" -o %T | grep -q . || break
  sleep 0.1
done
[ -n "$killed" ] && pass "killed hostc (slurmd and its Caliper processes) after $killed runs" ||
  fail "hostc was not killed mid-run (runs done: ${done_runs:-none}; job: $(slurm_a squeue -h -j "$job"))"
grep -q 'runs done' <<<"$st" && pass "slurm status during the run: $(tr '\n' ' ' <<<"$st")" ||
  fail "slurm status shows no progress: $st"
slurm_wait_job "$job" 240 || fail "job $job still queued after 240 s: $(slurm_a squeue -h -j "$job")"
state=$(slurm_a scontrol show job "$job" 2>/dev/null | grep -oE 'JobState=\S+|ExitCode=\S+' | xargs)
grep -q 'JobState=COMPLETED' <<<"$state" && pass "job $job: $state" ||
  { fail "job $job ended: $state"; tail -n 20 "$OUT1"/slurm-*.out "$OUT1/progress.log"; }
rows=$(awk -F, 'NR > 1' "$OUT1/summary.csv" 2>/dev/null | wc -l)
done_rows=$(awk -F, 'NR > 1 && $2 == "done"' "$OUT1/summary.csv" 2>/dev/null | wc -l)
[ "$rows" = 20 ] && [ "$done_rows" = 20 ] && pass "20 runs in the summary, each done once" ||
  fail "summary: $rows rows, $done_rows done"
n=$(same_as_reference "$OUT1")
[ "$n" = 20 ] && pass "all 20 results equal the single-host run byte for byte" ||
  fail "$n of 20 results equal the single-host run"
retried=$(awk -F, 'NR > 1 && $4 > 1' "$OUT1/summary.csv" | wc -l)
[ "$retried" -ge 1 ] && pass "the summary lists $retried retried run(s): $(awk -F, 'NR > 1 && $4 > 1 {print $1": "$11; exit}' "$OUT1/summary.csv" | cut -c1-160)" ||
  fail "no retry listed after hostc was killed"
hosts=$(awk -F, 'NR > 1 {sub(/.*@/, "", $3); print $3}' "$OUT1/summary.csv" | sort -u | xargs)
pass "runs ended on: $hosts"
grep -q '"state": "done"' "$OUT1/status.json" && pass "status.json says done" || fail "status.json: $(cat "$OUT1/status.json")"
left=$(caliper_processes)
[ -z "$left" ] && pass "no Caliper process left after the job" || fail "left after job $job: $left"
slurm_node_start c
for _ in $(seq 1 300); do
  [ "$(slurm_a sinfo -h -N -o '%N %t' 2>/dev/null | sort | tr '\n' ' ')" = "hostb idle hostc idle " ] && break
  sleep 0.1
done

# ---------------------------------------------------------------- 2. scancel
OUT2=$SHARED/job2
job2=$(caliper slurm batch "$SHARED/sweep.json" --out "$OUT2" --nodes 2 --no-requeue 2>"$WORK/submit2.err" | tail -1)
[[ "$job2" =~ ^[0-9]+$ ]] || { cat "$WORK/submit2.err"; fail "slurm batch (2) did not submit"; }
for _ in $(seq 1 600); do
  done_runs=$(grep -o '"runs_done": "[0-9]*"' "$OUT2/status.json" 2>/dev/null | grep -o '[0-9]*')
  [ "${done_runs:-0}" -ge 2 ] && break
  sleep 0.1
done
ns_addr=$(sed -n 's/^naming service //p' "$OUT2/job.txt")
slurm_a scancel "$job2"
t=$SECONDS
while [ -n "$(caliper_processes)" ] && [ $((SECONDS - t)) -lt 30 ]; do sleep 0.2; done
left=$(caliper_processes)
[ -z "$left" ] && pass "scancel of job $job2 (after ${done_runs:-?} runs): no Caliper process on any host after $((SECONDS - t)) s" ||
  fail "after scancel: $left"
slurm_wait_job "$job2" 60 || fail "job $job2 still queued after scancel"
out=$(in_ns b timeout 5 nameclt -ORBInitRef "NameService=${ns_addr/ssliop/}" list 2>&1)
grep -q 'TRANSIENT\|COMM_FAILURE' <<<"$out" && pass "no naming service answers at ${ns_addr} (no names outlive the job)" ||
  fail "the naming service of job $job2 still answers: $out"
[ ! -e "$OUT2/session/omninames" ] && pass "the naming service's data is removed" || fail "$OUT2/session/omninames left"
kept=$(awk -F, 'NR > 1 && $2 == "done"' "$OUT2/summary.csv" 2>/dev/null | wc -l)
cut_runs=$(awk -F, 'NR > 1 && $2 == "interrupted"' "$OUT2/summary.csv" 2>/dev/null | wc -l)
files=$(ls "$OUT2/runs" 2>/dev/null | wc -l)
[ "$kept" -ge 1 ] && [ $((kept + cut_runs)) = 20 ] && [ "$files" = "$kept" ] &&
  pass "the summary keeps $kept finished runs (their CSVs there) and marks $cut_runs interrupted" ||
  fail "after scancel: $kept done, $cut_runs interrupted, $files CSVs; statuses: $(awk -F, 'NR > 1 {print $2": "$12}' "$OUT2/summary.csv" | sort | uniq -c | head -5)"
grep -q '"state": "interrupted"' "$OUT2/status.json" && pass "status.json says interrupted" ||
  { fail "status.json after scancel: $(cat "$OUT2/status.json" 2>&1)"; cat "$OUT2"/slurm-*.out; tail -n 5 "$OUT2/progress.log"; }

# ---------------------------------------------------------------- 3. a job array, one task lost
OUT3=$SHARED/array
ids=$(caliper slurm batch "$SHARED/sweep.json" --out "$OUT3" --array 4 --models-per-node 1 \
  2>"$WORK/submit3.err")
arr=$(grep -o 'array job [0-9]*' "$WORK/submit3.err" | grep -o '[0-9]*')
merge=$(grep -o 'merge job [0-9]*' "$WORK/submit3.err" | grep -o '[0-9]*')
[ -n "$arr" ] && [ -n "$merge" ] || { cat "$WORK/submit3.err"; fail "the array was not submitted"; }
slurm_a scancel "${arr}_2"  # one task fails on purpose
slurm_wait_job "$merge" 180 || fail "merge job $merge still queued"
slurm_wait_job "$arr" 10 || fail "array job $arr still queued"
missing=$(awk -F, 'NR > 1 && $2 == "missing"' "$OUT3/summary.csv" 2>/dev/null | wc -l)
got=$(awk -F, 'NR > 1 && $2 == "done"' "$OUT3/summary.csv" 2>/dev/null | wc -l)
[ "$missing" = 5 ] && [ "$got" = 15 ] && pass "the merge job: 15 runs merged, the cancelled task's 5 listed missing" ||
  fail "after the first merge: $got done, $missing missing; $(cat "$OUT3"/array/0/slurm-merge-*.out 2>&1 | tail -3)"
st=$(caliper slurm status "$arr" 2>&1)
grep -q "rerun" <<<"$st" && pass "slurm status says what to do: $(tail -1 <<<"$st" | cut -c1-200)" || fail "status: $st"
caliper slurm rerun "$OUT3" >"$WORK/rerun.out" 2>&1 || { cat "$WORK/rerun.out"; fail "slurm rerun"; }
merge2=$(grep -o 'merge job [0-9]*' "$WORK/rerun.out" | grep -o '[0-9]*')
[ -n "$merge2" ] && pass "rerun: $(grep -o 'array job .*' "$WORK/rerun.out" | head -1)" || fail "rerun: $(cat "$WORK/rerun.out")"
slurm_wait_job "${merge2:-0}" 180 || fail "merge job $merge2 still queued"
rerun_runs=$(cat "$OUT3"/tasks/1-*/summary.csv 2>/dev/null | grep -vc '^name,')
[ "$rerun_runs" = 5 ] && pass "the rerun ran only the 5 missing runs" || fail "the rerun ran $rerun_runs runs"
got=$(awk -F, 'NR > 1 && $2 == "done"' "$OUT3/summary.csv" | wc -l)
n=$(same_as_reference "$OUT3")
[ "$got" = 20 ] && [ "$n" = 20 ] && pass "merged: 20 of 20 done, every result equal to the single-host run byte for byte" ||
  fail "merged: $got done, $n equal to the reference"
cmp -s <(cut -d, -f1,2,5,6,7 "$WORK/reference/summary.csv") <(cut -d, -f1,2,5,6,7 "$OUT3/summary.csv") &&
  pass "the merged summary lists the runs as one batch does (name, status, duration, steps, samples)" ||
  fail "merged summary differs: $(diff <(cut -d, -f1,2,5,6,7 "$WORK/reference/summary.csv") <(cut -d, -f1,2,5,6,7 "$OUT3/summary.csv") | head -5)"
left=$(caliper_processes)
[ -z "$left" ] && pass "no Caliper process left after the array" || fail "left: $left"

# ---------------------------------------------------------------- 4. a calibration, --insecure
OUT4=$SHARED/calibration
job4=$(caliper slurm calibrate "$SHARED/cal.json" --out "$OUT4" --nodes 2 --models-per-node 1 \
  --insecure --no-requeue 2>"$WORK/submit4.err" | tail -1)
[[ "$job4" =~ ^[0-9]+$ ]] || { cat "$WORK/submit4.err"; fail "slurm calibrate did not submit"; }
slurm_wait_job "${job4:-0}" 180 || fail "calibration job $job4 still queued"
state=$(slurm_a scontrol show job "$job4" 2>/dev/null | grep -oE 'JobState=\S+' | xargs)
if grep -q COMPLETED <<<"$state" && [ -s "$OUT4/parameters.csv" ] && grep -q '"state": "done"' "$OUT4/status.json"; then
  pass "calibration job $job4 over 2 nodes (plain GIOP, --insecure): $(grep -i 'best cost\|final cost\|cost' "$OUT4/calibrate.out" | tail -1 | cut -c1-120)"
else
  fail "calibration job $job4: $state; $(tail -n 5 "$OUT4"/slurm-*.out "$OUT4/progress.log" 2>&1)"
fi
grep -q WARNING "$OUT4"/slurm-*.out "$OUT4"/session/*.out 2>/dev/null && pass "--insecure warns in the job's output" ||
  fail "no INSECURE warning from the calibration job"
left=$(caliper_processes)
[ -z "$left" ] && pass "no Caliper process left after the calibration" || fail "left: $left"

[ "$FAILS" -eq 0 ] || { echo "$FAILS check(s) failed; slurm logs:"; slurm_logs | tail -n 60; exit 1; }
echo "all checks passed"

#!/usr/bin/env bash
# Slurm benchmarks on a real Slurm cluster of network namespaces on this machine (the slurm test's
# support/slurm.sh: slurmctld on hosta, a slurmd with 2 CPUs on hostb and hostc), over TLS:
#   RATIO slurm_vs_direct_overhead: the wall time of a 200-run sweep of 1 s arm runs submitted
#     with `launch/caliper slurm batch` on 2 nodes (from the job's start to its end: naming
#     service, logger, managers by srun, Models, the batch, the teardown; the wait for the
#     allocation excluded) against the same on 2 managers started directly in the same hosts;
#     five pairs (which goes first alternates), the median ratio
#   a 1,000-run sweep of 0.2 s runs through Slurm on 2 nodes with hostc killed mid-run: its wall
#     time and runs per second, and that every run is done
# Needs root (namespaces) and Slurm (launch/caliper deps slurm). Run through
# `launch/caliper bench slurm`. BENCH_PAIRS="1" runs one pair (default 1 2 3 4 5); BENCH_VERBOSE=1 prints each job's
# timeline (naming service, managers up, client exit, teardown).
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export CALIPER_BIN_DIR=${CALIPER_BIN_DIR:-$ROOT/build/bin} CALIPER_SOURCE_DIR=$ROOT
TAG=sb$$
# shellcheck source=../tests/integration/support/netns.sh
source "$ROOT/tests/integration/support/netns.sh"
# shellcheck source=../tests/integration/support/slurm.sh
source "$ROOT/tests/integration/support/slurm.sh"
unset CALIPER_INSECURE CALIPER_TLS_IDENTITY CALIPER_LISTEN CALIPER_NAMESERVICE CALIPER_SOCKET_DIR
netns_require
slurm_require
netns_hosts
slurm_cluster
PKI=$WORK/pki SHARED=$WORK/shared BUILD=$(dirname "$BIN")
mkdir -p "$SHARED" "$WORK/home"
{ c() { bash "$SRC/launch/caliper" certs "$@" --dir "$PKI"; }
  c ca && c host hostb && c host hostc && c user root; } >"$WORK/certs.out" 2>&1 ||
  { cat "$WORK/certs.out"; echo "certs failed"; exit 1; }
caliper() { slurm_a env CALIPER_NO_BUILD=1 CALIPER_BUILD_DIR="$BUILD" CALIPER_PKI="$PKI" \
  HOME="$WORK/home" bash "$SRC/launch/caliper" "$@"; }
now() { date +%s.%N; }

sweep() {  # FILE RUNS DURATION_S
  /usr/bin/python3 - "$@" "$SRC/models/ecce_arm.dae" <<'PY'
import json, sys
path, runs, duration, scene = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
json.dump({"name": "arm", "scene": scene, "duration_s": duration, "every_n_steps": 20,
           "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
           "commands": [[0, "elbow_flexor", 6], [duration / 2, "elbow_extensor", 4]],
           "sweep": {"ecce_arm.forearm.mass": [round(0.3 + 0.4 * i / runs, 6) for i in range(runs)]}},
          open(path, "w"))
PY
}
sweep "$SHARED/sweep200.json" 200 1
sweep "$SHARED/sweep1000.json" 1000 0.2

# the same as the job script, by hand: naming service and logger on hostb, a manager with 2
# Models on hostb and hostc, the batch, the teardown. Prints the wall time [s].
direct() {  # OUT
  local out=$1 t0 t1 p
  local -a pids=()
  mkdir -p "$out/session"
  t0=$(now)
  in_ns b env CALIPER_HOST=hostb CALIPER_PKI="$PKI" bash -c '
    source "$0/launch/naming.sh"; start_nameserver "$1" 198.51.100.2 tls >/dev/null 2>&1
    echo "$NS_ADDR $NS_PID"; wait' "$SRC" "$out/session" >"$out/ns.txt" &
  pids+=($!)
  for _ in $(seq 1 100); do [ -s "$out/ns.txt" ] && break; sleep 0.05; done
  local ns
  ns=$(awk '{print $1}' "$out/ns.txt")
  in_ns b env CALIPER_HOST=hostb CALIPER_PKI="$PKI" "$BIN/caliper-logger" --nameservice "$ns" \
    --listen 198.51.100.2 -o "logger.directory=$out/session" -o exec.auto_activate=true \
    -o "log.spool_dir=$out/session/spool" >"$out/session/logger.out" 2>&1 &
  pids+=($!)
  for h in b c; do
    in_ns $h env CALIPER_HOST=host$h CALIPER_PKI="$PKI" "$BIN/caliper-manager" --nameservice "$ns" \
      --listen "198.51.100.$([ $h = b ] && echo 2 || echo 3)" -o manager.max_models=2 \
      -o "manager.output_dir=$out/session/manager-$h" -o "log.spool_dir=$out/session/spool" \
      >"$out/session/manager-$h.out" 2>&1 &
    pids+=($!)
  done
  local ctl=(in_ns b env CALIPER_HOST=hostb CALIPER_PKI="$PKI" "$BIN/caliper-ctl" --nameservice "$ns")
  for _ in $(seq 1 1200); do
    [ "$("${ctl[@]}" managers 2>/dev/null | grep -v unreachable | grep -c 'manager0.rtc')" -ge 2 ] && break
    sleep 0.05
  done
  "${ctl[@]}" batch "$SHARED/sweep200.json" --spawn 4 --out "$out" >"$out/batch.out" 2>"$out/progress.log"
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -TERM "${pids[$i]}" 2>/dev/null; done
  for p in $(ip netns pids "$TAG-b") $(ip netns pids "$TAG-c"); do
    case "$(ps -o comm= -p "$p" 2>/dev/null)" in omniNames|caliper-*) kill -TERM "$p" 2>/dev/null ;; esac
  done
  wait "${pids[@]}" 2>/dev/null
  t1=$(now)
  grep -q '^200 of 200 runs done' "$out/batch.out" || { echo "direct run failed: $(tail -2 "$out/batch.out")" >&2; }
  echo "$t0 $t1" | awk '{printf "%.3f", $2 - $1}'
}

through_slurm() {  # OUT SWEEP [KILL_AFTER_RUNS]: prints the job's wall time [s]
  local out=$1 job t
  job=$(caliper slurm batch "$2" --out "$out" --nodes 2 --models-per-node 2 --no-requeue 2>/dev/null | tail -1)
  if [ -n "${3:-}" ]; then
    for _ in $(seq 1 3000); do
      t=$(grep -o '"runs_done": "[0-9]*"' "$out/status.json" 2>/dev/null | grep -o '[0-9]*')
      [ "${t:-0}" -ge "$3" ] && { slurm_kill_node c; break; }
      sleep 0.1
    done
  fi
  # the job's own end mark, read from the shared directory: polling squeue (a process and an
  # RPC to slurmctld five times a second) would take CPU from the Models being measured
  for _ in $(seq 1 6000); do
    grep -q '^ended' "$out/job.txt" 2>/dev/null && break
    sleep 0.1
  done
  slurm_wait_job "$job" 600 || { echo "job $job did not end" >&2; return 1; }
  awk '/^started/ {s = $2} /^ended/ {e = $2} END {printf "%.3f", e - s}' "$out/job.txt"
}

ratios=()
for i in ${BENCH_PAIRS:-1 2 3 4 5}; do
  # alternating which goes first: this VM's speed drifts over a minute
  if [ $((i % 2)) = 1 ]; then
    d=$(direct "$WORK/direct$i")
    s=$(through_slurm "$SHARED/slurm$i" "$SHARED/sweep200.json")
  else
    s=$(through_slurm "$SHARED/slurm$i" "$SHARED/sweep200.json")
    d=$(direct "$WORK/direct$i")
  fi
  done_runs=$(awk -F, 'NR > 1 && $2 == "done"' "$SHARED/slurm$i/summary.csv" 2>/dev/null | wc -l)
  r=$(awk -v s="$s" -v d="$d" 'BEGIN {printf "%.3f", s / d}')
  bw() { grep -o '[0-9.]* s of wall time' "$1/batch.out" | grep -o '^[0-9.]*'; }
  echo "# pair $i: 200 runs of 1 s on 2 nodes x 2 Models: direct $d s (batch $(bw "$WORK/direct$i") s), through Slurm $s s (batch $(bw "$SHARED/slurm$i") s; $done_runs done): $r"
  ratios+=("$r")
  [ -z "${BENCH_VERBOSE:-}" ] || { grep caliper-job "$SHARED/slurm$i"/slurm-*.out; grep -h 'runs done' "$WORK/direct$i/batch.out" "$SHARED/slurm$i/batch.out"; }
done
median=$(printf '%s\n' "${ratios[@]}" | sort -n | sed -n "$(( (${#ratios[@]} + 1) / 2 ))p")
ok=$(awk -v m="$median" 'BEGIN {print (m <= 1.10) ? "" : "  <- off target"}')
echo "RATIO slurm_vs_direct_overhead $median (target <= 1.10)$ok"

w=$(through_slurm "$SHARED/big" "$SHARED/sweep1000.json" 300)
done_runs=$(awk -F, 'NR > 1 && $2 == "done"' "$SHARED/big/summary.csv" 2>/dev/null | wc -l)
retried=$(awk -F, 'NR > 1 && $4 > 1' "$SHARED/big/summary.csv" 2>/dev/null | wc -l)
echo "# 1000 runs of 0.2 s through Slurm on 2 nodes x 2 Models, hostc killed after 300: $done_runs done ($retried retried) in $w s of wall time: $(awk -v w="$w" -v n="$done_runs" 'BEGIN {printf "%.1f", n / w}') runs/s"

#!/usr/bin/env bash
# Cluster runs across three "hosts" made of Linux network namespaces on this machine:
#   hosta 198.51.100.1: naming service and the batch client
#   hostb 198.51.100.2, hostc 198.51.100.3: a manager each, with two Models
# joined by a bridge that lives in a namespace of its own. Every process runs inside a
# namespace; the root namespace never sends to the test addresses. Everything on the network
# talks TLS with client certificates (network mode's default): `launch/caliper certs` makes a CA,
# an identity per host (the naming service, the managers and their Models use their host's) and
# one for the user alice (the batch client). Checks: network mode is reachable from another host
# over TLS, and plain GIOP is refused; loopback mode is not reachable; 20 experiments survive a
# SIGKILLed Model and a link down for a few seconds, each result exists once and equals a
# single-host run bit for bit; the manager reports the dead Model; components register again
# after the naming service restarts. Needs root (ip netns); without it the test is skipped
# (exit 77) and says why.
set -uo pipefail
TAG=cl$$
# shellcheck source=support/netns.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/netns.sh"  # BIN, SRC, WORK, skip, fail, pass, in_ns...
NS=corbaname:ssliop:198.51.100.1:2809
PKI=$WORK/pki
unset CALIPER_INSECURE CALIPER_TLS_IDENTITY CALIPER_LISTEN

# caliper-ctl from host A with the naming service on A, as the user alice
ctl() { in_ns a env CALIPER_HOST=hosta CALIPER_PKI="$PKI" CALIPER_TLS_IDENTITY=users/alice \
  "$BIN/caliper-ctl" --nameservice "$NS" "$@"; }
# an omniORB tool (omniNames, nameclt) on host A with hosta's identity (launch/naming.sh)
tls_tool() { in_ns a env CALIPER_PKI="$PKI" CALIPER_TLS_IDENTITY=hosts/hosta bash -c \
  "source '$SRC/launch/naming.sh'; tls_identity; tls_exec \"\$@\"" tls_tool "$@"; }

netns_require
command -v openssl >/dev/null || { echo "FAIL: no openssl command (launch/deps.txt lists it)"; exit 1; }

# ---------------------------------------------------------------- the hosts
netns_hosts

# ---------------------------------------------------------------- certificates
{ launcher() { bash "$SRC/launch/caliper" certs "$@" --dir "$PKI"; }
  launcher ca && launcher host hosta && launcher host hostb && launcher host hostc &&
    launcher user alice; } >"$WORK/certs.out" 2>&1 ||
  { cat "$WORK/certs.out"; echo "FAIL: launch/caliper certs"; exit 1; }

# the naming service over TLS only, as launch/naming.sh starts it (the same pid: tls_exec execs)
start_naming() {  # DATADIR
  mkdir -p "$1"
  tls_tool env "ORBserverTransportRule=* ssl" "ORBclientTransportRule=* ssl" \
    omniNames -start 2809 -always -nohostname -datadir "$1" \
    -ORBendPoint giop:ssl:198.51.100.1:2809 -ORBgiopMaxMsgSize 4194304 >>"$WORK/naming-service.out" 2>&1 &
  NAMING_PID=$!
  for _ in $(seq 1 50); do
    tls_tool nameclt -ORBInitRef "NameService=$NS" list >/dev/null 2>&1 && return 0
    sleep 0.1
  done
  echo "FAIL: omniNames did not start on hosta"; cat "$WORK/naming-service.out"; exit 1
}
start_naming "$WORK/names1"

# managers on B and C, listening on their own addresses
for h in b c; do
  addr=198.51.100.$([ $h = b ] && echo 2 || echo 3)
  in_ns $h env CALIPER_HOST=host$h CALIPER_PKI="$PKI" CALIPER_LISTEN=$addr "$BIN/caliper-manager" \
    --nameservice "$NS" -o manager.max_models=2 -o "manager.output_dir=$WORK/$h" \
    -o "log.spool_dir=$WORK/spool" -o naming.update.interval=0.5 >"$WORK/manager-$h.out" 2>&1 &
done
for h in b c; do
  for _ in $(seq 1 100); do ctl state host$h/manager0 >/dev/null 2>&1 && break; sleep 0.1; done
  ctl create --manager host$h/manager0 --count 2 -o naming.update.interval=0.5 \
    >"$WORK/create-$h.out" 2>&1 || { cat "$WORK/create-$h.out"; echo "FAIL: create on host$h"; exit 1; }
done
ctl ls >"$WORK/ls.out" 2>&1
models=$(grep -c '^model' "$WORK/ls.out")
[ "$models" -eq 4 ] && pass "4 Models on hostb and hostc" || { cat "$WORK/ls.out"; fail "expected 4 Models, found $models"; }

# ---------------------------------------------------------------- network mode vs loopback
if ctl status --model hostc/model0 >/dev/null 2>&1; then pass "a network-mode Model on hostc answers hosta over TLS"
else fail "hostc/model0 does not answer from hosta"; fi
# the name batch summaries print works as well: INSTANCE@HOST
if ctl status --model model0@hostc 2>&1 | grep -q "hostc.host_cxt/model0.rtc"; then
  pass "model0@hostc names hostc's model0"
else fail "model0@hostc does not name hostc's model0"; fi
# a name that is not bound: the message lists what is, each as INSTANCE@HOST (hosts differ)
if ctl status --model model9@hostc >"$WORK/nf.out" 2>&1; then fail "model9@hostc found"
elif grep -q "bound: .*model0@hostc" "$WORK/nf.out"; then pass "an unknown name lists the bound ones as INSTANCE@HOST"
else cat "$WORK/nf.out"; fail "the unknown name's message does not list INSTANCE@HOST"; fi
if in_ns b ss -ltn | grep -q '198.51.100.2:'; then pass "hostb's Models listen on 198.51.100.2"
else fail "nothing listens on 198.51.100.2 in hostb"; fi
# without TLS: hostc's Models refuse plain GIOP, and so does the naming service
port=$(in_ns c ss -ltnpH | grep caliper-model | awk '{sub(/.*:/, "", $4); print $4}' | head -1)
for to in "198.51.100.3:${port:-none}" 198.51.100.1:2809; do
  out=$(in_ns a timeout 10 nameclt -ORBInitRef "NameService=corbaloc::$to/NameService" list 2>&1)
  if [ -n "$port" ] && ! grep -q OBJECT_NOT_EXIST <<<"$out" && grep -q "COMM_FAILURE\|TRANSIENT" <<<"$out"; then
    pass "plain GIOP to $to refused ($(grep -o 'COMM_FAILURE\|TRANSIENT' <<<"$out" | head -1))"
  else fail "plain GIOP to $to not refused: $out"; fi
done
# a component without --listen (in TLS mode for its naming service, but listening locally only,
# on a unix socket): bound in the naming service but unreachable
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$PKI" "$BIN/caliper-model" --nameservice "$NS" --instance loopback \
  -o "log.spool_dir=$WORK/spool" >"$WORK/loopback.out" 2>&1 &
for _ in $(seq 1 100); do grep -q "is up as" "$WORK/loopback.out" && break; sleep 0.1; done
lpid=$(pgrep -f -- '--instance loopback' | head -1)
if in_ns c ss -lxpH | grep -q "pid=$lpid," && ! in_ns c ss -ltnpH | grep -q "pid=$lpid,"; then
  pass "a local-mode Model listens on no TCP port, only on a unix socket ($(in_ns c ss -lxpH | grep "pid=$lpid," | awk '{print $5}' | head -1))"
else
  fail "the local-mode Model listens elsewhere: $(in_ns c ss -ltnpH; in_ns c ss -lxpH)"
fi
if ctl --timeout 2 status --model hostc/loopback0 >/dev/null 2>&1; then
  fail "a local-mode Model on hostc answered hosta"
else pass "a local-mode Model on hostc is not reachable from hosta"; fi
kill "$lpid" 2>/dev/null

# ---------------------------------------------------------------- the experiments
cat >"$WORK/runs.json" <<JSON
{"name": "arm", "scene": "$SRC/models/ecce_arm.dae", "duration_s": 8, "every_n_steps": 20,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension", "ecce_arm.hand.position"],
 "commands": [[0, "elbow_flexor", 6], [4, "elbow_flexor", 0], [4, "elbow_extensor", 4]],
 "sweep": {"ecce_arm.forearm.mass": [0.30, 0.31, 0.32, 0.33, 0.34, 0.35, 0.36, 0.37, 0.38, 0.39,
                                      0.40, 0.41, 0.42, 0.43, 0.44, 0.45, 0.46, 0.47, 0.48, 0.49]}}
JSON
# the single-host reference: hosta alone, its own loopback naming service and one Model
in_ns a omniNames -start 2810 -always -nohostname -datadir "$WORK/local" \
  -ORBendPoint giop:tcp:127.0.0.1:2810 >"$WORK/local-ns.log" 2>&1 &
mkdir -p "$WORK/local"
for _ in $(seq 1 50); do in_ns a nameclt -ORBInitRef NameService=corbaname::127.0.0.1:2810 list >/dev/null 2>&1 && break; sleep 0.1; done
in_ns a "$BIN/caliper-model" --nameservice corbaname::127.0.0.1:2810 -o "log.spool_dir=$WORK/spool" \
  >"$WORK/local-model.out" 2>&1 &
in_ns a "$BIN/caliper-ctl" --nameservice corbaname::127.0.0.1:2810 batch "$WORK/runs.json" \
  --out "$WORK/reference" >"$WORK/reference.out" 2>&1 || { cat "$WORK/reference.out"; fail "the single-host batch"; }
echo "reference: $(grep ' runs done' "$WORK/reference.out" | tail -1)"

# ---------------------------------------------------------------- the cluster run, with faults
ctl batch "$WORK/runs.json" --out "$WORK/cluster" --stall-timeout 2 >"$WORK/cluster.out" 2>"$WORK/cluster.err" &
batch=$!
# a Model on hostb that is running an experiment, killed with SIGKILL
victim=""
for _ in $(seq 1 100); do
  for inst in model0 model1; do
    if ctl --timeout 1 status --model hostb/$inst 2>/dev/null | grep -q RUNNING; then
      victim=$(ctl --timeout 1 ls 2>/dev/null | awk -v p="hostb.host_cxt/$inst.rtc" '$5 == p {print $4}')
      break 2
    fi
  done
  sleep 0.1
done
if [ -n "$victim" ]; then
  kill -KILL "$victim" && pass "killed hostb's busy Model (pid $victim) mid-run"
else
  fail "no busy Model on hostb to kill"
fi
# hostc's link down for a few seconds while its Models run
sleep 0.5
ip -n "$TAG-c" link set eth0 down
sleep 3
ip -n "$TAG-c" link set eth0 up
echo "note: took hostc's link down for 3 s mid-run"
for _ in $(seq 1 1200); do kill -0 $batch 2>/dev/null || break; sleep 0.1; done
if kill -0 $batch 2>/dev/null; then fail "the batch did not end within 120 s"; kill $batch; fi
wait $batch; rc=$?
cat "$WORK/cluster.out"
[ $rc -eq 0 ] && pass "the batch exited 0" || { cat "$WORK/cluster.err"; fail "the batch exited $rc"; }

# ---------------------------------------------------------------- the results
rows=$(tail -n +2 "$WORK/cluster/summary.csv" | wc -l)
done_rows=$(tail -n +2 "$WORK/cluster/summary.csv" | cut -d, -f2 | grep -c '^done$')
[ "$rows" -eq 20 ] && [ "$done_rows" -eq 20 ] && pass "20 runs in the summary, each done once" ||
  fail "summary has $rows rows, $done_rows done"
files=$(ls "$WORK/cluster/runs" | wc -l)
[ "$files" -eq 20 ] && pass "20 recordings" || fail "$files recordings instead of 20"
same=0
for f in "$WORK"/reference/runs/*.csv; do
  cmp -s "$f" "$WORK/cluster/runs/$(basename "$f")" && same=$((same + 1))
done
[ "$same" -eq 20 ] && pass "all 20 recordings equal the single-host run bit for bit" ||
  fail "only $same of 20 recordings equal the single-host run"
distinct=$(md5sum "$WORK"/cluster/runs/*.csv | cut -d' ' -f1 | sort -u | wc -l)
[ "$distinct" -eq 20 ] && pass "the 20 recordings differ from one another (the sweep took effect)" ||
  fail "only $distinct distinct recordings"
# a retry reads `modelN@hostb: REASON`; the Model column has no colon after the host
if grep -q '@hostb: ' "$WORK/cluster/summary.csv"; then
  pass "the summary lists the retry of the killed Model's run: $(grep -o 'model[0-9]@hostb: [^;,"]*' "$WORK/cluster/summary.csv" | head -1)"
else
  fail "no retry on hostb in the summary"
fi
hosts=$(tail -n +2 "$WORK/cluster/summary.csv" | cut -d, -f3 | sed 's/.*@//' | sort -u | xargs)
[ "$hosts" = "hostb hostc" ] && pass "runs ended on both hosts ($hosts)" || fail "runs ended on: $hosts"
ctl managers >"$WORK/managers.out" 2>&1
if grep -q "killed by signal 9" "$WORK/managers.out"; then pass "hostb's manager reports its Model killed by signal 9"
else cat "$WORK/managers.out"; fail "the manager does not report the killed Model"; fi

# ---------------------------------------------------------------- a host's Models by glob
# `*@hostc` matches hostc's manager too: the pool takes only Models (no retry spent on it)
cat >"$WORK/two.json" <<JSON
{"name": "two", "scene": "$SRC/models/ecce_arm.dae", "duration_s": 0.5,
 "record": ["ecce_arm.elbow.position"], "sweep": {"ecce_arm.forearm.mass": [0.30, 0.31]}}
JSON
ctl batch "$WORK/two.json" --models '*@hostc' --out "$WORK/hostc" >"$WORK/hostc.out" 2>&1
models=$(tail -n +2 "$WORK/hostc/summary.csv" 2>/dev/null | cut -d, -f3 | sort -u | xargs)
retries=$(tail -n +2 "$WORK/hostc/summary.csv" 2>/dev/null | cut -d, -f11 | grep -c . || true)
if [ -n "$models" ] && ! grep -q "manager\|BAD_OPERATION" "$WORK/hostc.out" "$WORK/hostc/summary.csv" &&
  [ "$retries" -eq 0 ] && [ -z "$(tr ' ' '\n' <<<"$models" | grep -v '^model[0-9]*@hostc$')" ]; then
  pass "--models '*@hostc' ran on hostc's Models only ($models), no retry"
else cat "$WORK/hostc.out" "$WORK/hostc/summary.csv"; fail "--models '*@hostc' took more than hostc's Models"; fi

# ---------------------------------------------------------------- the naming service restarts
kill -TERM "$NAMING_PID" 2>/dev/null
sleep 0.5
start_naming "$WORK/names2"  # a fresh data directory: every binding is gone
for _ in $(seq 1 100); do
  n=$(ctl --timeout 1 ls 2>/dev/null | grep -c 'host[bc].host_cxt/' || true)
  [ "$n" -ge 5 ] && break
  sleep 0.1
done
[ "${n:-0}" -ge 5 ] && pass "managers and Models on hostb and hostc registered again after the restart ($n names)" ||
  fail "after the naming service restart only ${n:-0} of 5 components registered again"

# ---------------------------------------------------------------- the managers stop their Models
for h in b c; do ctl exit host$h/manager0 >/dev/null 2>&1; done
for _ in $(seq 1 100); do
  left=$( (ip netns pids "$TAG-b"; ip netns pids "$TAG-c") | wc -l)
  [ "$left" -eq 0 ] && break
  sleep 0.1
done
[ "$left" -eq 0 ] && pass "stopping the managers ended every process on hostb and hostc" ||
  fail "$left processes left on hostb and hostc"

if [ $FAILS -eq 0 ]; then echo "cluster_test: all checks passed"; exit 0; fi
echo "cluster_test: $FAILS checks failed; the batch's stderr and the managers' output:"
tail -n 5 "$WORK/cluster.err" "$WORK"/manager-*.out
exit 1

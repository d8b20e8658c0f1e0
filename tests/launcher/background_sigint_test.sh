#!/usr/bin/env bash
# A headless session started in the background by this (non-interactive) script, the way CI
# scripts and wrappers start it: bash starts such a job with SIGINT ignored, and the launcher must
# still stop on `kill -INT`: it shuts every process of the session down and exits with 130.
# Everything on a private loopback naming service; bounded waits; kills what it started.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
has_bit() { (((16#$1 >> ($2 - 1)) & 1)); }  # MASK SIGNAL
mask() { sed -n "s/^$2:[[:space:]]*//p" "/proc/$1/status" 2>/dev/null; }  # PID SigIgn|SigCgt

WORK=$(mktemp -d)
LAUNCHER="" CHILDREN=()
cleanup() {
  local p
  for p in $LAUNCHER "${CHILDREN[@]}"; do kill -KILL "$p" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT

# the premise: a background job of this script starts with SIGINT ignored
grep '^SigIgn:' /proc/self/status >"$WORK/premise" &
wait $!
if has_bit "$(awk '{print $2}' "$WORK/premise")" 2; then
  pass "a background job of a script starts with SIGINT ignored ($(cat "$WORK/premise"))"
else fail "the premise: a background job did not inherit SIGINT ignored ($(cat "$WORK/premise"))"; fi

mkdir -m 700 "$WORK/run"
XDG_RUNTIME_DIR=$WORK/run CALIPER_SESSIONS_DIR=$WORK/sessions CALIPER_BUILD_DIR=$BIN/.. \
  CALIPER_NO_BUILD=1 "$SRC/launch/caliper" session --headless "$SRC/models/pendulum_tendon.dae" \
  >"$WORK/out" 2>&1 &
LAUNCHER=$!
started=$SECONDS
for _ in $(seq 1 300); do
  grep -q "press Ctrl-C to stop" "$WORK/out" && break
  kill -0 "$LAUNCHER" 2>/dev/null || break
  sleep 0.1
done
if ! grep -q "press Ctrl-C to stop" "$WORK/out"; then
  fail "the session did not start in 30 s:"; cat "$WORK/out"; exit 1
fi
pass "session up in $((SECONDS - started)) s"
mapfile -t CHILDREN < <(pgrep -P "$LAUNCHER")
if ! has_bit "$(mask "$LAUNCHER" SigIgn)" 2 && has_bit "$(mask "$LAUNCHER" SigCgt)" 2; then
  pass "the launcher (same pid) no longer ignores SIGINT and traps it; ${#CHILDREN[@]} children"
else fail "the launcher's SigIgn $(mask "$LAUNCHER" SigIgn), SigCgt $(mask "$LAUNCHER" SigCgt)"; fi

kill -INT "$LAUNCHER"
for _ in $(seq 1 200); do kill -0 "$LAUNCHER" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$LAUNCHER" 2>/dev/null; then
  fail "the launcher ignored kill -INT for 20 s"
else
  wait "$LAUNCHER"
  rc=$?
  LAUNCHER=""
  [ "$rc" = 130 ] && grep -q "shutting the session down" "$WORK/out" &&
    pass "kill -INT: the session shut down, exit status $rc" ||
    { fail "kill -INT: exit status $rc (130 expected):"; cat "$WORK/out"; }
fi
left=()
for p in "${CHILDREN[@]}"; do
  kill -0 "$p" 2>/dev/null && left+=("$p $(cat "/proc/$p/comm" 2>/dev/null)")
done
[ ${#CHILDREN[@]} -ge 3 ] && [ ${#left[@]} = 0 ] &&
  pass "none of the ${#CHILDREN[@]} processes of the session is left" ||
  fail "processes of the session left: ${left[*]:-} (of ${#CHILDREN[@]})"

[ "$FAILS" = 0 ] && echo "PASS" || { echo "FAILED: $FAILS"; exit 1; }

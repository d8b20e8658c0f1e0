#!/usr/bin/env bash
# Which session a client reaches, from another terminal: `caliper-ctl address` names the newest
# running session; a $CALIPER_NAMESERVICE left from a session that has ended gives way to it, with
# a note; stopping an older session keeps the newer one's pointer; `node` without --nameservice
# joins the newest session; with no session the error says where the address came from; the
# naming service of `nameserver start` is found too. Private HOME and runtime directory (unix
# sockets only, no network); bounded waits; kills what it started.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
# shellcheck source=../integration/support/checks.sh
source "$SRC/tests/integration/support/checks.sh"

WORK=$(mktemp -d)
PIDS=()
cleanup() {
  local p
  # Ctrl-C lets each launcher shut its session down (components, then the naming service);
  # KILL only what is still there after 15 s
  for p in "${PIDS[@]}"; do kill -INT "$p" 2>/dev/null; done
  for _ in $(seq 1 150); do
    local alive=0
    for p in "${PIDS[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  for p in "${PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done
  pkill -KILL -f "$WORK/" 2>/dev/null  # a component orphaned by a KILLed launcher
  (launcher nameserver stop >/dev/null 2>&1)
  wait 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT
mkdir -m 700 "$WORK/run" "$WORK/home"
# the launcher in this test's environment; `exec`, so that `launcher ... &` makes $! the
# launcher's own pid (a signal to it, not to a subshell)
launcher() {
  exec env -u CALIPER_NAMESERVICE -u CALIPER_SOCKET_DIR HOME="$WORK/home" XDG_RUNTIME_DIR="$WORK/run" \
    CALIPER_SESSIONS_DIR="$WORK/sessions" CALIPER_BUILD_DIR="$BIN/.." CALIPER_NO_BUILD=1 \
    "$SRC/launch/caliper" "$@"
}
env_of() { echo HOME="$WORK/home" XDG_RUNTIME_DIR="$WORK/run" CALIPER_BUILD_DIR="$BIN/.." CALIPER_NO_BUILD=1; }
in_env() {
  local vars
  read -r -a vars <<<"$(env_of)"
  env -u CALIPER_NAMESERVICE "${vars[@]}" "$@"
}

# NAME: a headless session in the background; waits until it runs (30 s at most)
start_session() {
  launcher session --headless "$SRC/models/pendulum_tendon.dae" >"$WORK/$1.out" 2>&1 &
  PIDS+=($!)
  eval "$1=$!"
  for _ in $(seq 1 300); do
    grep -q "press Ctrl-C to stop" "$WORK/$1.out" && return 0
    sleep 0.1
  done
  cat "$WORK/$1.out"
  fail "session $1 did not start in 30 s"
  exit 1
}
stop() {  # PID: Ctrl-C, then wait (20 s at most)
  kill -INT "$1" 2>/dev/null
  for _ in $(seq 1 200); do kill -0 "$1" 2>/dev/null || return 0; sleep 0.1; done
  fail "pid $1 did not stop on SIGINT in 20 s"
}
address_of() { grep -o -m1 'corbaname:omniunix:[^ ,]*' "$WORK/$1.out"; }

start_session A
A_ADDR=$(address_of A)
in_env "$SRC/launch/caliper" ctl address >"$WORK/addr" 2>"$WORK/addr.err"
[ "$(cat "$WORK/addr")" = "$A_ADDR" ] && grep -q "the newest running session" "$WORK/addr.err" &&
  pass "ctl address: the session's naming service ($(cat "$WORK/addr.err"))" ||
  { cat "$WORK/addr" "$WORK/addr.err"; fail "ctl address is not session A's"; }

# a variable left from a session that has ended
in_env CALIPER_NAMESERVICE="corbaname:omniunix:$WORK/gone/naming.sock" \
  "$SRC/launch/caliper" ctl status >"$WORK/stale" 2>&1
if grep -q "^state  *STOPPED" "$WORK/stale" && grep -q "does not answer; using the newest running session" "$WORK/stale"; then
  pass "a stale \$CALIPER_NAMESERVICE gives way to the running session, said: $(grep -m1 'does not answer' "$WORK/stale" | cut -c1-100)"
else cat "$WORK/stale"; fail "stale \$CALIPER_NAMESERVICE"; fi
# a variable that answers is kept, without a note
in_env CALIPER_NAMESERVICE="$A_ADDR" "$SRC/launch/caliper" ctl address >"$WORK/kept" 2>&1
grep -q '^caliper-ctl: the naming service of \$CALIPER_NAMESERVICE$' "$WORK/kept" &&
  ! grep -q "does not answer" "$WORK/kept" && pass "a \$CALIPER_NAMESERVICE that answers is used" ||
  { cat "$WORK/kept"; fail "a live \$CALIPER_NAMESERVICE"; }

start_session B
B_ADDR=$(address_of B)
[ "$(in_env "$SRC/launch/caliper" ctl address 2>/dev/null)" = "$B_ADDR" ] &&
  pass "the newer session B is the newest" || fail "ctl address is not session B's"
stop "$A"
[ "$(in_env "$SRC/launch/caliper" ctl address 2>/dev/null)" = "$B_ADDR" ] &&
  pass "stopping the older session A keeps B as the newest" ||
  fail "after A stopped, ctl address is not B's: $(in_env "$SRC/launch/caliper" ctl address 2>&1)"

# a node joins the newest session without --nameservice
launcher node --models 1 >"$WORK/node.out" 2>&1 &
NODE=$!
PIDS+=("$NODE")
for _ in $(seq 1 300); do grep -q "manager pid" "$WORK/node.out" && break; sleep 0.1; done
if grep -q "joining $B_ADDR (the naming service of the newest running session" "$WORK/node.out" &&
  in_env "$SRC/launch/caliper" ctl managers 2>&1 | grep -q "1/.* running"; then
  pass "node without --nameservice joined session B and started its Model"
else cat "$WORK/node.out"; fail "node without --nameservice"; fi
stop "$NODE"
stop "$B"

# nothing runs: the error says where the address came from
if in_env "$SRC/launch/caliper" ctl address >"$WORK/none" 2>&1; then fail "ctl address without a session succeeded"
elif grep -q "the default (no running session of yours was found)" "$WORK/none"; then
  pass "without a session: $(grep -m1 -o 'the address is the default[^;]*' "$WORK/none")"
else cat "$WORK/none"; fail "the error without a session does not say why"; fi

# the naming service of `nameserver start` is found by itself
(launcher nameserver start) >"$WORK/ns" 2>"$WORK/ns.err" || { cat "$WORK/ns.err"; fail "nameserver start"; }
if in_env "$SRC/launch/caliper" ctl address 2>&1 | grep -q "nameserver start" &&
  grep -q 'eval' "$WORK/ns.err"; then
  pass "ctl finds the naming service of nameserver start; it says how to eval its export line"
else cat "$WORK/ns" "$WORK/ns.err"; fail "nameserver start's naming service"; fi
(launcher nameserver stop) >/dev/null 2>&1

# --port: a bad one is refused before anything starts
if (launcher session --headless --listen 127.0.0.1 --port 99999) >"$WORK/port" 2>&1; then
  fail "--port 99999 accepted"
else grep -q -- "--port needs a TCP port number" "$WORK/port" && pass "--port 99999 refused" ||
  { cat "$WORK/port"; fail "--port 99999: no reason"; }; fi

if (launcher session --headless --port 2809) >"$WORK/port2" 2>&1; then
  fail "--port without --listen accepted"
else grep -q -- "--port is for network mode" "$WORK/port2" && pass "--port without --listen refused" ||
  { cat "$WORK/port2"; fail "--port without --listen: no reason"; }; fi

# --physics-threads: a count of 0-8, refused otherwise before anything starts
for bad in 9 -1 two; do
  if (launcher session --headless --physics-threads "$bad") >"$WORK/threads" 2>&1; then
    fail "--physics-threads $bad accepted"
  else grep -q -- "--physics-threads needs a count of 0-8" "$WORK/threads" &&
    pass "--physics-threads $bad refused" ||
    { cat "$WORK/threads"; fail "--physics-threads $bad: no reason"; }; fi
done

finish

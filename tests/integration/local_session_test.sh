#!/usr/bin/env bash
# A local session is reachable only by its own user. Two Unix users made for the test: alice runs
# `launch/caliper session --headless` and a manager; mallory, on the same machine, tries to reach
# them. Checks: the session's processes listen on no TCP port, only on unix sockets (0600) in a
# directory only alice can enter (0700); alice's own tools (caliper-ctl, Python) work unchanged;
# mallory is refused by the naming service, the Model, the logger and the manager (through a
# naming service of her own holding their references, given to her by root), each with the
# message that says why; her raw connect() gets EACCES; a state directory she made for alice
# beforehand (/tmp/caliper-UID, to point alice's tools at a session of hers) is refused by the
# launcher. Needs root (useradd, runuser); without it the test is skipped (exit 77) and says why.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
ALICE=calip-alice MALLORY=calip-mallory
FAILS=0
skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }

[ "$(id -u)" = 0 ] || skip "a second Unix user needs root (useradd, runuser): run the tests as root, as CI does"
command -v useradd >/dev/null && command -v runuser >/dev/null || skip "no useradd/runuser (passwd, util-linux)"

WORK=$(mktemp -d)
chmod 755 "$WORK"
SESSION_PID=
cleanup() {
  [ -n "$SESSION_PID" ] && kill -TERM -- "-$SESSION_PID" 2>/dev/null
  for u in $ALICE $MALLORY; do
    pkill -KILL -u "$u" 2>/dev/null
  done
  sleep 0.3
  for u in $ALICE $MALLORY; do
    id "$u" >/dev/null 2>&1 || continue
    rm -rf "/tmp/caliper-$(id -u "$u")" "/tmp/caliper-$(id -u "$u")"-*
    userdel -r "$u" 2>/dev/null
  done
  rm -rf "$WORK"
}
trap cleanup EXIT
for u in $ALICE $MALLORY; do
  id "$u" >/dev/null 2>&1 && { pkill -KILL -u "$u"; userdel -r "$u" 2>/dev/null; }
  useradd -m -s /bin/bash "$u" || { echo "FAIL: useradd $u"; exit 1; }
done
BUILD=$(dirname "$BIN")
PY=$BUILD/python
# a command as USER, with a clean environment of that user
as() {
  local u=$1
  shift
  runuser -u "$u" -- env -i HOME="/home/$u" USER="$u" LOGNAME="$u" PATH=/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 CALIPER_NO_BUILD=1 CALIPER_BUILD_DIR="$BUILD" CALIPER_BIN_DIR="$BIN" \
    CALIPER_CONFIG_DIR="${CALIPER_CONFIG_DIR:-$SRC/config}" PYTHONPATH="$PY" "$@"
}
ALICE_UID=$(id -u $ALICE)
STATE=/tmp/caliper-$ALICE_UID

# ---------------------------------------------------------------- a squatted state directory
rm -rf "$STATE"
as $MALLORY mkdir -m 777 "$STATE"
out=$(as $ALICE timeout 30 bash "$SRC/launch/caliper" session --headless 2>&1)
if [ $? -ne 0 ] && grep -q "belongs to another user" <<<"$out"; then
  pass "the launcher refuses a state directory made by another user: $(grep -o 'error: .*' <<<"$out" | cut -c1-90)..."
else fail "a squatted $STATE was used: $out"; fi
rm -rf "$STATE"

# ---------------------------------------------------------------- alice's session and manager
setsid runuser -u $ALICE -- env -i HOME=/home/$ALICE USER=$ALICE LOGNAME=$ALICE PATH=/usr/bin:/bin \
  LANG=C.UTF-8 CALIPER_NO_BUILD=1 CALIPER_BUILD_DIR="$BUILD" \
  CALIPER_CONFIG_DIR="${CALIPER_CONFIG_DIR:-$SRC/config}" \
  bash "$SRC/launch/caliper" session --headless >"$WORK/session.out" 2>&1 &
SESSION_PID=$!
for _ in $(seq 1 150); do
  [ -s "$STATE/latest-session" ] && as $ALICE "$BIN/caliper-ctl" state model0 >/dev/null 2>&1 && break
  sleep 0.2
done
ADDR=$(sed -n 1p "$STATE/latest-session" 2>/dev/null)
SDIR=$(sed -n 3p "$STATE/latest-session" 2>/dev/null)
[ -n "$ADDR" ] || { cat "$WORK/session.out"; echo "FAIL: alice's session did not start"; exit 1; }
echo "alice's session: $ADDR"
as $ALICE "$BIN/caliper-manager" --nameservice "$ADDR" -o manager.max_models=1 \
  -o "log.spool_dir=/home/$ALICE/spool" >"$WORK/manager.out" 2>&1 &
for _ in $(seq 1 100); do as $ALICE "$BIN/caliper-ctl" state manager0 >/dev/null 2>&1 && break; sleep 0.1; done

case "$ADDR" in corbaname:omniunix:/*) pass "the naming service is on a unix socket" ;;
  *) fail "the session's naming service is not on a unix socket: $ADDR" ;; esac
mode() { stat -c %a "$1"; }
[ "$(mode "$SDIR")" = 700 ] && [ "$(mode "$SDIR/sock")" = 700 ] && [ "$(mode "$STATE")" = 700 ] &&
  pass "the session directory, its sock/ and the state directory are 0700" ||
  fail "modes: session $(mode "$SDIR"), sock $(mode "$SDIR/sock"), state $(mode "$STATE")"
socks=$(find "$SDIR/sock" "$STATE" -type s | wc -l)
open=$(find "$SDIR/sock" "$STATE" -type s ! -perm 600 | wc -l)
[ "$socks" -ge 4 ] && [ "$open" -eq 0 ] && pass "$socks sockets (naming service, logger, Model, manager), each 0600" ||
  fail "$socks sockets, $open not 0600: $(find "$SDIR/sock" "$STATE" -type s -ls)"
pids=$(pgrep -u $ALICE -f 'omniNames|caliper-' | tr '\n' ' ')
tcp=$(ss -ltnpH | grep -E "pid=($(tr ' ' '|' <<<"${pids% }"))," || true)
[ -n "$pids" ] && [ -z "$tcp" ] && pass "alice's $(wc -w <<<"$pids") processes listen on no TCP port" ||
  fail "alice's processes listen on TCP: $tcp (pids $pids)"

# ---------------------------------------------------------------- alice's tools work unchanged
out=$(as $ALICE "$BIN/caliper-ctl" ls 2>&1)
for n in logger0 model0 manager0; do
  grep -q "^$n " <<<"$out" || fail "alice's caliper-ctl ls misses $n: $out"
done
HOSTPATH=$(awk '$1 == "model0" {print $5}' <<<"$out")
as $ALICE "$BIN/caliper-ctl" step 100 >/dev/null 2>&1 &&
  steps=$(as $ALICE "$BIN/caliper-ctl" status 2>&1 | awk '/^steps/ {print $2}')
[ "${steps:-0}" = 100 ] && pass "alice's caliper-ctl (latest session found) steps her Model: $steps steps" ||
  fail "alice's caliper-ctl status says ${steps:-nothing}"
out=$(as $ALICE /usr/bin/python3 -c '
import caliper
m = caliper.connect().model("model0")
m.step(50)
print("python steps", m.status().steps)' 2>&1)
grep -q "python steps 150" <<<"$out" && pass "alice's Python client: $out" || fail "alice's Python: $out"

# ---------------------------------------------------------------- mallory is refused
why="reachable only by the user who started it"
out=$(as $MALLORY timeout 20 "$BIN/caliper-ctl" --nameservice "$ADDR" ls 2>&1)
if grep -q "$why" <<<"$out" && grep -q "$ALICE" <<<"$out" && grep -q "naming service" <<<"$out"; then
  pass "mallory's caliper-ctl ls is refused by the naming service: $(head -c 400 <<<"$out")"
else fail "mallory reached the naming service, or no reason: $out"; fi
out=$(as $MALLORY timeout 20 /usr/bin/python3 -c "
import caliper
try:
    caliper.connect('$ADDR').models()
    print('REACHED')
except caliper.ConnectionError as e:
    print(type(e).__name__, e)" 2>&1)
grep -q "ConnectionError" <<<"$out" && grep -q "$why" <<<"$out" && pass "mallory's Python: caliper.ConnectionError with the reason" ||
  fail "mallory's Python: $out"
out=$(as $MALLORY /usr/bin/python3 -c "
import socket
s = socket.socket(socket.AF_UNIX)
try:
    s.connect('${ADDR#corbaname:omniunix:}'); print('CONNECTED')
except OSError as e:
    print(e.__class__.__name__, e.errno)" 2>&1)
[ "$out" = "PermissionError 13" ] && pass "mallory's raw connect() to the naming socket: EACCES" || fail "mallory's raw connect: $out"

# the references, which root can read, handed to mallory's own naming service
HOSTCXT=${HOSTPATH%%/*}
MDIR=$(as $MALLORY mktemp -d /tmp/calip-m.XXXXXX)
as $MALLORY omniNames -start -always -nohostname -datadir "$MDIR" -ORBendPoint "giop:unix:$MDIR/ns.sock" \
  >"$WORK/mallory-ns.out" 2>&1 &
MNS=corbaname:omniunix:$MDIR/ns.sock
for _ in $(seq 1 50); do as $MALLORY nameclt -ORBInitRef "NameService=$MNS" list >/dev/null 2>&1 && break; sleep 0.1; done
as $MALLORY nameclt -ORBInitRef "NameService=$MNS" bind_new_context "$HOSTCXT" >/dev/null
for n in model0 logger0 manager0; do
  ior=$(nameclt -ORBInitRef "NameService=$ADDR" resolve "$HOSTCXT/$n.rtc" 2>/dev/null | grep -o 'IOR:[0-9a-f]*')
  [ -n "$ior" ] || { fail "root could not resolve $n in alice's session"; continue; }
  as $MALLORY nameclt -ORBInitRef "NameService=$MNS" bind "$HOSTCXT/$n.rtc" "$ior" >/dev/null
done
for n in model0 logger0 manager0; do
  out=$(as $MALLORY timeout 20 "$BIN/caliper-ctl" --nameservice "$MNS" --timeout 5 state "$n" 2>&1)
  if grep -q "$why" <<<"$out" && grep -q "$ALICE" <<<"$out"; then
    pass "alice's $n refuses mallory: $(grep -o "the object's unix socket [^,]*" <<<"$out")"
  else fail "mallory's state $n: $out"; fi
done
out=$(as $MALLORY timeout 20 "$BIN/caliper-ctl" --nameservice "$MNS" --timeout 5 status --model model0 2>&1)
grep -q "$why" <<<"$out" && pass "mallory's status on alice's Model: refused with the reason" || fail "mallory's status: $out"
steps=$(as $ALICE "$BIN/caliper-ctl" status 2>&1 | awk '/^steps/ {print $2}')
[ "$steps" = 150 ] && pass "alice's Model is untouched (150 steps)" || fail "alice's Model has $steps steps"

# ---------------------------------------------------------------- the session ends cleanly
# TERM to the launcher itself, as Ctrl-C or kill would (runuser, TERMed, KILLs its child)
kill -TERM "$(pgrep -u $ALICE -f 'launch/caliper session' | head -1)" 2>/dev/null
for _ in $(seq 1 100); do kill -0 "$SESSION_PID" 2>/dev/null || break; sleep 0.1; done
SESSION_PID=
left=$(find "$SDIR/sock" -type s | wc -l)
[ "$left" -eq 0 ] && pass "the session's sockets are gone after it stopped" ||
  fail "$left sockets left in $SDIR/sock: $(ls -l "$SDIR/sock"; pgrep -u $ALICE -a; tail -n 4 "$WORK/session.out")"

[ "$FAILS" -eq 0 ] || { echo "$FAILS check(s) failed"; exit 1; }
echo "all checks passed"

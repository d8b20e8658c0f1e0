#!/usr/bin/env bash
# The log directory's disk fills up: the session log is on a 1 MiB tmpfs mounted in a private mount
# namespace (`unshare -m`, so the host never sees it), filled to the last byte while a sample
# component logs 100 records/s with a spool bound of 0.05 MiB (log.spool_max) on another disk.
# Checks: the logger says so once, naming the file and the system's reason; it stays ACTIVE and
# answers queries; the sender's spool stays within its bound and the sender says it drops; nothing
# crashes; when space returns the logger says it writes again, the kept records arrive, the sender
# reports how many it dropped (exactly the gap in its sequence numbers), nothing is stored twice,
# and every line of the file is whole. Needs root (mount namespaces); skipped otherwise.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
skip() { echo "SKIPPED: $*"; exit 77; }
if [ -z "${CALIPER_IN_MOUNT_NS:-}" ]; then
  [ "$(id -u)" = 0 ] || skip "a tmpfs in a private mount namespace needs root (run the tests as root, as CI does)"
  command -v unshare >/dev/null || skip "no 'unshare' (util-linux)"
  unshare -m --propagation private true 2>/dev/null || skip "this kernel or container does not allow 'unshare -m'"
  exec unshare -m --propagation private env CALIPER_IN_MOUNT_NS=1 bash "$0" "$@"
fi

FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
WORK=$(mktemp -d)
LOGS=$WORK/logs
SPOOL=$WORK/spool
# shellcheck source=../../launch/naming.sh
source "$SRC/launch/naming.sh"
declare -a PIDS=()
cleanup() {
  local p
  for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done
  for p in "${PIDS[@]}"; do
    for _ in $(seq 1 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null
  done
  wait 2>/dev/null
  umount "$LOGS" 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT

mkdir -p "$LOGS" "$SPOOL"
mount -t tmpfs -o size=1m caliper-disk-full "$LOGS" || { echo "FAIL: cannot mount a tmpfs"; exit 1; }
if grep -q caliper-disk-full /proc/1/mounts; then fail "the tmpfs is visible outside the test's mount namespace"
else pass "a 1 MiB tmpfs for the log directory, private to the test"; fi

start_nameserver "$WORK/ns"
PIDS+=("$NS_PID")
COMMON=(--nameservice "$NS_ADDR" -o "log.spool_dir=$SPOOL" -o naming.update.interval=1)
ctl() { "$BIN/caliper-ctl" --nameservice "$NS_ADDR" --timeout 3 "$@"; }
"$BIN/caliper-logger" "${COMMON[@]}" -o "logger.directory=$LOGS" -o logger.session=full \
  -o exec.auto_activate=true >"$WORK/logger.out" 2>&1 &
LOGGER=$!
PIDS+=("$LOGGER")
for _ in $(seq 1 100); do ctl state logger0 2>/dev/null | grep -q ACTIVE && break; sleep 0.1; done
"$BIN/caliper-sample" "${COMMON[@]}" -o exec.auto_activate=true -o exec.rate=20 \
  -o sample.records_per_tick=5 -o log.spool_max=0.05 >"$WORK/sample.out" 2>&1 &
SAMPLE=$!
PIDS+=("$SAMPLE")
LOG=""
for _ in $(seq 1 100); do
  LOG=$(ls "$LOGS"/caliper-*-full.log 2>/dev/null | head -1)
  [ -n "$LOG" ] && grep -q "sample" "$LOG" && break
  sleep 0.1
done
[ -n "$LOG" ] || { cat "$WORK"/*.out; echo "FAIL: no session log"; exit 1; }

# ---------------------------------------------------------------- the disk fills up
dd if=/dev/zero of="$LOGS/filler" bs=4k 2>/dev/null
echo "note: filled $LOGS ($(df -k --output=avail "$LOGS" | tail -1 | xargs) KiB left)"
said_full() { grep -q "cannot write session log $LOG: No space left on device; records are refused" "$WORK/logger.out"; }
for _ in $(seq 1 50); do said_full && break; sleep 0.1; done
if said_full; then pass "the logger says so: $(grep -m1 'cannot write session log' "$WORK/logger.out" | cut -c1-160)..."
else tail -n 5 "$WORK/logger.out"; fail "the logger did not report the full disk"; fi
sleep 6  # 600 records, about 90 KiB: more than the sender's spool may hold
# the spool lies in the session's folder below log.spool_dir (a folder per naming service)
spool_bytes=$(cat "$SPOOL"/*/sample-"$SAMPLE".spool 2>/dev/null | wc -c)
BOUND=52428  # log.spool_max = 0.05 MiB
if [ "$spool_bytes" -gt $((BOUND / 2)) ] && [ "$spool_bytes" -le "$BOUND" ]; then
  pass "the sender's spool stays within its bound: $spool_bytes of $BOUND bytes"
else fail "the sender's spool holds $spool_bytes bytes (bound $BOUND)"; fi
grep -q "is at its bound of 0.05 MiB" "$WORK/sample.out" &&
  pass "the sender says it drops: $(grep -m1 'at its bound' "$WORK/sample.out" | cut -c1-120)..." ||
  fail "the sender did not say that it drops records"
if ctl state logger0 | grep -q ACTIVE && ctl log --limit 3 >/dev/null; then
  pass "the logger stays ACTIVE and answers queries"
else fail "the logger does not answer: $(ctl state logger0 2>&1)"; fi
kill -0 "$LOGGER" && kill -0 "$SAMPLE" && pass "nothing crashed" || fail "a process died"
gone_stored=$(grep -c . "$LOG")

# ---------------------------------------------------------------- space returns
rm -f "$LOGS/filler"
# the logger's last word on the file (a batch may still fit into the file's last page between two
# refused ones, so it can say both more than once while the disk is full)
last_word() { grep -E "cannot write session log|session log .* written again after" "$WORK/logger.out" | tail -n 1; }
said_back() { last_word | grep -q "session log $LOG written again after"; }
dropped_said() { grep -q "log records of this process were dropped" "$LOG"; }
for _ in $(seq 1 100); do said_back && dropped_said && break; sleep 0.1; done
said_back && pass "the logger writes again: $(last_word | sed 's/.*session log [^ ]* //') ($(grep -c 'cannot write session log' "$WORK/logger.out") refusal reports)" ||
  fail "the logger did not say that it writes again"
sleep 2
after=$(grep -c . "$LOG")
[ "$after" -gt "$gone_stored" ] && pass "logging resumed: $((after - gone_stored)) more lines" ||
  fail "nothing was written after space returned"
# the sample's records: the dropped ones are exactly the gap, the rest once and in order
src=$(awk -F'\t' '!/^#/ && $4 ~ /^sample/ {print $7; exit}' "$LOG")
reported=$(grep "log records of this process were dropped" "$LOG" | awk -F'\t' -v s="$src" '$7 == s {split($9, w, " "); n += w[1]} END {print n + 0}')
read -r count lo hi dup disorder < <(awk -F'\t' -v s="$src" '
  !/^#/ && $7 == s { seq = $8 + 0; if (seen[seq]++) dup++; if (seq < last) disorder++; last = seq; n++
                     if (!lo || seq < lo) lo = seq; if (seq > hi) hi = seq }
  END { print n + 0, lo + 0, hi + 0, dup + 0, disorder + 0 }' "$LOG")
missing=$((hi - lo + 1 - count))
echo "note: the sample's records: $count stored, seq $lo..$hi, $missing missing, $reported reported dropped"
if [ "$reported" -gt 0 ] && [ "$missing" = "$reported" ] && [ "$dup" = 0 ] && [ "$disorder" = 0 ] && [ "$lo" = 1 ]; then
  pass "every record kept arrived once and in order; the $reported dropped ones are reported"
else
  fail "the sample's records: $missing missing but $reported reported dropped, $dup duplicates, $disorder out of order"
fi
torn=$(awk -F'\t' '!/^#/ && NF != 9' "$LOG" | wc -l)
[ "$torn" = 0 ] && pass "every line of the session log is whole" || fail "$torn broken lines in the session log"
grep -E "terminate called|Segmentation|Aborted" "$WORK"/*.out && fail "a crash (above)"
echo "disk full: $FAILS failures"
[ "$FAILS" = 0 ]

#!/usr/bin/env bash
# Soak: a GUI session (tests/faults/session_lib.sh) with the PD controller at 1 kHz, the renderer,
# the plotter (2 curves, every step), the log viewer, the main window, a sample component logging
# once a second and a recording (caliper-ctl record of 3 ids every 10 steps) for --minutes M
# (default 10). Each process's resident memory (VmRSS), open file descriptors (/proc/PID/fd) and
# threads (/proc/PID/task) are read every 5 s. After the warm-up (a quarter of the run, at most
# 60 s) memory must stay flat, at most 5 MiB of growth from the start to the end of the measured
# part (each the median of three readings), and descriptors and threads must not grow: the median
# of the last third of the measured readings against the median of the first third, at most one
# more (omniORB opens a connection, a socket and the thread serving it, on demand and closes idle
# ones: a 10-minute run read the sample's threads 7 then 8). Prints one row per process and PASS or
# FAIL (fd0/fd1 and threads0/threads1 in the table are those medians).
#
# Bounded caches are filled during the warm-up so that they do not pass for growth: the plotter
# keeps 10,000 samples per curve (its layout's buffer), the logger 2,000 records in memory.
set -uo pipefail
MINUTES=10
KEEP=""
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) MINUTES=$2; shift 2 ;;
    --keep) KEEP=1; shift ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "usage: soak_test.sh [--minutes M] [--keep]"; exit 2 ;;
  esac
done
[[ "$MINUTES" =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "--minutes takes a number"; exit 2; }
CTRL_RATE=1000
# shellcheck source=session_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/session_lib.sh"
command -v ss >/dev/null || skip "no 'ss' (apt-get install iproute2)"
command -v bc >/dev/null || skip "no 'bc' (apt-get install bc)"
cleanup() {
  [ -z "${REC_PID:-}" ] || kill -INT "$REC_PID" 2>/dev/null
  stop_session
  [ -n "$KEEP" ] && echo "work directory: $WORK" || rm -rf "$WORK"
}
trap cleanup EXIT

TOTAL=$(echo "$MINUTES * 60 / 1" | bc)
WARMUP=$(echo "w = $TOTAL / 4; if (w > 60) w = 60; w" | bc)
SAMPLE_EVERY=5
[ "$TOTAL" -ge 40 ] || { echo "--minutes: at least 0.7 (40 s)"; exit 2; }

cat >"$WORK/plotter.ini" <<'INI'
[plotter]
layout="# caliper-plotter layout\nversion = 1\nwindow_s = 10\nbuffer_samples = 10000\nevery_n_steps = 1\n\n[plot]\nautoscale = true\ncurve = ecce_arm.elbow.position line\ncurve = ecce_arm.elbow_flexor.tendon.tension line\n"
INI
PLOTTER_ARGS=()  # the layout in the session file
SAMPLE_RATE=0.5   # one record a second
LOGGER_MEMORY=2000
start_session
[ "$FAILS" = 0 ] || { for f in "$WORK"/*.out; do echo "== $f"; tail -n 5 "$f"; done; exit 1; }
# the recording, until the end of the soak
"$BIN/caliper-ctl" --nameservice "$NS_ADDR" record ecce_arm.elbow.position \
  ecce_arm.elbow_flexor.tendon.tension ecce_arm.hand.position --every 10 \
  --csv "$WORK/record.csv" >"$WORK/record.out" 2>"$WORK/record.err" &
REC_PID=$!
PID[record]=$REC_PID
NAMES=(naming logger model controller sample renderer plotter logviewer main record)
echo "soak: $MINUTES min ($TOTAL s, warm-up $WARMUP s), controller at $CTRL_RATE Hz; readings every $SAMPLE_EVERY s"
steps0=$(model_steps)
steps0_at=$(now)

# readings: WORK/readings/NAME: lines "t rss_kib fds threads"
mkdir -p "$WORK/readings"
reading() {  # NAME T
  local p=${PID[$1]} rss fds threads
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$p/status" 2>/dev/null) || return
  fds=$(ls "/proc/$p/fd" 2>/dev/null | wc -l)
  threads=$(ls "/proc/$p/task" 2>/dev/null | wc -l)
  [ -n "$rss" ] && echo "$2 $rss $fds $threads" >>"$WORK/readings/$1"
}
START=$(now)
t=0
while [ "$t" -lt "$TOTAL" ]; do
  for n in "${NAMES[@]}"; do reading "$n" "$t"; done
  sleep "$SAMPLE_EVERY"
  t=$(printf '%.0f' "$(echo "$(now) - $START" | bc -l)")
done
for n in "${NAMES[@]}"; do reading "$n" "$t"; done
steps1=$(model_steps)
steps1_at=$(now)
kill -INT "$REC_PID"
wait "$REC_PID"
rec_rc=$?
REC_PID=""

# the table
# the median of integers, one a line (the lower middle of an even count)
median() { sort -n | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
printf '\n%-10s %8s %8s %8s %8s %6s %6s %8s %8s  %s\n' process "RSS0" "RSS1" "RSSmax" "growth" fd0 fd1 threads0 threads1 verdict
printf '%-10s %8s %8s %8s %8s %6s %6s %8s %8s\n' "" MiB MiB MiB MiB "" "" "" ""
dead=""
for n in "${NAMES[@]}"; do
  f=$WORK/readings/$n
  if ! kill -0 "${PID[$n]}" 2>/dev/null && [ "$n" != record ]; then dead="$dead $n"; fi
  measured=$(awk -v w="$WARMUP" '$1 >= w' "$f" 2>/dev/null)
  [ "$(wc -l <<<"$measured")" -ge 6 ] || { fail "$n: too few readings after the warm-up"; continue; }
  rss0=$(head -3 <<<"$measured" | awk '{print $2}' | median)
  rss1=$(tail -3 <<<"$measured" | awk '{print $2}' | median)
  rssmax=$(awk '{print $2}' <<<"$measured" | sort -n | tail -1)
  # descriptors and threads: the median of the last third of the measured readings against the
  # median of the first third (a spike early or late does not move a median; a slow leak does).
  # omniORB opens a connection (a socket and the thread serving it) on demand and closes idle
  # ones: one more is allowed, measured (the sample's threads 7 then 8 in a 10-minute run)
  third=$(($(wc -l <<<"$measured") / 3))
  fd0=$(head -n "$third" <<<"$measured" | awk '{print $3}' | median)
  fd1=$(tail -n "$third" <<<"$measured" | awk '{print $3}' | median)
  th0=$(head -n "$third" <<<"$measured" | awk '{print $4}' | median)
  th1=$(tail -n "$third" <<<"$measured" | awk '{print $4}' | median)
  growth=$((rss1 - rss0))
  verdict=ok
  [ "$growth" -le 5120 ] || verdict="RSS +$((growth / 1024)) MiB"
  [ "$fd1" -le $((fd0 + 1)) ] || verdict="$verdict fds +$((fd1 - fd0))"
  [ "$th1" -le $((th0 + 1)) ] || verdict="$verdict threads +$((th1 - th0))"
  verdict=${verdict#ok }
  mib() { echo "scale=1; $1 / 1024" | bc | sed 's/^\./0./; s/^-\./-0./'; }
  printf '%-10s %8s %8s %8s %8s %6s %6s %8s %8s  %s\n' "$n" "$(mib "$rss0")" "$(mib "$rss1")" \
    "$(mib "$rssmax")" "$(mib "$growth")" "$fd0" "$fd1" "$th0" "$th1" "$verdict"
  [ "$verdict" = ok ] || fail "$n: $verdict"
done
echo
[ -z "$dead" ] || fail "died during the soak:$dead"
rate=$(echo "($steps1 - $steps0) / ($steps1_at - $steps0_at)" | bc -l | xargs printf '%.1f')
if [ "$(echo "$rate > 950" | bc -l)" = 1 ]; then pass "the Model stepped $rate steps/s (real time: 1000)"
else fail "the Model stepped only $rate steps/s (real time: 1000)"; fi
rows=$(($(wc -l <"$WORK/record.csv") - 1))
echo "recording: $rows rows; $(tr '\r' '\n' <"$WORK/record.err" | grep -v '^recording: t =' | grep . | xargs)"
# caliper-ctl record ends with 0 when stopped by Ctrl-C and nothing went wrong
[ "$rec_rc" = 0 ] && [ "$rows" -gt $((TOTAL * 80)) ] && pass "the recording ran all along ($rows rows)" ||
  fail "the recording: exit $rec_rc, $rows rows (expected about $((TOTAL * 100)))"
stop_session
echo "soak: $([ "$FAILS" = 0 ] && echo PASS || echo "FAIL ($FAILS)")"
[ "$FAILS" = 0 ]

#!/usr/bin/env bash
# caliper-ctl recording and replay against real Models on a private loopback naming service: a
# recording with two channels, motor commands, a parameter write and an edit verifies bit for
# bit; --info and --csv report it with units; replayed in the Model, the DAQ recorder (`record`,
# the Graph Plotter's interface) gets the recorded values; seek back and forth; fork accepts
# commands; a Model killed with SIGKILL while recording leaves a file that opens and holds its
# last 0.5 s; a recording whose scene was replaced is refused naming the file; a size limit ends
# a recording with the reason while the simulation runs on.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
# shellcheck source=support/checks.sh
source "$SRC/tests/integration/support/checks.sh"
# shellcheck source=../../launch/local_models.sh
source "$SRC/launch/local_models.sh"
WORK=$(mktemp -d)
trap 'local_models_stop; rm -rf "$WORK"' EXIT
# the Models write recordings only below their write directory
mkdir -p "$WORK/files"
export CALIPER_FILES_DIR=$WORK/files
local_models_start "$WORK" 1
ctl() { timeout 60 "$BIN/caliper-ctl" "$@"; }
F=$WORK/files
field() { awk -v k="$1" 'index($0, k) == 1 {print $NF; exit}'; }  # LABEL: the line's last word

ctl load "$SRC/models/ecce_arm.dae" >/dev/null || fail "load"

# ------------------------------------------------------------------ a refused path, a recording
if ctl recording start "$WORK/outside.caliper" >"$WORK/out" 2>&1; then fail "recorded outside the write dir"
elif grep -q "only below its write directory $F" "$WORK/out"; then pass "refused outside: $(head -1 "$WORK/out" | cut -c1-100)"
else cat "$WORK/out"; fail "no reason for the refused path"; fi

CH1=ecce_arm.elbow.position
CH2=ecce_arm.elbow_flexor.tension
# a name without a directory starts from the write directory and gets the one extension .caliper
ctl recording start run --channel $CH1 --channel $CH2 >"$WORK/out" 2>&1 ||
  { cat "$WORK/out"; fail "recording start"; }
grep -q "^model0: recording to $F/run.caliper$" "$WORK/out" &&
  pass "recording start run: into the write directory as run.caliper" ||
  { cat "$WORK/out"; fail "recording start run: not $F/run.caliper"; }
grep -q "^recording  *yes" "$WORK/out" && pass "recording started" || fail "not recording"
ctl motor elbow_flexor 3 >/dev/null && ctl step 300 >/dev/null || fail "command, step"
ctl set ecce_arm.elbow_extensor.stiffness 4000 >/dev/null && ctl step 300 >/dev/null ||
  fail "parameter write, step"
ctl edit mass forearm 0.8 >/dev/null && ctl step 400 >/dev/null || fail "edit, step"
ctl motor elbow_flexor -2 >/dev/null && ctl step 9000 >/dev/null || fail "command, step"
ctl recording stop >"$WORK/stop" 2>&1 || { cat "$WORK/stop"; fail "recording stop"; }
steps=$(field "steps recorded" <"$WORK/stop")
seconds=$(field "simulated time recorded" <"$WORK/stop")
bytes=$(awk '/^size/ {print $3}' "$WORK/stop")
per_min=$(field "bytes per simulated minute" <"$WORK/stop")
[ "$steps" = 10000 ] && [ "$seconds" = 10 ] && [ "$bytes" = "$(stat -c %s "$F/run.caliper")" ] &&
  pass "stop: $steps steps, $seconds s, $bytes bytes, $per_min bytes per simulated minute" ||
  { cat "$WORK/stop"; fail "stop's numbers"; }

# ------------------------------------------------------------------ the file alone
ctl replay --verify "$F/run.caliper" >"$WORK/verify" 2>"$WORK/verify.err"
rc=$?
if [ $rc = 0 ] && grep -q "^identical: 10000 steps, [0-9]* keyframes, 10000 samples compared bit for bit" "$WORK/verify"; then
  pass "verify: $(cat "$WORK/verify"); $(tail -1 "$WORK/verify.err")"
else cat "$WORK/verify" "$WORK/verify.err"; fail "verify (exit $rc)"; fi

ctl replay --info "$F/run.caliper" >"$WORK/info" 2>&1 || { cat "$WORK/info"; fail "--info"; }
grep -q "^model  *ecce_arm$" "$WORK/info" && grep -q "^duration \[s\]  *10$" "$WORK/info" &&
  grep -q "^steps  *10000 (0 to 10000)" "$WORK/info" && grep -q "^keyframes  *10[0-9] (every 100" "$WORK/info" &&
  grep -q "^  $CH1 \[rad\]$" "$WORK/info" && grep -q "^  $CH2 \[N\]$" "$WORK/info" &&
  grep -q "^events  *2 command, 1 edit, .*1 parameter" "$WORK/info" &&
  grep -q "(and 1 edited versions)" "$WORK/info" &&
  pass "--info: $(grep -E '^(events|bytes per)' "$WORK/info" | tr -s ' ' | paste -sd';')" ||
  { cat "$WORK/info"; fail "--info's content"; }

ctl replay --csv "$F/run.caliper" "$WORK/run.csv" >/dev/null 2>&1 || fail "--csv"
[ "$(head -1 "$WORK/run.csv")" = "time [s],$CH1 [rad],$CH2 [N]" ] &&
  [ "$(wc -l <"$WORK/run.csv")" = 10001 ] && pass "--csv: $(head -1 "$WORK/run.csv"), 10000 rows" ||
  { head -2 "$WORK/run.csv"; fail "--csv columns"; }

# ------------------------------------------------------------------ replay in the Model
ctl replay "$F/run.caliper" >"$WORK/open" 2>&1 || { cat "$WORK/open"; fail "replay FILE"; }
grep -q "^time / end \[s\]  *0 / 10$" "$WORK/open" && pass "replay opened at 0 of 10 s" ||
  { cat "$WORK/open"; fail "replay status after open"; }
if ctl motor elbow_flexor 1 >"$WORK/out" 2>&1; then fail "a command during a replay was accepted"
elif grep -q "replays .*fork" "$WORK/out"; then pass "command refused while replaying: $(cut -c1-90 "$WORK/out")"
else cat "$WORK/out"; fail "the refusal does not say the Model replays"; fi

# the DAQ recorder while stepping through the replay: the recorded values, bit for bit
ctl record $CH1 $CH2 --csv "$WORK/daq.csv" --duration 1.5 >/dev/null 2>"$WORK/daq.err" &
rec=$!
for _ in $(seq 1 50); do grep -q "samples come once it runs" "$WORK/daq.err" && break; sleep 0.1; done
ctl step 1600 >/dev/null || fail "step through the replay"
wait $rec || { cat "$WORK/daq.err"; fail "record during the replay"; }
if python3 - "$WORK/daq.csv" "$WORK/run.csv" >"$WORK/cmp" 2>&1 <<'EOF'
import csv, sys
daq = list(csv.reader(open(sys.argv[1])))
recorded = list(csv.reader(open(sys.argv[2])))
assert daq[0] == recorded[0], (daq[0], recorded[0])
rec = {row[0]: row[1:] for row in recorded[1:]}
rows = daq[1:]
assert len(rows) == 1500, len(rows)
for row in rows:
    assert [float(v) for v in row[1:]] == [float(v) for v in rec[row[0]]], (row, rec.get(row[0]))
print(f"{len(rows)} samples equal, t = {rows[0][0]} .. {rows[-1][0]} s")
EOF
then pass "record during the replay: $(cat "$WORK/cmp")"
else cat "$WORK/cmp"; fail "the DAQ's values differ from the recording's"; fi

# seek back and forth
seek_time() { ctl replay seek "$1" | awk '/^time \/ end/ {print $5}'; }
t1=$(seek_time 7.25) t2=$(seek_time 0.42) t3=$(seek_time 99) t4=$(seek_time 0.5)
[ "$t1" = 7.25 ] && [ "$t2" = 0.42 ] && [ "$t3" = 10 ] && [ "$t4" = 0.5 ] &&
  pass "seek 7.25, 0.42, 99 (clamped), 0.5: $t1 $t2 $t3 $t4 s" || fail "seek: $t1 $t2 $t3 $t4"
[ "$(ctl replay status | awk '/^step \/ last/ {print $4}')" = 500 ] && pass "replay status: step 500" ||
  fail "replay status after seek"
# after a seek the replay goes on as recorded: the next step's value is the file's
ctl step 1 >/dev/null
got=$(ctl get $CH2 | awk '{print $3}')
want=$(awk -F, 'NR == 502 {printf "%.7g", $3}' "$WORK/run.csv")  # step 501 (header, steps 1..)
[ -n "$got" ] && [ "$got" = "$want" ] && pass "after the seek, t = 0.501 s: $CH2 = $got N as recorded" ||
  fail "after the seek: $CH2 = '$got', recorded '$want'"

# a copy outside the Model's directories (yesterday's session, another disk) goes by content
cp "$F/run.caliper" "$WORK/yesterday.caliper"
ctl replay "$WORK/yesterday.caliper" >"$WORK/open" 2>&1 || { cat "$WORK/open"; fail "replay by content"; }
grep -q "replaying $WORK/yesterday.caliper (sent by content)" "$WORK/open" &&
  grep -q "^time / end \[s\]  *0 / 10$" "$WORK/open" &&
  pass "a recording outside the Model's directories replays by content: $(head -1 "$WORK/open" | cut -c1-110)" ||
  { cat "$WORK/open"; fail "replay of a file outside the Model's directories"; }
# a name that is no file here is the Model's: relative, from its write directory (as recording
# start names it)
(cd "$WORK" && ctl replay run.caliper) >"$WORK/open" 2>&1 || { cat "$WORK/open"; fail "replay NAME"; }
grep -q "replaying $F/run.caliper (paused" "$WORK/open" &&
  pass "replay run.caliper: the Model's $F/run.caliper, by path" ||
  { cat "$WORK/open"; fail "replay run.caliper did not open the write directory's file"; }
ctl replay seek 0.5 >/dev/null && ctl step 1 >/dev/null || fail "back to the replay by path"

ctl replay fork >/dev/null 2>&1 || fail "fork"
ctl motor elbow_flexor 1 >/dev/null 2>&1 && ctl step 10 >/dev/null 2>&1 &&
  pass "fork at 0.501 s: a command is accepted, steps go on" || fail "command after fork"
[ "$(ctl replay status | awk '/^replaying/ {print $2}')" = no ] || fail "still replaying after fork"

# ------------------------------------------------------------------ a replaced scene is refused
python3 - "$F/run.caliper" "$F/changed.caliper" "$SRC/models/pendulum_tendon.dae" <<'EOF'
import shutil, sqlite3, sys
shutil.copy(sys.argv[1], sys.argv[2])
db = sqlite3.connect(sys.argv[2])
db.execute("UPDATE scenes SET data = ?", (open(sys.argv[3], "rb").read(),))
db.commit()
EOF
if ctl replay "$F/changed.caliper" >"$WORK/out" 2>&1; then fail "a recording of another scene replayed"
elif grep -q "changed.caliper" "$WORK/out"; then pass "replaced scene refused: $(head -1 "$WORK/out" | cut -c1-140)"
else cat "$WORK/out"; fail "the refusal does not name the file"; fi

# ------------------------------------------------------------------ the session's log
# a Logging component joins; the Model listens to it (within its 2 s check), so a recording holds
# every component's records: here those of a second Model that starts while recording
"$BIN/caliper-logger" -o logger.directory="$WORK/logs" -o log.spool_dir="$WORK/spool" \
  >>"$WORK/logger.out" 2>&1 &
LOCAL_MODELS_PIDS+=($!)
for _ in $(seq 1 100); do ctl state logger0 >/dev/null 2>&1 && break; sleep 0.1; done
sleep 2.5  # the Model's next look for the Logging component
ctl recording start "$F/with_log.caliper" >/dev/null 2>&1 || fail "recording start (log)"
local_models_add "$WORK"
logged_model=$LOCAL_MODEL_PID
for _ in $(seq 1 100); do ctl state model1 >/dev/null 2>&1 && break; sleep 0.1; done
ctl step 50 >/dev/null
sleep 1.5  # the records reach the logger and its listeners
ctl recording stop >/dev/null || fail "recording stop (log)"
kill -TERM "$logged_model" 2>/dev/null; wait "$logged_model" 2>/dev/null
components=$(python3 -c "
import sqlite3, sys
db = sqlite3.connect('file:' + sys.argv[1] + '?mode=ro', uri=True)
print(' '.join(sorted({c for (c,) in db.execute('SELECT component FROM log')})))" "$F/with_log.caliper")
if echo " $components " | grep -q " model1 "; then
  pass "the recording holds the session log: records of $components"
else fail "the recording's log has records of '$components', none of model1"; fi

# ------------------------------------------------------------------ a size limit, a full disk
# records FILE with two channels at full speed until the recording stops by itself; then the
# reason must match PATTERN and the simulation must still be stepping
fills_up() {  # LABEL FILE PATTERN [recording start options]
  local label=$1 file=$2 pattern=$3 why="" s1 s2
  shift 3
  ctl load "$SRC/models/ecce_arm.dae" >/dev/null || fail "$label: load"
  ctl rtf 0 >/dev/null || fail "$label: rtf 0"
  ctl recording start "$file" --channel $CH1 --channel $CH2 "$@" >/dev/null 2>&1 ||
    fail "$label: recording start"
  ctl start >/dev/null || fail "$label: start"
  for _ in $(seq 1 150); do
    why=$(ctl recording status | sed -n 's/^error  *//p')
    [ -n "$why" ] && [ "$why" != "-" ] && break
    sleep 0.1
  done
  s1=$(ctl status | awk '/^steps/ {print $2}')
  sleep 0.3
  s2=$(ctl status | awk '/^steps/ {print $2}')
  if echo "$why" | grep -qi "$pattern" && [ "$s2" -gt "$s1" ]; then
    pass "$label: '$(echo "$why" | cut -c1-110)'; the simulation ran on ($s1 -> $s2 steps)"
  else fail "$label: error '$why', steps $s1 -> $s2"; fi
  ctl stop >/dev/null
}
fills_up "--max-mb 1" "$F/full.caliper" "limit" --max-mb 1

# a disk that is really full: a 1 MB tmpfs inside the write directory (mounting needs root, which
# CI has)
if [ "$(id -u)" = 0 ] && mkdir -p "$F/tiny" && mount -t tmpfs -o size=1m tmpfs "$F/tiny" 2>/dev/null; then
  trap 'umount "$F/tiny" 2>/dev/null; local_models_stop; rm -rf "$WORK"' EXIT
  fills_up "a full disk" "$F/tiny/full.caliper" "disk full"
  ctl replay --info "$F/tiny/full.caliper" >"$WORK/full" 2>&1 &&
    pass "the full disk's file opens: $(grep -m1 duration "$WORK/full")" ||
    { cat "$WORK/full"; fail "the full disk's file does not open"; }
  umount "$F/tiny" || fail "umount"
else
  echo "note: the real full disk part needs root to mount a tmpfs; the size limit above stands in"
fi

# ------------------------------------------------------------------ SIGKILL while recording
local_models_add "$WORK"
victim=$LOCAL_MODEL_PID
for _ in $(seq 1 100); do ctl state model1 >/dev/null 2>&1 && break; sleep 0.1; done
ctl load "$SRC/models/ecce_arm.dae" --model model1 >/dev/null || fail "load model1"
ctl recording start "$F/killed.caliper" --channel $CH1 --model model1 >/dev/null || fail "start model1"
ctl start --model model1 >/dev/null || fail "start model1"
sleep 2
at_kill=$(ctl status --model model1 | awk '/^simulated time/ {print $4}')
kill -KILL "$victim"
wait "$victim" 2>/dev/null
ctl replay --info "$F/killed.caliper" >"$WORK/killed" 2>&1 || { cat "$WORK/killed"; fail "the killed Model's file"; }
last=$(field "duration" <"$WORK/killed")
if awk -v a="$at_kill" -v l="$last" 'BEGIN {exit !(l > 0 && a - l <= 0.75 && l <= a + 0.1)}'; then
  pass "kill -9 at t = $at_kill s: the file opens and ends at $last s (lost $(awk -v a="$at_kill" -v l="$last" 'BEGIN {print a - l}') s)"
else cat "$WORK/killed"; fail "after kill -9: status said $at_kill s, the file ends at $last s"; fi

finish

# A whole GUI session for the fault and soak suites, sourced by tests/faults/*.sh: a private
# omniNames on a free loopback port, the logger, the Model with the shipped arm running in real
# time, the PD controller, a sample component logging steadily, the renderer, the plotter, the log
# viewer and the main window, each a process of its own whose pid is kept by name, so that a test
# can kill, stop and restart them one at a time as a supervisor would. Needs an X display (an own
# Xvfb is started when there is none) and the programs of a build (CALIPER_BIN_DIR).
#
# Every process listens on a unix socket only (the components' default endpoint, omniNames on
# sock/naming.sock in a directory only this user can enter): nothing is reachable from another
# host or user. A process is told by its socket, as the Model and the logger name their clients
# (client unix:SOCKET).

BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
WORK=${WORK:-$(mktemp -d)}
INTERVAL=${INTERVAL:-1}       # naming.update.interval and renderer.check_interval [s]
CTRL_RATE=${CTRL_RATE:-100}   # the controller's execution context [Hz]
SAMPLE_RATE=${SAMPLE_RATE:-20}        # the sample component's ticks [Hz], 2 records each
LOGGER_MEMORY=${LOGGER_MEMORY:-200000}  # logger.memory_records
# the plotter's plots (the soak gives a layout with a bounded buffer in the session file instead)
PLOTTER_ARGS=(--ids ecce_arm.elbow.position,ecce_arm.elbow_flexor.tendon.tension)
FAILS=0
declare -A PID=()

# shellcheck source=../../launch/naming.sh
source "$SRC/launch/naming.sh"

fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
note() { echo "note: $*"; }
skip() { echo "SKIPPED: $*"; exit 77; }
now() { date +%s.%N; }
elapsed() { echo "$(now) - $1" | bc -l | xargs printf '%.2f'; }  # seconds since START
ctl() { "$BIN/caliper-ctl" --nameservice "$NS_ADDR" --timeout 3 "$@"; }

# an X display: the one given, else an own Xvfb (sets XVFB_PID)
XVFB_PID=""
need_display() {
  [ -n "${DISPLAY:-}" ] && return 0
  command -v Xvfb >/dev/null || skip "no DISPLAY and no Xvfb (apt-get install xvfb): the renderer needs GLX"
  local fifo display=""
  fifo=$WORK/xvfb.fifo
  mkfifo "$fifo"
  Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$fifo" >"$WORK/xvfb.out" 2>&1 &
  XVFB_PID=$!
  read -r -t 10 display <"$fifo" || true
  rm -f "$fifo"
  [ -n "$display" ] || { echo "FAIL: Xvfb did not start (see $WORK/xvfb.out)"; exit 1; }
  export DISPLAY=:$display
}

# the naming service on NS_PORT (a free one the first time) with a fresh database in DIR
start_naming() {  # DIR
  if [ -z "${NS_PORT:-}" ]; then
    # the same socket every time (CALIPER_SOCKET_DIR stays), a fresh database
    start_nameserver "$1"
  else
    mkdir -p "$1"
    omniNames -start "$NS_PORT" -always -nohostname -datadir "$1" \
      -ORBendPoint "giop:tcp:127.0.0.1:$NS_PORT" >>"$WORK/omninames.log" 2>&1 &
    NS_PID=$!
    for _ in $(seq 1 100); do naming_answers "$NS_ADDR" && break; sleep 0.1; done
  fi
  PID[naming]=$NS_PID
}

COMMON=()
# starts NAME (logger, model, controller, sample, renderer, plotter, logviewer, main); its output
# goes to WORK/NAME.out (appended: a restart keeps the earlier lines)
start() {  # NAME
  local name=$1
  local -a cmd
  case "$name" in
    logger) cmd=("$BIN/caliper-logger" "${COMMON[@]}" -o "logger.directory=$LOG_DIR"
                 -o logger.session=faults -o exec.auto_activate=true
                 -o "logger.memory_records=$LOGGER_MEMORY") ;;
    model) cmd=("$BIN/caliper-model" "${COMMON[@]}" -o "model.scene=$SRC/models/ecce_arm.dae"
                -o exec.auto_activate=true -o model.autostart=true -o model.real_time_factor=1) ;;
    controller) cmd=("$BIN/caliper-pd-controller" "${COMMON[@]}" -o exec.auto_activate=true
                     -o "exec.rate=$CTRL_RATE" -o controller.target=1.0) ;;
    sample) cmd=("$BIN/caliper-sample" "${COMMON[@]}" -o exec.auto_activate=true
                 -o "exec.rate=$SAMPLE_RATE" -o sample.records_per_tick=2) ;;
    renderer) cmd=("$BIN/caliper-renderer" "${COMMON[@]}" -o "renderer.check_interval=$INTERVAL") ;;
    plotter) cmd=("$BIN/caliper-plotter" --nameservice "$NS_ADDR" --session "$WORK/plotter.ini"
                  "${PLOTTER_ARGS[@]}") ;;
    logviewer) cmd=("$BIN/caliper-logviewer" --nameservice "$NS_ADDR" --session "$WORK/logviewer.ini") ;;
    main) cmd=(env "CALIPER_MAIN_SETTINGS=$WORK/main.ini" "$BIN/caliper-main"
               --nameservice "$NS_ADDR" --no-tools) ;;
    *) echo "FAIL: no process called $name"; return 1 ;;
  esac
  "${cmd[@]}" >>"$WORK/$name.out" 2>&1 &
  PID[$name]=$!
}

# the unix socket a process listens on (its ORB's endpoint), "" while it has none
socket_of() {  # PID
  ss -lxpH 2>/dev/null | awk -v p="pid=$1," 'index($0, p) { print $5; exit }'
}

# the session log
session_log() { ls "$LOG_DIR"/caliper-*-faults.log 2>/dev/null | head -1; }
log_has() { local f; f=$(session_log); [ -n "$f" ] && grep -qF -- "$1" "$f"; }

# waits up to SECONDS for COMMAND to succeed; prints the time it took, returns 1 on timeout
wait_until() {  # SECONDS COMMAND...
  local limit=$1 start
  shift
  start=$(now)
  while ! "$@" >/dev/null 2>&1; do
    if [ "$(echo "$(now) - $start > $limit" | bc -l)" = 1 ]; then
      elapsed "$start"
      return 1
    fi
    sleep 0.1
  done
  elapsed "$start"
}

# a component is bound in the naming service and served by PID
bound_as() {  # INSTANCE PID
  ctl ls 2>/dev/null | awk -v i="$1" -v p="$2" '$1 == i && $4 == p {f = 1} END {exit !f}'
}

# the Model registered a subscription, an observer, or the logger a listener, of the process PID
subscribed() { local p; p=$(socket_of "$1"); [ -n "$p" ] && log_has "added (client unix:$p)"; }
# as above, but a line after the first N lines of the session log
subscribed_after() {  # PID LINES
  local p f
  p=$(socket_of "$1"); f=$(session_log)
  [ -n "$p" ] && [ -n "$f" ] && tail -n +"$(($2 + 1))" "$f" | grep -qF "added (client unix:$p)"
}
log_lines() { local f; f=$(session_log); [ -n "$f" ] && wc -l <"$f" || echo 0; }

# the process is up: its ORB listens, or (a client only, the main window) it holds a connection
up() {  # PID
  [ -n "$(socket_of "$1")" ] ||
    ss -xpH state established 2>/dev/null | awk -v p="pid=$1," 'index($0, p) {f = 1} END {exit !f}'
}

# the process holds a connection to the Model (the main window polls its status)
connected_to_model() {  # PID
  local ms
  ms=$(socket_of "${PID[model]}")
  # the Model's ends of its connections (its socket's path, their inodes), and a connection of
  # PID whose peer is one of them (ss -x with one state: netid, queues, local path, local inode,
  # peer path, peer inode)
  [ -n "$ms" ] && ss -xpH state established 2>/dev/null |
    awk -v p="pid=$1," -v m="pid=${PID[model]}," -v path="$ms" '
      index($0, m) && $4 == path {model[$5] = 1}
      index($0, p) {peer[$7] = 1}
      END {for (i in peer) if (i in model) exit 0; exit 1}'
}

model_steps() { ctl status 2>/dev/null | awk '$1 == "steps" {print $2}'; }

# the Model's steps per wall second over SECONDS (from its status, twice)
step_rate() {  # SECONDS
  local s0 t0 s1 t1
  s0=$(model_steps); t0=$(now)
  sleep "$1"
  s1=$(model_steps); t1=$(now)
  [ -n "$s0" ] && [ -n "$s1" ] || { echo 0; return; }
  echo "($s1 - $s0) / ($t1 - $t0)" | bc -l | xargs printf '%.1f'
}

# every process up: components bound, the renderer observing, the plotter subscribed, the log
# viewer listening, the main window talking to the Model
start_session() {
  need_display
  LOG_DIR=${LOG_DIR:-$WORK/logs}
  start_naming "$WORK/names"
  COMMON=(--nameservice "$NS_ADDR" -o "log.spool_dir=$WORK/spool" -o "naming.update.interval=$INTERVAL")
  start logger
  wait_until 20 bound_as logger0 "${PID[logger]}" >/dev/null || { echo "FAIL: the logger did not start"; exit 1; }
  start model
  wait_until 20 bound_as model0 "${PID[model]}" >/dev/null || { echo "FAIL: the Model did not start"; exit 1; }
  local p
  for p in controller sample renderer plotter logviewer main; do start "$p"; done
  local t
  t=$(wait_until 60 bound_as pd_controller0 "${PID[controller]}") || fail "the controller did not register ($t s)"
  t=$(wait_until 60 bound_as sample0 "${PID[sample]}") || fail "the sample component did not register ($t s)"
  t=$(wait_until 60 subscribed "${PID[renderer]}") || fail "the renderer did not observe the Model ($t s)"
  t=$(wait_until 60 subscribed "${PID[plotter]}") || fail "the plotter did not subscribe ($t s)"
  t=$(wait_until 60 subscribed "${PID[logviewer]}") || fail "the log viewer did not listen ($t s)"
  t=$(wait_until 60 connected_to_model "${PID[main]}") || fail "the main window did not reach the Model ($t s)"
  [ "$FAILS" = 0 ] || { for f in "$WORK"/*.out; do echo "== $f"; tail -n 5 "$f"; done; exit 1; }
}

# TERM to every process (newest components first, so that their last records reach the logger),
# then the naming service and the Xvfb of our own
stop_session() {
  local name p
  for name in main logviewer plotter renderer sample controller model logger naming; do
    p=${PID[$name]:-}
    [ -n "$p" ] || continue
    kill -CONT "$p" 2>/dev/null
    kill -TERM "$p" 2>/dev/null || continue
    for _ in $(seq 1 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$p" 2>/dev/null && { note "$name (pid $p) ignored TERM: killed"; kill -KILL "$p" 2>/dev/null; }
    unset "PID[$name]"
  done
  if [ -n "$XVFB_PID" ]; then
    kill "$XVFB_PID" 2>/dev/null
    wait "$XVFB_PID" 2>/dev/null
  fi
  XVFB_PID=""
}

# every record of the session log once: per source, no sequence number twice, none missing
# between the first and the last, in increasing order; prints a summary line
check_records() {
  local f
  f=$(session_log)
  [ -n "$f" ] || { fail "no session log in $LOG_DIR"; return; }
  local out
  out=$(awk -F'\t' '
    /^#/ { next }
    { n++; src = $7; seq = $8 + 0
      if (seq == 0) next
      if ((src, seq) in seen) { dup++; if (dups < 5) { dups++; print "duplicate: " src " " seq > "/dev/stderr" } }
      seen[src, seq] = 1
      if (src in last && seq < last[src]) disorder++
      last[src] = seq; cnt[src]++
      if (!(src in lo) || seq < lo[src]) lo[src] = seq
      if (!(src in hi) || seq > hi[src]) hi[src] = seq }
    END { for (s in cnt) { sources++
            if (lo[s] != 1) { late++; print "source " s " starts at " lo[s] > "/dev/stderr" }
            if (hi[s] - lo[s] + 1 > cnt[s]) { gaps += hi[s] - lo[s] + 1 - cnt[s]; print "source " s ": " hi[s] - lo[s] + 1 - cnt[s] " missing" > "/dev/stderr" } }
          printf "%d %d %d %d %d %d\n", n, sources, dup + 0, gaps + 0, disorder + 0, late + 0 }' "$f" 2>"$WORK/records.err")
  local n sources dup gaps disorder late
  read -r n sources dup gaps disorder late <<<"$out"
  if [ "$dup" = 0 ] && [ "$gaps" = 0 ] && [ "$disorder" = 0 ] && [ "$late" = 0 ]; then
    pass "session log: $n records from $sources sources, each once, no gaps, in order per source"
  else
    head -n 20 "$WORK/records.err"
    fail "session log: $n records from $sources sources: $dup duplicates, $gaps missing, $disorder out of order, $late sources not starting at 1"
  fi
}

#!/usr/bin/env bash
# Faults on a running GUI session (tests/faults/session_lib.sh: naming service, logger, the Model
# with the shipped arm stepping in real time, PD controller, a logging sample component, renderer,
# plotter, log viewer, main window):
#  - SIGSTOP of an observer (the renderer) and of a DAQ subscriber (the plotter) for --freeze S
#    seconds (default 30): the Model steps at most 5 % slower than just before, and the frozen
#    peer is served again within two intervals of SIGCONT;
#  - SIGKILL, in turn, of the renderer, main window, plotter, log viewer, logger, controller and
#    naming service, each restarted as a supervisor would (the naming service on its port with an
#    empty database): each is back within two intervals of being up (components bound again, the
#    renderer observing, the plotter subscribed, the log viewer listening, the main window
#    talking to the Model), the log viewer listens again to a restarted logger, every component
#    registers again in a restarted naming service, and the Model never stops stepping;
#  - at the end the session log holds every record once: per source no sequence number twice, none
#    missing, in order.
# The interval is naming.update.interval = renderer.check_interval = 1 s (the log viewer looks
# for its logger every 1 s). Options: --freeze S, --keep (leave the work directory).
set -uo pipefail
FREEZE=30
KEEP=""
while [ $# -gt 0 ]; do
  case "$1" in
    --freeze) FREEZE=$2; shift 2 ;;
    --keep) KEEP=1; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "usage: fault_test.sh [--freeze S] [--keep]"; exit 2 ;;
  esac
done
[[ "$FREEZE" =~ ^[0-9]+$ ]] && [ "$FREEZE" -ge 3 ] || { echo "--freeze takes whole seconds, at least 3"; exit 2; }
# shellcheck source=session_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/session_lib.sh"
command -v ss >/dev/null || skip "no 'ss' (apt-get install iproute2): the test finds each process's port with it"
command -v bc >/dev/null || skip "no 'bc' (apt-get install bc)"
cleanup() { stop_session; [ -n "$KEEP" ] && echo "work directory: $WORK" || rm -rf "$WORK"; }
trap cleanup EXIT

START=$(now)
start_session
pass "session up in $(elapsed "$START") s: $(ctl ls | tail -n +2 | awk '{print $1}' | xargs)"
BACK=$((2 * INTERVAL))  # what "within two intervals" allows [s]

# ---------------------------------------------------------------- freezes
# steps/s before and while PEER is stopped; the peer is served again after SIGCONT
freeze() {  # NAME WHAT (observer|subscription)
  local name=$1 what=$2 before during lines t
  before=$(step_rate "$FREEZE")
  lines=$(log_lines)
  kill -STOP "${PID[$name]}"
  during=$(step_rate "$FREEZE")
  kill -CONT "${PID[$name]}"
  local port
  port=$(socket_of "${PID[$name]}")
  note "$name stopped for $FREEZE s: the Model stepped $before steps/s before, $during while it was stopped"
  if [ "$(echo "$during >= 0.95 * $before && $before > 0" | bc -l)" = 1 ]; then
    pass "the Model kept stepping while the $name was stopped ($during vs $before steps/s)"
  else
    fail "the Model slowed down while the $name was stopped: $during vs $before steps/s"
  fi
  # the Model logged that the push failed, and then that it answers again
  served_again() {
    tail -n +"$((lines + 1))" "$(session_log)" | grep -F "(client unix:$port) answers again" | grep -q "$what [0-9]"
  }
  if t=$(wait_until "$BACK" served_again); then
    pass "the $name is served again ${t} s after SIGCONT ($what kept)"
  else
    fail "the $name was not served again within $BACK s of SIGCONT"
    # what the Model said of its observers and subscriptions since the freeze (time, message)
    tail -n +"$((lines + 1))" "$(session_log)" | grep -E $'\tcaliper\\.model\\.(daq|observers)\t' |
      cut -f1,9 | sed 's/^/  /'
  fi
}
freeze renderer observer
freeze plotter subscription

# ---------------------------------------------------------------- kills
# SIGKILL NAME, start it again, and wait until CHECK (a function of the new pid) holds
kill_and_restart() {  # NAME CHECK DESCRIPTION
  local name=$1 check=$2 what=$3 old t started
  old=${PID[$name]}
  kill -KILL "$old"
  wait "$old" 2>/dev/null
  start "$name"
  started=$(now)
  # "within two intervals of being up": the process's own start-up (until its ORB listens or, for
  # the main window, a client only, until it holds a connection) is not part of the budget
  if ! t=$(wait_until 30 up "${PID[$name]}"); then
    fail "the restarted $name (pid ${PID[$name]}) did not come up in 30 s"; return
  fi
  if t=$(wait_until "$((BACK + 8))" "$check" "${PID[$name]}"); then
    local total
    total=$(elapsed "$started")
    if [ "$(echo "$t <= $BACK" | bc -l)" = 1 ]; then
      pass "$name killed and restarted: $what ${t} s after it was up (${total} s after the restart)"
    else
      fail "$name killed and restarted: $what only ${t} s after it was up (more than $BACK s)"
    fi
  else
    fail "$name killed and restarted: not $what within $((BACK + 8)) s of being up"
  fi
}
renderer_back() { bound_as renderer0 "$1" && subscribed "$1"; }
plotter_back() { subscribed "$1"; }
logviewer_back() { subscribed "$1"; }
controller_back() { bound_as pd_controller0 "$1"; }
logger_back() { bound_as logger0 "$1"; }

steps_before=$(model_steps)
kill_and_restart renderer renderer_back "bound as renderer0 and observing the Model"
kill_and_restart main connected_to_model "talking to the Model"
kill_and_restart plotter plotter_back "subscribed"
kill_and_restart logviewer logviewer_back "listening to the logger"

# the logger: records sent meanwhile wait in the senders' spools; the log viewer listens again
lines=$(log_lines)
kill_and_restart logger logger_back "bound as logger0"
viewer_relistens() { subscribed_after "${PID[logviewer]}" "$lines"; }
if t=$(wait_until "$((BACK + 2))" viewer_relistens); then
  pass "the log viewer listens to the restarted logger ${t} s after it was bound"
else
  fail "the log viewer did not listen to the restarted logger within $((BACK + 2)) s"
fi

kill_and_restart controller controller_back "bound as pd_controller0"

# the naming service: on its port again, with an empty database; everyone registers again
kill -KILL "${PID[naming]}"
wait "${PID[naming]}" 2>/dev/null
sleep "$INTERVAL"  # at least one re-registration fails meanwhile
start_naming "$WORK/names-restarted"
all_bound() {
  local listing
  listing=$(ctl ls 2>/dev/null) || return 1
  for i in logger0 model0 pd_controller0 sample0 renderer0; do
    grep -q "^$i " <<<"$listing" || return 1
  done
}
if t=$(wait_until "$BACK" all_bound); then
  pass "naming service killed and restarted empty: every component registered again ${t} s after it answered"
else
  fail "not every component registered again within $BACK s of the naming service's restart: $(ctl ls 2>&1 | xargs)"
fi

# the Model stepped all along and every process is alive
steps_after=$(model_steps)
if [ -n "$steps_after" ] && [ -n "$steps_before" ] && [ "$steps_after" -gt "$steps_before" ] &&
    ctl status | grep -q RUNNING; then
  pass "the Model ran all along ($((steps_after - steps_before)) steps during the kills)"
else
  fail "the Model is not running: $(ctl status 2>&1 | xargs)"
fi
dead=""
for name in "${!PID[@]}"; do kill -0 "${PID[$name]}" 2>/dev/null || dead="$dead $name"; done
[ -z "$dead" ] && pass "every process alive at the end" || fail "died:$dead"

stop_session
check_records
for name in logger model controller sample renderer; do
  grep -E "terminate called|Segmentation|Aborted|assert" "$WORK/$name.out" && fail "$name crashed (see above)"
done
echo "faults: $FAILS failures"
[ "$FAILS" = 0 ]

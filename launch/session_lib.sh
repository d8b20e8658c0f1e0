# shellcheck shell=bash
# The pieces of a Caliper session for the launcher's user verbs (session, demo, node): the naming
# service's security mode, the session directory, starting a component and waiting until it is
# bound, the Model, the Main Window, the session's recording, and the shutdown in order. Sourced
# by launch/caliper (which defines ROOT, BIN, STATE_DIR, LATEST, SESSIONS_DIR, say and die, and
# sources naming.sh and certs.sh first), not run.

# network mode: TLS unless --insecure (CALIPER_INSECURE=1), which says loudly what it gives up
network_security() {  # sets NS_MODE (tls|plain) for start_nameserver
  if [ -z "${CALIPER_LISTEN:-}" ]; then NS_MODE=local; return 0; fi
  case "${CALIPER_INSECURE:-}" in
    1|true|yes)
      NS_MODE=plain
      say "WARNING: INSECURE network mode (--insecure): plain GIOP without TLS on ${CALIPER_LISTEN};"
      say "WARNING: no encryption, no authentication: anyone who reaches this host's ports can load"
      say "WARNING: and write files and drive the Models. Use it only on a network you fully trust." ;;
    *) NS_MODE=tls; tls_identity ;;
  esac
}

SESSION_PIDS=()
SESSION_NAMES=()

start_component() {  # NAME BINARY ARGS...
  local name=$1 bin=$2
  shift 2
  "$BIN/$bin" --nameservice "$NS_ADDR" -o "log.spool_dir=$SESSION_DIR/spool" "$@" \
    >"$SESSION_DIR/$name.out" 2>&1 &
  SESSION_PIDS+=($!)
  SESSION_NAMES+=("$name")
}

wait_bound() {  # INSTANCE
  for _ in $(seq 1 100); do
    "$BIN/caliper-ctl" --nameservice "$NS_ADDR" state "$1" >/dev/null 2>&1 && return 0
    sleep 0.1
  done
  die "$1 did not register; see $SESSION_DIR/*.out"
}

stop_process() {  # PID NAME: SIGTERM, up to 5 s, then SIGKILL (adds NAME to `left`)
  kill -TERM "$1" 2>/dev/null || return 0
  for _ in $(seq 1 50); do kill -0 "$1" 2>/dev/null || return 0; sleep 0.1; done
  left+=("$2")
  kill -KILL "$1" 2>/dev/null || true
}

stop_session() {
  trap - EXIT
  trap '' INT TERM  # a second Ctrl-C must not cut the shutdown short
  local i pid left=()
  say "shutting the session down"
  # components first (newest first), so that their last records still reach the logger; the
  # naming service last; each gets 5 s, then SIGKILL, so that the shutdown is bounded
  for ((i = ${#SESSION_PIDS[@]} - 1; i >= 0; i--)); do
    stop_process "${SESSION_PIDS[$i]}" "${SESSION_NAMES[$i]}"
  done
  [ -z "${NS_PID:-}" ] || stop_process "$NS_PID" "naming service"
  # reap them; only those it started (a bare `wait` would also wait for any other child)
  for pid in "${SESSION_PIDS[@]}" ${NS_PID:+"$NS_PID"}; do wait "$pid" 2>/dev/null || true; done
  # the pointer to the newest session, unless a newer session has written its own since
  if [ "$(sed -n 3p "$LATEST" 2>/dev/null)" = "$SESSION_DIR" ]; then rm -f "$LATEST"; fi
  # sockets of processes that did not unlink theirs (omniNames, a killed component)
  find "$CALIPER_SOCKET_DIR" -maxdepth 1 -type s -delete 2>/dev/null
  # a socket directory made under /tmp because the session's path was too long
  if [ -L "$SESSION_DIR/sock" ]; then rm -rf "$(readlink "$SESSION_DIR/sock")"; fi
  [ ${#left[@]} -eq 0 ] || say "had to kill: ${left[*]}"
  say "session log: $(ls "$SESSION_DIR"/caliper-*.log 2>/dev/null | head -1)"
}

new_session() {
  private_state_dir
  SESSION_ID=s$$
  SESSION_DIR=$SESSIONS_DIR/$(date +%Y%m%d-%H%M%S)-$SESSION_ID
  # the session's files, its log and its sockets are its user's alone
  mkdir -p -m 700 "$SESSIONS_DIR"
  mkdir -p -m 700 "$SESSION_DIR"
  # a local session listens on unix sockets in here: no other user of the host reaches it
  session_socket_dir "$SESSION_DIR"
  # the components' default write directory for paths from clients (model.write_dir,
  # renderer.write_dir): a directory of its own, so that clients cannot overwrite the session
  # log, the naming service's data, the spool or the *.out files; the Main Window's tools
  # inherit it
  mkdir -p "$SESSION_DIR/files"
  export CALIPER_FILES_DIR=$SESSION_DIR/files
  network_security
  start_nameserver "$SESSION_DIR" "${CALIPER_LISTEN:-127.0.0.1}" "$NS_MODE"
  printf '%s\n%s\n%s\n' "$NS_ADDR" "$NS_PID" "$SESSION_DIR" >"$LATEST"
  trap stop_session EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  start_component logger caliper-logger -o "logger.directory=$SESSION_DIR" \
    -o "logger.session=$SESSION_ID" -o exec.auto_activate=true
  wait_bound logger0
  say "session $SESSION_ID: naming service $NS_ADDR, files in $SESSION_DIR"
  [ -z "${NS_TCP_ADDR:-}" ] || say "for other ORBs (Tcl): naming service $NS_TCP_ADDR (loopback TCP)"
}

ctl() { "$BIN/caliper-ctl" --nameservice "$NS_ADDR" "$@"; }

# the session's Model with MODEL loaded; sets MODEL_NAME (the id prefix of its channels)
start_model() {  # MODEL [extra args]
  local model=$1
  shift
  [ -f "$model" ] || die "no model file $model"
  start_component model caliper-model -o "model.scene=$(realpath "$model")" \
    -o exec.auto_activate=true "$@"
  wait_bound model0
}

# a desktop: an X display or a Wayland one
have_display() { [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; }

# the Main Window on the session's naming service; it opens the Scene Renderer, the Graph Plotter
# and the Log Viewer as their own processes and places them (a saved session places them where they
# were); each argument is one plot the plotter shows when it has no layout of its own (ids
# separated by commas). Sets MAIN_PID.
start_gui() {  # [PLOT ...]
  local tools=renderer
  [ -x "$BIN/caliper-plotter" ] && tools=$tools,plotter
  [ -x "$BIN/caliper-logviewer" ] && tools=$tools,log_viewer
  local args=(--nameservice "$NS_ADDR" --tools "$tools")
  local plot
  for plot in "$@"; do args+=(--plot "$plot"); done
  "$BIN/caliper-main" "${args[@]}" >"$SESSION_DIR/main.out" 2>&1 &
  MAIN_PID=$!
  SESSION_PIDS+=("$MAIN_PID")
  SESSION_NAMES+=(main)
  say "main window (pid $MAIN_PID) opens: ${tools//,/, }; its session: ${CALIPER_MAIN_SETTINGS:-~/.config/caliper/caliper-main.ini}"
}

# the session's recording, from the first step: once the Model has loaded its scene, before
# anything runs (the Model loads model.scene as it initialises; a slow load is waited for)
start_session_recording() {  # FILE
  local out
  for _ in $(seq 1 100); do
    if out=$(ctl recording start "$1" 2>&1); then
      say "recording the session to $(sed -n 's/^.*: recording to //p' <<<"$out") (launch/caliper ctl recording stop ends it)"
      return 0
    fi
    case "$out" in *"no scene"*) sleep 0.1 ;; *) die "--record: $out" ;; esac
  done
  die "--record: the Model loaded no scene within 10 s; see $SESSION_DIR/model.out"
}


#!/usr/bin/env bash
# `launch/caliper demo` gives the Main Window a GUI session file of its own, fresh and inside the
# demo's session folder, and the demo's plots: a plotter layout that an earlier session saved in
# the user's session file (~/.config/caliper/caliper-main.ini, or $CALIPER_MAIN_SETTINGS) would
# otherwise replace the demo's plots. No display is needed: DISPLAY is set to a name nothing
# opens, and the build folder holds stand-ins; caliper-main's stand-in records the session file it
# was given, whether that file held a plotter layout when it started, and its arguments. The
# naming service is the real omniNames, on loopback, stopped by the launcher.
set -uo pipefail
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }

WORK=$(mktemp -d)
LAUNCHER=""
cleanup() {
  [ -z "$LAUNCHER" ] || kill -TERM "$LAUNCHER" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$WORK"
}
trap cleanup EXIT

BIN=$WORK/build/bin REC=$WORK/main.rec
mkdir -p "$BIN" "$WORK/home/.config/caliper" "$WORK/run"
chmod 700 "$WORK/run"
# components that only have to run until the launcher stops them
for b in caliper-logger caliper-model caliper-pd-controller; do
  printf '#!/bin/sh\nexec sleep 30\n' >"$BIN/$b"
done
# caliper-ctl: every verb answers (state: registered), so the demo runs its whole script
printf '#!/bin/sh\nexit 0\n' >"$BIN/caliper-ctl"
printf '#!/bin/sh\nexit 0\n' >"$BIN/caliper-plotter"
cat >"$BIN/caliper-main" <<'STUB'
#!/bin/bash
{
  echo "settings=${CALIPER_MAIN_SETTINGS:-}"
  # the file the real one reads: $CALIPER_MAIN_SETTINGS, else the per-user file (QSettings)
  file=${CALIPER_MAIN_SETTINGS:-${XDG_CONFIG_HOME:-$HOME/.config}/caliper/caliper-main.ini}
  if grep -q '^layout=' "$file" 2>/dev/null; then echo "held_layout=yes"; else echo "held_layout=no"; fi
  printf 'arg=%s\n' "$@"
} >"$REC"
STUB
chmod +x "$BIN"/*
export REC

# the user's session file holds a plotter layout with other plots, as after any earlier session
USER_INI=$WORK/home/.config/caliper/caliper-main.ini
cat >"$USER_INI" <<'INI'
[plotter]
layout="# caliper-plotter layout\nversion = 1\n\n[plot]\nautoscale = true\ncurve = other.joint.position line\n"
INI

run_demo() {  # extra environment, as NAME=VALUE words
  rm -f "$REC"
  env -u CI -u WAYLAND_DISPLAY -u CALIPER_NAMESERVICE "$@" HOME="$WORK/home" DISPLAY=:nothing \
    XDG_CONFIG_HOME="$WORK/home/.config" XDG_RUNTIME_DIR="$WORK/run" \
    CALIPER_SESSIONS_DIR="$WORK/sessions" CALIPER_BUILD_DIR="$WORK/build" CALIPER_NO_BUILD=1 \
    timeout 60 "$SRC/launch/caliper" demo --duration 0.1 >"$WORK/out" 2>&1 &
  LAUNCHER=$!
  wait "$LAUNCHER"
  RC=$?
  LAUNCHER=""
}

check() {  # what the demo gave caliper-main; $1 names the case
  if [ "$RC" != 0 ] || [ ! -s "$REC" ]; then
    fail "$1: the demo exited with $RC and started no main window:"
    cat "$WORK/out"
    return
  fi
  local settings
  settings=$(sed -n 's/^settings=//p' "$REC")
  case "$settings" in
    "$WORK/sessions"/*/gui-session.ini) pass "$1: the main window's session is the demo's own: $settings" ;;
    *) fail "$1: the main window's session is '${settings:-(unset: the per-user file)}', not a file of the demo's session folder" ;;
  esac
  if grep -qx 'held_layout=no' "$REC"; then pass "$1: that session file held no plotter layout"
  else fail "$1: the session file held a plotter layout when the main window started"; fi
  if grep -qx 'arg=ecce_arm.elbow.position' "$REC" &&
    grep -qx 'arg=ecce_arm.elbow_flexor.tendon.tension,ecce_arm.elbow_extensor.tendon.tension' "$REC"
  then pass "$1: the demo's two plots are passed (--plot)"
  else fail "$1: the demo's plots are not among the main window's arguments: $(tr '\n' ' ' <"$REC")"; fi
  if grep -qx 'arg=--tools' "$REC" && grep -q '^arg=.*plotter' "$REC"; then
    pass "$1: the plotter is among the tools"
  else fail "$1: no plotter among the tools: $(tr '\n' ' ' <"$REC")"; fi
}

run_demo
check "default session file"
# a user who keeps the session elsewhere: that file holds a layout too
cp "$USER_INI" "$WORK/elsewhere.ini"
run_demo CALIPER_MAIN_SETTINGS="$WORK/elsewhere.ini"
check "CALIPER_MAIN_SETTINGS set"
if [ "$(ls "$WORK/sessions" | wc -l)" = 2 ]; then pass "each demo run has its own session folder"
else fail "session folders: $(ls "$WORK/sessions")"; fi

[ "$FAILS" = 0 ] && echo "PASS" || { echo "$FAILS failure(s)"; exit 1; }

#!/usr/bin/env bash
# caliper-ctl edit against a real Model on a private loopback naming service: a via point
# inserted, moved and removed while the simulation has run, an obstacle added and wrapped
# around, a tendon added with an actuator of a registered kind, a mass and a shape changed; each
# refused edit exits 1 with the Model's reason and changes nothing; undo and redo walk the
# history; `save` writes the edited scene and loading it again gives the same paths.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
# shellcheck source=support/checks.sh
source "$SRC/tests/integration/support/checks.sh"
# shellcheck source=../../launch/local_models.sh
source "$SRC/launch/local_models.sh"
local_models_session 1
ctl() { "$BIN/caliper-ctl" "$@"; }

ctl load "$SRC/models/ecce_arm.dae" >/dev/null || fail "load"
ctl step 200 >/dev/null || fail "step"
steps_before=$(ctl status | awk '/^steps/ {print $2}')

# insert a via point on the elbow flexor, in the upper arm's frame
if ctl edit insert elbow_flexor 1 upper_arm 0.02 0 -0.1 >"$WORK/out" 2>&1 &&
   grep -q "undo: insert point in 'upper_arm' at 1 of elbow_flexor" "$WORK/out"; then
  pass "insert: $(grep undo: "$WORK/out")"
else cat "$WORK/out"; fail "insert a via point"; fi
ctl edit path elbow_flexor >"$WORK/path" 2>&1
if awk '$1 == 1 && $2 == "upper_arm" && $3 == 20 && $4 == 0 && $5 == -100' "$WORK/path" | grep -q .; then
  pass "the path lists the new via point at 20 0 -100 mm"
else cat "$WORK/path"; fail "path after insert"; fi
[ "$(ctl status | awk '/^steps/ {print $2}')" = "$steps_before" ] && pass "the edit kept the step count ($steps_before)" ||
  fail "the edit changed the step count"

ctl edit move elbow_flexor 1 upper_arm 0.025 0.005 -0.12 >/dev/null 2>&1 || fail "move"
ctl edit path elbow_flexor | awk '$1 == 1 && $3 == 25 && $4 == 5 && $5 == -120' | grep -q . &&
  pass "moved to 25 5 -120 mm" || fail "move did not move"

# refused edits: the reason, exit 1, nothing changed
check_refused() {  # PATTERN ARGS...
  local pattern=$1
  shift
  if ctl edit "$@" >"$WORK/refused" 2>&1; then
    fail "accepted: edit $*"
  elif grep -q "$pattern" "$WORK/refused"; then
    pass "refused: $(tail -1 "$WORK/refused")"
  else cat "$WORK/refused"; fail "edit $* refused without '$pattern'"; fi
}
check_refused "no body 'elbow'" move elbow_flexor 1 elbow 0 0 0
check_refused "an end of the tendon" remove-point elbow_flexor 0
check_refused "mass must be in" mass forearm -2
check_refused "no actuator kind 'rocket'" add-tendon t2 upper_arm 0 0 0 forearm 0 0 0 rocket
check_refused "wraps around it" remove-obstacle elbow_pulley
ctl edit path elbow_flexor | awk '$1 == 1 && $3 == 25' | grep -q . && pass "refusals changed nothing" ||
  fail "a refused edit changed the path"

# an obstacle, wrapped around
ctl edit obstacle knob upper_arm sphere 0.03 0 -0.2 0.015 >/dev/null 2>&1 || fail "add obstacle"
ctl edit insert elbow_extensor 1 knob >/dev/null 2>&1 || fail "wrap around the new obstacle"
ctl edit path elbow_extensor | grep -q "wrap knob" && pass "elbow_extensor wraps around knob" ||
  fail "no wrap around knob"
ctl edit obstacle knob upper_arm sphere 0.03 0 -0.2 0.02 >/dev/null 2>&1 || fail "resize the obstacle"
# a cylinder moved and resized keeps its axis (the elbow pulley turns about x)
ctl edit obstacle elbow_pulley upper_arm cylinder 0 0 -0.29 0.045 0.06 >/dev/null 2>&1 ||
  fail "move the elbow pulley"
ctl save "$WORK/pulley.dae" >/dev/null 2>&1
if grep -A3 '<obstacle name="elbow_pulley"' "$WORK/pulley.dae" | grep -q 'radius="0.045"' &&
   grep -A3 '<obstacle name="elbow_pulley"' "$WORK/pulley.dae" | grep -Eq '<rotate>-?1 0 0 -?90'; then
  pass "the moved pulley keeps its axis"
else grep -A3 '<obstacle name="elbow_pulley"' "$WORK/pulley.dae"; fail "the pulley's axis"; fi

# a pull while stepping: a command the Model shows as channels; released at the end
ctl edit pull hand 0.3 0 -0.5 --for 1.5 >"$WORK/pull" 2>&1 &
pull_pid=$!
sleep 0.7
ctl step 100 >/dev/null 2>&1
body=$(ctl get ecce_arm.pull.body | awk '{print $3}')
force=$(ctl get ecce_arm.pull.force_x | awk '{print $3}')
wait $pull_pid || fail "pull --for"
[ "$body" = "5" ] && awk -v f="$force" 'BEGIN {exit !(f > 0.1)}' &&
  pass "pulling the hand: pull.body = $body, pull.force_x = $force N" ||
  { cat "$WORK/pull"; fail "pull channels: body '$body' force '$force'"; }
ctl step 1 >/dev/null 2>&1
[ "$(ctl get ecce_arm.pull.body | awk '{print $3}')" = "-1" ] && pass "released after --for" ||
  fail "the pull outlived ctl"

# a new tendon with a ligament at its defaults, a mass, a shape
ctl edit add-tendon strap upper_arm 0.03 0 -0.05 forearm 0.03 0 -0.05 ligament strap_ligament \
  >"$WORK/add" 2>&1 || { cat "$WORK/add"; fail "add a tendon"; }
ctl motor | grep -q "strap_ligament *ligament *strap" && pass "the new ligament is an actuator" ||
  fail "the new ligament is not listed"
ctl edit mass forearm 0.8 >/dev/null 2>&1 || fail "mass"
ctl get ecce_arm.forearm.mass | awk '$3 == 0.8 {found = 1} END {exit !found}' && pass "forearm mass 0.8 kg" || fail "mass not read back"
ctl edit shapes forearm >"$WORK/shapes" 2>&1
dims=$(awk 'NR == 1 {print $3, $4, $5, $6}' "$WORK/shapes")
ctl edit shape forearm 0 0.05 0.3 >/dev/null 2>&1 || fail "shape ($dims)"
ctl edit shapes forearm | head -1 | grep -q " 0.05 0.3 m" && pass "forearm shape 0: 0.05 0.3 m" ||
  fail "shape not changed"
# a capsule that large overlaps its neighbours: the step faults with the reason, the undo of the
# edit clears the fault and the simulation steps on from the last sound state
if ctl step 100 >"$WORK/fault" 2>&1; then fail "the oversized forearm did not fault"
elif grep -q "faulted" "$WORK/fault"; then pass "oversized shape: $(tail -1 "$WORK/fault" | cut -c1-110)"
else cat "$WORK/fault"; fail "no fault message"; fi
ctl edit undo >/dev/null 2>&1 || fail "undo after the fault"
ctl status | grep -q "PAUSED" && pass "the undo cleared the fault" || { ctl status; fail "still faulted"; }
ctl step 100 >"$WORK/after" 2>&1 && pass "steps on after the undo" || { cat "$WORK/after"; fail "steps after the undo"; }
ctl edit redo >/dev/null 2>&1 || fail "redo of the shape"

# undo and redo: the history's labels
ctl edit undo >"$WORK/undo" 2>&1 && grep -q "redo: set capsule 0 of forearm" "$WORK/undo" &&
  pass "undo: $(grep redo: "$WORK/undo")" || { cat "$WORK/undo"; fail "undo"; }
ctl edit redo >/dev/null 2>&1 || fail "redo"
ctl edit shapes forearm | head -1 | grep -q " 0.05 0.3 m" && pass "redo set the shape again" ||
  fail "redo"

# the edited scene, saved and loaded again
ctl save "$WORK/edited.dae" >/dev/null 2>&1 || fail "save"
ctl edit path elbow_flexor >"$WORK/path.edited"
ctl load "$WORK/edited.dae" >/dev/null 2>&1 || fail "load the edited scene"
ctl edit path elbow_flexor >"$WORK/path.loaded"
if cmp -s "$WORK/path.edited" "$WORK/path.loaded" && ctl edit path elbow_extensor | grep -q "wrap knob" &&
   ctl motor | grep -q strap_ligament; then
  pass "the saved scene loads with the edits"
else diff "$WORK/path.edited" "$WORK/path.loaded"; fail "round trip"; fi
ctl edit | grep -q "undo: (nothing)" && pass "a load starts a new history" || fail "history after load"

finish

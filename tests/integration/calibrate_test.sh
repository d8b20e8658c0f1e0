#!/usr/bin/env bash
# caliper-calibrate against two real Models on a private loopback naming service: a short search
# lowers the cost and moves the parameters toward the truth, the tuned scene re-imports with the
# fitted values, a SIGKILLed calibration resumes from its checkpoint, a Model killed mid-search
# loses nothing, faulting candidates cost a finite amount, and --dry-run reports the initial cost
# with its plots. Also batch runs' handling of a physics fault (failed once, not retried).
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
# shellcheck source=support/checks.sh
source "$SRC/tests/integration/support/checks.sh"
# shellcheck source=../../launch/local_models.sh
source "$SRC/launch/local_models.sh"
local_models_session 2

# the truth: forearm 1.3 kg (shipped 1), flexor tendon 4000 N/m (shipped 3000)
cat >"$WORK/runs.json" <<JSON
{"scene": "$SRC/models/ecce_arm.dae", "duration_s": 1.5, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
 "commands": [[0, "elbow_flexor", 6], [0.7, "elbow_flexor", 1], [0.7, "elbow_extensor", 5]]}
JSON
sed 's/"commands"/"set": {"ecce_arm.forearm.mass": 1.3, "ecce_arm.elbow_flexor.stiffness": 4000}, "commands"/' \
  "$WORK/runs.json" >"$WORK/truth.json"
"$BIN/caliper-ctl" batch "$WORK/truth.json" --out "$WORK/truth" >/dev/null 2>&1 || fail "recording the truth"
cat >"$WORK/cal.json" <<JSON
{"experiments": "runs.json", "measured": {"runs": "truth/runs/truth.csv"},
 "parameters": [{"id": "ecce_arm.forearm.mass", "lower": 0.5, "upper": 2, "scale": "log"},
                {"id": "ecce_arm.elbow_flexor.stiffness", "lower": 1500, "upper": 8000, "scale": "log"}],
 "optimiser": {"generations": 12, "population": 6, "sigma0": 0.2}, "seed": 3}
JSON

# --dry-run
"$BIN/caliper-calibrate" "$WORK/cal.json" --dry-run --out "$WORK/dry" >"$WORK/dry.out" 2>&1
if grep -q "initial cost" "$WORK/dry.out" && [ -f "$WORK/dry/channels-runs.csv" ]; then
  pass "dry run: $(grep 'initial cost' "$WORK/dry.out")"
else cat "$WORK/dry.out"; fail "the dry run"; fi

# a short search
"$BIN/caliper-calibrate" "$WORK/cal.json" --out "$WORK/fit" >"$WORK/fit.out" 2>"$WORK/fit.err"
rc=$?
[ $rc -eq 0 ] && pass "the search exited 0" || { cat "$WORK/fit.err"; fail "the search exited $rc"; }
line=$(grep '^cost ' "$WORK/fit.out")
echo "  $line"
before=$(echo "$line" | awk '{print $2}'); after=$(echo "$line" | awk '{print $4}')
awk -v a="$before" -v b="$after" 'BEGIN { exit !(b < a / 5) }' &&
  pass "the cost fell more than 5x ($before -> $after)" || fail "the cost fell only from $before to $after"
# parameters.csv: id,unit,initial,fitted,...
mass=$(awk -F, '$1 == "ecce_arm.forearm.mass" {print $4}' "$WORK/fit/parameters.csv")
stiff=$(awk -F, '$1 == "ecce_arm.elbow_flexor.stiffness" {print $4}' "$WORK/fit/parameters.csv")
awk -v m="$mass" -v k="$stiff" 'BEGIN { exit !((m - 1.3)^2 < (1 - 1.3)^2 / 4 && (k - 4000)^2 < (3000 - 4000)^2 / 4) }' &&
  pass "fitted mass $mass kg (truth 1.3), stiffness $stiff N/m (truth 4000)" ||
  fail "fitted mass $mass kg, stiffness $stiff N/m are not closer to 1.3 and 4000"
[ "$(grep -c ',global$' "$WORK/fit/cost.csv")" -eq 13 ] &&
  pass "cost.csv has the start and 12 generations of the search (and $(grep -c ',refinement$' "$WORK/fit/cost.csv") refinement steps)" ||
  fail "cost.csv: $(grep -c ',global$' "$WORK/fit/cost.csv") rows of the search"
if [ -x "$BIN/caliper-renderer" ]; then
  [ -s "$WORK/fit/report.png" ] && pass "report.png written" || fail "no report.png"
fi
# the tuned scene re-imports with the fitted values
"$BIN/caliper-ctl" load "$WORK/fit/tuned.dae" >/dev/null 2>&1 || fail "loading tuned.dae"
got=$("$BIN/caliper-ctl" get ecce_arm.forearm.mass | awk '{print $3}')
awk -v g="$got" -v m="$mass" 'BEGIN { exit !((g - m)^2 < 1e-10) }' &&
  pass "tuned.dae re-imports with the fitted mass ($got kg)" || fail "tuned.dae has mass $got, fitted $mass"

# SIGKILL mid-search, then --resume
sed 's/"generations": 12/"generations": 40/' "$WORK/cal.json" >"$WORK/long.json"
"$BIN/caliper-calibrate" "$WORK/long.json" --out "$WORK/resume" >/dev/null 2>"$WORK/killed.err" &
cal=$!
for _ in $(seq 1 300); do grep -q '^gen 3/' "$WORK/killed.err" && break; sleep 0.1; done
kill -KILL $cal; wait $cal 2>/dev/null
done_gens=$(grep -c '^gen ' "$WORK/killed.err")
"$BIN/caliper-calibrate" "$WORK/long.json" --out "$WORK/resume" --resume --generations $((done_gens + 3)) \
  >"$WORK/resumed.out" 2>"$WORK/resumed.err"
rc=$?
resumed_at=$(sed -n 's/^resuming at generation \([0-9]*\).*/\1/p' "$WORK/resumed.err")
if [ $rc -eq 0 ] && [ "${resumed_at:-0}" -ge 3 ] && grep -q "^gen $((done_gens + 3))/" "$WORK/resumed.err"; then
  pass "killed after $done_gens generations, resumed at generation $resumed_at and finished"
else cat "$WORK/resumed.err"; fail "resume after SIGKILL (rc $rc, resumed at '${resumed_at}')"; fi

# a Model killed mid-search: its runs go to the other one
"$BIN/caliper-calibrate" "$WORK/cal.json" --out "$WORK/lost" >"$WORK/lost.out" 2>"$WORK/lost.err" &
cal=$!
for _ in $(seq 1 300); do grep -q '^gen 2/' "$WORK/lost.err" && break; sleep 0.1; done
victim=$("$BIN/caliper-ctl" ls | awk '$1 == "model1" {print $4}')
kill -KILL "$victim"
wait $cal; rc=$?
if [ $rc -eq 0 ] && grep -q "Model lost" "$WORK/lost.err" && grep -q '^cost ' "$WORK/lost.out"; then
  pass "a Model killed mid-search: $(grep -m1 'Model lost' "$WORK/lost.err")"
else cat "$WORK/lost.err"; fail "the search with a killed Model (rc $rc)"; fi

# candidates whose physics faults: a large finite cost each, the search goes on
cat >"$WORK/faulty.json" <<JSON
{"scene": "$SRC/models/ecce_arm.dae", "duration_s": 1, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position"], "commands": [[0, "biceps", 1]]}
JSON
cat >"$WORK/faults.json" <<JSON
{"experiments": "faulty.json", "measured": {"faulty": "truth/runs/truth.csv"},
 "parameters": [{"id": "ecce_arm.biceps.max_isometric_force", "lower": 100, "upper": 1e16, "scale": "log"}],
 "optimiser": {"generations": 2, "population": 6, "sigma0": 0.5}, "seed": 5}
JSON
"$BIN/caliper-calibrate" "$WORK/faults.json" --out "$WORK/faults" >"$WORK/faults.out" 2>"$WORK/faults.err"
rc=$?
faulted=$(sed -n 's/.* \([0-9]*\) faulted).*/\1/p' "$WORK/faults.out")
if [ $rc -eq 0 ] && [ "${faulted:-0}" -ge 1 ] && ! grep -qi nan "$WORK/faults/cost.csv"; then
  pass "$faulted faulting candidates got a finite cost and the search finished"
else cat "$WORK/faults.out" "$WORK/faults.err"; fail "faulting candidates (rc $rc, faulted '${faulted}')"; fi

# batch runs: a run whose physics faults fails once with the Model's report, never retried
cat >"$WORK/explode.json" <<JSON
{"scene": "$SRC/models/ecce_arm.dae", "duration_s": 0.5, "record": ["ecce_arm.elbow.position"],
 "set": {"ecce_arm.biceps.max_isometric_force": 1e15}, "commands": [[0, "biceps", 1]]}
JSON
"$BIN/caliper-ctl" batch "$WORK/explode.json" --models model0 --out "$WORK/explode" >"$WORK/explode.out" 2>&1
rc=$?
row=$(tail -n +2 "$WORK/explode/summary.csv")
if [ $rc -eq 1 ] && [[ "$row" == explode,failed,*,1,* ]] && [[ "$row" == *"faulted at t ="* ]]; then
  pass "batch: the exploding run failed once with the report: ${row##*,}"
else cat "$WORK/explode.out"; fail "batch with a faulting run (rc $rc): $row"; fi

if [ $FAILS -eq 0 ]; then echo "calibrate_test: all checks passed"; exit 0; fi
echo "calibrate_test: $FAILS checks failed"; exit 1

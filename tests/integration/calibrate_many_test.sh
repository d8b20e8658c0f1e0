#!/usr/bin/env bash
# A larger calibration: 14 independent tendon-driven pendulums (support/make_pendulum_bank.py),
# 42 parameters (every tendon's stiffness and damping, every motor's resistance) starting 25 %
# off, recovered within 1 % from noise-free synthetic recordings, the evaluations spread over two
# Models. Prints the wall time and evaluations (docs/benchmarks.md has how they grow with N).
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
PY=/usr/bin/python3
PENDULUMS=${CALIPER_BANK_PENDULUMS:-14}
# shellcheck source=support/checks.sh
source "$SRC/tests/integration/support/checks.sh"
# shellcheck source=../../launch/local_models.sh
source "$SRC/launch/local_models.sh"
local_models_session 2

$PY "$SRC/tests/integration/support/make_pendulum_bank.py" "$PENDULUMS" "$WORK/bank" >"$WORK/bank.out" ||
  fail "writing the pendulum bank"
"$BIN/caliper-ctl" batch "$WORK/bank/truth.json" --out "$WORK/bank/truth" >/dev/null 2>&1 ||
  fail "recording the truth"
begin=$(date +%s.%N)
"$BIN/caliper-calibrate" "$WORK/bank/calibration.json" --out "$WORK/fit" >"$WORK/fit.out" 2>"$WORK/fit.err"
rc=$?
wall=$(awk -v b="$begin" -v e="$(date +%s.%N)" 'BEGIN { printf "%.1f", e - b }')
[ $rc -eq 0 ] && pass "the calibration of $((3 * PENDULUMS)) parameters exited 0" ||
  { tail -20 "$WORK/fit.err"; fail "exit $rc"; }
grep -E "^(converged|NOT)" "$WORK/fit.out" | sed 's/^/  /'
grep -E "^refinement: (converged|stopped)|^Jacobian" "$WORK/fit.err" | sed 's/^/  /'
$PY - "$WORK/fit/result.json" "$WORK/bank/truth.csv" "$wall" <<'PY' >"$WORK/check.out"
import csv, json, sys
r = json.load(open(sys.argv[1]))
truth = {row["id"]: float(row["truth"]) for row in csv.DictReader(open(sys.argv[2]))}
errors = sorted((abs(p["fitted"] - truth[p["id"]]) / truth[p["id"]], p["id"]) for p in r["parameters"])
worst, worst_id = errors[-1]
within = sum(e < 0.01 for e, _ in errors)
print(len(errors), within, f"{100 * worst:.3g}", worst_id, r["evaluations"], sys.argv[3],
      r["refinement"]["iterations"])
PY
read -r n within worst worst_id evaluations wall_s iterations <"$WORK/check.out"
[ "$n" -eq $((3 * PENDULUMS)) ] && [ "$within" -eq "$n" ] &&
  pass "$within of $n parameters within 1 % of the truth (worst $worst % $worst_id); $evaluations evaluations, $iterations LM iterations, $wall_s s on 2 Models" ||
  fail "$within of $n parameters within 1 % (worst $worst % $worst_id)"

if [ $FAILS -eq 0 ]; then echo "calibrate_many_test: all checks passed"; exit 0; fi
echo "calibrate_many_test: $FAILS checks failed"; exit 1

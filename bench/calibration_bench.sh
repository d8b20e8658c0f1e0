#!/usr/bin/env bash
# Calibration benchmarks, each ratio measured in this one run:
#  - evaluations per second of the global search with 1 and with 2 Models (islands);
#  - the refinement's Jacobian at the example's start (12 runs: central differences of its 6
#    parameters) on 1 and on 2 Models;
#  - how the wall time grows with the number of parameters: the pendulum bank of
#    tests/integration (3 parameters per pendulum) with 2, 6 and 14 pendulums, calibrated to
#    within 1 % from 25 % off on 2 Models (figures, no ratio);
#  - with --example, examples/calibration end to end: evaluations and wall time to convergence
#    (several minutes).
# Run through `launch/caliper bench calibration [--example]`.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${CALIPER_BIN_DIR:-$ROOT/build/bin}
# shellcheck source=../launch/local_models.sh
source "$ROOT/launch/local_models.sh"
local_models_session 2
# the example's experiments and measurements
CALIPER_CTL="$BIN/caliper-ctl" "$ROOT/examples/calibration/make_measurements.sh" >/dev/null 2>&1
rate() {  # MODELS_GLOB: evaluations per second of 16 generations, no refinement
  "$BIN/caliper-calibrate" "$ROOT/examples/calibration/calibration.json" --generations 16 \
    --iterations 0 --models "$1" --out "$WORK/out" 2>&1 >/dev/null |
    sed -n 's/^gen .* \([0-9.]*\) evals\/s .*/\1/p' | tail -1
}
one=$(rate model0)
two=$(rate 'model[01]')
echo "calibration: $one evaluations/s with 1 Model, $two with 2 (3 experiments, 7 simulated s each)"
awk -v a="$one" -v b="$two" 'BEGIN { printf "RATIO calibration_2_vs_1_models %.3f (target >= 1.8)\n", b / a }'

jacobian() {  # MODELS_GLOB: seconds for the Jacobian at the start (no search, no refinement)
  "$BIN/caliper-calibrate" "$ROOT/examples/calibration/calibration.json" --generations 0 \
    --iterations 0 --models "$1" --out "$WORK/jacobian" 2>&1 >/dev/null |
    sed -n 's/^Jacobian at the optimum: \([0-9]*\) runs in \([0-9.e+-]*\) s.*/\1 \2/p'
}
read -r runs j1 <<<"$(jacobian model0)"
read -r _ j2 <<<"$(jacobian 'model[01]')"
echo "calibration: a Jacobian of $runs runs (x 3 experiments) takes $j1 s on 1 Model, $j2 s on 2"
awk -v a="$j1" -v b="$j2" 'BEGIN { printf "RATIO calibration_jacobian_2_vs_1_models %.3f (target >= 1.8)\n", a / b }'

# the wall time against the number of parameters
for n in 2 6 14; do
  /usr/bin/python3 "$ROOT/tests/integration/support/make_pendulum_bank.py" "$n" "$WORK/bank$n" >/dev/null
  "$BIN/caliper-ctl" batch "$WORK/bank$n/truth.json" --out "$WORK/bank$n/truth" >/dev/null 2>&1
  begin=$(date +%s.%N)
  "$BIN/caliper-calibrate" "$WORK/bank$n/calibration.json" --out "$WORK/bank$n/fit" >/dev/null 2>&1
  end=$(date +%s.%N)
  /usr/bin/python3 - "$WORK/bank$n/fit/result.json" "$WORK/bank$n/truth.csv" "$begin" "$end" <<'PY'
import csv, json, sys
r = json.load(open(sys.argv[1]))
truth = {row["id"]: float(row["truth"]) for row in csv.DictReader(open(sys.argv[2]))}
worst = max(abs(p["fitted"] - truth[p["id"]]) / truth[p["id"]] for p in r["parameters"])
n = len(r["parameters"])
wall = float(sys.argv[4]) - float(sys.argv[3])
print(f"calibration: {n} parameters: {r['evaluations']} evaluations, "
      f"{r['refinement']['iterations']} LM iterations, {wall:.1f} s on 2 Models, "
      f"worst error {100 * worst:.3g} %, {'converged' if r['converged'] else 'NOT converged'}")
PY
done

if [ "${1:-}" = --example ]; then
  begin=$(date +%s)
  CALIPER_NO_BUILD=1 "$ROOT/examples/calibration/run.sh" --out "$WORK/example" >"$WORK/example.out" 2>&1
  wall=$(( $(date +%s) - begin ))
  tail -12 "$WORK/example.out"
  evaluations=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["evaluations"])' "$WORK/example/result.json")
  echo "calibration: the example took $evaluations evaluations and $wall s to convergence"
  echo "RATIO calibration_example_wall_s $wall (target <= 900)"
fi

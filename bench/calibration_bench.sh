#!/usr/bin/env bash
# Calibration benchmarks: evaluations per second with 1 and with 2 Models (islands), and, with
# --example, the wall time of examples/calibration (several minutes). Prints RATIO lines; run
# through `launch/caliper bench calibration`.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${CALIPER_BIN_DIR:-$ROOT/build/bin}
# shellcheck source=../launch/local_models.sh
source "$ROOT/launch/local_models.sh"
local_models_session 2
# the example's experiments and measurements, 16 generations
CALIPER_CTL="$BIN/caliper-ctl" "$ROOT/examples/calibration/make_measurements.sh" >/dev/null 2>&1
rate() {  # MODELS_GLOB
  "$BIN/caliper-calibrate" "$ROOT/examples/calibration/calibration.json" --generations 16 \
    --models "$1" --out "$WORK/out" 2>&1 >/dev/null | sed -n 's/.* \([0-9.]*\) evals\/s .*/\1/p' | tail -1
}
one=$(rate model0)
two=$(rate 'model[01]')
echo "calibration: $one evaluations/s with 1 Model, $two with 2 (3 experiments, 7 simulated s each)"
awk -v a="$one" -v b="$two" 'BEGIN { printf "RATIO calibration_2_vs_1_models %.3f (target >= 1.8)\n", b / a }'
if [ "${1:-}" = --example ]; then
  begin=$(date +%s)
  CALIPER_NO_BUILD=1 "$ROOT/examples/calibration/run.sh" --out "$WORK/example" >"$WORK/example.out" 2>&1
  wall=$(( $(date +%s) - begin ))
  tail -8 "$WORK/example.out"
  echo "RATIO calibration_example_wall_s $wall (target <= 900)"
fi

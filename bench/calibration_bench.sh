#!/usr/bin/env bash
# Calibration benchmarks: evaluations per second with 1 and with 2 Models (islands), and, with
# --example, the wall time of examples/calibration (several minutes). Prints RATIO lines; run
# through `launch/caliper bench calibration`.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${CALIPER_BIN_DIR:-$ROOT/build/bin}
WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
PORT=$((20000 + RANDOM % 20000))
omniNames -start "$PORT" -always -nohostname -datadir "$WORK" \
  -ORBendPoint "giop:tcp:127.0.0.1:$PORT" >"$WORK/ns.log" 2>&1 &
PIDS+=($!)
export CALIPER_NAMESERVICE=corbaname::127.0.0.1:$PORT
for _ in $(seq 1 50); do nameclt -ORBInitRef "NameService=$CALIPER_NAMESERVICE" list >/dev/null 2>&1 && break; sleep 0.1; done
for i in 0 1; do
  "$BIN/caliper-model" -o "log.spool_dir=$WORK/spool" -o log.level=warn >"$WORK/model$i.out" 2>&1 &
  PIDS+=($!)
done
for i in 0 1; do
  for _ in $(seq 1 100); do "$BIN/caliper-ctl" state "model$i" >/dev/null 2>&1 && break; sleep 0.1; done
done
# the example's experiments and measurements, 8 generations
CALIPER_CTL="$BIN/caliper-ctl" "$ROOT/examples/calibration/make_measurements.sh" >/dev/null
rate() {  # MODELS_GLOB
  "$BIN/caliper-calibrate" "$ROOT/examples/calibration/calibration.json" --generations 8 \
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

#!/usr/bin/env bash
# Cluster benchmarks on this machine (loopback): batch throughput with 1 and 2 Models, and the
# per-run overhead (dispatch, scene transfer and load, result transfer) against stepping.
# Prints RATIO lines; run through `launch/caliper bench cluster`.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BIN=${CALIPER_BIN_DIR:-$ROOT/build/bin}
# shellcheck source=../launch/local_models.sh
source "$ROOT/launch/local_models.sh"
local_models_session 2
NS=$CALIPER_NAMESERVICE

# the shipped arm bending its elbow, 8 runs of 3 s (a sweep over the forearm mass)
cat >"$WORK/throughput.json" <<JSON
{"scene": "$ROOT/models/ecce_arm.dae", "duration_s": 3, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
 "commands": [[0, "elbow_flexor", 6], [1.5, "elbow_extensor", 4]],
 "sweep": {"ecce_arm.forearm.mass": [0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65]}}
JSON
cat >"$WORK/overhead.json" <<JSON
{"scene": "$ROOT/models/ecce_arm.dae", "duration_s": 10, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension",
            "ecce_arm.hand.position"],
 "commands": [[0, "elbow_flexor", 6], [5, "elbow_extensor", 4]],
 "experiments": [{"name": "arm10s-a"}, {"name": "arm10s-b"}, {"name": "arm10s-c"}]}
JSON

# simulated seconds per wall second of a whole batch, from its summary line
throughput() {  # MODELS_GLOB OUT
  "$BIN/caliper-ctl" --nameservice "$NS" batch "$WORK/throughput.json" --models "$1" \
    --out "$WORK/$2" 2>/dev/null | sed -n 's/.*(\([0-9.]*\) sim-s\/s).*/\1/p'
}
one=$(throughput model0 one)
two=$(throughput 'model[01]' two)
echo "batch throughput: 1 Model $one sim-s/s, 2 Models $two sim-s/s (24 simulated s each)"
awk -v a="$one" -v b="$two" 'BEGIN { printf "RATIO cluster_2_vs_1_models %.3f (target >= 1.8)\n", b / a }'

"$BIN/caliper-ctl" --nameservice "$NS" batch "$WORK/overhead.json" --models model0 \
  --out "$WORK/overhead" >/dev/null 2>&1
# summary columns: 8 wall_time, 9 load_wall_time, 10 step_wall_time
awk -F, 'NR > 1 { wall += $8; load += $9; step += $10 }
  END {
    printf "10 s arm runs: %.3f s of stepping, %.3f s per run end to end (load %.4f s)\n", step / (NR - 1), wall / (NR - 1), load / (NR - 1)
    printf "RATIO cluster_run_overhead %.4f (target <= 0.05)\n", (wall - step) / step
  }' "$WORK/overhead/summary.csv"

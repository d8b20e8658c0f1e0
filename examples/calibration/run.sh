#!/usr/bin/env bash
# The calibration example in one command: builds Caliper if needed, starts a private naming
# service and one Model per core, records the "real robot" (the shipped arm with true parameters
# 30-50 % away from the file's, optionally with Gaussian noise), calibrates the six parameters
# from the file's values, and prints each fitted value against the truth. Stops everything at the
# end. Usage: examples/calibration/run.sh [--noise 0.01] [--out DIR] [extra caliper-calibrate args]
set -euo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
NOISE=0
OUT=$HERE/results
EXTRA=()
while [ $# -gt 0 ]; do
  case "$1" in
    --noise) NOISE=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) EXTRA+=("$1"); shift ;;
  esac
done
[ "${CALIPER_NO_BUILD:-}" = 1 ] || "$ROOT/launch/caliper" build >/dev/null
BIN=${CALIPER_BIN_DIR:-$ROOT/build/bin}
# shellcheck source=../../launch/local_models.sh
source "$ROOT/launch/local_models.sh"
trap 'exit 130' INT TERM
MODELS=$(nproc)
local_models_session "$MODELS"
echo "$MODELS Models on $CALIPER_NAMESERVICE"
CALIPER_CTL="$BIN/caliper-ctl" "$HERE/make_measurements.sh" "$NOISE"
begin=$(date +%s)
rc=0
"$BIN/caliper-calibrate" "$HERE/calibration.json" --out "$OUT" "${EXTRA[@]}" || rc=$?
echo "wall time: $(( $(date +%s) - begin )) s"
# the truth, as make_measurements.sh used it
python3 - "$OUT/parameters.csv" <<'PY'
import csv, sys
truth = {"ecce_arm.elbow_flexor.stiffness": 4200, "ecce_arm.elbow_extensor.stiffness": 2000,
         "ecce_arm.elbow_flexor.resistance": 0.75, "ecce_arm.elbow.spring_damping": 0.2,
         "ecce_arm.forearm.mass": 1.4, "ecce_arm.elbow_flexor.spool_radius": 0.006}
print(f"{'parameter':44} {'truth':>10} {'initial':>10} {'fitted':>10} {'error':>8}")
for row in csv.DictReader(open(sys.argv[1])):
    t = truth[row["id"]]
    f = float(row["fitted"])
    print(f"{row['id']:44} {t:10.5g} {float(row['initial']):10.5g} {f:10.5g} {100 * (f - t) / t:7.2f}%")
PY
exit $rc

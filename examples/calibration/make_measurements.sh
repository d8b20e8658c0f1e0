#!/usr/bin/env bash
# Makes the "real robot's" recordings of this example: the experiments of runs.json run with the
# true parameters below (30-50 % away from the shipped arm's), optionally with Gaussian noise of
# NOISE (e.g. 0.01: 1 % of each channel's range). Needs a running session (launch/caliper ctl).
# Usage: make_measurements.sh [NOISE]
set -euo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
CTL=${CALIPER_CTL:-$ROOT/launch/caliper ctl}
NOISE=${1:-0}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# the truth: what the calibration should find
cat >"$WORK/true.json" <<JSON
{"scene": "$ROOT/models/ecce_arm.dae", "every_n_steps": 10,
 "record": $(python3 -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))["record"]))' "$HERE/runs.json"),
 "set": {"ecce_arm.elbow_flexor.stiffness": 4200, "ecce_arm.elbow_extensor.stiffness": 2000,
         "ecce_arm.elbow_flexor.resistance": 0.75, "ecce_arm.elbow.spring_damping": 0.2,
         "ecce_arm.forearm.mass": 1.4, "ecce_arm.elbow_flexor.spool_radius": 0.006},
 "experiments": $(python3 -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))["experiments"]))' "$HERE/runs.json")}
JSON
$CTL batch "$WORK/true.json" --out "$WORK/out" >/dev/null
mkdir -p "$HERE/measured"
for f in "$WORK"/out/runs/*.csv; do
  # noise: a fixed seed per file, so that the example is the same every time
  python3 - "$f" "$HERE/measured/$(basename "$f")" "$NOISE" <<'PY'
import csv, random, sys
src, dst, noise = sys.argv[1], sys.argv[2], float(sys.argv[3])
rows = list(csv.reader(open(src)))
head, data = rows[0], [[float(v) for v in r] for r in rows[1:]]
rng = random.Random(len(data))
for c in range(1, len(head)):
    col = [r[c] for r in data]
    span = max(col) - min(col)
    for r in data:
        r[c] += rng.gauss(0.0, noise * span)
with open(dst, "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(head)
    w.writerows([[repr(v) for v in r] for r in data])
PY
done
echo "measurements (noise $NOISE of each channel's range): $HERE/measured/*.csv"

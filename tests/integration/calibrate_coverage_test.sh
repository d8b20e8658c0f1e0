#!/usr/bin/env bash
# caliper-calibrate's 95 % intervals cover the truth at about their nominal rate: the shipped arm
# with a known truth (forearm 1.3 kg, flexor tendon 4000 N/m) recorded once, then 20 noisy copies
# of the recording (white noise of 1 % of each channel's range, seeds 1..20), each calibrated
# from the shipped values (1 kg, 3000 N/m) by the Levenberg-Marquardt refinement alone. At least
# 17 of the 20 intervals must hold the truth, per parameter, and the noise estimated per channel
# must be the noise added (within 15 % on average).
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
PY=/usr/bin/python3
SEEDS=${CALIPER_COVERAGE_SEEDS:-20}
# shellcheck source=support/checks.sh
source "$SRC/tests/integration/support/checks.sh"
# shellcheck source=../../launch/local_models.sh
source "$SRC/launch/local_models.sh"
local_models_session 2

cat >"$WORK/runs.json" <<JSON
{"scene": "$SRC/models/ecce_arm.dae", "duration_s": 1.2, "every_n_steps": 10,
 "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
 "experiments": [{"name": "steps",
   "commands": [[0, "elbow_flexor", 6], [0.6, "elbow_flexor", 1], [0.6, "elbow_extensor", 5]]}]}
JSON
sed 's/"every_n_steps": 10,/"every_n_steps": 10, "set": {"ecce_arm.forearm.mass": 1.3, "ecce_arm.elbow_flexor.stiffness": 4000},/' \
  "$WORK/runs.json" >"$WORK/truth.json"
"$BIN/caliper-ctl" batch "$WORK/truth.json" --out "$WORK/truth" >/dev/null 2>&1 || fail "recording the truth"

: >"$WORK/results.txt"
for seed in $(seq 1 "$SEEDS"); do
  mkdir -p "$WORK/$seed"
  # the noisy copy, and the noise added per channel [unit]
  $PY - "$WORK/truth/runs/steps.csv" "$WORK/$seed/steps.csv" "$seed" >"$WORK/$seed/sigma.txt" <<'PY'
import csv, random, sys
rows = list(csv.reader(open(sys.argv[1])))
head, data = rows[0], [[float(v) for v in r] for r in rows[1:]]
rng = random.Random(int(sys.argv[3]))
for c in range(1, len(head)):
    col = [r[c] for r in data]
    sigma = 0.01 * (max(col) - min(col))
    print(head[c].split(" [")[0], sigma)
    for r in data:
        r[c] += rng.gauss(0.0, sigma)
with open(sys.argv[2], "w", newline="") as f:
    w = csv.writer(f); w.writerow(head); w.writerows([[repr(v) for v in r] for r in data])
PY
  cat >"$WORK/$seed/cal.json" <<JSON
{"experiments": "../runs.json", "measured": {"steps": "steps.csv"},
 "parameters": [{"id": "ecce_arm.forearm.mass", "lower": 0.5, "upper": 2, "scale": "log"},
                {"id": "ecce_arm.elbow_flexor.stiffness", "lower": 1500, "upper": 8000, "scale": "log"}],
 "optimiser": {"generations": 0}, "refinement": {"iterations": 15}, "seed": $seed}
JSON
  if ! "$BIN/caliper-calibrate" "$WORK/$seed/cal.json" --out "$WORK/$seed/out" >"$WORK/$seed/out.txt" 2>&1; then
    cat "$WORK/$seed/out.txt"; fail "seed $seed: the calibration failed"; continue
  fi
  $PY - "$WORK/$seed/out/result.json" "$WORK/$seed/sigma.txt" "$seed" >>"$WORK/results.txt" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
added = dict((l.split()[0], float(l.split()[1])) for l in open(sys.argv[2]))
truth = {"ecce_arm.forearm.mass": 1.3, "ecce_arm.elbow_flexor.stiffness": 4000}
cover = [int(p["lower95"] is not None and p["lower95"] <= truth[p["id"]] <= p["upper95"])
         for p in r["parameters"]]
ratio = [n["sigma"] / added[n["column"]] for n in r["noise"]]
fitted = [p["fitted"] for p in r["parameters"]]
half = [(p["upper95"] - p["lower95"]) / 2 for p in r["parameters"]]
print(sys.argv[3], *cover, *ratio, *fitted, *half)
PY
done
echo "  seed, mass covered, stiffness covered, noise ratios (position, tension), fitted, half-widths"
sed 's/^/  /' "$WORK/results.txt"
read -r runs mass stiff noise <<<"$(awk '{n++; m += $2; k += $3; r += $4 + $5} END {printf "%d %d %d %.3f", n, m, k, r / (2 * n)}' "$WORK/results.txt")"
need=$(( (SEEDS * 17 + 19) / 20 ))
[ "$runs" -eq "$SEEDS" ] && [ "$mass" -ge "$need" ] && [ "$stiff" -ge "$need" ] &&
  pass "95 % intervals held the truth in $mass (mass) and $stiff (stiffness) of $runs noisy runs (need $need)" ||
  fail "coverage: mass $mass, stiffness $stiff of $runs runs (need $need of $SEEDS)"
awk -v r="$noise" 'BEGIN { exit !(r > 0.85 && r < 1.15) }' &&
  pass "the noise estimated per channel is $noise x the noise added, on average" ||
  fail "the noise estimated per channel is $noise x the noise added"

if [ $FAILS -eq 0 ]; then echo "calibrate_coverage_test: all checks passed"; exit 0; fi
echo "calibrate_coverage_test: $FAILS checks failed"; exit 1

#!/usr/bin/env python3
"""Writes a test scene of N independent tendon-driven pendulums and the files to calibrate it.

    make_pendulum_bank.py N OUTDIR [--offset 0.25]

Into OUTDIR:
  bank.urdf, bank.caliper.xml  the scene: N rods (1 kg, 0.5 m) hanging from frames 1 m up, 0.5 m
                               apart along y, each on a hinge `pivot_I` about y, each pulled from
                               the +x side by one DC motor `motor_I` through a series-elastic
                               tendon `tendon_I`; gravity swings a rod back when its motor eases.
                               The side file holds the START values (truth * (1 +- offset)).
  runs.json                    the experiments (voltage schedules, recorded channels).
  truth.json                   the same experiments with "set" = the true values: run it with
                               `caliper-ctl batch truth.json --out OUTDIR/truth` to record the
                               "real robot" (OUTDIR/truth/runs/NAME.csv).
  calibration.json             fits every tendon's stiffness and damping and every motor's
                               resistance (3 N parameters) to those recordings.
  truth.csv                    id,truth for a test to compare the fit with.

Prints the number of parameters and one line per parameter: id, truth, start.
Python 3 standard library only.
"""

import argparse
import json
import os
import sys

ROBOT = "bank"
SPACING = 0.5          # m between neighbouring pendulums along y (they swing in x-z planes)
HEIGHT = 1.0           # m, pivot height
ROD_LENGTH = 0.5       # m
ROD_MASS = 1.0         # kg
ROD_RADIUS = 0.015     # m
ANCHOR = (0.2, 0.0, 0.0)       # tendon anchor on the frame [m, frame coordinates]
ROD_POINT = (0.0, 0.0, -0.3)   # tendon attachment on the rod [m, rod coordinates]
TIME_STEP = 0.001      # s
EVERY_N_STEPS = 5      # 200 samples/s
DURATIONS = {"steps": 1.2, "pulses": 1.0}  # s, simulated time of each experiment

# The motor: a small geared DC motor (low ratio, so that it is a torque source the pendulum can
# back-drive, and its stall tension V * eta N k_t / (R r) sets where the rod stands).
MOTOR = {
    "torque_constant": (0.0115, "N m/A"),
    "back_emf_constant": (0.0115, "V s/rad"),
    "gear_ratio": (8, ""),
    "efficiency": (0.85, ""),
    "spool_radius": (0.01, "m"),
    "rest_length": (0.05, "m"),
}


def truths(i):
    """The true stiffness [N/m], damping [N s/m] and resistance [ohm] of pendulum i."""
    stiffness = 200.0 * 1.05 ** i
    damping = 10.0 * 1.05 ** i
    resistance = 4.0 * 1.03 ** i
    return stiffness, damping, resistance


def parameter_ids(i):
    return [f"{ROBOT}.motor_{i}.stiffness", f"{ROBOT}.motor_{i}.damping",
            f"{ROBOT}.motor_{i}.resistance"]


def schedules(i):
    """Voltage commands [[t, actuator, V], ...] of pendulum i for each experiment: a holding
    voltage from 0, then steps up and down at times that differ between pendulums."""
    motor = f"motor_{i}"
    shift = 0.03 * (i % 5)
    steps = [[0.0, motor, 1.5],
             [round(0.25 + shift, 6), motor, 5.0],
             [round(0.65 + shift, 6), motor, 2.5],
             [round(0.95 + shift / 2, 6), motor, 4.0]]
    shift = 0.02 * (i % 7)
    pulses = [[0.0, motor, 3.0],
              [round(0.2 + shift, 6), motor, 6.0],
              [round(0.3 + shift, 6), motor, 2.0],
              [round(0.5 + shift, 6), motor, 4.5]]
    return {"steps": steps, "pulses": pulses}


def fmt(x):
    return repr(float(x))


def write_urdf(path, n):
    inertia_xx = ROD_MASS * (ROD_LENGTH ** 2 / 12 + ROD_RADIUS ** 2 / 4)
    inertia_zz = ROD_MASS * ROD_RADIUS ** 2 / 2
    lines = ['<?xml version="1.0"?>',
             f"<!-- {n} independent tendon-driven pendulums: written by make_pendulum_bank.py -->",
             f'<robot name="{ROBOT}">', '  <link name="world"/>']
    for i in range(n):
        y = i * SPACING
        lines += [
            f'  <link name="frame_{i}">',
            '    <visual><geometry><box size="0.05 0.05 0.05"/></geometry></visual>',
            '  </link>',
            f'  <link name="rod_{i}">',
            '    <inertial>',
            f'      <origin xyz="0 0 {fmt(-ROD_LENGTH / 2)}"/>',
            f'      <mass value="{fmt(ROD_MASS)}"/>',
            f'      <inertia ixx="{fmt(inertia_xx)}" ixy="0" ixz="0" iyy="{fmt(inertia_xx)}"'
            f' iyz="0" izz="{fmt(inertia_zz)}"/>',
            '    </inertial>',
            f'    <visual><origin xyz="0 0 {fmt(-ROD_LENGTH / 2)}"/><geometry><cylinder'
            f' radius="{fmt(ROD_RADIUS)}" length="{fmt(ROD_LENGTH)}"/></geometry></visual>',
            f'    <collision><origin xyz="0 0 {fmt(-ROD_LENGTH / 2)}"/><geometry><cylinder'
            f' radius="{fmt(ROD_RADIUS)}" length="{fmt(ROD_LENGTH)}"/></geometry></collision>',
            '  </link>',
            f'  <joint name="mount_{i}" type="fixed">',
            f'    <parent link="world"/><child link="frame_{i}"/>'
            f'<origin xyz="0 {fmt(y)} {fmt(HEIGHT)}"/>',
            '  </joint>',
            f'  <joint name="pivot_{i}" type="continuous">',
            f'    <parent link="frame_{i}"/><child link="rod_{i}"/><axis xyz="0 1 0"/>',
            '    <dynamics damping="0.005"/>',
            '  </joint>',
        ]
    lines.append("</robot>")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_side_file(path, n, start):
    lines = ['<?xml version="1.0"?>',
             "<!-- Caliper's data for bank.urdf: one DC motor tendon per pendulum. The values of",
             "     stiffness, damping and resistance are the calibration's starting point, not the",
             "     truth (truth.json / truth.csv hold that). -->",
             "<caliper>",
             "  <settings>",
             f'    <time_step unit="s">{fmt(TIME_STEP)}</time_step>',
             "  </settings>"]
    for i in range(n):
        k, c, r = (start[pid] for pid in parameter_ids(i))
        lines += [
            f'  <tendon name="tendon_{i}" radius="0.001" collide_with_bodies="false">',
            f'    <attachment body="frame_{i}">{" ".join(fmt(v) for v in ANCHOR)}</attachment>',
            f'    <attachment body="rod_{i}">{" ".join(fmt(v) for v in ROD_POINT)}</attachment>',
            "  </tendon>",
            f'  <actuator name="motor_{i}" kind="dc_motor_tendon" tendon="tendon_{i}">',
        ]
        for name, (value, unit) in MOTOR.items():
            lines.append(f'    <param name="{name}" unit="{unit}">{fmt(value)}</param>')
        lines += [
            f'    <param name="stiffness" unit="N/m">{fmt(k)}</param>',
            f'    <param name="damping" unit="N s/m">{fmt(c)}</param>',
            f'    <param name="resistance" unit="ohm">{fmt(r)}</param>',
            "  </actuator>",
        ]
    lines.append("</caliper>")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def record_ids(n):
    ids = []
    for i in range(n):
        ids += [f"{ROBOT}.pivot_{i}.position", f"{ROBOT}.tendon_{i}.tendon.tension",
                f"{ROBOT}.motor_{i}.current"]
    return ids


def experiments(n, set_values=None):
    per = [schedules(i) for i in range(n)]
    doc = {"scene": "bank.urdf", "every_n_steps": EVERY_N_STEPS, "record": record_ids(n)}
    if set_values:
        doc["set"] = set_values
    doc["experiments"] = []
    for name, duration in DURATIONS.items():
        commands = sorted((c for p in per for c in p[name]), key=lambda c: (c[0], c[1]))
        doc["experiments"].append({"name": name, "duration_s": duration, "commands": commands})
    return doc


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("n", type=int, help="number of pendulums (3 parameters each)")
    parser.add_argument("outdir")
    parser.add_argument("--offset", type=float, default=0.25,
                        help="start = truth * (1 +- offset), the sign alternating per parameter")
    args = parser.parse_args()
    if args.n < 1:
        parser.error("N must be at least 1")
    if not 0 <= args.offset < 2 / 3:
        parser.error("--offset must be in [0, 2/3): the start must stay inside the bounds "
                     "truth/3 .. truth*3")
    os.makedirs(args.outdir, exist_ok=True)

    truth, start = {}, {}
    j = 0
    for i in range(args.n):
        for pid, value in zip(parameter_ids(i), truths(i)):
            truth[pid] = value
            start[pid] = value * (1 + (args.offset if j % 2 == 0 else -args.offset))
            j += 1

    write_urdf(os.path.join(args.outdir, "bank.urdf"), args.n)
    write_side_file(os.path.join(args.outdir, "bank.caliper.xml"), args.n, start)
    with open(os.path.join(args.outdir, "runs.json"), "w") as f:
        json.dump(experiments(args.n), f, indent=1)
        f.write("\n")
    with open(os.path.join(args.outdir, "truth.json"), "w") as f:
        json.dump(experiments(args.n, truth), f, indent=1)
        f.write("\n")
    calibration = {
        "experiments": "runs.json",
        "measured": {name: f"truth/runs/{name}.csv" for name in DURATIONS},
        "parameters": [{"id": pid, "lower": v / 3, "upper": v * 3, "scale": "log"}
                       for pid, v in truth.items()],
        "optimiser": {"generations": 1, "population": 6},
        "refinement": {"iterations": 30, "jacobian": "forward"},
        "seed": 1,
    }
    with open(os.path.join(args.outdir, "calibration.json"), "w") as f:
        json.dump(calibration, f, indent=1)
        f.write("\n")
    with open(os.path.join(args.outdir, "truth.csv"), "w") as f:
        f.write("id,truth\n")
        for pid, v in truth.items():
            f.write(f"{pid},{fmt(v)}\n")

    print(f"{len(truth)} parameters")
    for pid, v in truth.items():
        print(f"{pid} {v:.10g} {start[pid]:.10g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

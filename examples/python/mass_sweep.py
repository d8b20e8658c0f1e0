#!/usr/bin/env python3
"""A sweep over the forearm's mass, run as a batch across the session's Models.

Every run is the same experiment (the shipped arm, the same motor commands, the elbow angle and
the flexor tendon's tension recorded every 10 ms) with one value of ecce_arm.forearm.mass [kg];
caliper.run_batch spreads the runs over the Models (one run per Model at a time, each on a fresh
load of the scene, so a run gives the same numbers on any Model). The motor commands:

    0 s ..  T/2   elbow_flexor at --flex-v (12 V), elbow_extensor off
    T/2 .. T      elbow_flexor off, elbow_extensor at --extend-v (4 V)

It prints a table (mass [kg], final angle [rad], peak angle [rad]), writes it as CSV, and plots
the elbow angle against time for each mass: a heavier forearm rises more slowly and less far.

    launch/caliper python examples/python/mass_sweep.py
    launch/caliper python examples/python/mass_sweep.py --masses-kg 0.5 1 2 4 --models 4
    launch/caliper python examples/python/mass_sweep.py --latest     # every Model of a session
"""

import argparse
import csv
import os
import sys

import numpy as np

import caliper

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
MASS = "ecce_arm.forearm.mass"
ANGLE = "ecce_arm.elbow.position"
TENSION = "ecce_arm.elbow_flexor.tendon.tension"


# -- the sweep ------------------------------------------------------------------------------------
def experiments(args: argparse.Namespace) -> dict:
    """The batch in the format of experiment files (docs/cluster.md): top-level keys are every
    run's defaults, each entry of "experiments" one run with its own "set"."""
    switch_s = args.duration_s / 2
    return {
        "scene": SCENE,
        "duration_s": args.duration_s,
        "every_n_steps": 10,
        "record": [ANGLE, TENSION],
        "commands": [[0.0, "elbow_flexor", args.flex_v], [0.0, "elbow_extensor", 0.0],
                     [switch_s, "elbow_flexor", 0.0], [switch_s, "elbow_extensor", args.extend_v]],
        "experiments": [{"name": f"mass_{m:g}kg", "set": {MASS: m}} for m in args.masses_kg],
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    parser.add_argument("--masses-kg", type=float, nargs="+",
                        default=[0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
                        help="forearm masses to run [kg] (the shipped arm's is 1 kg)")
    parser.add_argument("--duration-s", type=float, default=4.0,
                        help="simulated time of each run [s]")
    parser.add_argument("--flex-v", type=float, default=12.0,
                        help="elbow_flexor's command in the first half [V]")
    parser.add_argument("--extend-v", type=float, default=4.0,
                        help="elbow_extensor's command in the second half [V]")
    parser.add_argument("--models", type=int, default=2,
                        help="Models of the private session (the runs spread over them)")
    parser.add_argument("--glob", default="*",
                        help="with a running session: the Models to use (a glob, e.g. '*@hostb')")
    parser.add_argument("--out", default="results", metavar="DIR",
                        help="folder of the figure and the table")
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    if any(not m > 0 for m in args.masses_kg):
        parser.error("masses must be > 0 kg")
    if len(set(args.masses_kg)) != len(args.masses_kg):
        parser.error("masses must differ")
    if args.duration_s <= 0 or args.models < 1:
        parser.error("--duration-s and --models must be positive")
    args.masses_kg = sorted(args.masses_kg)

    with caliper.cli.open_session(args, models=args.models, scene=SCENE) as session:
        print(f"{len(args.masses_kg)} runs of {args.duration_s:g} s: flexor {args.flex_v:g} V "
              f"for {args.duration_s / 2:g} s, then extensor {args.extend_v:g} V")
        batch = caliper.run_batch(experiments(args), session=session, models=args.glob,
                                  progress=False)
    print(f"batch: {len(batch.results)} runs done, {len(batch.failures)} failed, on "
          f"{len(batch.models)} Models ({', '.join(batch.models)}) in {batch.wall_s:.2f} s of "
          f"wall time")
    for name, why in batch.failures.items():
        print(f"  {name} FAILED: {why}")
    if batch.failures:
        return 1

    rows = []
    print(f"{'mass [kg]':>10} {'final angle [rad]':>18} {'peak angle [rad]':>17} "
          f"{'peak at [s]':>12}")
    for m in args.masses_kg:
        data = batch[f"mass_{m:g}kg"]
        q = data[ANGLE]
        peak = int(np.argmax(q))
        rows.append((m, q[-1], q[peak], data.time[peak]))
        print(f"{m:10.2f} {q[-1]:18.4f} {q[peak]:17.4f} {data.time[peak]:12.2f}")

    os.makedirs(args.out, exist_ok=True)
    table = os.path.join(args.out, "mass_sweep.csv")
    with open(table, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["mass [kg]", "final angle [rad]", "peak angle [rad]", "peak time [s]"])
        w.writerows([[repr(float(v)) for v in r] for r in rows])
    print(f"table: {os.path.abspath(table)}")
    png = os.path.join(args.out, "mass_sweep.png")
    plot(batch, args, np.array(rows), png)
    print(f"figure: {os.path.abspath(png)}")
    return 0


def plot(batch: "caliper.Batch", args: argparse.Namespace, rows: np.ndarray, png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True,
                                     gridspec_kw={"width_ratios": [1.6, 1]})
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(args.masses_kg)))
    for m, color in zip(args.masses_kg, colors):
        data = batch[f"mass_{m:g}kg"]
        ax_t.plot(data.time, data[ANGLE], color=color, label=f"{m:g} kg")
    ax_t.axvline(args.duration_s / 2, color="0.5", linestyle=":", linewidth=1)
    for text, offset, align in ((f"flexor {args.flex_v:g} V", -6, "right"),
                                (f"extensor {args.extend_v:g} V", 6, "left")):
        ax_t.annotate(text, (args.duration_s / 2, 0.3), xycoords=("data", "axes fraction"),
                      xytext=(offset, 0), textcoords="offset points", ha=align)
    ax_t.set_xlabel("simulated time [s]")
    ax_t.set_ylabel("elbow angle [rad]")
    ax_t.set_title("Elbow angle per forearm mass")
    ax_t.legend(title="forearm mass", loc="lower right")
    ax_m.plot(rows[:, 0], rows[:, 2], "o-", label="peak angle")
    ax_m.plot(rows[:, 0], rows[:, 1], "s-", label="final angle")
    ax_m.set_xlabel("forearm mass [kg]")
    ax_m.set_ylabel("elbow angle [rad]")
    ax_m.set_title("Peak and final angle")
    ax_m.legend()
    for ax in (ax_t, ax_m):
        ax.grid(True, alpha=0.3)
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())

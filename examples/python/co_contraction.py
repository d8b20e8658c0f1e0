#!/usr/bin/env python3
"""A long co-contraction of the shipped arm's two elbow motors, with their heat.

Both elbow motors of models/ecce_arm.dae pull against each other at full voltage, so each holds
its driver's current limit at stall. The script gives both motors a thermal model (the four
constants a motor datasheet lists under "thermal data", here of the order of a 20 W maxon
motor's; type your own with --r-wh, --r-ha, --tau-w, --tau-m) and a driver current limit above
the motor's continuous current, then runs the Model as fast as it can and prints, every
--print-every-s of simulated time, the winding and housing temperatures, the current, and the
driver's current limit. As the windings approach --max-winding-c the driver lowers its limit
toward the continuous current (the derating band, --band-k) and the Model logs a warning.

    launch/caliper python examples/python/co_contraction.py
    launch/caliper python examples/python/co_contraction.py --duration-s 600 --current-limit-a 5

The figure (results/co_contraction.png) shows temperatures, currents and the limit over time.
Every id it reads is a DAQ channel: the plotter shows the same live
(`launch/caliper open plotter`, ids ecce_arm.elbow_flexor.winding_temperature, ...).
"""

import argparse
import os
import sys
import time

import numpy as np

import caliper

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
MOTORS = ("elbow_flexor", "elbow_extensor")
QUANTITIES = ("winding_temperature", "housing_temperature", "current", "current_limit_now",
              "derating")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    parser.add_argument("--duration-s", type=float, default=240.0, help="simulated time [s]")
    parser.add_argument("--voltage-v", type=float, default=12.0,
                        help="the command of both motors [V]")
    parser.add_argument("--current-limit-a", type=float, default=6.0,
                        help="the drivers' current limit [A]")
    parser.add_argument("--r-wh", type=float, default=2.9,
                        help="thermal resistance winding-housing [K/W]")
    parser.add_argument("--r-ha", type=float, default=11.5,
                        help="thermal resistance housing-ambient [K/W]")
    parser.add_argument("--tau-w", type=float, default=12.0,
                        help="thermal time constant of the winding [s]")
    parser.add_argument("--tau-m", type=float, default=600.0,
                        help="thermal time constant of the motor [s]")
    parser.add_argument("--ambient-c", type=float, default=25.0, help="ambient temperature [degC]")
    parser.add_argument("--max-winding-c", type=float, default=125.0,
                        help="maximum winding temperature [degC]")
    parser.add_argument("--band-k", type=float, default=10.0,
                        help="derating band below the maximum [K]")
    parser.add_argument("--chunk-steps", type=int, default=500,
                        help="physics steps between samples")
    parser.add_argument("--print-every-s", type=float, default=20.0,
                        help="print a row every this much simulated time [s]")
    parser.add_argument("--model", default="model0", help="the Model to run")
    parser.add_argument("--out", default="results", metavar="DIR", help="folder of the figure")
    parser.add_argument("--no-plot", action="store_true", help="write no figure")
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    if args.duration_s <= 0 or args.chunk_steps < 1 or args.current_limit_a <= 0:
        parser.error("--duration-s, --chunk-steps and --current-limit-a must be positive")

    with caliper.cli.open_session(args, models=1, scene=SCENE) as session:
        arm = session.model(args.model)
        caliper.cli.prepare(arm, SCENE)
        prefix = arm.channels("*.elbow.position")[0].id[:-len("elbow.position")]
        for motor in MOTORS:
            # R_ha last: it turns the thermal model on, which needs the other three
            for name, value in (("thermal_resistance_winding_housing", args.r_wh),
                                ("thermal_time_constant_winding", args.tau_w),
                                ("thermal_time_constant_motor", args.tau_m),
                                ("ambient_temperature", args.ambient_c),
                                ("max_winding_temperature", args.max_winding_c),
                                ("derating_band", args.band_k),
                                ("current_limit", args.current_limit_a),
                                ("thermal_resistance_housing_ambient", args.r_ha)):
                arm.set(f"{prefix}{motor}.{name}", value)
        limit = float(arm.get_values([f"{prefix}{MOTORS[0]}.current_limit"])[0])
        ids = [f"{prefix}{m}.{q}" for m in MOTORS for q in QUANTITIES]
        dt = arm.time_step_s
        chunks = max(1, round(args.duration_s / (args.chunk_steps * dt)))
        print_every = max(1, round(args.print_every_s / (args.chunk_steps * dt)))
        print(f"co-contraction at {args.voltage_v:g} V, current limit {limit:g} A, "
              f"thermal R_wh {args.r_wh:g} K/W, R_ha {args.r_ha:g} K/W, tau_w {args.tau_w:g} s, "
              f"tau_m {args.tau_m:g} s, max winding {args.max_winding_c:g} degC "
              f"(band {args.band_k:g} K)")
        print(f"{'time [s]':>9} {'winding [degC]':>15} {'housing [degC]':>15} {'current [A]':>12} "
              f"{'limit [A]':>10}   (elbow_flexor)")
        log = np.zeros((chunks + 1, 1 + len(ids)))
        arm.set_commands({m: args.voltage_v for m in MOTORS})
        started = time.monotonic()
        derating_from = None
        for k in range(chunks + 1):
            values = arm.get_values(ids)
            t = k * args.chunk_steps * dt
            log[k] = (t, *values)
            if derating_from is None and values[4] > 0:
                derating_from = t
            if k % print_every == 0 or k == chunks:
                print(f"{t:9.1f} {values[0]:15.2f} {values[1]:15.2f} {abs(values[2]):12.3f} "
                      f"{values[3]:10.3f}")
            if k < chunks:
                arm.step(args.chunk_steps)
        wall_s = time.monotonic() - started
        arm.set_commands({m: 0.0 for m in MOTORS})

    winding = log[:, 1]
    print(f"highest winding temperature: {winding.max():.2f} degC (maximum "
          f"{args.max_winding_c:g} degC)")
    if derating_from is None:
        print("the driver never derated: the windings stayed below "
              f"{args.max_winding_c - args.band_k:g} degC")
    else:
        print(f"the driver derated from {derating_from:.1f} s; final current "
              f"{abs(log[-1, 3]):.3f} A against a limit of {args.current_limit_a:g} A")
    print(f"{log[-1, 0]:.0f} s simulated in {wall_s:.1f} s of wall time "
          f"({log[-1, 0] / wall_s:.1f}x real time)")
    if not args.no_plot:
        png = os.path.join(args.out, "co_contraction.png")
        plot(log, args, png)
        print(f"figure: {os.path.abspath(png)}")
    return 0


def plot(log: np.ndarray, args: argparse.Namespace, png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    t = log[:, 0]
    n = len(QUANTITIES)
    fig, (ax_t, ax_i) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, constrained_layout=True)
    for m, motor in enumerate(MOTORS):
        ax_t.plot(t, log[:, 1 + m * n], label=f"{motor} winding")
        ax_t.plot(t, log[:, 2 + m * n], linestyle="--", label=f"{motor} housing")
        ax_i.plot(t, np.abs(log[:, 3 + m * n]), label=f"{motor} |current|")
        ax_i.plot(t, log[:, 4 + m * n], linestyle=":", label=f"{motor} driver limit")
    ax_t.axhline(args.max_winding_c, color="k", linewidth=1, label="maximum winding")
    ax_t.axhline(args.max_winding_c - args.band_k, color="k", linestyle=":", linewidth=1,
                 label="derating starts")
    ax_t.set_ylabel("temperature [degC]")
    ax_t.legend(loc="lower right", fontsize=8)
    ax_t.set_title(f"Co-contraction of the elbow at {args.voltage_v:g} V")
    ax_i.set_ylabel("current [A]")
    ax_i.set_xlabel("time [s]")
    ax_i.legend(loc="lower left", fontsize=8)
    fig.savefig(png, dpi=100)


if __name__ == "__main__":
    sys.exit(main())

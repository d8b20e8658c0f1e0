#!/usr/bin/env python3
"""The demo's PD elbow controller, written in Python and run in lock-step.

Each tick reads the elbow's angle q [rad] and velocity qd [rad/s], commands both elbow motors
with the arithmetic of the C++ controller (components/pd_controller/pd_controller_component.cc)

    u        = kp * (target - q) - kd * qd            [V]
    flexor   = clamp(bias + u, 0, max)                [V]
    extensor = clamp(bias - u, 0, max)                [V]

and then steps the Model `--steps-per-tick` physics steps (10 x 1 ms by default; the C++
controller's lock-step mode, controller.lockstep). The target here is 0.8 rad (the demo asks its
controller for 1.0 rad: `--target-rad 1.0`). Nothing else moves the Model, so a run is a
function of its options. It prints the elbow angle every 0.5 s of simulated time and the final
error, and plots angle, motor commands and tendon tensions.

Run it right after building (it starts a private session with one Model of the shipped arm):

    launch/caliper python examples/python/pd_elbow.py
    launch/caliper python examples/python/pd_elbow.py --target-rad 1.0 --kd 2 --duration-s 8

or on the Model of a running session (`--latest`, or `--nameservice corbaname::HOST:PORT`); stop
the demo's own controller first (`launch/caliper ctl deactivate pd_controller0`), or both
controllers will command the same motors.
"""

import argparse
import os
import sys
import time

import numpy as np

import caliper

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")


# -- the controller -------------------------------------------------------------------------------
def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    parser.add_argument("--target-rad", type=float, default=0.8, help="elbow target [rad]")
    parser.add_argument("--kp", type=float, default=20.0, help="proportional gain [V/rad]")
    parser.add_argument("--kd", type=float, default=1.0, help="derivative gain [V s/rad]")
    parser.add_argument("--bias-v", type=float, default=1.0,
                        help="co-contraction voltage on both motors [V]")
    parser.add_argument("--max-v", type=float, default=6.0, help="largest motor voltage [V]")
    parser.add_argument("--steps-per-tick", type=int, default=10,
                        help="physics steps per controller tick")
    parser.add_argument("--duration-s", type=float, default=6.0, help="simulated time [s]")
    parser.add_argument("--print-every-s", type=float, default=0.5,
                        help="print the angle every this much simulated time [s]")
    parser.add_argument("--model", default="model0", help="the Model to control")
    parser.add_argument("--out", default="results", metavar="DIR",
                        help="folder of the figure")
    parser.add_argument("--plot", metavar="PNG",
                        help="the figure's file (default: DIR/pd_elbow.png)")
    parser.add_argument("--no-plot", action="store_true", help="write no figure")
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    if args.steps_per_tick < 1 or args.duration_s <= 0 or args.max_v < 0:
        parser.error("--steps-per-tick, --duration-s and --max-v must be positive")

    flexor, extensor = "elbow_flexor", "elbow_extensor"
    with caliper.cli.open_session(args, models=1, scene=SCENE) as session:
        arm = session.model(args.model)
        caliper.cli.prepare(arm, SCENE)
        # the joint's channels, found as the C++ controller finds them
        position = arm.channels("*.elbow.position")[0].id      # ecce_arm.elbow.position
        velocity = position[:-len("position")] + "velocity"
        prefix = position[:-len("elbow.position")]
        ids = [position, velocity, f"{prefix}{flexor}.tendon.tension",
               f"{prefix}{extensor}.tendon.tension"]
        period_s = args.steps_per_tick * arm.time_step_s
        ticks = max(1, round(args.duration_s / period_s))
        print_every = max(1, round(args.print_every_s / period_s))
        print(f"PD on {arm.name}: target {args.target_rad:.3f} rad, kp {args.kp:g} V/rad, "
              f"kd {args.kd:g} V s/rad, bias {args.bias_v:g} V, max {args.max_v:g} V, "
              f"{args.steps_per_tick} steps ({period_s * 1e3:.3g} ms) per tick, {ticks} ticks")
        print(f"{'time [s]':>9} {'elbow [rad]':>12} {'error [rad]':>12} {'flexor [V]':>11} "
              f"{'extensor [V]':>13}")

        log = np.zeros((ticks + 1, 7))  # time, q, qd, flexor V, extensor V, tensions [N]
        commands = (0.0, 0.0)
        started = time.monotonic()
        for k in range(ticks + 1):
            q, qd, tension_flexor, tension_extensor = arm.get_values(ids)
            t = k * period_s
            if k < ticks:  # the last row is the state after the last tick
                u = args.kp * (args.target_rad - q) - args.kd * qd
                commands = (float(np.clip(args.bias_v + u, 0.0, args.max_v)),
                            float(np.clip(args.bias_v - u, 0.0, args.max_v)))
            if k % print_every == 0 or k == ticks:
                print(f"{t:9.2f} {q:12.4f} {args.target_rad - q:12.4f} {commands[0]:11.2f} "
                      f"{commands[1]:13.2f}")
            log[k] = (t, q, qd, *commands, tension_flexor, tension_extensor)
            if k < ticks:
                arm.set_commands({flexor: commands[0], extensor: commands[1]})
                arm.step(args.steps_per_tick)
        wall_s = time.monotonic() - started
        arm.set_commands({flexor: 0.0, extensor: 0.0})

    q_final = log[-1, 1]
    error = abs(args.target_rad - q_final)
    print(f"final elbow angle: {q_final:.4f} rad (target {args.target_rad:.4f} rad) after "
          f"{log[-1, 0]:.2f} s")
    print(f"final error: {error:.4f} rad")
    print(f"{ticks} ticks in {wall_s:.2f} s of wall time ({log[-1, 0] / wall_s:.1f}x real time, "
          f"{wall_s / ticks * 1e3:.2f} ms per tick)")

    if not args.no_plot:
        png = args.plot or os.path.join(args.out, "pd_elbow.png")
        plot(log, args, png)
        print(f"figure: {os.path.abspath(png)}")
    return 0


def plot(log: np.ndarray, args: argparse.Namespace, png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log[:, 0]
    fig, (ax_q, ax_v, ax_n) = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True,
                                           constrained_layout=True)
    ax_q.plot(t, log[:, 1], label="elbow angle")
    ax_q.axhline(args.target_rad, color="k", linestyle="--", linewidth=1,
                 label=f"target {args.target_rad:g} rad")
    ax_q.set_ylabel("elbow angle [rad]")
    ax_q.legend(loc="lower right")
    ax_q.set_title(f"PD elbow control in lock-step: kp {args.kp:g} V/rad, kd {args.kd:g} V s/rad, "
                   f"bias {args.bias_v:g} V, max {args.max_v:g} V")
    ax_v.step(t, log[:, 3], where="post", label="elbow_flexor")
    ax_v.step(t, log[:, 4], where="post", label="elbow_extensor")
    ax_v.set_ylabel("motor command [V]")
    ax_v.set_ylim(-0.3, args.max_v + 0.5)
    ax_v.legend(loc="upper right")
    ax_n.plot(t, log[:, 5], label="elbow_flexor tendon")
    ax_n.plot(t, log[:, 6], label="elbow_extensor tendon")
    ax_n.set_ylabel("tendon tension [N]")
    ax_n.set_xlabel("simulated time [s]")
    ax_n.legend(loc="lower right")
    for ax in (ax_q, ax_v, ax_n):
        ax.grid(True, alpha=0.3)
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())

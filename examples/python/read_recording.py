#!/usr/bin/env python3
"""Record a few seconds of the arm, then read the recording with caliper.Recording.

Without a file argument it has a Model record its session (model.start_recording: keyframes
every 100 steps, every command and parameter write, and the chosen channels every --every
steps) while it drives the elbow through three phases (flex, extend with a heavier forearm,
co-contract), copies the file into --out, and reads it back. With a file (a recording from
`launch/caliper session --record`, `ctl recording start` or the Main Window) it only reads that
one and needs no session.

What it prints: the header (model, scene, engine, time step [s], duration [s]), the channels
with their units, the events counted by kind and the commands and parameter writes with their
times [s], the keyframe times [s]; it plots one channel against time with the events marked,
exports the channels as CSV, and with --verify re-simulates the recording and compares it bit
for bit (caliper.verify).

    launch/caliper python examples/python/read_recording.py
    launch/caliper python examples/python/read_recording.py --verify
    launch/caliper python examples/python/read_recording.py FILE --channel ecce_arm.hand.position
"""

import argparse
import collections
import os
import shutil
import sys
import time

import numpy as np

import caliper

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
CHANNELS = ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension",
            "ecce_arm.elbow_extensor.tendon.tension", "ecce_arm.hand.position"]


# -- making a recording ---------------------------------------------------------------------------
def record(args: argparse.Namespace) -> str:
    """Records --duration-s of the arm on a Model and returns the copy in --out."""
    with caliper.cli.open_session(args, models=1, scene=SCENE) as session:
        arm = session.model(args.model)
        caliper.cli.prepare(arm, SCENE)
        # a name of its own: a recording never overwrites a file
        name = time.strftime(f"read_recording-%Y%m%d-%H%M%S-{os.getpid()}.caliper")
        status = arm.start_recording(name, channels=args.channels, every=args.every)
        print(f"{arm.name} records into {status.path} (on its host)")
        third = max(1, round(args.duration_s / 3 / arm.time_step_s))
        arm.set_commands({"elbow_flexor": 8.0, "elbow_extensor": 0.0})          # [V]
        arm.step(third)
        arm.set("ecce_arm.forearm.mass", 1.5)                                  # [kg]
        arm.set_commands({"elbow_flexor": 0.0, "elbow_extensor": 4.0})
        arm.step(third)
        arm.set_commands({"elbow_flexor": 2.0, "elbow_extensor": 2.0})
        arm.step(third)
        status = arm.stop_recording()
        arm.set_commands({"elbow_flexor": 0.0, "elbow_extensor": 0.0})
        if status.error:
            raise SystemExit(f"the recording stopped early: {status.error}")
        print(f"recorded {status.steps} steps, {status.bytes / 1e3:.0f} kB")
        if not arm.local:
            raise SystemExit(f"{arm.name} runs on another host: {status.path} is there; copy it "
                             "here and pass it as the argument")
        os.makedirs(args.out, exist_ok=True)
        # the private session's folder goes when it ends: keep a copy (a recording that ended is
        # one complete SQLite file)
        copy = os.path.join(args.out, "read_recording.caliper")
        shutil.copyfile(status.path, copy)
        return copy


# -- reading it -----------------------------------------------------------------------------------
def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    parser.add_argument("recording", nargs="?",
                        help="a recording to read (default: make one, see above)")
    parser.add_argument("--channel", default=CHANNELS[0], help="the channel to plot")
    parser.add_argument("--channels", nargs="+", default=CHANNELS, metavar="ID",
                        help="the channels to record")
    parser.add_argument("--every", type=int, default=10,
                        help="record the channels every this many steps")
    parser.add_argument("--duration-s", type=float, default=3.0,
                        help="simulated time to record [s]")
    parser.add_argument("--model", default="model0", help="the Model that records")
    parser.add_argument("--verify", action="store_true",
                        help="re-simulate the recording and compare it bit for bit")
    parser.add_argument("--out", default="results", metavar="DIR",
                        help="folder of the recording's copy, the CSV and the figure")
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    if args.duration_s <= 0 or args.every < 1:
        parser.error("--duration-s and --every must be positive")

    path = args.recording or record(args)
    rec = caliper.Recording(path)
    print(f"\n{rec}")
    print(f"  model {rec.model_name}, scene {rec.scene_file_name}, engine {rec.engine}")
    print(f"  time step {rec.time_step_s * 1e3:g} ms, steps {rec.first_step} .. {rec.last_step}, "
          f"duration {rec.duration_s:.3f} s, file {os.path.getsize(path) / 1e3:.0f} kB")
    print(f"  keyframes every {rec.keyframe_every} steps, channels every {rec.channels_every} "
          f"steps")

    print(f"channels ({len(rec.channels)}):")
    for c in rec.channels:
        shape = "scalar" if c.shape == () else f"shape {c.shape}"
        print(f"  {c.id:<42} {'[' + (c.unit or '-') + ']':<7} {shape}")

    events = rec.events()
    print("events by kind: " + ", ".join(f"{kind} {n}" for kind, n in
                                          sorted(collections.Counter(e.kind for e in events)
                                                 .items())))
    changes = [e for e in events if e.kind not in ("keyframe", "end")]
    if changes:
        print("  (commands in the actuator's unit, V for the arm's motors; parameters in their "
              "DAQ unit, kg for a mass)")
    for e in changes:
        values = " ".join(f"{v:g}" for v in e.values)
        print(f"  t = {e.step * rec.time_step_s:6.3f} s (step {e.step:6d})  {e.kind:<9} "
              f"{e.target} = {values}")

    times = rec.keyframe_times_s
    spacing = f", every {np.median(np.diff(times)):.3f} s" if len(times) > 1 else ""
    shown = ", ".join(f"{t:.1f}" for t in times[:6]) + (", ..." if len(times) > 6 else "")
    print(f"keyframes: {len(times)} at {shown} s{spacing}")
    print(f"scene versions: {len(rec.scenes())}, log records: {len(rec.log())}")

    data = rec.channels_data()
    print(f"samples: {len(data)} from {data.time[0]:.3f} to {data.time[-1]:.3f} s"
          if len(data) else "samples: none (a recording without channels)")

    os.makedirs(args.out, exist_ok=True)
    csv = os.path.join(args.out, "read_recording.csv")
    rec.export_csv(csv)
    print(f"csv: {os.path.abspath(csv)}")
    if args.channel in data and len(data):
        png = os.path.join(args.out, "read_recording.png")
        plot(rec, data, args.channel, changes, png)
        print(f"figure: {os.path.abspath(png)}")
    else:
        print(f"no figure: the recording has no samples of {args.channel} (it has "
              f"{', '.join(data.ids()) or 'no channels'})")

    if args.verify:
        started = time.monotonic()
        identical, report = caliper.verify(path)
        print(f"verify ({time.monotonic() - started:.2f} s): "
              f"{'IDENTICAL' if identical else 'DIFFERENT'}: {report.splitlines()[0]}")
        if not identical:
            print(report)
            return 1
    return 0


def plot(rec: "caliper.Recording", data: "caliper.Data", channel: str, changes: list,
         png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    unit = data.units[channel]
    values = data[channel].reshape(len(data), -1)
    fig, ax = plt.subplots(figsize=(9, 4.5), constrained_layout=True)
    labels = ["x", "y", "z"] if values.shape[1] == 3 else [f"[{i}]" for i in range(values.shape[1])]
    for i in range(values.shape[1]):
        ax.plot(data.time, values[:, i],
                label=channel if values.shape[1] == 1 else f"{channel} {labels[i]}")
    # the events: a line where the commands or parameters changed, labelled once per time
    by_time = collections.defaultdict(list)
    for e in changes:
        by_time[e.step * rec.time_step_s].append(
            f"{e.target} {' '.join(f'{v:g}' for v in e.values)}")
    for t, texts in sorted(by_time.items()):
        ax.axvline(t, color="0.4", linestyle=":", linewidth=1)
        ax.annotate("\n".join(texts), (t, 0.97), xycoords=("data", "axes fraction"),
                    xytext=(4, 0), textcoords="offset points", va="top", fontsize=8)
    ax.plot(rec.keyframe_times_s, np.zeros_like(rec.keyframe_times_s), "|", color="C3",
            markersize=8, transform=ax.get_xaxis_transform(), label="keyframes")
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel(f"{channel.split('.', 1)[-1]} [{unit}]" if unit else channel)
    ax.set_title(f"{os.path.basename(rec.path)}: {rec.model_name}, {rec.duration_s:.2f} s, "
                 f"{len(rec.keyframe_times_s)} keyframes")
    ax.margins(y=0.35)
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())

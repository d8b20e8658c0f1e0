#!/usr/bin/env python3
"""Episodes in caliper.TendonEnv: random actions against a scripted PD policy, repeatable seeds,
and a VectorEnv stepping two Models at once.

The task: bring the elbow to --target-rad (0.8 rad) with the elbow's two motors. An action is
the two motor voltages [V] in [0, --max-v]; one action lasts 10 physics steps (10 ms); the
observation is the elbow angle [rad] and velocity [rad/s]; the reward is -|angle - target|
[rad] per action, so an episode's return is minus the summed error (the mean error [rad] is
-return / actions). At every reset the forearm's mass is drawn uniformly from --mass-kg.

It runs --episodes random episodes and as many with the PD policy of pd_elbow.py on the same
seeds, shows that reset(seed=s) repeats an episode bit for bit (the same drawn mass, the same
random actions, the same observations), then runs a VectorEnv of two environments on two Models
in parallel with the PD policy, and plots angle against time.

    launch/caliper python examples/python/episodes.py
    launch/caliper python examples/python/episodes.py --episodes 5 --actions 800 --max-v 12
"""

import argparse
import os
import sys
import time

import numpy as np

import caliper

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
MASS = "ecce_arm.forearm.mass"


# -- the task and the policies ------------------------------------------------------------------
def make_env(session: "caliper.Session", name: str, args: argparse.Namespace) -> caliper.TendonEnv:
    model = session.model(name)
    caliper.cli.prepare(model, SCENE)
    target = args.target_rad
    return caliper.TendonEnv(
        model, session=session,
        actuators=["elbow_flexor", "elbow_extensor"],
        observations=["ecce_arm.elbow.position", "ecce_arm.elbow.velocity"],
        reward=lambda obs, action, env: -abs(obs[0] - target),
        frames_per_action=10, max_episode_steps=args.actions,
        action_low=0.0, action_high=args.max_v,
        randomize={MASS: tuple(args.mass_kg)})


def pd_policy(obs: np.ndarray, args: argparse.Namespace) -> np.ndarray:
    """pd_elbow.py's controller: kp 20 V/rad, kd 1 V s/rad, bias 1 V (clipped by the env)."""
    u = 20.0 * (args.target_rad - obs[0]) - 1.0 * obs[1]
    return np.array([1.0 + u, 1.0 - u])


def episode(env: caliper.TendonEnv, seed: int, policy, args: argparse.Namespace):
    """One episode from reset(seed): (return, drawn mass [kg], angles [rad] after each action)."""
    obs, info = env.reset(seed=seed)
    total, angles = 0.0, [obs[0]]
    truncated = terminated = False
    while not (terminated or truncated):
        action = env.action_space.sample() if policy is None else policy(obs, args)
        obs, reward, terminated, truncated, info = env.step(action)
        total += reward
        angles.append(obs[0])
    return total, info["parameters"][MASS], np.array(angles)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    parser.add_argument("--episodes", type=int, default=3,
                        help="random episodes, and as many PD ones (seeds 0, 1, ...)")
    parser.add_argument("--actions", type=int, default=500,
                        help="actions (10 ms each) per episode")
    parser.add_argument("--target-rad", type=float, default=0.8, help="elbow target [rad]")
    parser.add_argument("--max-v", type=float, default=6.0, help="largest motor voltage [V]")
    parser.add_argument("--mass-kg", type=float, nargs=2, default=[0.5, 2.0],
                        metavar=("LOW", "HIGH"), help="range of the forearm's mass [kg]")
    parser.add_argument("--out", default="results", metavar="DIR", help="folder of the figure")
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    if args.episodes < 1 or args.actions < 1 or args.max_v <= 0:
        parser.error("--episodes, --actions and --max-v must be positive")

    with caliper.cli.open_session(args, models=2, scene=SCENE) as session:
        names = session.models()[:2]
        env = make_env(session, names[0], args)
        print(env)
        print(f"action space {env.action_space} [V], observation space "
              f"{env.observation_space} [rad, rad/s]")
        period_s = env.control_period_s
        print(f"episodes of {args.actions} actions ({args.actions * period_s:g} s), target "
              f"{args.target_rad:g} rad, forearm mass drawn from [{args.mass_kg[0]:g}, "
              f"{args.mass_kg[1]:g}] kg")

        print(f"{'policy':>7} {'seed':>5} {'mass [kg]':>10} {'return [rad]':>13} "
              f"{'mean error [rad]':>17} {'final angle [rad]':>18}")
        traces = {}
        started = time.monotonic()
        returns = {"random": [], "PD": []}
        for label, policy in (("random", None), ("PD", pd_policy)):
            for seed in range(args.episodes):
                ret, mass, angles = episode(env, seed, policy, args)
                returns[label].append(ret)
                traces[(label, seed)] = (mass, angles)
                print(f"{label:>7} {seed:5d} {mass:10.3f} {ret:13.3f} {-ret / args.actions:17.4f} "
                      f"{angles[-1]:18.4f}")
        wall_s = time.monotonic() - started
        n = 2 * args.episodes * args.actions
        print(f"mean return: random {np.mean(returns['random']):.3f} rad, PD "
              f"{np.mean(returns['PD']):.3f} rad ({n} actions in {wall_s:.2f} s, "
              f"{wall_s / n * 1e3:.2f} ms per action)")

        # the same seed, the same episode
        seed = 1
        first = episode(env, seed, None, args)
        again = episode(env, seed, None, args)
        same = first[0] == again[0] and first[1] == again[1] and np.array_equal(first[2], again[2])
        print(f"reset(seed={seed}) twice, random actions: returns {first[0]:.6f} and "
              f"{again[0]:.6f} rad, masses {first[1]:.4f} and {again[1]:.4f} kg, "
              f"angles identical: {same}")
        env.close()

        # two environments on two Models, stepped in parallel
        vector = None
        if len(names) >= 2:
            vector = caliper.VectorEnv([make_env(session, n, args) for n in names])
            obs, info = vector.reset(seed=10)
            masses = [p[MASS] for p in info["parameters"]]
            totals = np.zeros(vector.num_envs)
            angles = [obs[:, 0].copy()]
            started = time.monotonic()
            for _ in range(args.actions):
                actions = np.stack([pd_policy(o, args) for o in obs])
                obs, rewards, terminated, truncated, info = vector.step(actions)
                totals += rewards
                # at the last action both are truncated and reset: their last observation is
                # info["final_observation"]
                last = np.stack(info["final_observation"]) if "final_observation" in info else obs
                angles.append(last[:, 0].copy())
            wall_s = time.monotonic() - started
            print(f"VectorEnv of {vector.num_envs} on {', '.join(names)}: {args.actions} steps "
                  f"in {wall_s:.2f} s ({wall_s / args.actions * 1e3:.2f} ms per step of both)")
            for i in range(vector.num_envs):
                print(f"  env {i} ({names[i]}): mass {masses[i]:.3f} kg, PD return "
                      f"{totals[i]:.3f} rad, final angle {angles[-1][i]:.4f} rad")
            vector_trace = (masses, np.array(angles))
            vector.close()
        else:
            print("VectorEnv skipped: the session has one Model")
            vector_trace = None

    png = os.path.join(args.out, "episodes.png")
    plot(traces, vector_trace, args, period_s, png)
    print(f"figure: {os.path.abspath(png)}")
    return 0


def plot(traces: dict, vector_trace, args: argparse.Namespace, period_s: float, png: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = 2 if vector_trace is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(5.5 * panels + 1, 4.5), sharey=True,
                             constrained_layout=True, squeeze=False)
    ax = axes[0, 0]
    for seed in range(args.episodes):
        for label, style in (("random", ":"), ("PD", "-")):
            mass, angles = traces[(label, seed)]
            t = np.arange(len(angles)) * period_s
            ax.plot(t, angles, style, color=f"C{seed}",
                    label=f"{label}, seed {seed} ({mass:.2f} kg)")
    ax.axhline(args.target_rad, color="k", linestyle="--", linewidth=1, label="target")
    ax.set_title("TendonEnv: random actions (dotted) and PD (solid)")
    ax.set_xlabel("time in the episode [s]")
    ax.set_ylabel("elbow angle [rad]")
    ax.legend(fontsize=8, loc="center right")
    if vector_trace is not None:
        masses, angles = vector_trace
        ax = axes[0, 1]
        t = np.arange(len(angles)) * period_s
        for i, mass in enumerate(masses):
            ax.plot(t, angles[:, i], label=f"env {i}: forearm {mass:.2f} kg")
        ax.axhline(args.target_rad, color="k", linestyle="--", linewidth=1, label="target")
        ax.set_title("VectorEnv: PD on two Models in parallel")
        ax.set_xlabel("time in the episode [s]")
        ax.legend(fontsize=8, loc="lower right")
    for ax in axes[0]:
        ax.grid(True, alpha=0.3)
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())

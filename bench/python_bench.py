#!/usr/bin/python3
"""The Python package's benchmarks (`launch/caliper bench python`), each measured in this one run
on a private session (caliper.LocalSession) with the shipped arm:

  RATIO python_vs_cpp_control_cycle  a lock-step control cycle (get 10 channels, set 2 commands,
                                     step 1) from Python / the same from the C++ client library
                                     (bench/control_cycle_bench), best of the rounds [target <= 1.3]
  RATIO python_record_values_per_s   values per second of a lossless record (Model.record) into
                                     numpy: 20,000 steps of every state channel (236 of the arm)
                                     [target >= 1,000,000]
  RATIO python_vector_env_2_vs_1     environment steps per second of a VectorEnv on 2 Models /
                                     a TendonEnv on 1 (20 physics steps per action) [target >= 1.8]
"""

import argparse
import os
import subprocess
import sys
import time

import numpy as np

import caliper

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
IDS = ["ecce_arm.elbow.position", "ecce_arm.elbow.velocity", "ecce_arm.shoulder_flexion.position",
       "ecce_arm.shoulder_flexion.velocity", "ecce_arm.wrist.position", "ecce_arm.wrist.velocity",
       "ecce_arm.elbow_flexor.tendon.tension", "ecce_arm.elbow_extensor.tendon.tension",
       "ecce_arm.elbow_flexor.current", "ecce_arm.elbow_extensor.current"]
ACTUATORS = ["elbow_flexor", "elbow_extensor"]


def ratio(name, value, target, ok):
    print(f"RATIO {name} {value:.3f} (target {target}){'' if ok else '  <- off target'}",
          flush=True)


def python_cycle_us(arm, cycles, rounds):
    a1, a2 = ACTUATORS
    best = float("inf")
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(cycles):
            v = arm.get_values(IDS)
            arm.set_commands({a1: 1.0 + 0.5 * v[0], a2: 1.0 - 0.5 * v[0]})
            arm.step(1)
        best = min(best, (time.perf_counter() - start) / cycles * 1e6)
    return best


def cpp_cycle_us(binary, session, cycles, rounds):
    out = subprocess.run([binary, session.address, "model0", str(cycles), str(rounds)] +
                         ACTUATORS + IDS, check=True, capture_output=True, text=True).stdout
    return float(out.split()[1])


def control_cycle(session, binary, cycles):
    arm = session.model("model0")
    missing = [i for i in IDS if not arm.channels(i)]
    if missing:
        sys.exit(f"the arm lacks {missing}")
    python_cycle_us(arm, 200, 1)  # warm-up
    py, cpp = [], []
    for _ in range(3):  # interleaved, so that both see the same machine
        cpp.append(cpp_cycle_us(binary, session, cycles, 1))
        py.append(python_cycle_us(arm, cycles, 1))
    print(f"control cycle: C++ {min(cpp):.1f} us, Python {min(py):.1f} us "
          f"(best of 3 rounds of {cycles} cycles)")
    value = min(py) / min(cpp)
    ratio("python_vs_cpp_control_cycle", value, "<= 1.3", value <= 1.3)


def record_rate(session, steps):
    arm = session.model("model0")
    arm.reset()
    ids = [c.id for c in arm.channels("*") if not c.static]  # the whole state
    arm.record(ids, steps=500)  # warm-up
    arm.reset()
    start = time.perf_counter()
    data = arm.record(ids, steps=steps)
    wall = time.perf_counter() - start
    values = data.values.size
    assert len(data) == steps and np.all(np.diff(data.time) > 0)
    print(f"record: {len(ids)} channels, {data.values.shape[1]} values per step, {steps} steps, "
          f"{values} values in {wall:.3f} s ({steps / wall:.0f} steps/s)")
    value = values / wall
    ratio("python_record_values_per_s", value, ">= 1000000", value >= 1e6)


def env_rate(session, seconds):
    kw = dict(actuators=ACTUATORS, observations=IDS, frames_per_action=20,
              max_episode_steps=10 ** 9, reward=lambda obs, action, env: -abs(obs[0] - 1.0))
    single = caliper.TendonEnv(session.model("model0"), session=session, **kw)
    vector = caliper.VectorEnv.across(session, **kw)
    rng = np.random.default_rng(1)

    def rate(step, n_envs, shape, window_s):
        count, start = 0, time.perf_counter()
        while time.perf_counter() - start < window_s:
            step(rng.uniform(0, 6, size=shape))
            count += n_envs
        return count / (time.perf_counter() - start)

    # this machine's speed drifts (a shared virtual machine): short windows of 1 and 2 Models
    # alternate, and the median of the windows' ratios is the figure
    single.reset(seed=1)
    vector.reset(seed=1)
    rounds = max(4, int(seconds / 2))
    one, two = [], []
    for _ in range(rounds):
        one.append(rate(single.step, 1, (2,), 1.0))
        two.append(rate(vector.step, 2, (2, 2), 1.0))
    vector.close()
    ratios = np.array(two) / np.array(one)
    print(f"environment: 1 Model {np.median(one):.0f} steps/s, 2 Models {np.median(two):.0f} "
          f"steps/s (medians of {rounds} alternating windows of 1 s; 20 physics steps of 1 ms "
          f"per action); window ratios {np.min(ratios):.2f} .. {np.max(ratios):.2f}")
    value = float(np.median(ratios))
    ratio("python_vector_env_2_vs_1", value, ">= 1.8", value >= 1.8)


def physics_reference(session):
    """What this machine gives two Model processes at all: 5,000 steps on one Model against
    5,000 on each of two at once (no client work between steps), the ceiling of the ratio
    above."""
    import threading
    a, b = session.model("model0"), session.model("model1")
    ratios = []
    for _ in range(3):
        a.reset()
        b.reset()
        start = time.perf_counter()
        a.step(5000)
        one = time.perf_counter() - start
        threads = [threading.Thread(target=m.step, args=(5000,)) for m in (a, b)]
        start = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        ratios.append(2 * one / (time.perf_counter() - start))
    print(f"reference: two Models stepping at once / one: {np.median(ratios):.2f} "
          f"(median of 3; the machine's ceiling for the environment ratio)")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cpp-cycle", required=True, help="bench/control_cycle_bench")
    parser.add_argument("--cycles", type=int, default=3000)
    parser.add_argument("--record-steps", type=int, default=20000)
    parser.add_argument("--env-seconds", type=float, default=10.0)
    args = parser.parse_args()
    with caliper.LocalSession(models=2, scene=SCENE) as session:
        control_cycle(session, args.cpp_cycle, args.cycles)
        record_rate(session, args.record_steps)
        env_rate(session, args.env_seconds)
        physics_reference(session)


if __name__ == "__main__":
    main()

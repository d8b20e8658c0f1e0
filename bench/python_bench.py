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

    def rate(step, reset, n_envs, shape):
        reset(seed=1)
        count, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            step(rng.uniform(0, 6, size=shape))
            count += n_envs
        return count / (time.perf_counter() - start)

    one, two = [], []
    for _ in range(2):
        one.append(rate(single.step, single.reset, 1, (2,)))
        two.append(rate(vector.step, vector.reset, 2, (2, 2)))
    vector.close()
    print(f"environment: 1 Model {max(one):.0f} steps/s, 2 Models {max(two):.0f} steps/s "
          f"(20 physics steps of 1 ms per action)")
    value = max(two) / max(one)
    ratio("python_vector_env_2_vs_1", value, ">= 1.8", value >= 1.8)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cpp-cycle", required=True, help="bench/control_cycle_bench")
    parser.add_argument("--cycles", type=int, default=3000)
    parser.add_argument("--record-steps", type=int, default=20000)
    parser.add_argument("--env-seconds", type=float, default=4.0)
    args = parser.parse_args()
    with caliper.LocalSession(models=2, scene=SCENE) as session:
        control_cycle(session, args.cpp_cycle, args.cycles)
        record_rate(session, args.record_steps)
        env_rate(session, args.env_seconds)


if __name__ == "__main__":
    main()
